// Task kind placement (pdamp optimize, pdamp run): the site along a beam, or among named
// points, where one damper adds the most damping to the target modes at their stated
// amplitudes; the damping per target mode there and at the case's own site.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/placement.hpp"

namespace pdamp::tasks {

struct PlacementOptions {
  case_file::LossMethod method = case_file::LossMethod::kFormulas;  ///< formulas or field
  std::optional<optimizer::Backend> backend;  ///< the beam's local refinement; default: the task's
};

struct PlacementStudy {
  std::string case_name;
  case_file::LossMethod method = case_file::LossMethod::kFormulas;
  std::string damper;
  optimizer::PlacementObjective objective = optimizer::PlacementObjective::kWeightedMean;
  bool beam = false;  ///< searched along a beam (else among named points)
  optimizer::PlacementResult result;
  std::vector<std::string> warnings;
};

/// The placement study of a case whose task is kind placement, on the primary process alone
/// (on another: base::JobsServedElsewhere).
PlacementStudy run_placement(const case_file::Case& c, const PlacementOptions& options,
                             base::Executor& executor = base::local_executor());
/// The result keys (task, case, method, damper, objective, design, current, solver, ...).
nlohmann::json to_json(const PlacementStudy& study);

}  // namespace pdamp::tasks
