// The optimiser's problem of a filling_ratios case (filling_ratio_problem.hpp).
#include "pdamp/case_file/filling_ratio_problem.hpp"

#include <algorithm>
#include <numbers>

#include "pdamp/case_file/case_error.hpp"
#include "pdamp/case_file/structure_setup.hpp"

namespace pdamp::case_file {

FillingRatioProblem filling_ratio_problem(const Case& c) {
  const FillingRatiosTask& task = *c.task.filling_ratios;
  FillingRatioProblem p;
  StructureSetup setup = structure_setup(c, LossMethod::kFormulas);
  p.warnings = setup.warnings;
  const DamperSpec& spec = c.dampers.front();
  p.modal = setup.modal;
  p.options.damper = setup.dampers.front();
  p.options.fixed_dampers.assign(setup.dampers.begin() + 1, setup.dampers.end());
  p.options.model = spec.model;
  p.options.model_options = spec.model_options;
  p.options.mass_budget_kg = task.mass_budget_kg;
  p.options.objective = task.objective == FillingRatiosTask::Objective::kIntegralSquare
                            ? optimizer::FillingObjective::kIntegralSquare
                            : optimizer::FillingObjective::kSettlingTime;
  for (std::size_t k = 0; k < spec.layers.size(); ++k) {
    const LayerSpec& layer = spec.layers[k];
    const double r = layer.particle_radius_m;
    optimizer::LayerCandidate l;
    l.name = layer.name;
    l.inner_length_m = layer.container.inner_length(spec.drive_axis);
    l.slab_length_m = 2.0 * r;
    l.spheres_per_slab = task.spheres_per_slab.at(k);
    l.spheres_per_lane = task.spheres_per_lane.at(k);
    l.sphere_mass_kg = layer.bed_mass_kg / layer.particle_count;
    l.sphere_volume_m3 = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    l.cross_section_m2 = 1.0;
    for (int axis = 0; axis < 3; ++axis)
      if (axis != spec.drive_axis) l.cross_section_m2 *= layer.container.box_inner_size_m[static_cast<std::size_t>(axis)];
    const int whole = layer.particle_count / l.spheres_per_slab;
    if (layer.particle_count % l.spheres_per_slab != 0)
      p.warnings.push_back("layer " + layer.name + ": " + std::to_string(layer.particle_count) +
                           " particles are not whole slabs of " + std::to_string(l.spheres_per_slab) +
                           ": the starting design takes " + std::to_string(whole) + " slabs");
    l.initial_slabs = std::min(whole, l.max_slabs());
    p.options.layers.push_back(l);
  }
  const Eigen::VectorXd q0 = initial_modal_amplitudes(c, setup, task.decay);
  p.initial_modal_displacements = q0;
  p.options.decay.initial_modal_amplitudes = q0.cwiseAbs();  // released from rest: a_j = |q_j(0)|
  if (!(p.options.decay.initial_modal_amplitudes.maxCoeff() > 0.0))
    throw CaseError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  p.options.decay.duration_s = task.decay.duration_s;
  p.options.decay.threshold_fraction = task.decay.settling_threshold;
  // The coarsest RK4 rule free_decay allows (ln a changes <= 0.2 a step: local error about
  // 3e-6 of ln a): the search runs hundreds of decays; the comparison files use the same.
  p.options.decay.step_log_change = 0.2;
  if (const auto problems = p.options.validate(); !problems.empty()) throw CaseError(c.path, "/task", problems.front());
  // The beds' inertia enters through the coupling, their weight only through the geometric
  // stiffness of a beam under axial gravity: only there do the modes depend on the design.
  if (setup.beam && setup.beam->geometric_stiffness && setup.beam->axial_gravity_m_s2 != 0.0)
    p.warnings.push_back("the search scores every design on the starting design's modes (under axial gravity the "
                         "beds' weights load the beam's geometric stiffness); the DEM verification gives each "
                         "verified design its own");
  return p;
}

}  // namespace pdamp::case_file
