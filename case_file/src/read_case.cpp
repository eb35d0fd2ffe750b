// load_case(): the top level of a case file (formats 1 and 2) and the section order.
#include "pdamp/case_file/case.hpp"

#include <cmath>

#include "pdamp/base/input_file.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "readers.hpp"

namespace pdamp::case_file {

namespace fm = formulas;
using detail::ObjectReader;
using nlohmann::json;

namespace {

fm::Material read_material(ObjectReader& r, const fm::Material& defaults) {
  fm::Material m;
  m.density_kg_m3 = r.number("density_kg_m3", defaults.density_kg_m3, limits::kDensity, " kg/m^3");
  m.youngs_modulus_pa = r.number("youngs_modulus_pa", defaults.youngs_modulus_pa, limits::kModulus, " Pa");
  m.poisson_ratio = r.number("poisson_ratio", defaults.poisson_ratio, limits::kPoisson, "");
  return m;
}

void read_materials(ObjectReader& r, const json& root, Case& c) {
  c.materials["steel"] = fm::Material{};
  r.object("materials", false, [&](ObjectReader& m) {
    for (const auto& [name, value] : root.at("materials").items()) {
      (void)value;
      if (name.empty()) m.fail("", "a material needs a name (the key \"\" is empty)");
      const fm::Material defaults = c.materials.count(name) ? c.materials.at(name) : fm::Material{};
      // A copy of the key: clang 14 cannot capture a structured binding in a lambda (C++20 P1091).
      const std::string key = name;
      m.object(key, true, [&](ObjectReader& one) { c.materials[key] = read_material(one, defaults); });
    }
  });
  for (const auto& [name, material] : c.materials) {
    auto& out = c.resolved["materials"][name];
    out["density_kg_m3"] = material.density_kg_m3;
    out["youngs_modulus_pa"] = material.youngs_modulus_pa;
    out["poisson_ratio"] = material.poisson_ratio;
  }
}

/// Reads `key` with `read`, or its defaults (recorded as if given) when it is absent.
template <typename Fn>
void section_or_defaults(ObjectReader& r, const std::string& key, Fn&& read) {
  r.object(key, false, read);
  if (!r.has(key)) {
    ObjectReader defaults(r.file(), detail::empty_object(), "/" + key, r.resolved()[key]);
    read(defaults);
  }
}

void read_buffer(ObjectReader& b, Case& c) {
  BufferSpec spec;
  spec.layer_material = b.text("layer_material", std::nullopt);
  if (!c.materials.count(spec.layer_material))
    b.fail("layer_material", "'" + spec.layer_material + "' is not defined in /materials");
  auto& in = spec.input;
  in.frequency_hz = b.number("design_frequency_hz", std::nullopt, limits::kFrequency, " Hz");
  const auto amplitude = b.optional_number("design_amplitude_m", limits::kStroke, " m");
  const auto intensity = b.optional_number("design_intensity", limits::kIntensity, "");
  if (amplitude.has_value() == intensity.has_value())
    b.fail("design_amplitude_m", "give exactly one of design_amplitude_m and design_intensity");
  in.amplitude_m = amplitude.value_or(0.0);
  in.intensity = intensity.value_or(0.0);
  in.particles_per_contact = b.number("particles_per_contact", 1.0, {1.0, 1e9});
  in.impact_velocity_m_s = b.optional_number("impact_velocity_m_s", limits::kImpactSpeed, " m/s").value_or(0.0);
  in.model = buffer_model(b.text("model", std::string("layered"), {"layered", "half_space"}), b.file(),
                          b.pointer() + "/model");
  in.allowable_strain = b.number("allowable_strain", formulas::kDefaultAllowableStrain, limits::kAllowableStrain);
  const LayerSpec& layer = c.dampers.front().layers.front();
  in.particle_radius_m = layer.particle_radius_m;
  in.particle = c.materials.at(layer.particle_material);
  in.layer = c.materials.at(spec.layer_material);
  for (const auto& line : in.validate()) b.fail("", line);
  c.buffer = spec;
}

void read_sensitivity(ObjectReader& r, Case& c) {
  SensitivitySpec s;
  s.frequency_hz = r.number("frequency_hz", c.excitation.frequency_hz, limits::kFrequency, " Hz");
  const auto amplitude = r.optional_number("amplitude_m", limits::kStroke, " m");
  if (amplitude) s.amplitude_m = *amplitude;
  else if (c.excitation.amplitude_m) s.amplitude_m = *c.excitation.amplitude_m;
  r.array("parameters", [&](ObjectReader& p) {
    SensitivityParameter parameter;
    parameter.name = p.text("name", std::nullopt,
                            {"friction", "restitution", "rolling_friction", "particle_radius_m", "particle_count",
                             "youngs_modulus_factor", "tilt_x_deg", "tilt_y_deg", "tilt_z_deg"});
    for (const auto& other : s.parameters)
      if (other.name == parameter.name) p.fail("name", "'" + parameter.name + "' is given twice");
    // At most kMaxSensitivityValues: each value is a case of its own, held at once (10,000
    // took 3 GB and 45 s before the first run); a finer scan is a field or a sweep.
    parameter.values = p.number_array("values", Range{-1e6, 1e6}, "", 1, kMaxSensitivityValues);
    s.parameters.push_back(std::move(parameter));
  });
  s.threads = r.integer("threads", c.field.threads, 1, 256);
  c.sensitivity = std::move(s);
}

Case read_case(const json& root, const std::string& path) {
  // The root's errors carry no pointer ("<file>: must be a JSON object").
  if (!root.is_object()) throw CaseError(path, "", std::string("must be a JSON object, got ") + root.type_name());
  Case c;
  c.path = path;
  c.document = root;
  ObjectReader r(path, root, "", c.resolved);
  c.format_version = r.integer("format_version", 1, 1, 2);
  c.name = r.text("name", std::nullopt);
  if (c.name.empty()) r.fail("name", "must not be empty (it names the plots and the default output folder)");
  c.description = r.text("description", std::string());
  if (c.format_version == 1) r.text("task", std::string("damper_design"), {"damper_design"});
  read_materials(r, root, c);

  if (c.format_version == 1) {
    // One damper of one layer; its DEM geometry is read with /dem.
    r.object("damper", true, [&](ObjectReader& d) {
      DamperSpec damper;
      damper.name = "damper_1";
      LayerSpec layer;
      layer.name = "layer_1";
      detail::read_damper_drive(d, damper);
      layer.compartment.layer = detail::provisional_wall_layer(root);
      detail::read_layer_bed(d, c, damper, layer);
      damper.layers.push_back(std::move(layer));
      c.dampers.push_back(std::move(damper));
    });
  } else {
    r.object("structure", true, [&](ObjectReader& s) { c.structure = detail::read_structure(s, c); });
    detail::read_dampers(r, c);
    c.task = detail::read_task(r, c);
  }
  r.object("excitation", true, [&](ObjectReader& e) {
    c.excitation.frequency_hz = e.number("frequency_hz", std::nullopt, limits::kFrequency, " Hz");
    c.excitation.amplitude_m = e.optional_number("amplitude_m", limits::kStroke, " m");
  });
  section_or_defaults(r, "design", [&](ObjectReader& d) {
    c.design.target_stroke_m = d.optional_number("target_stroke_m", limits::kStroke, " m");
    c.design.sweep_min_over_clearance = d.number("sweep_min_over_clearance", 0.05, {0.0, 100.0, true});
    c.design.sweep_max_over_clearance = d.number("sweep_max_over_clearance", 1.5, {0.0, 100.0, true});
    c.design.sweep_points = d.integer("sweep_points", 301, 2, 100000);
    if (c.design.sweep_max_over_clearance <= c.design.sweep_min_over_clearance)
      d.fail("sweep_max_over_clearance", "must be > sweep_min_over_clearance");
  });
  section_or_defaults(r, "dem", [&](ObjectReader& d) { detail::read_dem(d, c); });
  // Without an operating stroke the DEM is checked at X = h (the closed forms' scale);
  // pdamp dem and pdamp field check their own points again.
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    const double x = c.excitation.amplitude_m.value_or(c.dampers[i].layers.front().clearance_m);
    const auto problems = dem_options(c, i, x, c.excitation.frequency_hz).validate("");
    if (!problems.empty()) throw dem_case_error(c, i, problems.front());
  }
  section_or_defaults(r, "field", [&](ObjectReader& f) { detail::read_field(f, c); });
  r.object("buffer", false, [&](ObjectReader& b) { read_buffer(b, c); });
  r.object("sensitivity", false, [&](ObjectReader& s) { read_sensitivity(s, c); });
  r.finish();
  return c;
}

}  // namespace

