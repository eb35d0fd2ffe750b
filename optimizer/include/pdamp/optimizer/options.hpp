// Options of optimizer::solve: back end, stages, tolerances, budget, seed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pdamp::optimizer {

/// Which solver runs the local stage. Both start from the global stage's best point
/// when Options::global_stage is on (the NLopt ISRES search; for Ipopt this makes the
/// "hybrid": Ipopt is a local method, docs/optimizer.md).
enum class Backend {
  kNlopt,  ///< NLopt's local algorithm (Options::nlopt_local_algorithm)
  kIpopt,  ///< Ipopt 3.11 interior point, limited-memory (L-BFGS) Hessian
};
/// "nlopt", "ipopt".
std::string_view to_string(Backend backend);
/// Inverse of to_string; std::nullopt for anything else.
std::optional<Backend> backend_from_string(std::string_view name);

/// NLopt's local refinement (NLopt docs, "NLopt Algorithms").
enum class NloptLocalAlgorithm {
  /// LD_SLSQP: sequential quadratic programming with bounds and inequality constraints,
  /// using gradients (analytic or forward differences); superlinear near a smooth optimum.
  kSlsqp,
  /// LN_COBYLA: derivative-free, linear models of f and c in a trust region; slower, but
  /// needs no slope, for objectives with kinks (bilinear field lookups).
  kCobyla,
};
std::string_view to_string(NloptLocalAlgorithm algorithm);

struct Options {
  Backend backend = Backend::kNlopt;
  NloptLocalAlgorithm nlopt_local_algorithm = NloptLocalAlgorithm::kSlsqp;
  /// Run the global stage (NLopt GN_ISRES over the whole box) before the local stage.
  /// Off: the local stage starts from Variable::initial and may stop on the wrong side
  /// of a cliff (a flat plateau has zero slope).
  bool global_stage = true;
  /// Evaluations of the global stage, in [1, max_evaluations).
  int global_evaluations = 2000;
  /// Budget of both stages: point evaluations (f and every c at one x, finite-difference
  /// points included), >= 2. Ipopt checks it once per iteration, so it may be exceeded
  /// by one iteration's line search.
  int max_evaluations = 10000;
  /// Local stage stopping tolerance, dimensionless, in (0, 0.1]: NLopt xtol_rel (the
  /// relative change of x); Ipopt `tol` (its scaled optimality error).
  double relative_tolerance = 1e-8;
  /// c_i(x) <= constraint_tolerance counts as satisfied, in the unit of c_i, in (0, 1]:
  /// NLopt's constraint tolerance, Ipopt's `constr_viol_tol`, and the feasibility test
  /// of the result.
  double constraint_tolerance = 1e-8;
  /// Seed of NLopt's random generator (nlopt_srand) for the global stage: equal seeds
  /// give equal results.
  std::uint64_t seed = 20240611;
  /// true: a solve that finds no point satisfying every constraint throws
  /// std::invalid_argument naming the most violated constraint (bad input: the CLI
  /// exits 2); false: it returns Outcome::kInfeasible.
  bool infeasible_is_error = true;
  /// One line per violated rule ("max_evaluations = 0: must be >= 2"); empty if valid.
  std::vector<std::string> validate() const;
};

}  // namespace pdamp::optimizer
