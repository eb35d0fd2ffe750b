// Case files: strict JSON reading (unknown keys, types, ranges) into option structs.
#include "case_io.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>
#include <vector>

#include "errors.hpp"
#include "limits.hpp"
#include "pdamp/formulas/input_file.hpp"

namespace pdamp::cli {

using nlohmann::json;
namespace fm = formulas;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

constexpr Range kPositive{0.0, kInf, true};
const json kEmptyObject = json::object();  // stands in for an omitted section
/// Restitution the DEM's calibrated damping covers (formulas::DampingTable).
constexpr Range kRestitution{dem_reference::limits::kMinRestitution, 1.0};

std::string type_name(const json& value) { return value.type_name(); }

/// A number for messages, with enough digits to tell 0.1000001 from 0.1.
std::string number_text(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

/// Reads one JSON object: every read key is recorded with its resolved value, and
/// finish() rejects the keys nobody read, naming the allowed ones.
class ObjectReader {
 public:
  ObjectReader(const std::string& file, const json& object, std::string pointer, json& resolved)
      : file_(file), object_(object), pointer_(std::move(pointer)), resolved_(resolved) {
    if (!object_.is_object()) fail("", "must be a JSON object, got " + type_name(object_));
    resolved_ = json::object();
  }

  /// `key` may be a path below this object ("lattice/0"): each token is escaped as a
  /// JSON pointer (RFC 6901: "~" -> "~0", "/" -> "~1") except the separators given.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw InputError(file_, pointer_ + (key.empty() ? "" : "/" + key), what);
  }
  [[noreturn]] void fail_at_key(const std::string& key, const std::string& what) const {
    std::string token;
    for (char ch : key) token += ch == '~' ? std::string("~0") : ch == '/' ? std::string("~1") : std::string(1, ch);
    fail(token, what);
  }
  bool has(const std::string& key) const { return object_.contains(key); }
  bool is_string(const std::string& key) const { return has(key) && object_.at(key).is_string(); }
  bool is_number(const std::string& key) const { return has(key) && object_.at(key).is_number(); }
  std::vector<double> number_array(const std::string& key, Range range, const std::string& unit, std::size_t min_size) {
    known_.insert(key);
    if (!has(key) || !object_.at(key).is_array()) fail(key, "required (an array of numbers" + unit + ")");
    if (object_.at(key).size() < min_size)
      fail(key, "has " + std::to_string(object_.at(key).size()) + " entries: needs at least " + std::to_string(min_size));
    std::vector<double> values;
    for (std::size_t i = 0; i < object_.at(key).size(); ++i) {
      const json& item = object_.at(key)[i];
      if (!item.is_number() || !range.contains(item.get<double>()))
        fail(key + "/" + std::to_string(i), range.text() + unit);
      values.push_back(item.get<double>());
    }
    resolved_[key] = values;
    return values;
  }
  /// An array of objects; the callback reads each element with its own reader.
  template <typename Fn>
  void array(const std::string& key, Fn&& read) {
    known_.insert(key);
    if (!has(key)) {
      resolved_[key] = json::array();
      return;
    }
    const json& items = object_.at(key);
    if (!items.is_array()) fail(key, "must be an array of objects, got " + type_name(items));
    resolved_[key] = json::array();
    for (std::size_t i = 0; i < items.size(); ++i) {
      resolved_[key].push_back(json::object());
      ObjectReader child(file_, items[i], pointer_ + "/" + key + "/" + std::to_string(i), resolved_[key][i]);
      read(child);
      child.finish();
    }
  }

  double number(const std::string& key, std::optional<double> fallback, Range range, const std::string& unit = "") {
    known_.insert(key);
    double value = 0.0;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (" + range.text() + unit + ")");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_number()) fail(key, "must be a number" + unit + ", got " + type_name(item));
      value = item.get<double>();
    }
    if (!range.contains(value)) {
      std::ostringstream out;
      out.precision(10);  // 0.1000001 is not 0.1
      out << "= " << value << ": " << range.text() << unit;
      fail(key, out.str());
    }
    resolved_[key] = value;
    return value;
  }
  /// Absent: nothing. null is not "absent" (it would hide a half-edited value): a
  /// number must be given or the key omitted.
  std::optional<double> optional_number(const std::string& key, Range range, const std::string& unit = "") {
    if (!object_.contains(key)) {
      known_.insert(key);
      return std::nullopt;
    }
    if (object_.at(key).is_null()) fail(key, "must be a number" + unit + " (omit the key for the default), got null");
    return number(key, std::nullopt, range, unit);
  }
  int integer(const std::string& key, std::optional<int> fallback, int min, int max) {
    known_.insert(key);
    int value = 0;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "])");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      // A whole number written 36.0 or 1e3 is an integer too (as lattice counts and
      // --periods take it); the comparison is done in double, so 2^64 - 1 (an unsigned
      // JSON integer) is not read as -1.
      const bool whole = item.is_number_integer() ||
                         (item.is_number_float() && std::isfinite(item.get<double>()) &&
                          item.get<double>() == std::floor(item.get<double>()));
      if (!whole) fail(key, "must be a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " +
                                (item.is_number() ? number_text(item.get<double>()) : type_name(item)));
      const double wide = item.is_number_unsigned() ? static_cast<double>(item.get<unsigned long long>())
                                                    : item.get<double>();
      if (wide < min || wide > max)
        fail(key, "= " + number_text(wide) + ": must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
      value = static_cast<int>(wide);
    }
    resolved_[key] = value;
    return value;
  }
  std::string text(const std::string& key, std::optional<std::string> fallback,
                   const std::vector<std::string>& allowed = {}) {
    known_.insert(key);
    std::string value;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required" + allowed_text(allowed));
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_string()) fail(key, "must be a string, got " + type_name(item));
      value = item.get<std::string>();
    }
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), value) == allowed.end())
      fail(key, "'" + value + "' is not allowed" + allowed_text(allowed));
    resolved_[key] = value;
    return value;
  }
  std::array<double, 3> vector3(const std::string& key, std::optional<std::array<double, 3>> fallback, Range range,
                                const std::string& unit) {
    known_.insert(key);
    std::array<double, 3> value{};
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (3 numbers" + unit + ")");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_array() || item.size() != 3) fail(key, "must be an array of 3 numbers" + unit);
      for (std::size_t i = 0; i < 3; ++i) {
        if (!item[i].is_number()) fail(key + "/" + std::to_string(i), "must be a number" + unit);
        value[i] = item[i].get<double>();
        if (!range.contains(value[i])) {
          std::ostringstream out;
          out.precision(10);  // 0.1000001 is not 0.1
          out << "= " << value[i] << ": " << range.text() << unit;
          fail(key + "/" + std::to_string(i), out.str());
        }
      }
    }
    resolved_[key] = value;
    return value;
  }
  /// A nested object; the callback reads it with its own reader.
  template <typename Fn>
  void object(const std::string& key, bool required, Fn&& read) {
    known_.insert(key);
    if (!object_.contains(key)) {
      if (required) fail(key, "required (a JSON object)");
      return;
    }
    ObjectReader child(file_, object_.at(key), pointer_ + "/" + key, resolved_[key]);
    read(child);
    child.finish();
  }
  void finish() const {
    for (const auto& [key, value] : object_.items()) {
      (void)value;
      if (!known_.count(key)) {
        std::string allowed;
        for (const auto& k : known_) allowed += (allowed.empty() ? "" : ", ") + k;
        fail_at_key(key, "unknown key (allowed here: " + allowed + ")");
      }
    }
  }
  json& resolved() { return resolved_; }
  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }

 private:
  static std::string allowed_text(const std::vector<std::string>& allowed) {
    if (allowed.empty()) return "";
    std::string out = " (one of:";
    for (const auto& a : allowed) out += " " + a;
    return out + ")";
  }

  const std::string& file_;
  const json& object_;
  std::string pointer_;
  json& resolved_;
  std::set<std::string> known_;
};