Case load_case_document(const json& document, const std::string& path) {
  try {
    return read_case(document, path);
  } catch (const CaseError&) {
    throw;
  } catch (const base::InputError& e) {  // the reader's own checks: unknown keys, file, JSON
    throw CaseError(e.file(), e.pointer(), e.rule());
  }
}

Case load_case(const std::string& path) {
  // Results and resolved cases record the case's path in JSON, which holds UTF-8 only.
  if (!base::valid_utf8(path))
    throw CaseError(path, "", "the file's path is not valid UTF-8 (results record it in JSON): rename the file");
  json document;
  try {
    document = base::parse_json_document(base::read_input_file(path), path);
  } catch (const base::InputError& e) {
    throw CaseError(e.file(), e.pointer(), e.rule());
  }
  return load_case_document(document, path);
}

std::string_view to_string(TaskKind kind) {
  switch (kind) {
    case TaskKind::kDamperDesign: return "damper_design";
    case TaskKind::kFrf: return "frf";
    case TaskKind::kDecay: return "decay";
    case TaskKind::kModes: return "modes";
    case TaskKind::kFillingRatios: return "filling_ratios";
    case TaskKind::kPlacement: return "placement";
    case TaskKind::kClearance: return "clearance";
  }
  return "unknown";
}

formulas::BufferModel buffer_model(const std::string& name, const std::string& where, const std::string& key) {
  if (name == "layered") return formulas::BufferModel::kLayered;
  if (name == "half_space") return formulas::BufferModel::kHalfSpace;
  throw CaseError(where, key, "'" + name + "': must be layered or half_space");
}

