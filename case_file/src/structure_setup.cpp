// Runtime models of a format-2 case: modal model and dampers with their loss models.
#include "pdamp/case_file/structure_setup.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "pdamp/case_file/ranges.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace pdamp::case_file {

namespace {

namespace st = pdamp::structure;
namespace sg = pdamp::surrogate;

std::string layer_pointer(std::size_t damper, std::size_t layer) {
  return "/dampers/" + std::to_string(damper) + "/layers/" + std::to_string(layer);
}

/// The layer's effective field, looked up at the layer's own clearance (a field of
/// another clearance is reused at equal Γ and X/h, and said so).
std::shared_ptr<const sg::LossModel> field_loss_model(const Case& c, std::size_t d, std::size_t l,
                                                      StructureSetup& setup) {
  std::vector<std::string>& warnings = setup.warnings;
  const LayerSpec& layer = c.dampers[d].layers[l];
  if (layer.field_file.empty()) {
    throw CaseError(c.path, layer_pointer(d, l) + "/field_file",
                    "required with --method field (the layer's effective field, made by pdamp field)");
  }
  sg::EffectiveField field;
  try {
    field = sg::read_effective_field(layer.field_file);
  } catch (const base::InputError&) {
    throw;  // names the field file and the pointer in it
  } catch (const std::exception& e) {
    throw CaseError(c.path, layer_pointer(d, l) + "/field_file", e.what());
  }
  if (field.provenance.source == sg::FieldSource::kDem && field.provenance.approach_amplitude_m == 0.0)
    setup.fields_from_rest.push_back(c.dampers[d].name + "/" + layer.name);
  sg::LookupOptions lookup;
  lookup.clearance_m = layer.clearance_m;
  if (std::abs(field.clearance_m - layer.clearance_m) > 1e-9 * layer.clearance_m) {
    std::ostringstream out;
    out << c.dampers[d].name << "/" << layer.name << ": the field " << layer.field_file << " was made for h = "
        << field.clearance_m << " m, the layer has h = " << layer.clearance_m
        << " m: it is reused at equal intensity and X/h (docs/effective_fields.md says when that holds)";
    warnings.push_back(out.str());
  }
  try {
    return std::make_shared<sg::EffectiveFieldLossModel>(field, lookup);
  } catch (const std::invalid_argument& e) {
    throw CaseError(layer.field_file, "", e.what());
  }
}

}  // namespace

std::string_view to_string(LossMethod method) {
  return method == LossMethod::kFormulas ? "formulas" : "field";
}

st::BeamModel loaded_beam(const Case& c, std::optional<std::size_t> without_damper) {
  // The dampers' containers and beds hang on the beam: their weight loads its geometric
  // stiffness (a standing beam with a tip damper), their inertia enters through the coupling.
  const st::BeamModel& beam = c.structure->beam;
  st::BeamModel loaded = beam;
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    if (without_damper == i) continue;
    const DamperSpec& d = c.dampers[i];
    double mass = d.container_mass_kg;
    for (const LayerSpec& layer : d.layers) mass += layer.bed_mass_kg;
    for (const auto& p : beam.points)
      if (p.name == d.site) loaded.carried_weights.push_back({p.position_m, mass});
    for (const auto& p : beam.point_masses)
      if (p.name == d.site) loaded.carried_weights.push_back({p.position_m, mass});
  }
  return loaded;
}

