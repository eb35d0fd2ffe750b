// Private: evaluates a Problem for the back ends: f and every c at one point (cached),
// gradients (analytic or forward differences), the best point so far and the budget.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pdamp/optimizer/problem.hpp"

namespace pdamp::optimizer::detail {

/// f and every c at one point.
struct PointValues {
  double objective = 0.0;
  std::vector<double> constraints;
  double max_violation = 0.0;  ///< max(0, max_i c_i)
};

/// Best point evaluated so far (rule: Summary::x).
struct Incumbent {
  std::vector<double> x;  ///< empty until the first evaluation
  PointValues values;
  bool feasible = false;
};

class Evaluator {
 public:
  /// problem must be valid (Problem::validate); it must outlive the evaluator.
  Evaluator(const Problem& problem, double constraint_tolerance);

  std::size_t variable_count() const { return problem_.variables.size(); }
  std::size_t constraint_count() const { return problem_.constraints.size(); }
  const Problem& problem() const { return problem_; }

  /// f and every c at x; evaluating the same x again costs nothing.
  const PointValues& values(std::span<const double> x);
  /// ∇f (n values) and the constraint Jacobian (m×n, row-major: [i·n + j] = ∂c_i/∂x_j)
  /// at x; analytic gradients where the problem gives them, forward differences for
  /// the rest (one sweep of n extra points serves every function without a gradient).
  void gradients(std::span<const double> x, std::span<double> objective_gradient,
                 std::span<double> constraint_jacobian);

  /// Point evaluations allowed before budget_exhausted() turns true (cumulative).
  void set_evaluation_limit(std::int64_t limit) { evaluation_limit_ = limit; }
  bool budget_exhausted() const { return evaluations_ >= evaluation_limit_; }
  std::int64_t evaluations() const { return evaluations_; }
  std::int64_t gradient_evaluations() const { return gradient_evaluations_; }
  const Incumbent& incumbent() const { return incumbent_; }
  bool is_feasible(const PointValues& values) const {
    return values.max_violation <= constraint_tolerance_;
  }

 private:
  /// Evaluates f and every c at x into out, counts it and updates the incumbent.
  void evaluate_point(std::span<const double> x, PointValues& out);
  void update_incumbent(std::span<const double> x, const PointValues& values);

  const Problem& problem_;
  double constraint_tolerance_;
  std::int64_t evaluation_limit_ = INT64_MAX;
  std::int64_t evaluations_ = 0;
  std::int64_t gradient_evaluations_ = 0;
  std::vector<double> cached_x_;  ///< point of cached_values_ (empty: none)
  PointValues cached_values_;
  std::vector<double> cached_gradient_x_;  ///< point of the cached derivatives
  std::vector<double> cached_objective_gradient_;
  std::vector<double> cached_jacobian_;
  std::vector<double> perturbed_x_;  ///< finite-difference scratch
  PointValues perturbed_values_;
  Incumbent incumbent_;
};

/// "(0.5, 1.25)": a point for messages.
std::string format_point(std::span<const double> x);

}  // namespace pdamp::optimizer::detail