int axis_index(const std::string& name) { return name == "x" ? 0 : name == "y" ? 1 : 2; }

fm::Material read_material(ObjectReader& r, const fm::Material& defaults) {
  fm::Material m;
  m.density_kg_m3 = r.number("density_kg_m3", defaults.density_kg_m3, limits::kDensity, " kg/m^3");
  m.youngs_modulus_pa = r.number("youngs_modulus_pa", defaults.youngs_modulus_pa, limits::kModulus, " Pa");
  m.poisson_ratio = r.number("poisson_ratio", defaults.poisson_ratio, limits::kPoisson, "");
  return m;
}

void read_model_options(ObjectReader& r, fm::ModelOptions& options) {
  const fm::ModelOptions defaults;
  options.rolling_inertia_factor = r.number("rolling_inertia_factor", defaults.rolling_inertia_factor, {0.0, 1.0, true});
  options.rolling_calibration = r.number("rolling_calibration", defaults.rolling_calibration, {0.0, 2.0, true});
  options.bouncing_calibration = r.number("bouncing_calibration", defaults.bouncing_calibration, {0.0, 2.0, true});
  r.object("scattered", false, [&](ObjectReader& s) {
    options.scattered.jump_fraction =
        s.number("jump_fraction", defaults.scattered.jump_fraction, {0.0, formulas::kMaxJumpFraction});
    options.scattered.exponent = s.number("exponent", defaults.scattered.exponent, {0.0, 10.0});
    options.scattered.s_min = s.number("s_min", defaults.scattered.s_min, {0.0, 0.999});
    options.scattered.s_max = s.number("s_max", defaults.scattered.s_max, {options.scattered.s_min, 1.0});
    // Fitted only when both coefficients are given: a partial object keeps a default
    // coefficient, which stays provisional (and says so in the warnings).
    options.scattered.provisional = !(s.has("jump_fraction") && s.has("exponent"));
    options.scattered.source =
        s.text("source", options.scattered.provisional ? defaults.scattered.source : std::string("case file"));
  });
  if (!r.has("scattered")) {
    auto& s = r.resolved()["scattered"];
    s["jump_fraction"] = defaults.scattered.jump_fraction;
    s["exponent"] = defaults.scattered.exponent;
    s["s_min"] = defaults.scattered.s_min;
    s["s_max"] = defaults.scattered.s_max;
    s["source"] = defaults.scattered.source;
  }
}

