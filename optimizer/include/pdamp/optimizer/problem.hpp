// Problem description shared by every optimiser back end: bounded variables, an
// objective to minimise and inequality constraints c(x) <= 0 (docs/optimizer.md).
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

namespace pdamp::optimizer {

/// A scalar function of the design variables x (in the order of Problem::variables).
using ScalarFunction = std::function<double(std::span<const double> x)>;
/// Writes ∂f/∂x_j into gradient[j] (gradient.size() == x.size()).
using GradientFunction = std::function<void(std::span<const double> x, std::span<double> gradient)>;

/// One design variable, lower <= initial <= upper. A bound may be ±infinity only when
/// the global stage is off (Options::global_stage): the global search needs a box.
struct Variable {
  std::string name;  ///< unique, non-empty; errors and reports name it ("clearance_m")
  std::string unit;  ///< for reports only ("m"; "" when dimensionless)
  double lower = 0.0;
  double upper = 0.0;
  double initial = 0.0;  ///< start of the local stage when the global stage is off
};

/// A function with an optional analytic gradient. Without one, the gradient is taken
/// by forward differences (step rule: finite_difference_step()).
struct Function {
  std::string name;  ///< unique among the constraints, non-empty; errors name it
  ScalarFunction value;
  GradientFunction gradient;  ///< empty: forward differences
};

/// Minimise objective(x) subject to lower <= x <= upper and constraints[i](x) <= 0.
/// Functions must return finite values inside the bounds (std::domain_error otherwise,
/// naming the function and the point); they may throw, and the exception leaves
/// solve() unchanged after the solver has been stopped.
struct Problem {
  std::vector<Variable> variables;
  Function objective;
  std::vector<Function> constraints;
  /// One line per violated rule, naming the variable or function
  /// ("variable 'clearance_m': lower = 0.05 > upper = 0.01"); empty if valid.
  std::vector<std::string> validate() const;
};

/// Signed forward-difference step of a variable at value x (Nocedal & Wright, Numerical
/// Optimization, 2nd ed., §8.1: h = √ε_mach · scale balances truncation and rounding):
///   h = √ε · max(|x|, upper − lower)   (upper − lower replaced by 1 when not finite),
/// rounded so that x + h is a double exactly h away; negative (backwards) when
/// x + h > upper, so that no point leaves the bounds (the side with more room when
/// neither fits). 0 for a fixed variable (lower == upper): its slope is taken as 0. A step that straddles a
/// discontinuity (the onset cliff) gives a meaningless slope: local stages are meant
/// to run inside one smooth region (docs/optimizer.md).
double finite_difference_step(const Variable& variable, double x);

/// Largest disagreement between the analytic gradients of a problem and forward
/// differences at x (the Ceres GradientChecker idea): for every function that has a
/// gradient, |g_analytic − g_fd| / max(|g_analytic|, |g_fd|, 1) per component.
struct GradientCheck {
  double max_error = 0.0;  ///< dimensionless; ~1e-7 for a correct gradient of O(1) curvature
  std::string worst;       ///< "constraint 'margin' d/d(clearance_m)"; empty: no analytic gradient
};
/// x must lie inside the bounds (std::invalid_argument otherwise, and for an invalid problem).
GradientCheck check_gradients(const Problem& problem, std::span<const double> x);

}  // namespace pdamp::optimizer
