// Private: the Ipopt local stage: the problem as an Ipopt::TNLP, constraints as
// constraints (g(x) = c(x) in (-inf, 0]), exact or finite-difference first
// derivatives from the Evaluator, and a limited-memory (L-BFGS) Hessian.
#include <coin/IpIpoptApplication.hpp>
#include <coin/IpTNLP.hpp>

#include <cmath>
#include <exception>
#include <limits>
#include <span>
#include <sstream>
#include <string>

#include "stages.hpp"

namespace pdamp::optimizer::detail {
namespace {

using Ipopt::Index;
using Ipopt::Number;

/// An exception never leaves a TNLP method (Ipopt's C++ code would report it as
/// NonIpopt_Exception_Thrown and lose it): it is stored, the evaluation answers false
/// and intermediate_callback answers false, which stops Ipopt with User_Requested_Stop
/// (Ipopt docs, TNLP::intermediate_callback); run_ipopt_local_stage rethrows it.
class TnlpAdapter : public Ipopt::TNLP {
 public:
  TnlpAdapter(Evaluator& evaluator, const std::vector<double>& start)
      : evaluator_(evaluator),
        start_(start),
        unused_gradient_(evaluator.variable_count()),
        unused_jacobian_(evaluator.variable_count() * evaluator.constraint_count()) {}

  const std::exception_ptr& error() const { return error_; }
  int iterations() const { return iterations_; }

  bool get_nlp_info(Index& n, Index& m, Index& nonzeros_jacobian, Index& nonzeros_hessian,
                    IndexStyleEnum& index_style) override {
    n = static_cast<Index>(evaluator_.variable_count());
    m = static_cast<Index>(evaluator_.constraint_count());
    nonzeros_jacobian = n * m;  // dense
    nonzeros_hessian = 0;       // limited-memory: eval_h is never called
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_lower, Number* x_upper, Index m, Number* g_lower,
                       Number* g_upper) override {
    const auto& variables = evaluator_.problem().variables;
    for (Index j = 0; j < n; ++j) {
      // ±infinity lies beyond nlp_lower_bound_inf / nlp_upper_bound_inf (±1e19): no bound.
      x_lower[j] = variables[j].lower;
      x_upper[j] = variables[j].upper;
    }
    for (Index i = 0; i < m; ++i) {
      g_lower[i] = -std::numeric_limits<double>::infinity();
      g_upper[i] = 0.0;
    }
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    if (init_x) std::copy(start_.begin(), start_.begin() + n, x);
    return true;
  }

  bool eval_f(Index n, const Number* x, bool, Number& value) override {
    return guarded([&] { value = evaluator_.values(point(n, x)).objective; });
  }

  bool eval_grad_f(Index n, const Number* x, bool, Number* gradient) override {
    return guarded([&] { evaluator_.gradients(point(n, x), std::span(gradient, n), unused_jacobian_); });
  }

  bool eval_g(Index n, const Number* x, bool, Index, Number* g) override {
    return guarded([&] {
      const PointValues& values = evaluator_.values(point(n, x));
      std::copy(values.constraints.begin(), values.constraints.end(), g);
    });
  }

  bool eval_jac_g(Index n, const Number* x, bool, Index m, Index nonzeros, Index* rows, Index* columns,
                  Number* values) override {
    if (values == nullptr) {  // structure only: dense, row-major
      for (Index k = 0; k < nonzeros; ++k) {
        rows[k] = k / n;
        columns[k] = k % n;
      }
      return true;
    }
    return guarded([&] {
      evaluator_.gradients(point(n, x), unused_gradient_, std::span(values, static_cast<std::size_t>(n) * m));
    });
  }

  bool intermediate_callback(Ipopt::AlgorithmMode, Index iteration, Number, Number, Number, Number, Number, Number,
                             Number, Number, Index, const Ipopt::IpoptData*,
                             Ipopt::IpoptCalculatedQuantities*) override {
    iterations_ = iteration;
    return !error_ && !evaluator_.budget_exhausted();
  }