dem_reference::DamperSimulationOptions dem_options(const Case& c, std::size_t damper_index, double amplitude_m,
                                                   double frequency_hz) {
  const DamperSpec& damper = c.dampers.at(damper_index);
  auto options = c.dem.simulation;
  auto& world = options.world;
  world.compartments.clear();
  for (const auto& layer : damper.layers) {
    world.compartments.push_back(layer.compartment);
    for (auto& group : world.compartments.back().particles) group.radius_spread = c.dem.radius_spread;
  }
  world.gravity_m_s2 = damper.gravity_m_s2;
  options.drive_axis = {0.0, 0.0, 0.0};
  options.drive_axis[damper.drive_axis] = 1.0;
  options.amplitude_m = amplitude_m;
  options.frequency_hz = frequency_hz;
  return options;
}

formulas::ModelOptions layer_model_options(const DamperSpec& damper, const LayerSpec& layer) {
  formulas::ModelOptions options = damper.model_options;
  options.nested_bed = layer.bed.settled_upper_spheres > 0;
  // The settled bed's rows along the drive: its extent over one diameter (the lattice's
  // slabs, plus what settling spreads onto the base).
  const auto& bed = layer.bed;
  if (bed.slabs > 0 && bed.bed_extent_m > 0.0)
    options.rows_along_drive =
        std::round((bed.bed_extent_m + bed.clearance_m - bed.settled_clearance_m) / (bed.bed_extent_m / bed.slabs));
  return options;
}

std::vector<std::string> settled_bed_warnings(const Case& c) {
  std::vector<std::string> out;
  for (const DamperSpec& d : c.dampers) {
    for (const LayerSpec& layer : d.layers) {
      const auto& bed = layer.bed;
      // A lone sphere per lane, or a few spheres: no collected bed that moves as a block. The
      // collected-bed closed forms do not depend on restitution; such spheres rebound from the
      // walls (the one-sphere bound of bed_restitution, docs/theory.md §3.1).
      if (bed.slabs == 1 || layer.particle_count <= kFewParticles) {
        std::ostringstream text;
        text.precision(3);
        text << d.name << "/" << layer.name << ": "
             << (layer.particle_count <= kFewParticles ? std::to_string(layer.particle_count) + " particles"
                                                       : std::string("one particle per lane along the drive"))
             << ": the closed forms model a collected bed moving as one block, whose orbits do not depend on "
                "restitution; single spheres rebound from the walls";
        if (std::isfinite(d.model_options.particle_restitution))
          text << " (with eps = " << d.model_options.particle_restitution << ", rolling: bed_restitution between "
               << formulas::frictionless_wall_restitution(d.model_options.particle_restitution,
                                                          d.model_options.rolling_inertia_factor)
               << " at frictionless walls and "
               << formulas::bed_restitution_bound(d.model_options.particle_restitution,
                                                  d.model_options.rolling_inertia_factor)
               << " when the walls stop the spin)";
        text << ": set model_options.bed_restitution (docs/theory.md §3.1) or use the layer's DEM field";
        out.push_back(text.str());
      }
      if (bed.settled_clearance_m == bed.clearance_m) continue;
      std::ostringstream text;
      text.precision(4);
      text << d.name << "/" << layer.name << ": the bed is " << bed.spheres_per_lane
           << " spheres high across gravity and settles onto the base: h = " << bed.settled_clearance_m * 1e3
           << " mm, not the lattice's " << bed.clearance_m * 1e3 << " mm";
      if (bed.settled_upper_spheres > 0)
        text << "; " << bed.settled_upper_spheres
             << " spheres stay above the bottom rows, resting on two or more others: a nested bed, which does not "
                "roll; model auto takes it as a Coulomb block held by its base up to Gamma = mu = "
             << d.model_options.base_friction
             << " (docs/theory.md §3.3); the DEM holds a nested bed so only at low friction (mu <= 0.2) and moves "
                "differently from the block above it: use the layer's DEM field (docs/collect_and_collide.md §8)";
      out.push_back(text.str());
    }
  }
  return out;
}

std::string physics_hash(const Case& c, const std::string& source) {
  // Format 1 hashes exactly what it always hashed (shipped fields carry the value).
  json identity = c.format_version == 1 ? json{{"damper", c.resolved["damper"]}}
                                        : json{{"dampers", c.resolved["dampers"]}};
  identity["materials"] = c.resolved["materials"];
  identity["source"] = source;
  if (source == "dem") identity["dem"] = c.resolved["dem"];
  return surrogate::case_hash(identity);
}

}  // namespace pdamp::case_file
