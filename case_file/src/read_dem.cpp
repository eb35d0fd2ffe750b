// `dem`: materials and contact pairs, the layers' compartment geometry, numerics.
#include <limits>

#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace dr = dem_reference;

namespace {

/// Restitution the DEM's calibrated damping covers (formulas::DampingTable).
constexpr Range kRestitution{dr::limits::kMinRestitution, 1.0};

/// Contact parameters of a material pair: restitution as a number (constant) or a
/// table {speeds_m_s, values}; friction; rolling friction.
void read_contact_pair(ObjectReader& r, dr::ContactPairOptions& pair) {
  const dr::ContactPairOptions defaults;
  if (r.has("restitution") && !r.is_number("restitution")) {
    r.object("restitution", true, [&](ObjectReader& t) {
      // Two points at least: one value is a constant (give a number then).
      pair.restitution.table_speeds_m_s = t.number_array("speeds_m_s", {0.0, limits::kImpactSpeed.max}, " m/s", 2);
      pair.restitution.table_values = t.number_array("values", kRestitution, "", 2);
      if (pair.restitution.table_values.size() != pair.restitution.table_speeds_m_s.size())
        t.fail("values", "has " + std::to_string(pair.restitution.table_values.size()) + " entries: must have one per speed (" +
                             std::to_string(pair.restitution.table_speeds_m_s.size()) + ")");
      for (std::size_t k = 1; k < pair.restitution.table_speeds_m_s.size(); ++k)
        if (!(pair.restitution.table_speeds_m_s[k] > pair.restitution.table_speeds_m_s[k - 1]))
          t.fail("speeds_m_s/" + std::to_string(k), "speeds must increase strictly");
    });
  } else {
    pair.restitution.constant = r.number("restitution", defaults.restitution.constant, kRestitution);
  }
  pair.friction = r.number("friction", defaults.friction, {0.0, dr::limits::kMaxFriction});
  pair.rolling_friction = r.number("rolling_friction", defaults.rolling_friction, {0.0, dr::limits::kMaxRollingFriction});
}

/// The DEM contact of the first layer's spheres on its walls. The closed forms take its
/// friction as their base friction (where auto leaves rolling) and its rolling friction as
/// the rolling tail's resistance: one number each for both models.
const dr::ContactPairOptions& wall_contact(const dr::WorldOptions& world, const LayerSpec& layer) {
  const int particles = layer.compartment.particles.front().material;
  const int wall = layer.compartment.wall_material;
  const dr::ContactPairOptions* contact = &world.default_pair;
  for (const auto& pair : world.pairs)
    if ((pair.material_a == particles && pair.material_b == wall) || (pair.material_b == particles && pair.material_a == wall))
      contact = &pair;
  return *contact;
}

/// ε of the spheres on the walls of a layer when it is a constant (a table or a law: NaN),
/// for the one-sphere bound of the closed forms' bed_restitution (docs/theory.md §3.1).
double particle_restitution(const dr::ContactPairOptions& contact) {
  const dr::RestitutionOptions& restitution = contact.restitution;
  if (restitution.model || !restitution.table_values.empty()) return std::numeric_limits<double>::quiet_NaN();
  return restitution.constant;
}

}  // namespace

int material_index(const ObjectReader& r, const std::string& key, const std::string& name, const Case& c) {
  const auto it = c.materials.find(name);
  if (it == c.materials.end()) r.fail(key, "'" + name + "' is not defined in /materials (nor built in)");
  return static_cast<int>(std::distance(c.materials.begin(), it));
}

