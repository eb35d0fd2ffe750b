// The co-simulation's results as records and its steady-state test (cosimulation_result.hpp).
#include "pdamp/structure/cosimulation_result.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pdamp::structure {

const base::Fields<CosimulationSweepCycle>& CosimulationSweepCycle::fields() {
  using C = CosimulationSweepCycle;
  static const auto f =
      base::Fields<C>()
          .field("time_s", &C::time_s, "s", "the cycle's middle")
          .field("frequency_hz", &C::frequency_hz, "Hz", "the cycle's mean frequency")
          .field("magnitude", &C::site_amplitude_per_excitation, "1 or m/N",
                 "first-harmonic amplitude of each damper's site per unit excitation", base::kPerOutput)
          .derived(
              "phase_deg",
              [](const C& c) {
                std::vector<double> phase;
                for (const auto& a : c.site_amplitudes_m) phase.push_back(std::arg(a) * 180.0 / std::numbers::pi);
                return phase;
              },
              "deg", "phase of each damper site's first harmonic", base::kPerOutput)
          .field("bed_eta_star", &C::bed_reduced_loss_factor, "1", "each bed's reduced loss factor in the cycle",
                 base::kPerOutput | base::kNullable)
          .field("bed_apparent_mass_fraction", &C::bed_apparent_mass_fraction, "1",
                 "each bed's apparent mass over its mass in the cycle", base::kPerOutput | base::kNullable);
  return f;
}

AmplitudeWindow amplitude_window(const std::vector<double>& period_amplitudes, std::size_t window) {
  AmplitudeWindow out;
  const std::size_t n = period_amplitudes.size(), w = std::min(window, n);
  if (w < 2) return out;
  const auto first = period_amplitudes.end() - static_cast<std::ptrdiff_t>(w);
  double mean = 0.0;
  for (auto it = first; it != period_amplitudes.end(); ++it) mean += *it;
  mean /= static_cast<double>(w);
  if (!(mean > 0.0)) return out;
  double change = 0.0, ss = 0.0;
  for (auto it = first; it != period_amplitudes.end(); ++it) {
    ss += (*it - mean) * (*it - mean);
    if (it != first) change = std::max(change, std::abs(*it - *(it - 1)));
  }
  out.periods = static_cast<int>(w);
  out.max_relative_change = change / mean;
  out.relative_drift = std::abs(period_amplitudes.back() - *first) / mean;
  out.relative_spread = std::sqrt(ss / static_cast<double>(w - 1)) / mean;
  return out;
}

bool amplitudes_converged(const AmplitudeWindow& w, double tolerance, std::size_t window) {
  return w.periods >= static_cast<int>(window) && w.max_relative_change <= tolerance && w.relative_drift <= tolerance;
}

}  // namespace pdamp::structure
