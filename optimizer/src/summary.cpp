// Reports of an optimiser Summary.
#include "pdamp/optimizer/summary.hpp"

#include <sstream>

namespace pdamp::optimizer {

std::string_view to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::kConverged: return "converged";
    case Outcome::kMaxEvaluations: return "max evaluations";
    case Outcome::kInfeasible: return "infeasible";
    case Outcome::kFailed: return "failed";
  }
  return "unknown";
}

std::string Summary::brief_report() const {
  std::ostringstream out;
  out.precision(10);
  out << to_string(backend) << ": " << to_string(outcome) << ", objective " << objective << ", max violation "
      << max_constraint_violation << ", " << evaluations << " evaluations, "
      << (stage_times.global_stage_s + stage_times.local_stage_s) << " s";
  return out.str();
}

std::string Summary::full_report() const {
  std::ostringstream out;
  out.precision(10);
  out << brief_report() << '\n';
  for (std::size_t j = 0; j < x.size(); ++j) {
    out << "  ";
    if (j < variable_names.size()) {
      out << variable_names[j];
    } else {
      out << 'x' << j;
    }
    out << " = " << x[j] << '\n';
  }
  out << "  iterations " << iterations << ", evaluations " << evaluations << " (global stage "
      << global_evaluations << "), gradients " << gradient_evaluations << '\n';
  out << "  global stage " << stage_times.global_stage_s << " s, local stage " << stage_times.local_stage_s
      << " s\n";
  if (!message.empty()) out << "  " << message << '\n';
  return out.str();
}

}  // namespace pdamp::optimizer
