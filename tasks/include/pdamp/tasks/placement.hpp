// Task kind placement (pdamp optimize, pdamp run): the site along a beam, or among named
// points, where one damper adds the most damping to the target modes at their stated
// amplitudes; the damping per target mode there and at the case's own site; with `verify`,
// the DEM-in-the-loop decay of each target mode at the chosen site and at one other.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/base/run_hooks.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/placement.hpp"
#include "pdamp/tasks/mode_decay.hpp"

namespace pdamp::tasks {

struct PlacementOptions {
  case_file::LossMethod method = case_file::LossMethod::kFormulas;  ///< formulas or field
  std::optional<optimizer::Backend> backend;  ///< the beam's local refinement; default: the task's
  bool skip_verify = false;   ///< the placement only, even with the task's verify block
  bool force_verify = false;  ///< verify with the defaults when the task has no verify block
};

struct PlacementSiteCheck {
  std::string role;                    ///< "chosen" or "other"
  optimizer::PlacementPoint predicted; ///< the placement's evaluation of the site (ζ_add at the stated amplitude)
  std::vector<ModeDecayCheck> modes;  ///< in the order of the targets
  double predicted_objective = NAN;    ///< the objective of the modes' decay ζ_add, predicted
  double dem_objective = NAN;          ///< the same by the DEM
  double relative_difference = NAN;    ///< (predicted − DEM)/DEM of the objective
  static const base::Fields<PlacementSiteCheck>& fields();
};

struct PlacementVerification {
  case_file::PlacementVerifySpec settings;
  std::vector<PlacementSiteCheck> sites;  ///< the chosen site, then the other
  bool chosen_agrees = false;   ///< the chosen site's DEM objective within tolerance of the prediction
  bool ranking_agrees = false;  ///< the DEM's objective larger at the chosen site than at the other
  bool passed = false;          ///< chosen_agrees, and ranking_agrees where require_ranking
  static const base::Fields<PlacementVerification>& fields();
};

struct PlacementStudy {
  std::string case_name;
  case_file::LossMethod method = case_file::LossMethod::kFormulas;
  std::string damper;
  optimizer::PlacementObjective objective = optimizer::PlacementObjective::kWeightedMean;
  bool beam = false;  ///< searched along a beam (else among named points)
  optimizer::PlacementResult result;
  std::optional<PlacementVerification> verification;
  std::vector<std::string> warnings;
};

/// The placement study of a case whose task is kind placement, on the primary process alone
/// (on another: base::JobsServedElsewhere); with the verification, the DEM decays report
/// through `hooks`.
PlacementStudy run_placement(const case_file::Case& c, const PlacementOptions& options,
                             base::RunHooks& hooks = base::silent_hooks(),
                             base::Executor& executor = base::local_executor());
/// The result keys (task, case, method, damper, objective, design, current, solver, ...).
nlohmann::json to_json(const PlacementStudy& study);

}  // namespace pdamp::tasks
