// Dampers and their layers: drive, gravity, model constants, container, particles, bed.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

#include "pdamp/base/number_text.hpp"
#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace fm = formulas;

int axis_index(const std::string& name) { return name == "x" ? 0 : name == "y" ? 1 : 2; }

namespace {

/// ModelOptions::validate() owns the constants' ranges: its line "rolling_calibration =
/// 3: must be in (0, 2]" (or "scattered.s_max = ...") becomes the case's error at
/// model_options/rolling_calibration. base_friction and rolling_resistance are no keys of
/// model_options: they are the DEM contact's friction and rolling friction (checked there).
void check_model_options(const ObjectReader& r, const fm::ModelOptions& options) {
  for (const auto& line : options.validate()) {
    const auto cut = line.find(" = ");
    std::string field = line.substr(0, cut);
    if (field == "base_friction" || field == "particle_restitution" || field == "rolling_resistance")
      continue;  // the DEM contact's, checked there
    for (auto& ch : field)
      if (ch == '.') ch = '/';
    r.fail("model_options/" + field, line.substr(cut + 1));
  }
}

void read_model_options(ObjectReader& r, fm::ModelOptions& options) {
  const fm::ModelOptions defaults;
  options.rolling_inertia_factor = r.number("rolling_inertia_factor", defaults.rolling_inertia_factor, Range{});
  options.rolling_calibration = r.number("rolling_calibration", defaults.rolling_calibration, Range{});
  options.bouncing_calibration = r.number("bouncing_calibration", defaults.bouncing_calibration, Range{});
  r.object("scattered", false, [&](ObjectReader& s) {
    options.scattered.jump_fraction = s.number("jump_fraction", defaults.scattered.jump_fraction, Range{});
    options.scattered.exponent = s.number("exponent", defaults.scattered.exponent, Range{});
    options.scattered.s_min = s.number("s_min", defaults.scattered.s_min, Range{});
    options.scattered.s_max = s.number("s_max", defaults.scattered.s_max, Range{});
    // Fitted only when both coefficients are given: a partial object keeps a default
    // coefficient, which stays provisional (and says so in the warnings).
    options.scattered.provisional = !(s.has("jump_fraction") && s.has("exponent"));
    options.scattered.source =
        s.text("source", options.scattered.provisional ? defaults.scattered.source : std::string("case file"));
  });
  // The rebounding bed and the law below the onset (docs/theory.md §3.1, §4.2): read only
  // when given, so that a case without them keeps its resolved form and physics hash.
  if (const auto e_b = r.optional_number("bed_restitution", Range{})) options.bed_restitution = *e_b;
  const std::vector<std::string> below_onset_laws = {"scattered_fit", "impact_map", "rolling_tail"};
  if (r.has("below_onset"))
    options.below_onset = *fm::below_onset_model_from_string(r.text("below_onset", std::nullopt, below_onset_laws));
  if (r.has("below_onset_from_above"))
    options.below_onset_from_above =
        *fm::below_onset_model_from_string(r.text("below_onset_from_above", std::nullopt, below_onset_laws));
  if (!r.has("scattered")) {
    auto& s = r.resolved()["scattered"];
    s["jump_fraction"] = defaults.scattered.jump_fraction;
    s["exponent"] = defaults.scattered.exponent;
    s["s_min"] = defaults.scattered.s_min;
    s["s_max"] = defaults.scattered.s_max;
    s["source"] = defaults.scattered.source;
  }
}

}  // namespace

void read_damper_drive(ObjectReader& r, DamperSpec& d) {
  const std::string model = r.text("model", std::string("auto"), {"rolling", "bouncing", "auto"});
  d.model = *fm::damper_model_from_string(model);
  d.drive_axis = axis_index(r.text("drive_axis", std::string("x"), {"x", "y", "z"}));
  d.gravity_m_s2 = r.vector3("gravity_m_s2", fm::Vec3{0.0, 0.0, -fm::kStandardGravity}, limits::kGravity, " m/s^2");
  r.object("model_options", false, [&](ObjectReader& m) { read_model_options(m, d.model_options); });
  if (!r.has("model_options")) {
    ObjectReader defaults(r.file(), empty_object(), r.pointer() + "/model_options", r.resolved()["model_options"]);
    read_model_options(defaults, d.model_options);
  }
  check_model_options(r, d.model_options);
  // Gravity along the drive breaks the closed forms' assumption (docs/theory.md §2).
  const double g_norm = std::hypot(d.gravity_m_s2[0], d.gravity_m_s2[1], d.gravity_m_s2[2]);
  d.model_options.gravity_along_drive = g_norm > 0.0 && std::abs(d.gravity_m_s2[d.drive_axis]) > 0.01 * g_norm;
  const double g_across = std::sqrt(std::max(0.0, g_norm * g_norm - d.gravity_m_s2[d.drive_axis] * d.gravity_m_s2[d.drive_axis]));
  d.model_options.gravity_across_drive = g_across > 0.01 * std::max(g_norm, 1e-300);
}