void read_damper(ObjectReader& r, Case& c) {
  DamperSpec& d = c.damper;
  const std::string model = r.text("model", std::string("auto"), {"rolling", "bouncing", "auto"});
  d.model = *fm::damper_model_from_string(model);
  r.object("container", true, [&](ObjectReader& k) {
    const std::string shape = k.text("shape", std::nullopt, {"box", "cylinder"});
    if (shape == "box") {
      d.container.shape = fm::ContainerShape::kBox;
      d.container.box_inner_size_m = k.vector3("inner_size_m", std::nullopt, limits::kContainerSize, " m");
    } else {
      d.container.shape = fm::ContainerShape::kCylinder;
      d.container.cylinder_inner_radius_m = k.number("inner_radius_m", std::nullopt, limits::kContainerSize, " m");
      d.container.cylinder_inner_length_m = k.number("inner_length_m", std::nullopt, limits::kContainerSize, " m");
      d.container.cylinder_axis = axis_index(k.text("axis", std::string("x"), {"x", "y", "z"}));
    }
  });
  d.drive_axis = axis_index(r.text("drive_axis", std::string("x"), {"x", "y", "z"}));
  d.gravity_m_s2 = r.vector3("gravity_m_s2", fm::Vec3{0.0, 0.0, -fm::kStandardGravity}, limits::kGravity, " m/s^2");
  r.object("particles", true, [&](ObjectReader& p) {
    d.particle_count = p.integer("count", std::nullopt, 1, 10'000'000);
    d.particle_radius_m = p.number("radius_m", std::nullopt, limits::kParticleRadius, " m");
    d.particle_material = p.text("material", std::string("steel"));
    d.packing.collect_side = p.text("collect_side", std::string("negative"), {"negative", "positive"}) == "negative" ? -1 : 1;
    // Gap between neighbouring lanes across the drive: a number, or "auto" (the width
    // the lanes leave, shared out equally: each lane owns L/n).
    if (p.is_string("lane_gap_m")) {
      p.text("lane_gap_m", std::nullopt, {"auto"});
      d.packing.lane_gap_auto = true;
    } else {
      d.packing.lane_gap_m = p.number("lane_gap_m", 0.0, {0.0, limits::kContainerSize.max}, " m (or \"auto\")");
    }
    d.lot_diameter_variation_m = p.number("lot_diameter_variation_m",
                                          dem_reference::ParticleGroupOptions{}.lot_diameter_variation_m,
                                          {0.0, dem_reference::limits::kMaxLotDiameterVariation_m}, " m");
    if (p.has("lattice") && !p.is_string("lattice")) {
      const auto counts = p.vector3("lattice", std::nullopt, {1.0, 1e6}, "");
      std::array<int, 3> n{};
      for (int i = 0; i < 3; ++i) {
        if (counts[i] != std::floor(counts[i])) p.fail("lattice/" + std::to_string(i), "must be a whole number >= 1");
        n[i] = static_cast<int>(counts[i]);
      }
      d.packing.lattice_counts = n;
    } else {
      p.text("lattice", std::string("auto"), {"auto"});
    }
  });
  d.packing.drive_axis = d.drive_axis;
  // The bed rests on the wall gravity points to (the dominant component).
  int g_axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(d.gravity_m_s2[i]) > std::abs(d.gravity_m_s2[g_axis])) g_axis = i;
  const double g_norm = std::hypot(d.gravity_m_s2[0], d.gravity_m_s2[1], d.gravity_m_s2[2]);
  if (g_norm > 0.0) d.packing.gravity_axis_sign = std::make_pair(g_axis, d.gravity_m_s2[g_axis] < 0.0 ? -1 : 1);
  r.object("model_options", false, [&](ObjectReader& m) { read_model_options(m, d.model_options); });
  if (!r.has("model_options")) {
    ObjectReader defaults(r.file(), kEmptyObject, r.pointer() + "/model_options", r.resolved()["model_options"]);
    read_model_options(defaults, d.model_options);
  }
  // Gravity along the drive breaks the closed forms' assumption (PHYSICS.md §2).
  d.model_options.gravity_along_drive = g_norm > 0.0 && std::abs(d.gravity_m_s2[d.drive_axis]) > 0.01 * g_norm;
  const double g_across = std::sqrt(std::max(0.0, g_norm * g_norm - d.gravity_m_s2[d.drive_axis] * d.gravity_m_s2[d.drive_axis]));
  d.model_options.gravity_across_drive = g_across > 0.01 * std::max(g_norm, 1e-300);

  for (const auto& line : d.container.validate("damper/container")) r.fail("container", line);
  if (!c.materials.count(d.particle_material))
    r.fail("particles/material", "'" + d.particle_material + "' is not defined in /materials (nor built in)");
  try {
    d.bed = fm::collected_lattice(d.container, d.particle_count, d.particle_radius_m, d.packing);
  } catch (const std::invalid_argument& e) {
    r.fail("particles", e.what());
  }
  const auto explicit_clearance = r.optional_number("clearance_m", limits::kClearance, " m");
  d.clearance_m = explicit_clearance.value_or(d.bed.clearance_m);
  // A bed that leaves (nearly) no room is no damper: the derived clearance takes the
  // range of an explicit one.
  if (!explicit_clearance && !limits::kClearance.contains(d.bed.clearance_m)) {
    std::ostringstream out;
    out.precision(10);
    out << "the collected bed leaves a clearance of " << d.bed.clearance_m << " m (" << d.bed.slabs
        << " slabs of 2r in " << d.container.inner_length(d.drive_axis) << " m): " << limits::kClearance.text() << " m";
    r.fail("particles", out.str());
  }
  // The bed cannot travel farther than the container is long: an override beyond the
  // free length (inner length along the drive minus the bed) is a typo, not a design.
  const double inner_length = d.container.inner_length(d.drive_axis);
  if (explicit_clearance && *explicit_clearance > inner_length - d.bed.bed_extent_m + 1e-12) {
    std::ostringstream out;
    out.precision(10);  // 0.1000001 is not 0.1
    out << "= " << *explicit_clearance << ": must be <= the free length along the drive, " << inner_length - d.bed.bed_extent_m
        << " m (inner length " << inner_length << " m minus the bed's " << d.bed.bed_extent_m << " m)";
    r.fail("clearance_m", out.str());
  }
  const double volume = 4.0 / 3.0 * fm::kPi * std::pow(d.particle_radius_m, 3);
  d.bed_mass_kg = d.particle_count * volume * c.materials.at(d.particle_material).density_kg_m3;
  auto& derived = r.resolved()["derived"];
  derived["bed_clearance_m"] = d.bed.clearance_m;
  derived["bed_extent_m"] = d.bed.bed_extent_m;
  derived["bed_slabs"] = d.bed.slabs;
  derived["clearance_m"] = d.clearance_m;
  derived["bed_mass_kg"] = d.bed_mass_kg;
}

