// Summary of a DEM run: outcome names and reports.
#include "pdamp/dem_reference/summary.hpp"

#include <cstdio>
#include <sstream>

namespace pdamp::dem_reference {

std::string_view to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::kCompleted:
      return "completed";
    case Outcome::kUnstable:
      return "unstable";
    case Outcome::kFailed:
      return "failed";
  }
  return "failed";
}

double StageTimes::total() const {
  return integrate_s + neighbour_s + contact_forces_s + record_s;
}

std::string Summary::brief_report() const {
  std::ostringstream out;
  const double rate = wall_time_s > 0.0 ? static_cast<double>(particle_steps) / wall_time_s : 0.0;
  out << "DEM " << to_string(outcome) << ": " << steps << " steps of " << time_step_s << " s (" << simulated_time_s
      << " s simulated), " << particles << " particles, " << rate / 1e6 << " M particle-steps/s, " << wall_time_s
      << " s wall";
  return out.str();
}

std::string Summary::full_report() const {
  std::ostringstream out;
  out << brief_report() << "\n";
  out << "  neighbour rebuilds: " << neighbour_rebuilds << "\n";
  out << "  stage times (s): integrate " << stage_times.integrate_s << ", neighbours " << stage_times.neighbour_s
      << ", contact forces " << stage_times.contact_forces_s << ", record " << stage_times.record_s << "\n";
  if (!message.empty()) out << "  " << message << "\n";
  return out.str();
}

}  // namespace pdamp::dem_reference
