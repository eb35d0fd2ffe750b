// solve(): validation, the global and local stages (timed), the result and its outcome.
#include "pdamp/optimizer/solve.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "evaluator.hpp"
#include "stages.hpp"
#include "pdamp/base/number_text.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {
namespace {

std::vector<std::string> global_stage_violations(const Problem& problem) {
  std::vector<std::string> problems;
  for (const Variable& variable : problem.variables) {
    if (!std::isfinite(variable.lower) || !std::isfinite(variable.upper)) {
      problems.push_back("variable '" + variable.name + "': bounds [" + base::format_number(variable.lower, 10) + ", " +
                         base::format_number(variable.upper, 10) +
                         "]: must be finite for the global stage (or set global_stage = false)");
    }
  }
  return problems;
}

/// Adds the wall-clock time of its scope to seconds (also when a stage throws).
class StageTimer {
 public:
  explicit StageTimer(double& seconds) : seconds_(seconds), start_(std::chrono::steady_clock::now()) {}
  ~StageTimer() { seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double& seconds_;
  std::chrono::steady_clock::time_point start_;
};

/// "constraint 'margin' cannot be met within the bounds: ..." for the least violating point.
std::string infeasibility_message(const Problem& problem, const detail::Incumbent& best, const Options& options,
                                  std::int64_t evaluations) {
  std::size_t worst = 0;
  for (std::size_t i = 1; i < best.values.constraints.size(); ++i) {
    if (best.values.constraints[i] > best.values.constraints[worst]) worst = i;
  }
  return "constraint '" + problem.constraints[worst].name +
         "' cannot be met within the bounds: the least violating of " + std::to_string(evaluations) +
         " points evaluated has c = " + base::format_number(best.values.constraints[worst], 10) +
         " > constraint_tolerance = " + base::format_number(options.constraint_tolerance, 10) +
         " at x = " + detail::format_point(best.x);
}

}  // namespace

Summary solve(const Problem& problem, const Options& options) {
  detail::throw_if_invalid(problem.validate(), "optimisation problem");
  detail::throw_if_invalid(options.validate(), "optimiser options");
  if (options.global_stage) detail::throw_if_invalid(global_stage_violations(problem), "optimisation problem");

  Summary summary;
  summary.backend = options.backend;
  std::vector<double> start;
  for (const Variable& variable : problem.variables) {
    summary.variable_names.push_back(variable.name);
    start.push_back(variable.initial);
  }
  detail::Evaluator evaluator(problem, options.constraint_tolerance);
  if (options.global_stage) {
    evaluator.set_evaluation_limit(options.global_evaluations);
    {
      const StageTimer timer(summary.stage_times.global_stage_s);
      detail::run_global_stage(evaluator, start, options);
    }
    summary.global_evaluations = static_cast<int>(evaluator.evaluations());
    start = evaluator.incumbent().x;
  }
  evaluator.set_evaluation_limit(options.max_evaluations);
  detail::StageResult local;
  {
    const StageTimer timer(summary.stage_times.local_stage_s);
    local = options.backend == Backend::kIpopt ? detail::run_ipopt_local_stage(evaluator, start, options)
                                               : detail::run_nlopt_local_stage(evaluator, start, options);
  }

  const detail::Incumbent& best = evaluator.incumbent();
  summary.x = best.x;
  summary.objective = best.values.objective;
  summary.max_constraint_violation = best.values.max_violation;
  summary.iterations = local.iterations;
  summary.evaluations = static_cast<int>(evaluator.evaluations());
  summary.gradient_evaluations = static_cast<int>(evaluator.gradient_evaluations());
  if (!best.feasible) {
    summary.outcome = Outcome::kInfeasible;
    summary.message = infeasibility_message(problem, best, options, evaluator.evaluations());
    if (options.infeasible_is_error) throw std::invalid_argument(summary.message);
  } else if (local.outcome == Outcome::kInfeasible) {
    // A local method can report local infeasibility while a feasible point is known.
    summary.outcome = Outcome::kFailed;
    summary.message = local.message + "; the best feasible point evaluated is returned";
  } else {
    summary.outcome = local.outcome;
    summary.message = local.message;
  }
  return summary;
}

}  // namespace pdamp::optimizer