int material_index(ObjectReader& r, const std::string& key, const std::string& name,
                   const std::vector<dem_reference::MaterialOptions>& materials) {
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  r.fail(key, "'" + name + "' is not defined in /materials (nor built in)");
}

/// Contact parameters of a material pair: restitution as a number (constant) or a
/// table {speeds_m_s, values}; friction; rolling friction.
void read_contact_pair(ObjectReader& r, dem_reference::ContactPairOptions& pair) {
  const dem_reference::ContactPairOptions defaults;
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
  pair.friction = r.number("friction", defaults.friction, {0.0, dem_reference::limits::kMaxFriction});
  pair.rolling_friction = r.number("rolling_friction", defaults.rolling_friction, {0.0, dem_reference::limits::kMaxRollingFriction});
}

void read_dem(ObjectReader& r, Case& c) {
  namespace dr = dem_reference;
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
  const auto& d = c.damper;
  dr::CompartmentOptions compartment;
  compartment.container = d.container;
  const std::string wall = r.text("wall_material", std::string("steel"));
  compartment.wall_material = material_index(r, "wall_material", wall, world.materials);
  dr::ParticleGroupOptions group;
  group.count = d.particle_count;
  group.radius_m = d.particle_radius_m;
  group.material = material_index(r, "", d.particle_material, world.materials);
  group.radius_spread = r.number("radius_spread", 0.0, {0.0, 0.4999});
  group.lot_diameter_variation_m = d.lot_diameter_variation_m;
  compartment.particles = {group};
  const std::string placement =
      r.text("placement", std::string("collected_lattice"), {"collected_lattice", "centred_lattice", "random"});
  compartment.placement = placement == "collected_lattice" ? dr::InitialPlacement::kCollectedLattice
                          : placement == "centred_lattice" ? dr::InitialPlacement::kCentredLattice
                                                           : dr::InitialPlacement::kRandom;
  compartment.collect_axis = d.drive_axis;
  compartment.collect_side = d.packing.collect_side;
  compartment.lane_gap_m = d.packing.lane_gap_m;
  compartment.lane_gap_auto = d.packing.lane_gap_auto;
  if (d.packing.lattice_counts) compartment.lattice_counts.assign(d.packing.lattice_counts->begin(), d.packing.lattice_counts->end());

  r.object("contact", false, [&](ObjectReader& p) { read_contact_pair(p, world.default_pair); });
  if (!r.has("contact")) {
    ObjectReader fallback(r.file(), kEmptyObject, r.pointer() + "/contact", r.resolved()["contact"]);
    read_contact_pair(fallback, world.default_pair);
  }
  r.array("pairs", [&](ObjectReader& p) {
    dr::ContactPairOptions pair = world.default_pair;
    pair.material_a = material_index(p, "material_a", p.text("material_a", std::nullopt), world.materials);
    pair.material_b = material_index(p, "material_b", p.text("material_b", std::nullopt), world.materials);
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
  // The closed forms' base friction (where auto leaves rolling) is the DEM's
  // sphere-wall friction: one number for both models.
  {
    double mu = world.default_pair.friction;
    for (const auto& pair : world.pairs)
      if ((pair.material_a == group.material && pair.material_b == compartment.wall_material) ||
          (pair.material_b == group.material && pair.material_a == compartment.wall_material))
        mu = pair.friction;
    c.damper.model_options.base_friction = mu;
    c.resolved["damper"]["derived"]["base_friction"] = mu;
  }
  r.object("inner_structures", false, [&](ObjectReader& s) {
    s.array("plates", [&](ObjectReader& p) {
      dr::PlateOptions plate;
      plate.centre_m = p.vector3("centre_m", std::nullopt, limits::kPosition, " m");
      plate.size_m = p.vector3("size_m", std::nullopt, limits::kContainerSize, " m");
      plate.material = material_index(p, "material", p.text("material", wall), world.materials);
      compartment.plates.push_back(plate);
    });
    s.array("pins", [&](ObjectReader& p) {
      dr::PinOptions pin;
      pin.centre_m = p.vector3("centre_m", std::nullopt, limits::kPosition, " m");
      pin.axis = axis_index(p.text("axis", std::string("z"), {"x", "y", "z"}));
      pin.radius_m = p.number("radius_m", std::nullopt, limits::kContainerSize, " m");
      pin.length_m = p.number("length_m", std::nullopt, limits::kContainerSize, " m");
      pin.material = material_index(p, "material", p.text("material", wall), world.materials);
      compartment.pins.push_back(pin);
    });
  });
  r.object("wall_layer", false, [&](ObjectReader& l) {
    compartment.layer.thickness_m = l.number("thickness_m", std::nullopt, limits::kContainerSize, " m");
    compartment.layer.material = material_index(l, "material", l.text("material", std::nullopt), world.materials);
    const std::string axis = l.text("axis", std::string("all"), {"all", "x", "y", "z"});
    compartment.layer.axis = axis == "all" ? -1 : axis_index(axis);
  });
  world.compartments = {compartment};
  world.gravity_m_s2 = d.gravity_m_s2;
  sim.drive_axis = {0.0, 0.0, 0.0};
  sim.drive_axis[d.drive_axis] = 1.0;

  auto& integration = world.integration;
  integration.time_step_s = r.number("time_step_s", 0.0, {0.0, dr::limits::kMaxTimeStep_s}, " s (0 = automatic)");
  integration.steps_per_contact = r.integer("steps_per_contact", integration.steps_per_contact, dr::limits::kMinStepsPerContact,
                                            dr::limits::kMaxStepsPerContact);
  if (const auto v = r.optional_number("max_impact_speed_m_s", limits::kImpactSpeed, " m/s")) integration.max_impact_speed_m_s = *v;
  integration.skin_fraction = r.number("skin_fraction", integration.skin_fraction,
                                       {dr::limits::kMinSkinFraction, dr::limits::kMaxSkinFraction});
  integration.max_overlap_fraction = r.number("max_overlap_fraction", integration.max_overlap_fraction, {0.0, 0.999, true});
  sim.settling_time_s =
      r.number("settling_time_s", defaults.settling_time_s, {-1.0, dr::limits::kMaxSettlingTime_s}, " s (-1 = automatic)");
  if (sim.settling_time_s < 0.0 && sim.settling_time_s != -1.0) r.fail("settling_time_s", "must be -1 (automatic) or >= 0");
  sim.transient_periods = r.integer("transient_periods", defaults.transient_periods, 0, dr::limits::kMaxPeriods);
  sim.analysed_periods = r.integer("analysed_periods", defaults.analysed_periods, 1, dr::limits::kMaxPeriods);
  sim.samples_per_period = r.integer("samples_per_period", defaults.samples_per_period, dr::limits::kMinSamplesPerPeriod,
                                     dr::limits::kMaxSamplesPerPeriod);
  sim.snapshots = r.integer("snapshots", defaults.snapshots, 0, dr::limits::kMaxSnapshots);
  world.seed = static_cast<std::uint64_t>(r.integer("seed", 1, 0, std::numeric_limits<int>::max()));
  world.threads = r.integer("threads", 1, 0, dr::limits::kMaxThreads);
}

void read_axis_range(ObjectReader& r, surrogate::AxisRange& range, const surrogate::AxisRange& defaults,
                     const Range& axis_limits, const std::string& unit) {
  range.min = r.number("min", defaults.min, axis_limits, unit);
  range.max = r.number("max", defaults.max, axis_limits, unit);
  range.count = r.integer("count", defaults.count, 1, 10000);
  range.spacing = r.text("spacing", std::string(defaults.spacing == surrogate::AxisSpacing::kLog ? "log" : "linear"),
                         {"linear", "log"}) == "log"
                      ? surrogate::AxisSpacing::kLog
                      : surrogate::AxisSpacing::kLinear;
  if (range.max < range.min || (range.max == range.min && range.count != 1))
    r.fail("max", "must be > min (or equal to min with count 1)");
}

/// Default grid: the case frequency and strokes from 0.1 h to 1.0 h (10 points), or
/// Γ at that frequency and X/h over the same range.
void read_field(ObjectReader& r, Case& c) {
  FieldSpec& field = c.field;
  const std::string axes =
      r.text("axes", std::string("frequency_amplitude"), {"frequency_amplitude", "intensity_stroke_over_clearance"});
  const double h = c.damper.clearance_m;
  const double f = c.excitation.frequency_hz;
  surrogate::AxisRange default0{f, f, 1, surrogate::AxisSpacing::kLinear};
  // Strokes from 0.1 h to 1.0 h, within the range of a stroke (a 50 m clearance would
  // ask for 50 m strokes, a key the case never wrote).
  surrogate::AxisRange default1{std::min(0.1 * h, 0.5 * limits::kStroke.max), std::min(1.0 * h, limits::kStroke.max), 10,
                                surrogate::AxisSpacing::kLinear};
  std::string unit0 = " Hz", unit1 = " m";
  if (axes == "intensity_stroke_over_clearance") {
    field.axes = surrogate::GridAxes::kIntensityStrokeOverClearance;
    default0 = {0.5, 0.5, 1, surrogate::AxisSpacing::kLinear};
    default1 = {0.1, 1.0, 10, surrogate::AxisSpacing::kLinear};
    unit0 = unit1 = "";
  }
  const Range limits0 = field.axes == surrogate::GridAxes::kFrequencyAmplitude ? limits::kFrequency : limits::kIntensity;
  const Range limits1 = field.axes == surrogate::GridAxes::kFrequencyAmplitude ? limits::kStroke : Range{0.0, 100.0, true};
  const auto read0 = [&](ObjectReader& a) { read_axis_range(a, field.axis0, default0, limits0, unit0); };
  const auto read1 = [&](ObjectReader& a) { read_axis_range(a, field.axis1, default1, limits1, unit1); };
  r.object("axis0", false, read0);
  if (!r.has("axis0")) {
    ObjectReader fallback(r.file(), kEmptyObject, r.pointer() + "/axis0", r.resolved()["axis0"]);
    read0(fallback);
  }
  r.object("axis1", false, read1);
  if (!r.has("axis1")) {
    ObjectReader fallback(r.file(), kEmptyObject, r.pointer() + "/axis1", r.resolved()["axis1"]);
    read1(fallback);
  }
  field.threads = r.integer("threads", 2, 1, 256);
  surrogate::Grid grid;
  try {
    grid = surrogate::Grid::from_ranges(field.axes, field.axis0, field.axis1);  // the node limit, spacing rules
  } catch (const std::invalid_argument& e) {
    r.fail("", e.what());
  }
  // The sweep's own rules (nodes strictly increasing: min and max a rounding apart with
  // count 3 give equal nodes), as pdamp field checks them.
  if (const auto problems = grid.validate(); !problems.empty()) r.fail("", problems.front());
  // Every node must be a drive pdamp can evaluate: on intensity axes Γ and X/h give
  // f = √(Γg/X)/2π, which leaves the frequency range for tiny X/h.
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const auto drive = surrogate::drive_point(grid, k, h);
    for (const auto& [name, value, range] :
         {std::tuple{"frequency_hz", drive.frequency_hz, limits::kFrequency}, std::tuple{"amplitude_m", drive.amplitude_m, limits::kStroke}}) {
      if (range.contains(value)) continue;
      std::ostringstream out;
      out.precision(10);
      out << "node " << k << " (axis0 = " << grid.coordinate0(k) << ", axis1 = " << grid.coordinate1(k) << ") drives at "
          << name << " = " << value << ": " << range.text() << " (narrow the axes)";
      r.fail("", out.str());
    }
  }
}

}  // namespace