StructureSetup structure_setup(const Case& c, LossMethod method) {
  if (!c.structure) throw CaseError(c.path, "/structure", "required: pdamp modes, frf and decay need a format-2 case");
  StructureSetup out;
  out.warnings = settled_bed_warnings(c);
  const StructureSpec& s = *c.structure;
  if (s.kind == StructureSpec::Kind::kBeam) {
    st::BeamModel loaded = loaded_beam(c);
    st::BeamModalResult beam;
    try {
      beam = st::beam_modal_model(loaded, s.mode_count, s.damping);
    } catch (const std::invalid_argument& e) {
      throw CaseError(c.path, "/structure", e.what());
    }
    out.modal = std::move(beam.modal);
    out.beam = std::move(loaded);
    out.rigid_modes_dropped = beam.rigid_modes_dropped;
  } else {
    out.modal = *s.modal_data;
  }
  for (std::size_t d = 0; d < c.dampers.size(); ++d) {
    const DamperSpec& spec = c.dampers[d];
    st::Damper damper;
    damper.name = spec.name;
    damper.point = spec.site;
    damper.drive_direction = {spec.drive_direction[0], spec.drive_direction[1]};
    damper.container_mass_kg = spec.container_mass_kg;
    damper.container_rotary_inertia_kg_m2 = spec.container_rotary_inertia_kg_m2;
    for (const LayerSpec& layer : spec.layers) {
      damper.length_along_drive_m = std::max(damper.length_along_drive_m, layer.container.inner_length(spec.drive_axis));
    }
    for (std::size_t l = 0; l < spec.layers.size(); ++l) {
      const LayerSpec& layer = spec.layers[l];
      st::DamperLayer coupled;
      coupled.name = layer.name;
      coupled.bed_mass_kg = layer.bed_mass_kg;
      coupled.loss_model = method == LossMethod::kFormulas
                               ? std::make_shared<sg::ClosedFormLossModel>(spec.model, layer.clearance_m,
                                                                           layer_model_options(spec, layer))
                               : field_loss_model(c, d, l, out);
      damper.layers.push_back(std::move(coupled));
    }
    out.dampers.push_back(std::move(damper));
  }
  // The beds' modal mass ratio μ_j = Σ_d b_dj² Σ_l m_bed,l / m_j (as pdamp modes reports it):
  // the first-harmonic coupling of the averaging solvers (docs/theory.md §7.2-7.6) treats the
  // bed as a small load on the mode; above μ = 0.1 it is off by more than 6 %, and the DEM in
  // the loop (§7.8) is the check. A coupling the solvers refuse is reported by them, not here.
  try {
    const st::CoupledModel coupled = st::couple(out.modal, out.dampers);
    double largest = 0.0;
    Eigen::Index mode = 0;
    for (Eigen::Index j = 0; j < coupled.drive_shapes.rows(); ++j) {
      double ratio = 0.0;
      for (Eigen::Index d = 0; d < coupled.drive_shapes.cols(); ++d) {
        double bed = 0.0;
        for (const auto& l : out.dampers[static_cast<std::size_t>(d)].layers) bed += l.bed_mass_kg;
        ratio += coupled.drive_shapes(j, d) * coupled.drive_shapes(j, d) * bed / coupled.modal_masses_kg[j];
      }
      if (ratio > largest) {
        largest = ratio;
        mode = j;
      }
    }
    if (largest > kMaxModalMassRatio) {
      std::ostringstream text;
      text.precision(3);
      text << "the beds' modal mass ratio is " << largest << " in mode " << mode + 1 << " (above " << kMaxModalMassRatio
           << "): the first-harmonic coupling of the closed forms and fields is then off by more than 6 % "
              "(docs/theory.md section 7); check the result with the DEM in the loop (section 7.8: pdamp decay "
              "--method dem, or the verification of a filling_ratios task)";
      out.warnings.push_back(text.str());
    }
  } catch (const std::exception&) {
  }
  return out;
}

structure::CosimulationDamper cosimulation_damper(const Case& c, std::size_t damper_index) {
  const DamperSpec& spec = c.dampers.at(damper_index);
  structure::CosimulationDamper out;
  out.name = spec.name;
  out.point = spec.site;
  out.drive_direction = {spec.drive_direction[0], spec.drive_direction[1]};
  out.container_mass_kg = spec.container_mass_kg;
  out.container_rotary_inertia_kg_m2 = spec.container_rotary_inertia_kg_m2;
  // The World does not depend on the operating point (stroke and frequency only set the
  // harmonic drive, which the co-simulation replaces by the structure's motion).
  double clearance = 0.0;
  for (const LayerSpec& layer : spec.layers) clearance = std::max(clearance, layer.clearance_m);
  const auto options = dem_options(c, damper_index, clearance > 0.0 ? clearance : 0.01, c.excitation.frequency_hz);
  if (const auto problems = options.world.validate(""); !problems.empty())
    throw dem_case_error(c, damper_index, problems.front());
  out.world = options.world;
  dem_reference::Vec3 a{0.0, 0.0, 0.0};
  a[static_cast<std::size_t>(spec.drive_axis)] = 1.0;
  out.container_drive_axis = a;
  const auto& g = spec.gravity_m_s2;
  const double g_norm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  dem_reference::Vec3 perp{g[0], g[1], g[2]};
  perp[static_cast<std::size_t>(spec.drive_axis)] = 0.0;
  const double perp_norm = std::sqrt(perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]);
  dem_reference::Vec3 k{0.0, 0.0, 0.0};
  if (g_norm > 0.0 && perp_norm > 0.01 * g_norm) {
    const bool in_plane = c.structure && c.structure->kind == StructureSpec::Kind::kBeam &&
                          c.structure->beam.axial_gravity_m_s2 != 0.0;
    if (in_plane) {
      k = {a[1] * perp[2] - a[2] * perp[1], a[2] * perp[0] - a[0] * perp[2], a[0] * perp[1] - a[1] * perp[0]};
      const double n = std::sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
      for (auto& v : k) v /= n;
    } else {
      for (std::size_t i = 0; i < 3; ++i) k[i] = -perp[i] / perp_norm;
    }
  } else {
    k[static_cast<std::size_t>((spec.drive_axis + 2) % 3)] = 1.0;
  }
  out.container_rotation_axis = k;
  return out;
}