void read_layer_bed(ObjectReader& r, const Case& c, const DamperSpec& d, LayerSpec& layer) {
  r.object("container", true, [&](ObjectReader& k) {
    const std::string shape = k.text("shape", std::nullopt, {"box", "cylinder"});
    if (shape == "box") {
      layer.container.shape = fm::ContainerShape::kBox;
      layer.container.box_inner_size_m = k.vector3("inner_size_m", std::nullopt, limits::kContainerSize, " m");
    } else {
      layer.container.shape = fm::ContainerShape::kCylinder;
      layer.container.cylinder_inner_radius_m = k.number("inner_radius_m", std::nullopt, limits::kContainerSize, " m");
      layer.container.cylinder_inner_length_m = k.number("inner_length_m", std::nullopt, limits::kContainerSize, " m");
      layer.container.cylinder_axis = axis_index(k.text("axis", std::string("x"), {"x", "y", "z"}));
    }
  });
  auto& packing = layer.packing;
  r.object("particles", true, [&](ObjectReader& p) {
    layer.particle_count = p.integer("count", std::nullopt, 1, 10'000'000);
    layer.particle_radius_m = p.number("radius_m", std::nullopt, limits::kParticleRadius, " m");
    layer.particle_material = p.text("material", std::string("steel"));
    packing.collect_side = p.text("collect_side", std::string("negative"), {"negative", "positive"}) == "negative" ? -1 : 1;
    // Gap between neighbouring lanes across the drive: a number, or "auto" (the width
    // the lanes leave, shared out equally: each lane owns L/n).
    if (p.is_string("lane_gap_m")) {
      p.text("lane_gap_m", std::nullopt, {"auto"});
      packing.lane_gap_auto = true;
    } else {
      packing.lane_gap_m = p.number("lane_gap_m", 0.0, {0.0, limits::kContainerSize.max}, " m (or \"auto\")");
    }
    layer.lot_diameter_variation_m = p.number("lot_diameter_variation_m",
                                              dem_reference::ParticleGroupOptions{}.lot_diameter_variation_m,
                                              {0.0, dem_reference::limits::kMaxLotDiameterVariation_m}, " m");
    if (p.has("lattice") && !p.is_string("lattice")) {
      const auto counts = p.vector3("lattice", std::nullopt, {1.0, 1e6}, "");
      std::array<int, 3> n{};
      for (int i = 0; i < 3; ++i) {
        if (counts[i] != std::floor(counts[i])) p.fail("lattice/" + std::to_string(i), "must be a whole number >= 1");
        n[i] = static_cast<int>(counts[i]);
      }
      packing.lattice_counts = n;
    } else {
      packing.staggered = p.text("lattice", std::string("auto"), {"auto", "staggered"}) == "staggered";
    }
  });
  packing.drive_axis = d.drive_axis;
  // The bed rests on the wall gravity points to (the dominant component).
  int g_axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(d.gravity_m_s2[i]) > std::abs(d.gravity_m_s2[g_axis])) g_axis = i;
  const double g_norm = std::hypot(d.gravity_m_s2[0], d.gravity_m_s2[1], d.gravity_m_s2[2]);
  if (g_norm > 0.0) packing.gravity_axis_sign = std::make_pair(g_axis, d.gravity_m_s2[g_axis] < 0.0 ? -1 : 1);

  for (const auto& line : layer.container.validate("damper/container")) r.fail("container", line);
  if (!c.materials.count(layer.particle_material))
    r.fail("particles/material", "'" + layer.particle_material + "' is not defined in /materials (nor built in)");
  // A buffered wall's lining takes its thickness off the room the bed has (the DEM's
  // spheres meet the lining's surface), so the clearance is the free length between linings.
  const dem_reference::WallLayerOptions& lining = layer.compartment.layer;
  const fm::Container free_space = layer.container.lined(lining.thickness_m, lining.axis);
  if (!free_space.validate("").empty())
    throw CaseError(r.file(), (c.format_version == 1 ? "/dem" : r.pointer()) + "/wall_layer/thickness_m",
                    "= " + base::format_number(lining.thickness_m, 6) + " m: the lining leaves the container no room");
  try {
    layer.bed = fm::collected_lattice(free_space, layer.particle_count, layer.particle_radius_m, packing);
  } catch (const std::invalid_argument& e) {
    r.fail("particles", e.what());
  }
  const auto explicit_clearance = r.optional_number("clearance_m", limits::kClearance, " m");
  // The bed's clearance is that of the settled bed: a bed stacked across gravity spreads
  // its lanes' spheres onto the base (LatticeBed::settled_clearance_m).
  const double settled = layer.bed.settled_clearance_m;
  layer.clearance_m = explicit_clearance.value_or(settled);
  // A bed that leaves (nearly) no room is no damper: the derived clearance takes the
  // range of an explicit one.
  if (!explicit_clearance && !limits::kClearance.contains(settled)) {
    std::ostringstream out;
    out.precision(10);
    if (settled == layer.bed.clearance_m) {
      out << "the collected bed leaves a clearance of " << layer.bed.clearance_m << " m (" << layer.bed.slabs
          << " slabs of 2r in " << free_space.inner_length(d.drive_axis) << " m): " << limits::kClearance.text()
          << " m";
    } else {
      out << "the bed is stacked more than one sphere high across gravity: it settles into bottom rows that leave "
          << settled << " m of travel along the drive (its lattice of " << layer.bed.slabs << " slabs would leave "
          << layer.bed.clearance_m << " m; docs/collect_and_collide.md §8): " << limits::kClearance.text()
          << " m; use fewer spheres, a container one sphere high or a longer one";
    }
    r.fail("particles", out.str());
  }
  // The bed cannot travel farther than the container is long: an override beyond the
  // free length (inner length along the drive minus the settled bed) is a typo, not a design.
  if (explicit_clearance && *explicit_clearance > settled + 1e-12) {
    std::ostringstream out;
    out.precision(10);  // 0.1000001 is not 0.1
    out << "= " << *explicit_clearance << ": must be <= the free length along the drive, " << settled
        << " m (inner length " << free_space.inner_length(d.drive_axis) << " m"
        << (lining.thickness_m > 0.0 ? " inside the wall layers" : "") << " minus the settled bed)";
    r.fail("clearance_m", out.str());
  }
  const double volume = 4.0 / 3.0 * fm::kPi * std::pow(layer.particle_radius_m, 3);
  layer.bed_mass_kg = layer.particle_count * volume * c.materials.at(layer.particle_material).density_kg_m3;
  auto& derived = r.resolved()["derived"];
  derived["bed_clearance_m"] = layer.bed.settled_clearance_m;
  // Only a bed that settles differently from its lattice reports it (a bed one sphere high
  // keeps the resolved case, and the physics hash of the fields made for it, as it was).
  if (layer.bed.settled_clearance_m != layer.bed.clearance_m) {
    derived["lattice_clearance_m"] = layer.bed.clearance_m;
    derived["settled_upper_spheres"] = layer.bed.settled_upper_spheres;
  }
  derived["bed_extent_m"] = layer.bed.bed_extent_m;
  derived["bed_slabs"] = layer.bed.slabs;
  derived["clearance_m"] = layer.clearance_m;
  derived["bed_mass_kg"] = layer.bed_mass_kg;

  // The DEM's compartment takes the bed as the closed forms see it.
  auto& compartment = layer.compartment;
  compartment.container = layer.container;
  compartment.collect_axis = d.drive_axis;
  compartment.collect_side = packing.collect_side;
  compartment.lane_gap_m = packing.lane_gap_m;
  compartment.lane_gap_auto = packing.lane_gap_auto;
  compartment.staggered_lattice = packing.staggered;
  if (packing.lattice_counts) compartment.lattice_counts.assign(packing.lattice_counts->begin(), packing.lattice_counts->end());
  dem_reference::ParticleGroupOptions group;
  group.count = layer.particle_count;
  group.radius_m = layer.particle_radius_m;
  group.material = material_index(r, "particles/material", layer.particle_material, c);
  group.lot_diameter_variation_m = layer.lot_diameter_variation_m;
  compartment.particles = {group};
}