dem_reference::DamperSimulationOptions dem_options(const Case& c, double amplitude_m, double frequency_hz) {
  auto options = c.dem.simulation;
  options.amplitude_m = amplitude_m;
  options.frequency_hz = frequency_hz;
  return options;
}

formulas::BufferModel buffer_model(const std::string& name, const std::string& where, const std::string& key) {
  if (name == "layered") return formulas::BufferModel::kLayered;
  if (name == "half_space") return formulas::BufferModel::kHalfSpace;
  throw InputError(where, key, "'" + name + "': must be layered or half_space");
}

InputError dem_input_error(const Case& c, const std::string& problem) {
  // "<path> = <value>: <rule>" (dem_reference's validate(); "dem." before the path in
  // the time-step bound's message) or "<path> size = <n>: <rule>".
  std::string line = problem.rfind("dem.", 0) == 0 ? problem.substr(4) : problem;
  // Placement: "compartments[0]: lattice site 0 at (...) overlaps inner structure 0" —
  // named after what the user changes to make the bed fit.
  if (line.rfind("compartments[0]: ", 0) == 0) {
    const std::string what = line.substr(17);
    const std::string key = what.find("inner structure") != std::string::npos ? "/dem/inner_structures"
                            : what.find("layer") != std::string::npos        ? "/dem/wall_layer"
                                                                             : "/damper/particles";
    return InputError(c.path, key, what);
  }
  const auto cut = line.find(" = ");
  if (cut == std::string::npos) return InputError(c.path, "/dem", line);
  std::string path = line.substr(0, cut);
  const std::string rest = line.substr(cut + 1);
  if (path.size() > 5 && path.compare(path.size() - 5, 5, " size") == 0) path.resize(path.size() - 5);
  // Indices "[i]" become pointer tokens "/i".
  path = std::regex_replace(path, std::regex(R"(\[(\d+)\])"), ".$1");
  // Internal names of the world options and the case keys they come from (read_dem).
  static const std::vector<std::pair<std::regex, std::string>> kKeys = {
      {std::regex(R"(^integration\.(\w+)$)"), "/dem/$1"},
      {std::regex(R"(^compartments\.0\.plates\.(\d+)(\.(\w+))?(\.(\d+))?$)"), "/dem/inner_structures/plates/$1/$3/$5"},
      {std::regex(R"(^compartments\.0\.pins\.(\d+)(\.(\w+))?(\.(\d+))?$)"), "/dem/inner_structures/pins/$1/$3/$5"},
      {std::regex(R"(^compartments\.0\.layer\.(\w+)$)"), "/dem/wall_layer/$1"},
      {std::regex(R"(^compartments\.0\.particles\.0\.radius_spread$)"), "/dem/radius_spread"},
      {std::regex(R"(^compartments\.0\.particles\.0\.(\w+)$)"), "/damper/particles/$1"},
      {std::regex(R"(^compartments\.0\.container.*$)"), "/damper/container"},
      {std::regex(R"(^compartments\.0\.wall_material$)"), "/dem/wall_material"},
      {std::regex(R"(^compartments\.0\.lattice_counts.*$)"), "/damper/particles/lattice"},
      {std::regex(R"(^default_pair\.restitution\.table_speeds_m_s(\.(\d+))?$)"), "/dem/contact/restitution/speeds_m_s/$2"},
      {std::regex(R"(^default_pair\.restitution\.table_values(\.(\d+))?$)"), "/dem/contact/restitution/values/$2"},
      {std::regex(R"(^default_pair\.restitution\.\w+$)"), "/dem/contact/restitution"},
      {std::regex(R"(^default_pair\.(\w+)$)"), "/dem/contact/$1"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.table_speeds_m_s(\.(\d+))?$)"), "/dem/pairs/$1/restitution/speeds_m_s/$3"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.table_values(\.(\d+))?$)"), "/dem/pairs/$1/restitution/values/$3"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.\w+$)"), "/dem/pairs/$1/restitution"},
      {std::regex(R"(^pairs\.(\d+)\.(\w+)$)"), "/dem/pairs/$1/$2"},
      {std::regex(R"(^gravity_m_s2\.(\d+)$)"), "/damper/gravity_m_s2/$1"},
      {std::regex(R"(^(amplitude_m|frequency_hz)$)"), "/excitation/$1"},
      {std::regex(R"(^drive_axis$)"), "/damper/drive_axis"},
      {std::regex(R"(^(\w+)$)"), "/dem/$1"},
  };
  std::string pointer = "/dem";
  std::smatch match;
  if (std::regex_match(path, match, std::regex(R"(^materials\.(\d+)\.(\w+)$)"))) {
    const auto i = std::stoul(match[1]);
    auto it = c.materials.begin();
    if (i < c.materials.size()) std::advance(it, i);
    pointer = i < c.materials.size() ? "/materials/" + it->first + "/" + match[2].str() : "/materials";
  } else {
    for (const auto& [pattern, replacement] : kKeys) {
      if (!std::regex_match(path, pattern)) continue;
      pointer = std::regex_replace(path, pattern, replacement);
      // Optional groups that did not match leave empty tokens behind: "/a//" -> "/a".
      pointer = std::regex_replace(pointer, std::regex("/+"), "/");
      if (pointer.size() > 1 && pointer.back() == '/') pointer.pop_back();
      break;
    }
  }
  return InputError(c.path, pointer, rest);
}

