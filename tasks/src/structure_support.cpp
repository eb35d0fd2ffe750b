// Private helpers of the structure tasks (structure_support.hpp).
#include "structure_support.hpp"

#include "pdamp/base/run_errors.hpp"
#include "pdamp/structure/damper_coupling.hpp"

namespace pdamp::tasks::detail {

Setup make_setup(const case_file::Case& c, case_file::LossMethod method, bool rotation_check) {
  Setup out{method, case_file::structure_setup(c, method), {}};
  out.warnings.add(out.s.warnings);
  if (rotation_check) out.warnings.add(structure::rotation_warnings(out.s.modal, out.s.dampers));
  if (out.s.rigid_modes_dropped > 0)
    out.warnings.add("the structure has " + std::to_string(out.s.rigid_modes_dropped) +
                     " rigid-body mode(s) at 0 Hz; they are not kept (docs/structures.md)");
  return out;
}

std::vector<std::string> damper_names(const Setup& setup) {
  std::vector<std::string> names;
  for (const auto& d : setup.s.dampers) names.push_back(d.name);
  return names;
}

std::vector<std::string> layer_names(const Setup& setup) {
  std::vector<std::string> names;
  for (const auto& d : setup.s.dampers)
    for (const auto& l : d.layers) names.push_back(d.name + "/" + l.name);
  return names;
}

std::vector<structure::CosimulationDamper> dem_dampers(const case_file::Case& c) {
  std::vector<structure::CosimulationDamper> out;
  for (std::size_t d = 0; d < c.dampers.size(); ++d) out.push_back(case_file::cosimulation_damper(c, d));
  return out;
}

void check_cosimulation(const case_file::Case& c, const structure::ModalModel& modal,
                        const std::vector<structure::CosimulationDamper>& dampers, const structure::CosimulationRun& run) {
  if (const auto problems = structure::validate(run, modal); !problems.empty())
    throw base::InputError(c.path, "/task", problems.front());
  for (std::size_t d = 0; d < dampers.size(); ++d)
    if (const auto problems = dampers[d].validate(modal); !problems.empty())
      throw base::InputError(c.path, "/dampers/" + std::to_string(d), problems.front());
}

void check_outcome(dem_reference::Outcome outcome, const std::string& message, const std::string& label) {
  if (outcome == dem_reference::Outcome::kUnstable)
    throw base::NumericalError(label + ": DEM unstable: " + message +
                                      " (a smaller /dem/time_step_s, a larger /dem/steps_per_contact or "
                                      "/dem/max_impact_speed_m_s)");
  if (outcome != dem_reference::Outcome::kCompleted) throw base::NumericalError(label + ": DEM failed: " + message);
}

DesignModes design_modes(const case_file::Case& c, const case_file::FillingRatioProblem& p,
                         const std::vector<long>& slabs) {
  if (!c.structure || c.structure->kind != case_file::StructureSpec::Kind::kBeam ||
      !c.structure->beam.geometric_stiffness || c.structure->beam.axial_gravity_m_s2 == 0.0)
    return {p.modal, p.initial_modal_displacements};
  const case_file::Case dc = case_file::with_design(c, slabs);
  const case_file::StructureSetup setup = case_file::structure_setup(dc, case_file::LossMethod::kFormulas);
  return {setup.modal, case_file::initial_modal_amplitudes(dc, setup, c.task.filling_ratios->decay)};
}

}  // namespace pdamp::tasks::detail