/// A structure-plane direction, normalised; CaseError for a zero or non-finite one.
PlaneVector read_plane_direction(ObjectReader& r, const std::string& key, std::optional<PlaneVector> fallback) {
  PlaneVector v{};
  if (r.has(key) || !fallback) {
    const auto values = r.number_array(key, Range{-1e6, 1e6}, "", 2);
    if (values.size() != 2) r.fail(key, "has " + std::to_string(values.size()) + " entries: must be [x, y]");
    v = {values[0], values[1]};
  } else {
    v = *fallback;
  }
  const double norm = std::hypot(v[0], v[1]);
  if (!(norm > 1e-9))
    r.fail(key, "= [" + base::format_number(v[0], kMessageDigits) + ", " + base::format_number(v[1], kMessageDigits) +
                    "]: must be a non-zero direction");
  v = {v[0] / norm, v[1] / norm};
  r.resolved()[key] = v;
  return v;
}

std::string read_point_name(ObjectReader& r, const std::string& key, const Case& c) {
  const std::string name = r.text(key, std::nullopt);
  const auto& names = c.structure->point_names;
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;  // the first few: a message stays one readable line
    for (std::size_t k = 0; k < names.size() && k < 12; ++k) known += (k ? ", " : "") + names[k];
    if (names.size() > 12) known += ", ... (" + std::to_string(names.size()) + " points)";
    r.fail(key, "'" + name + "' is no named point of the structure (known: " + known + ")");
  }
  return name;
}

