// Entry point of the optimiser: solve(problem, options) -> Summary.
#pragma once

#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/problem.hpp"
#include "pdamp/optimizer/summary.hpp"

namespace pdamp::optimizer {

/// Minimise problem.objective in two named, timed stages (docs/optimizer.md):
///  1. global stage (Options::global_stage): NLopt GN_ISRES over the whole box,
///     seeded, constraints by stochastic ranking; it finds the smooth region of the
///     best basin, across cliffs;
///  2. local stage from the best point so far: NLopt SLSQP/COBYLA or Ipopt.
/// Throws std::invalid_argument for an invalid problem or options (every violation,
/// one a line) and, with Options::infeasible_is_error, when no point satisfies every
/// constraint (naming the most violated one). An exception thrown by a problem
/// function stops the solver and is rethrown unchanged.
Summary solve(const Problem& problem, const Options& options = {});

}  // namespace pdamp::optimizer