void read_layer_geometry(ObjectReader& r, const Case& c, LayerSpec& layer) {
  auto& compartment = layer.compartment;
  const std::string wall = r.text("wall_material", std::string("steel"));
  compartment.wall_material = material_index(r, "wall_material", wall, c);
  const std::string placement =
      r.text("placement", std::string("collected_lattice"), {"collected_lattice", "centred_lattice", "random"});
  compartment.placement = placement == "collected_lattice" ? dr::InitialPlacement::kCollectedLattice
                          : placement == "centred_lattice" ? dr::InitialPlacement::kCentredLattice
                                                           : dr::InitialPlacement::kRandom;
  r.object("inner_structures", false, [&](ObjectReader& s) {
    s.array("plates", [&](ObjectReader& p) {
      dr::PlateOptions plate;
      plate.centre_m = p.vector3("centre_m", std::nullopt, limits::kPosition, " m");
      plate.size_m = p.vector3("size_m", std::nullopt, limits::kContainerSize, " m");
      plate.material = material_index(p, "material", p.text("material", wall), c);
      compartment.plates.push_back(plate);
    });
    s.array("pins", [&](ObjectReader& p) {
      dr::PinOptions pin;
      pin.centre_m = p.vector3("centre_m", std::nullopt, limits::kPosition, " m");
      pin.axis = axis_index(p.text("axis", std::string("z"), {"x", "y", "z"}));
      pin.radius_m = p.number("radius_m", std::nullopt, limits::kContainerSize, " m");
      pin.length_m = p.number("length_m", std::nullopt, limits::kContainerSize, " m");
      pin.material = material_index(p, "material", p.text("material", wall), c);
      compartment.pins.push_back(pin);
    });
  });
  r.object("wall_layer", false, [&](ObjectReader& l) {
    compartment.layer.thickness_m = l.number("thickness_m", std::nullopt, limits::kContainerSize, " m");
    compartment.layer.material = material_index(l, "material", l.text("material", std::nullopt), c);
    const std::string axis = l.text("axis", std::string("all"), {"all", "x", "y", "z"});
    compartment.layer.axis = axis == "all" ? -1 : axis_index(axis);
  });
}

dr::WallLayerOptions provisional_wall_layer(const json& root) {
  dr::WallLayerOptions layer;
  const json* dem = root.contains("dem") ? &root.at("dem") : nullptr;
  if (!dem || !dem->is_object() || !dem->contains("wall_layer") || !dem->at("wall_layer").is_object()) return layer;
  const json& l = dem->at("wall_layer");
  const json* thickness = l.contains("thickness_m") ? &l.at("thickness_m") : nullptr;
  if (!thickness || !thickness->is_number() || !limits::kContainerSize.contains(thickness->get<double>())) return layer;
  const std::string axis = l.contains("axis") && l.at("axis").is_string() ? l.at("axis").get<std::string>() : "all";
  if (axis != "all" && axis != "x" && axis != "y" && axis != "z") return layer;
  layer.thickness_m = thickness->get<double>();
  layer.axis = axis == "all" ? -1 : axis_index(axis);
  return layer;
}