namespace {

/// The modal amplitudes of the task's release, as given or from the static deflection.
Eigen::VectorXd release_amplitudes(const Case& c, const StructureSetup& setup, const DecayTask& task) {
  const Eigen::Index modes = setup.modal.mode_count();
  if (task.initial_state == DecayTask::InitialState::kModalAmplitudes) {
    if (static_cast<Eigen::Index>(task.modal_amplitudes.size()) > modes) {
      throw CaseError(c.path, "/task/initial_state/values",
                      "has " + std::to_string(task.modal_amplitudes.size()) + " entries, the structure keeps " +
                          std::to_string(modes) + " modes (at most one value per mode)");
    }
    Eigen::VectorXd q = Eigen::VectorXd::Zero(modes);
    for (std::size_t j = 0; j < task.modal_amplitudes.size(); ++j) q[static_cast<Eigen::Index>(j)] = task.modal_amplitudes[j];
    return q;
  }
  const Eigen::Vector2d force(task.load_force_n[0], task.load_force_n[1]);
  try {
    if (setup.beam) {
      std::optional<double> position;
      for (const auto& p : setup.beam->points)
        if (p.name == task.load_point) position = p.position_m;
      for (const auto& m : setup.beam->point_masses)
        if (m.name == task.load_point) position = m.position_m;
      if (!position) {
        throw CaseError(c.path, "/task/initial_state/point", "'" + task.load_point + "' is not a named point of the beam");
      }
      return st::static_deflection_modal_amplitudes(*setup.beam, setup.modal, *position, force, 0.0);
    }
    return st::modal_static_deflection_amplitudes(setup.modal, task.load_point, force);
  } catch (const CaseError&) {
    throw;
  } catch (const std::invalid_argument& e) {
    throw CaseError(c.path, "/task/initial_state", e.what());
  }
}

/// The release must be one the dampers can meet: a site that starts more than the largest
/// stroke any loss model or the DEM takes (limits::kStroke, 10 m) from rest is a load, a modal
/// mass or a shape out of scale (each within its own range, their product is not), and would
/// give decays of 1e21 m. Named by the site, the quantity and the keys to check.
Eigen::VectorXd checked_release(const Case& c, const StructureSetup& setup, Eigen::VectorXd q) {
  for (const auto& damper : setup.dampers) {
    double envelope_m = 0.0;
    for (const auto& p : setup.modal.points)
      if (p.name == damper.point)
        for (Eigen::Index j = 0; j < q.size(); ++j) envelope_m += p.translation.col(j).norm() * std::abs(q[j]);
    if (!(envelope_m <= limits::kStroke.max))
      throw CaseError(c.path, "/task/initial_state",
                      "moves damper " + damper.name + "'s site '" + damper.point + "' by up to " +
                          base::format_number(envelope_m, 4) + " m, more than the " +
                          base::format_number(limits::kStroke.max) +
                          " m any damper model takes: check the load or amplitudes against the structure's modal "
                          "masses and shapes");
  }
  return q;
}

}  // namespace

Eigen::VectorXd initial_modal_amplitudes(const Case& c, const StructureSetup& setup, const DecayTask& task) {
  return checked_release(c, setup, release_amplitudes(c, setup, task));
}

}  // namespace pdamp::case_file
