// Outcome, counters, result and stage times of optimizer::solve.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "pdamp/optimizer/options.hpp"

namespace pdamp::optimizer {

enum class Outcome {
  kConverged,       ///< the local stage met its tolerances
  kMaxEvaluations,  ///< the evaluation (or Ipopt iteration) budget ran out first
  kInfeasible,      ///< no evaluated point satisfies every constraint (see message)
  kFailed,          ///< the solver gave up for another reason (see message)
};
/// "converged", "max evaluations", "infeasible", "failed".
std::string_view to_string(Outcome outcome);

struct StageTimes {
  double global_stage_s = 0.0;  ///< wall-clock time of the ISRES search (0 when off)
  double local_stage_s = 0.0;   ///< wall-clock time of the local refinement
};

struct Summary {
  Outcome outcome = Outcome::kFailed;
  /// The solver's own words and, when not converged, what to change.
  std::string message;
  Backend backend = Backend::kNlopt;
  /// Best point evaluated over both stages: the lowest objective among points whose
  /// constraints hold to Options::constraint_tolerance, or the least violating point.
  std::vector<double> x;
  double objective = 0.0;
  double max_constraint_violation = 0.0;  ///< max(0, max_i c_i(x)), in the unit of c
  /// Local stage iterations: Ipopt's iteration count; NLopt SLSQP's gradient requests
  /// (one per major iteration), COBYLA's evaluations (NLopt reports no iterations).
  int iterations = 0;
  int global_evaluations = 0;  ///< point evaluations of the global stage
  int evaluations = 0;         ///< point evaluations of both stages (FD points included)
  int gradient_evaluations = 0;
  std::vector<std::string> variable_names;  ///< for the reports
  StageTimes stage_times;

  /// One line: outcome, objective, violation, evaluations, time.
  std::string brief_report() const;
  /// Several lines: the brief report, each variable's value, the counters, stage times
  /// and the message.
  std::string full_report() const;
};

}  // namespace pdamp::optimizer
