// The optimiser's problem of a `placement` case (docs/optimizer.md, "Placement"): the
// damper to place with its loss models, the targets, and either the beam it moves along or
// the named points it is compared at; used by pdamp optimize.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/optimizer/placement.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::case_file {

struct PlacementProblem {
  optimizer::PlacementOptions options;
  /// A beam searched continuously (no candidate_points); its beam carries the other
  /// dampers' weights, the placed one's goes with the site (carried_mass_kg).
  std::optional<optimizer::BeamPlacement> beam;
  std::optional<double> current_position_m;  ///< beam: the case's own site along the axis, m
  structure::ModalModel modal;               ///< the case's modal model (candidate points are compared on it)
  std::vector<std::string> candidate_points; ///< the named points compared (empty: the beam search)
  std::vector<std::string> warnings;
};

/// The problem of the case's placement task (which must be present), its layers' loss models
/// by `method`. CaseError naming /task for options the optimiser refuses.
PlacementProblem placement_problem(const Case& c, LossMethod method);

}  // namespace pdamp::case_file
