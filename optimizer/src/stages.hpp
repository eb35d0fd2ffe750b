// Private: the stages of solve() as run by each back end.
#pragma once

#include <string>
#include <vector>

#include "evaluator.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/summary.hpp"

namespace pdamp::optimizer::detail {

/// How a stage ended, in the solver's terms mapped onto Outcome.
struct StageResult {
  Outcome outcome = Outcome::kFailed;
  int iterations = 0;
  std::string message;
};

// Each stage starts from start (inside the bounds), evaluates through evaluator until
// its budget (Evaluator::set_evaluation_limit, set by the caller) is spent or it stops,
// and rethrows an exception of a problem function once the solver has returned. The
// result point is evaluator.incumbent().

/// NLopt GN_ISRES over the whole box (finite bounds), Options::global_evaluations
/// evaluations, seeded with Options::seed. It always runs on its budget, so how it
/// ended says nothing: only its best point (the incumbent) matters.
void run_global_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options);
/// NLopt LD_SLSQP or LN_COBYLA (Options::nlopt_local_algorithm).
StageResult run_nlopt_local_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options);
/// Ipopt with a limited-memory Hessian, constraints as constraints.
StageResult run_ipopt_local_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options);

}  // namespace pdamp::optimizer::detail
