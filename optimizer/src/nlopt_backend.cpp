// Private: NLopt stages (global GN_ISRES, local LD_SLSQP / LN_COBYLA) through NLopt's C
// API, so that our callbacks, not the C++ wrapper's, decide what crosses the C boundary.
#include <nlopt.h>

#include <exception>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>

#include "stages.hpp"

namespace pdamp::optimizer::detail {
namespace {

struct NloptDeleter {
  void operator()(nlopt_opt opt) const { nlopt_destroy(opt); }
};
using NloptHandle = std::unique_ptr<std::remove_pointer_t<nlopt_opt>, NloptDeleter>;

/// What the C callbacks see. An exception never leaves a callback (NLopt is C: an
/// exception through its frames is undefined behaviour); it is stored, the solver is
/// told to stop (nlopt_force_stop, NLopt reference "Forced termination"), and
/// run_algorithm rethrows it after nlopt_optimize has returned.
struct CallbackContext {
  explicit CallbackContext(Evaluator& evaluator_to_use) : evaluator(evaluator_to_use) {}
  Evaluator& evaluator;
  nlopt_opt opt = nullptr;
  std::exception_ptr error;
  int gradient_requests = 0;
  std::vector<double> unused_gradient;  ///< the half of Evaluator::gradients a callback does not return
  std::vector<double> unused_jacobian;
};

template <class Body>
void guarded(CallbackContext& context, Body&& body) {
  if (context.error) return;  // already stopping: evaluate nothing more
  try {
    body();
    if (context.evaluator.budget_exhausted()) nlopt_force_stop(context.opt);
  } catch (...) {
    context.error = std::current_exception();
    nlopt_force_stop(context.opt);
  }
}

double objective_callback(unsigned n, const double* x, double* gradient, void* data) {
  auto& context = *static_cast<CallbackContext*>(data);
  double value = std::numeric_limits<double>::quiet_NaN();
  guarded(context, [&] {
    const std::span<const double> point(x, n);
    value = context.evaluator.values(point).objective;
    if (gradient != nullptr) {
      ++context.gradient_requests;
      context.evaluator.gradients(point, std::span(gradient, n), context.unused_jacobian);
    }
  });
  return value;
}

/// NLopt's vector-valued inequality constraint (nlopt_add_inequality_mconstraint):
/// result[i] = c_i(x) <= 0, gradient[i·n + j] = ∂c_i/∂x_j.
void constraints_callback(unsigned m, double* result, unsigned n, const double* x, double* gradient, void* data) {
  auto& context = *static_cast<CallbackContext*>(data);
  guarded(context, [&] {
    const std::span<const double> point(x, n);
    const PointValues& values = context.evaluator.values(point);
    std::copy(values.constraints.begin(), values.constraints.end(), result);
    if (gradient != nullptr) {
      context.evaluator.gradients(point, context.unused_gradient, std::span(gradient, std::size_t{m} * n));
    }
  });
}

void require_ok(nlopt_result result, nlopt_opt opt, const char* call) {
  if (result < 0) {
    throw std::logic_error(std::string("NLopt ") + call + " failed: " + nlopt_result_to_string(result) + " (" +
                           (nlopt_get_errmsg(opt) ? nlopt_get_errmsg(opt) : "no message") + ")");
  }
}

/// An optimiser over the problem's bounds with its objective and constraints.
NloptHandle make_optimizer(nlopt_algorithm algorithm, CallbackContext& context, double constraint_tolerance) {
  const Problem& problem = context.evaluator.problem();
  const auto n = static_cast<unsigned>(context.evaluator.variable_count());
  const auto m = static_cast<unsigned>(context.evaluator.constraint_count());
  NloptHandle opt(nlopt_create(algorithm, n));
  if (!opt) throw std::bad_alloc();
  context.opt = opt.get();
  context.unused_gradient.resize(n);
  context.unused_jacobian.resize(std::size_t{m} * n);
  std::vector<double> lower(n), upper(n);
  for (unsigned j = 0; j < n; ++j) {
    lower[j] = problem.variables[j].lower;
    upper[j] = problem.variables[j].upper;
  }
  require_ok(nlopt_set_lower_bounds(opt.get(), lower.data()), opt.get(), "set_lower_bounds");
  require_ok(nlopt_set_upper_bounds(opt.get(), upper.data()), opt.get(), "set_upper_bounds");
  require_ok(nlopt_set_min_objective(opt.get(), objective_callback, &context), opt.get(), "set_min_objective");
  if (m > 0) {
    const std::vector<double> tolerances(m, constraint_tolerance);
    require_ok(nlopt_add_inequality_mconstraint(opt.get(), m, constraints_callback, &context, tolerances.data()),
               opt.get(), "add_inequality_mconstraint");
  }
  return opt;
}

/// Runs opt from start, rethrows a stored exception, maps nlopt_result onto Outcome.
StageResult run_algorithm(CallbackContext& context, const std::vector<double>& start) {
  std::vector<double> x = start;
  double best = 0.0;
  const nlopt_result result = nlopt_optimize(context.opt, x.data(), &best);
  if (context.error) std::rethrow_exception(context.error);
  StageResult stage;
  const std::string algorithm = nlopt_algorithm_name(nlopt_get_algorithm(context.opt));
  stage.message = "NLopt " + algorithm + ": " + nlopt_result_to_string(result);
  switch (result) {
    case NLOPT_SUCCESS:
    case NLOPT_STOPVAL_REACHED:
    case NLOPT_FTOL_REACHED:
    case NLOPT_XTOL_REACHED:
      stage.outcome = Outcome::kConverged;
      break;
    // NLopt reference: "Halted because roundoff errors limited progress. (In this case,
    // the optimization still typically returns a useful result.)"
    case NLOPT_ROUNDOFF_LIMITED:
      stage.outcome = Outcome::kConverged;
      break;
    case NLOPT_MAXEVAL_REACHED:
    case NLOPT_MAXTIME_REACHED:
    case NLOPT_FORCED_STOP:  // only our budget check forces a stop without an error
      stage.outcome = Outcome::kMaxEvaluations;
      stage.message += " (evaluation budget spent: raise max_evaluations)";
      break;
    default:
      stage.outcome = Outcome::kFailed;
      break;
  }
  return stage;
}

}  // namespace

void run_global_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options) {
  CallbackContext context(evaluator);
  // GN_ISRES (Runarsson & Yao, stochastic ranking): NLopt's global algorithm that takes
  // nonlinear inequality constraints without a penalty weight (DIRECT-L and CRS2 take
  // bounds only); population 20(n+1) by default. It has no reliable convergence test,
  // so the stage runs on its budget; the local stage does the converging.
  NloptHandle opt = make_optimizer(NLOPT_GN_ISRES, context, options.constraint_tolerance);
  nlopt_srand(options.seed);
  require_ok(nlopt_set_maxeval(opt.get(), options.global_evaluations), opt.get(), "set_maxeval");
  run_algorithm(context, start);
}

StageResult run_nlopt_local_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options) {
  CallbackContext context(evaluator);
  const bool slsqp = options.nlopt_local_algorithm == NloptLocalAlgorithm::kSlsqp;
  NloptHandle opt = make_optimizer(slsqp ? NLOPT_LD_SLSQP : NLOPT_LN_COBYLA, context, options.constraint_tolerance);
  // xtol_rel only: an ftol test stops COBYLA early on a flat valley floor (a short
  // step there changes f by less than ftol while x is still 1e-2 away).
  require_ok(nlopt_set_xtol_rel(opt.get(), options.relative_tolerance), opt.get(), "set_xtol_rel");
  StageResult stage = run_algorithm(context, start);
  stage.iterations = slsqp ? context.gradient_requests : nlopt_get_numevals(opt.get());
  return stage;
}

}  // namespace pdamp::optimizer::detail