void read_dem(ObjectReader& r, Case& c) {
  DemSpec& dem = c.dem;
  dr::DamperSimulationOptions& sim = dem.simulation;
  dr::WorldOptions& world = sim.world;
  const dr::DamperSimulationOptions defaults;

  // Softer than 1e-6 leaves steel at 0.2 MPa: the contacts would overlap far beyond
  // Hertz and the time step no longer resolves anything meaningful.
  dem.stiffness_softening = r.number("stiffness_softening", 1.0, {1e-6, 1.0});
  world.materials.clear();
  for (const auto& [name, material] : c.materials) {
    dr::MaterialOptions m{name, material};
    m.material.youngs_modulus_pa *= dem.stiffness_softening;
    world.materials.push_back(m);
  }
  // Format 1 keeps the geometry of its one compartment here (format 2: in each layer).
  if (c.format_version == 1) read_layer_geometry(r, c, c.dampers.front().layers.front());
  dem.radius_spread = r.number("radius_spread", 0.0, {0.0, 0.4999});

  r.object("contact", false, [&](ObjectReader& p) { read_contact_pair(p, world.default_pair); });
  if (!r.has("contact")) {
    ObjectReader fallback(r.file(), empty_object(), r.pointer() + "/contact", r.resolved()["contact"]);
    read_contact_pair(fallback, world.default_pair);
  }
  r.array("pairs", [&](ObjectReader& p) {
    dr::ContactPairOptions pair = world.default_pair;
    pair.material_a = material_index(p, "material_a", p.text("material_a", std::nullopt), c);
    pair.material_b = material_index(p, "material_b", p.text("material_b", std::nullopt), c);
    read_contact_pair(p, pair);
    // One entry per pair of materials, in either order: two would leave it unclear
    // which one the DEM takes.
    for (std::size_t k = 0; k < world.pairs.size(); ++k) {
      const auto& other = world.pairs[k];
      if ((other.material_a == pair.material_a && other.material_b == pair.material_b) ||
          (other.material_a == pair.material_b && other.material_b == pair.material_a))
        p.fail("", "the pair " + p.resolved()["material_a"].get<std::string>() + "/" +
                       p.resolved()["material_b"].get<std::string>() + " is already given by " + r.pointer() + "/pairs/" +
                       std::to_string(k));
    }
    world.pairs.push_back(pair);
  });
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    auto& damper = c.dampers[i];
    const dr::ContactPairOptions& contact = wall_contact(world, damper.layers.front());
    damper.model_options.base_friction = contact.friction;
    damper.model_options.rolling_resistance = contact.rolling_friction;
    damper.model_options.particle_restitution = particle_restitution(contact);
    auto& resolved_damper = c.format_version == 1 ? c.resolved["damper"] : c.resolved["dampers"][i];
    resolved_damper["derived"]["base_friction"] = damper.model_options.base_friction;
  }

  auto& integration = world.integration;
  integration.time_step_s = r.number("time_step_s", 0.0, {0.0, dr::limits::kMaxTimeStep_s}, " s (0 = automatic)");
  integration.steps_per_contact = r.integer("steps_per_contact", 0, 0, dr::limits::kMaxStepsPerContact);
  if (integration.steps_per_contact != 0 && integration.steps_per_contact < dr::limits::kMinStepsPerContact)
    r.fail("steps_per_contact", "= " + std::to_string(integration.steps_per_contact) + ": must be 0 (automatic) or in [" +
                                    std::to_string(dr::limits::kMinStepsPerContact) + ", " +
                                    std::to_string(dr::limits::kMaxStepsPerContact) + "]");
  if (const auto v = r.optional_number("max_impact_speed_m_s", limits::kImpactSpeed, " m/s")) integration.max_impact_speed_m_s = *v;
  integration.skin_fraction = r.number("skin_fraction", integration.skin_fraction,
                                       {dr::limits::kMinSkinFraction, dr::limits::kMaxSkinFraction});
  integration.max_overlap_fraction = r.number("max_overlap_fraction", integration.max_overlap_fraction, {0.0, 0.999, true});
  sim.settling_time_s =
      r.number("settling_time_s", defaults.settling_time_s, {-1.0, dr::limits::kMaxSettlingTime_s}, " s (-1 = automatic)");
  if (sim.settling_time_s < 0.0 && sim.settling_time_s != -1.0) r.fail("settling_time_s", "must be -1 (automatic) or >= 0");
  // The approach from above (absent: from rest, and nothing added to the resolved case, so
  // the physics hash of every case without it is what it was).
  r.object("approach", false, [&](ObjectReader& a) {
    sim.approach_amplitude_m = a.number("amplitude_m", std::nullopt, {0.0, dr::limits::kMaxAmplitude_m, true}, " m");
    sim.approach_hold_periods =
        a.integer("hold_periods", defaults.approach_hold_periods, 0, dr::limits::kMaxPeriods);
    sim.approach_ramp_periods =
        a.integer("ramp_periods", defaults.approach_ramp_periods, 1, dr::limits::kMaxPeriods);
  });
  sim.transient_periods = r.integer("transient_periods", defaults.transient_periods, 0, dr::limits::kMaxPeriods);
  sim.analysed_periods = r.integer("analysed_periods", defaults.analysed_periods, 1, dr::limits::kMaxPeriods);
  sim.samples_per_period = r.integer("samples_per_period", defaults.samples_per_period, dr::limits::kMinSamplesPerPeriod,
                                     dr::limits::kMaxSamplesPerPeriod);
  sim.snapshots = r.integer("snapshots", defaults.snapshots, 0, dr::limits::kMaxSnapshots);
  world.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0, std::numeric_limits<int>::max()));
  world.threads = r.integer("threads", 1, 0, dr::limits::kMaxThreads);
}

}  // namespace pdamp::case_file::detail
