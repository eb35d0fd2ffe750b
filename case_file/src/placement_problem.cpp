// The optimiser's problem of a placement case (placement_problem.hpp).
#include "pdamp/case_file/placement_problem.hpp"

#include "pdamp/case_file/case_error.hpp"

namespace pdamp::case_file {

PlacementProblem placement_problem(const Case& c, LossMethod method) {
  const PlacementTask& task = *c.task.placement;
  PlacementProblem p;
  StructureSetup setup = structure_setup(c, method);
  p.warnings = setup.warnings;
  p.modal = setup.modal;
  p.options.damper = setup.dampers.at(task.damper_index);
  for (std::size_t d = 0; d < setup.dampers.size(); ++d)
    if (d != task.damper_index) p.options.fixed_dampers.push_back(setup.dampers[d]);
  p.options.targets = task.targets;
  p.options.objective = task.objective;
  p.options.rotation_warning_fraction = task.rotation_warning_fraction;
  if (const auto problems = p.options.validate(); !problems.empty()) throw CaseError(c.path, "/task", problems.front());
  p.candidate_points = task.candidate_points;
  if (!setup.beam || !p.candidate_points.empty()) return p;

  const StructureSpec& s = *c.structure;
  const DamperSpec& spec = c.dampers[task.damper_index];
  optimizer::BeamPlacement beam;
  beam.beam = loaded_beam(c, task.damper_index);
  beam.mode_count = s.mode_count;
  beam.damping = s.damping;
  beam.carried_mass_kg = spec.container_mass_kg;
  for (const LayerSpec& layer : spec.layers) beam.carried_mass_kg += layer.bed_mass_kg;
  beam.min_position_m = task.min_position_m;
  beam.max_position_m = task.max_position_m;
  beam.scan_positions = task.positions;
  for (const auto& point : s.beam.points)
    if (point.name == spec.site) p.current_position_m = point.position_m;
  for (const auto& point : s.beam.point_masses)
    if (point.name == spec.site) p.current_position_m = point.position_m;
  if (const auto problems = beam.validate(); !problems.empty()) throw CaseError(c.path, "/task", problems.front());
  p.beam = std::move(beam);
  return p;
}

}  // namespace pdamp::case_file
