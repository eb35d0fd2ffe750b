// The optimiser's problem of a `filling_ratios` case (docs/optimizer.md): the candidates
// from the first damper's layers, the modal model, the decay and the budget; used by
// pdamp optimize and by the benchmark, so both optimise the same thing.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/case_file/case.hpp"
#include "pdamp/optimizer/filling_ratios.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::case_file {

struct FillingRatioProblem {
  structure::ModalModel modal;
  optimizer::FillingRatioOptions options;
  Eigen::VectorXd initial_modal_displacements;  ///< q(0), signed (the DEM verification releases from it)
  std::vector<std::string> warnings;
};

/// The problem of the case's filling_ratios task (which must be present). Throws CaseError
/// naming /task for options the optimiser refuses and for an initial state exciting no mode.
FillingRatioProblem filling_ratio_problem(const Case& c);

}  // namespace pdamp::case_file