std::string resolve_case_relative(const ObjectReader& r, const std::string& path) {
  if (path.empty()) return path;
  const std::filesystem::path given(path);
  return (given.is_absolute() ? given : std::filesystem::path(r.file()).parent_path() / given).lexically_normal().string();
}

void read_dampers(ObjectReader& root, Case& c) {
  if (!root.has("dampers")) root.fail("dampers", "required (an array of at least one damper)");
  root.array("dampers", [&](ObjectReader& r) {
    DamperSpec d;
    d.name = r.text("name", "damper_" + std::to_string(c.dampers.size() + 1));
    for (const auto& other : c.dampers) {
      if (other.name == d.name) r.fail("name", "'" + d.name + "' names another damper already: names must be unique");
    }
    d.site = read_point_name(r, "site", c);
    d.drive_direction = read_plane_direction(r, "drive_direction", std::nullopt);
    d.container_mass_kg = r.number("container_mass_kg", std::nullopt, limits::kMass, " kg");
    d.container_rotary_inertia_kg_m2 =
        r.number("container_rotary_inertia_kg_m2", 0.0, limits::kRotaryInertia, " kg m^2");
    read_damper_drive(r, d);
    if (!r.has("layers")) r.fail("layers", "required (an array of at least one layer)");
    r.array("layers", [&](ObjectReader& l) {
      LayerSpec layer;
      layer.name = l.text("name", "layer_" + std::to_string(d.layers.size() + 1));
      for (const auto& other : d.layers) {
        if (other.name == layer.name) l.fail("name", "'" + layer.name + "' names another layer of this damper already");
      }
      layer.field_file = resolve_case_relative(l, l.text("field_file", std::string()));
      read_layer_geometry(l, c, layer);
      read_layer_bed(l, c, d, layer);
      layer.compartment.offset_m = l.vector3("offset_m", fm::Vec3{0.0, 0.0, 0.0}, limits::kPosition, " m");
      d.layers.push_back(std::move(layer));
    });
    if (d.layers.empty()) r.fail("layers", "is empty: a damper needs at least one layer");
    c.dampers.push_back(std::move(d));
  });
  if (c.dampers.empty()) root.fail("dampers", "is empty: give at least one damper");
}

}  // namespace pdamp::case_file::detail