std::string_view to_string(Task task) {
  switch (task) {
    case Task::kDamperDesign: return "damper_design";
  }
  return "unknown";
}

Case load_case(const std::string& path) {
  json root;
  try {
    root = formulas::parse_json_document(formulas::read_input_file(path), path);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string(e.what()));  // already "<file>: <what>"
  }
  Case c;
  c.path = path;
  ObjectReader r(path, root, "", c.resolved);
  r.integer("format_version", 1, 1, 1);
  c.name = r.text("name", std::nullopt);
  if (c.name.empty()) r.fail("name", "must not be empty (it names the plots and the default output folder)");
  c.description = r.text("description", std::string());
  r.text("task", std::string("damper_design"), {"damper_design"});
  c.task = Task::kDamperDesign;

  c.materials["steel"] = fm::Material{};
  r.object("materials", false, [&](ObjectReader& m) {
    for (const auto& [name, value] : root.at("materials").items()) {
      (void)value;
      if (name.empty()) m.fail("", "a material needs a name (the key \"\" is empty)");
      const fm::Material defaults = c.materials.count(name) ? c.materials.at(name) : fm::Material{};
      m.object(name, true, [&](ObjectReader& one) { c.materials[name] = read_material(one, defaults); });
    }
  });
  for (const auto& [name, material] : c.materials) {
    auto& out = c.resolved["materials"][name];
    out["density_kg_m3"] = material.density_kg_m3;
    out["youngs_modulus_pa"] = material.youngs_modulus_pa;
    out["poisson_ratio"] = material.poisson_ratio;
  }

  r.object("damper", true, [&](ObjectReader& d) { read_damper(d, c); });
  r.object("excitation", true, [&](ObjectReader& e) {
    c.excitation.frequency_hz = e.number("frequency_hz", std::nullopt, limits::kFrequency, " Hz");
    c.excitation.amplitude_m = e.optional_number("amplitude_m", limits::kStroke, " m");
  });
  const auto read_design = [&](ObjectReader& d) {
    c.design.target_stroke_m = d.optional_number("target_stroke_m", limits::kStroke, " m");
    c.design.sweep_min_over_clearance = d.number("sweep_min_over_clearance", 0.05, {0.0, 100.0, true});
    c.design.sweep_max_over_clearance = d.number("sweep_max_over_clearance", 1.5, {0.0, 100.0, true});
    c.design.sweep_points = d.integer("sweep_points", 301, 2, 100000);
    if (c.design.sweep_max_over_clearance <= c.design.sweep_min_over_clearance)
      d.fail("sweep_max_over_clearance", "must be > sweep_min_over_clearance");
  };
  r.object("design", false, read_design);
  if (!root.contains("design")) {
    ObjectReader defaults(path, kEmptyObject, "/design", c.resolved["design"]);
    read_design(defaults);
  }
  r.object("dem", false, [&](ObjectReader& d) { read_dem(d, c); });
  if (!root.contains("dem")) {
    ObjectReader defaults(path, kEmptyObject, "/dem", c.resolved["dem"]);
    read_dem(defaults, c);
  }
  {
    // Without an operating stroke the DEM is checked at X = h (the closed forms' scale);
    // pdamp dem and pdamp field check their own points again.
    const double x = c.excitation.amplitude_m.value_or(c.damper.clearance_m);
    const auto problems = dem_options(c, x, c.excitation.frequency_hz).validate("");
    if (!problems.empty()) throw dem_input_error(c, problems.front());
  }
  r.object("field", false, [&](ObjectReader& f) { read_field(f, c); });
  if (!root.contains("field")) {
    ObjectReader defaults(path, kEmptyObject, "/field", c.resolved["field"]);
    read_field(defaults, c);
  }
  r.object("buffer", false, [&](ObjectReader& b) {
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
    in.particle_radius_m = c.damper.particle_radius_m;
    in.particle = c.materials.at(c.damper.particle_material);
    in.layer = c.materials.at(spec.layer_material);
    for (const auto& line : in.validate()) b.fail("", line);
    c.buffer = spec;
  });
  r.finish();
  return c;
}

}  // namespace pdamp::cli
