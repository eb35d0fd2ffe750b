// Private helpers of the structure tasks (modes, frf, decay, the verification): a case's
// structure and dampers built for a loss method with their warnings, the solvers' refusals
// as the case's errors.
#pragma once

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "pdamp/case_file/filling_ratio_problem.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/base/input_error.hpp"
#include "task_support.hpp"

namespace pdamp::tasks::detail {

/// The case's structure and dampers, built for `method`, with the setup's warnings.
struct Setup {
  case_file::LossMethod method;
  case_file::StructureSetup s;
  Warnings warnings;
};

/// `rotation_check`: warn where a site rotates (the loss models assume pure translation;
/// the DEM co-simulation turns the container with the site and needs no such warning).
Setup make_setup(const case_file::Case& c, case_file::LossMethod method, bool rotation_check = true);
std::vector<std::string> damper_names(const Setup& setup);
std::vector<std::string> layer_names(const Setup& setup);

/// A structure solver's std::invalid_argument is a property of the case: InputError naming
/// the case file and `pointer`.
template <class F>
auto call_solver(const case_file::Case& c, const std::string& pointer, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, pointer, e.what());
  }
}

/// The case's dampers as co-simulation dampers (their beds as DEM worlds).
std::vector<structure::CosimulationDamper> dem_dampers(const case_file::Case& c);

/// The co-simulation options refused as the case's: /task for the run's own, /dampers/d for a damper's.
void check_cosimulation(const case_file::Case& c, const structure::ModalModel& modal,
                        const std::vector<structure::CosimulationDamper>& dampers, const structure::CosimulationRun& run);

/// The DEM's refusal of its options (a step above its bound) as the case's /dem.
template <class F>
auto call_dem(const case_file::Case& c, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw base::InputError(c.path, "/dem", what);
  }
}

/// A co-simulation that stopped: base::NumericalError with the advice on the case keys to change.
void check_outcome(dem_reference::Outcome outcome, const std::string& message, const std::string& label);

/// A filling-ratio design's modal model and release state (from rest at q(0)).
struct DesignModes {
  structure::ModalModel modal;
  Eigen::VectorXd initial_modal_displacements;
};

/// The modes of the design of whole `slabs`: under axial gravity its own beds' weights load
/// the beam's geometric stiffness (the beam analysed anew with them, and the static release
/// computed on it); otherwise the modes do not depend on the beds and are the problem's, exactly.
DesignModes design_modes(const case_file::Case& c, const case_file::FillingRatioProblem& p,
                         const std::vector<long>& slabs);

}  // namespace pdamp::tasks::detail