  void finalize_solution(Ipopt::SolverReturn, Index, const Number*, const Number*, const Number*, Index,
                         const Number*, const Number*, Number, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {}  // the result is evaluator_.incumbent()

 private:
  static std::span<const double> point(Index n, const Number* x) { return {x, static_cast<std::size_t>(n)}; }

  template <class Body>
  bool guarded(Body&& body) {
    if (error_) return false;
    try {
      body();
      return true;
    } catch (...) {
      error_ = std::current_exception();
      return false;
    }
  }

  Evaluator& evaluator_;
  const std::vector<double>& start_;
  std::vector<double> unused_gradient_;  ///< the half of Evaluator::gradients a method does not return
  std::vector<double> unused_jacobian_;
  std::exception_ptr error_;
  int iterations_ = 0;
};

std::string status_text(Ipopt::ApplicationReturnStatus status) {
  switch (status) {
    case Ipopt::Solve_Succeeded: return "Solve_Succeeded";
    case Ipopt::Solved_To_Acceptable_Level: return "Solved_To_Acceptable_Level";
    case Ipopt::Infeasible_Problem_Detected: return "Infeasible_Problem_Detected";
    case Ipopt::Search_Direction_Becomes_Too_Small: return "Search_Direction_Becomes_Too_Small";
    case Ipopt::Diverging_Iterates: return "Diverging_Iterates";
    case Ipopt::User_Requested_Stop: return "User_Requested_Stop";
    case Ipopt::Feasible_Point_Found: return "Feasible_Point_Found";
    case Ipopt::Maximum_Iterations_Exceeded: return "Maximum_Iterations_Exceeded";
    case Ipopt::Restoration_Failed: return "Restoration_Failed";
    case Ipopt::Error_In_Step_Computation: return "Error_In_Step_Computation";
    case Ipopt::Maximum_CpuTime_Exceeded: return "Maximum_CpuTime_Exceeded";
    case Ipopt::Not_Enough_Degrees_Of_Freedom: return "Not_Enough_Degrees_Of_Freedom";
    case Ipopt::Invalid_Problem_Definition: return "Invalid_Problem_Definition";
    case Ipopt::Invalid_Option: return "Invalid_Option";
    case Ipopt::Invalid_Number_Detected: return "Invalid_Number_Detected";
    case Ipopt::Unrecoverable_Exception: return "Unrecoverable_Exception";
    case Ipopt::NonIpopt_Exception_Thrown: return "NonIpopt_Exception_Thrown";
    case Ipopt::Insufficient_Memory: return "Insufficient_Memory";
    case Ipopt::Internal_Error: return "Internal_Error";
  }
  return "status " + std::to_string(static_cast<int>(status));
}

Outcome outcome_of(Ipopt::ApplicationReturnStatus status) {
  switch (status) {
    case Ipopt::Solve_Succeeded:
    case Ipopt::Solved_To_Acceptable_Level:
    // Ipopt stops when the step is below roundoff of x: with finite-difference slopes
    // this happens at the optimum, as NLopt's ROUNDOFF_LIMITED does.
    case Ipopt::Search_Direction_Becomes_Too_Small:
      return Outcome::kConverged;
    case Ipopt::Infeasible_Problem_Detected:
      return Outcome::kInfeasible;
    case Ipopt::User_Requested_Stop:  // our budget check (errors are rethrown first)
    case Ipopt::Maximum_Iterations_Exceeded:
    case Ipopt::Maximum_CpuTime_Exceeded:
      return Outcome::kMaxEvaluations;
    default:
      return Outcome::kFailed;
  }
}

}  // namespace

StageResult run_ipopt_local_stage(Evaluator& evaluator, const std::vector<double>& start, const Options& options) {
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  const Ipopt::SmartPtr<Ipopt::OptionsList> ipopt_options = app->Options();
  ipopt_options->SetStringValue("sb", "yes");  // no banner on stdout (DEPENDENCIES.md)
  ipopt_options->SetIntegerValue("print_level", 0);
  // Only first derivatives exist (analytic or differences): L-BFGS Hessian of the
  // Lagrangian (Ipopt options, "hessian_approximation").
  ipopt_options->SetStringValue("hessian_approximation", "limited-memory");
  ipopt_options->SetNumericValue("tol", options.relative_tolerance);
  ipopt_options->SetNumericValue("constr_viol_tol", options.constraint_tolerance);
  // An iteration costs at least one evaluation: the budget bounds the iterations too.
  ipopt_options->SetIntegerValue("max_iter", options.max_evaluations);
  // Ipopt relaxes the bounds by 1e-8 relative by default; 0 keeps every evaluation
  // inside [lower, upper], where the problem functions are defined (h > 0).
  ipopt_options->SetNumericValue("bound_relax_factor", 0.0);
  std::istringstream no_options_file;  // Initialize() would otherwise read ./ipopt.opt
  Ipopt::ApplicationReturnStatus status = app->Initialize(no_options_file);
  StageResult stage;
  if (status != Ipopt::Solve_Succeeded) {
    stage.message = "Ipopt initialisation failed: " + status_text(status);
    return stage;
  }
  const Ipopt::SmartPtr<TnlpAdapter> adapter = new TnlpAdapter(evaluator, start);
  status = app->OptimizeTNLP(adapter);
  if (adapter->error()) std::rethrow_exception(adapter->error());
  stage.outcome = outcome_of(status);
  stage.iterations = adapter->iterations();
  stage.message = "Ipopt: " + status_text(status);
  if (stage.outcome == Outcome::kMaxEvaluations) stage.message += " (budget spent: raise max_evaluations)";
  return stage;
}

}  // namespace pdamp::optimizer::detail
