// The analytic test problem of the optimiser, shaped like the layer problem: a smooth
// bowl on the good side of a cliff, a high plateau on the other, one constraint that
// cuts the bowl so that the optimum sits on the constraint, near the cliff.
#pragma once

#include "pdamp/optimizer/problem.hpp"

namespace pdamp::optimizer::test {

/// Cliff at x = 1 (the onset of the layer problem); the plateau stands for the
/// scattered state, the bowl for the smooth collect-and-collide branch.
inline constexpr double kCliffX = 1.0;
inline constexpr double kPlateauValue = 2.0;
/// Optimum: the bowl centre (1.5, 1) projected onto x + y = 1.8, 0.15 right of the cliff.
inline constexpr double kOptimumX = 1.15;
inline constexpr double kOptimumY = 0.65;
inline constexpr double kOptimumObjective = 2.0 * 0.35 * 0.35;

/// minimise f(x, y) = (x − 1.5)² + (y − 1)² for x >= 1, 2 for x < 1,
/// subject to x + y − 1.8 <= 0, (x, y) in [0, 3] × [-2, 2]; start on the plateau.
/// with_gradients = false leaves the gradients to forward differences.
inline Problem cliff_problem(bool with_gradients) {
  Problem problem;
  problem.variables = {{"x", "m", 0.0, 3.0, 0.5}, {"y", "m", -2.0, 2.0, 0.0}};
  problem.objective.name = "bowl_beyond_cliff";
  problem.objective.value = [](std::span<const double> x) {
    return x[0] >= kCliffX ? (x[0] - 1.5) * (x[0] - 1.5) + (x[1] - 1.0) * (x[1] - 1.0) : kPlateauValue;
  };
  Function cut{"cut", [](std::span<const double> x) { return x[0] + x[1] - 1.8; }, nullptr};
  if (with_gradients) {
    problem.objective.gradient = [](std::span<const double> x, std::span<double> gradient) {
      const bool bowl = x[0] >= kCliffX;
      gradient[0] = bowl ? 2.0 * (x[0] - 1.5) : 0.0;
      gradient[1] = bowl ? 2.0 * (x[1] - 1.0) : 0.0;
    };
    cut.gradient = [](std::span<const double>, std::span<double> gradient) {
      gradient[0] = 1.0;
      gradient[1] = 1.0;
    };
  }
  problem.constraints.push_back(cut);
  return problem;
}

}  // namespace pdamp::optimizer::test
