// Validation of the DEM world options: every violation, one line each.
#include "pdamp/dem_reference/world_options.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>

namespace pdamp::dem_reference {

namespace {

/// Collects "prefix.field = value: rule" lines.
class Violations {
 public:
  explicit Violations(std::vector<std::string>& out) : out_(out) {}
  template <class T>
  void check(bool ok, const std::string& field, const T& value, const std::string& rule) {
    if (ok) return;
    std::ostringstream line;
    line << field << " = " << value << ": " << rule;
    out_.push_back(line.str());
  }
  void append(const std::vector<std::string>& lines) { out_.insert(out_.end(), lines.begin(), lines.end()); }

 private:
  std::vector<std::string>& out_;
};

std::string index(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

bool finite_at_least(double v, double min) { return std::isfinite(v) && v >= min; }
bool finite_above(double v, double min) { return std::isfinite(v) && v > min; }
bool within(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

/// "[a, b]" with the stream's default formatting (1e-05, 0.01, 1000).
std::string interval(double lo, double hi, const char* open = "[", const char* close = "]") {
  std::ostringstream s;
  s << open << lo << ", " << hi << close;
  return s.str();
}

std::string vec3(const Vec3& v) {
  std::ostringstream s;
  s << "[" << v[0] << ", " << v[1] << ", " << v[2] << "]";
  return s.str();
}

/// The restitution every contact law of the world must stay in: the DEM turns ε into a
/// damping coefficient through formulas::DampingTable, which covers [0.01, 1] and
/// throws outside (inside the force sweep, where it would end the run).
constexpr double kMinRestitution = limits::kMinRestitution;
const std::string kRestitutionRule = "must be in " + interval(kMinRestitution, 1.0);

/// Impact speeds at which a velocity-dependent law is checked: 0, a geometric grid
/// from 1e-6·v_max (the slow end, where Thornton-like laws change fastest relative to
/// v) and a uniform grid up to v_max. A law is only called with the speeds of first
/// touches, and those the time step was chosen for are <= v_max; faster first touches
/// are clamped into the table's range (ContactLaw::damping_coefficient).
std::vector<double> model_check_speeds(double v_max) {
  std::vector<double> speeds{0.0};
  constexpr int kPoints = 64;
  for (int k = 0; k <= kPoints; ++k) speeds.push_back(v_max * std::pow(1e-6, 1.0 - static_cast<double>(k) / kPoints));
  for (int k = 1; k <= kPoints; ++k) speeds.push_back(v_max * k / kPoints);
  return speeds;
}

void validate_pair(Violations& v, const ContactPairOptions& p, const std::string& at, int materials,
                   double max_impact_speed_m_s) {
  v.check(p.material_a >= 0 && p.material_a < materials, at + ".material_a", p.material_a,
          "must index materials (0.." + std::to_string(materials - 1) + ")");
  v.check(p.material_b >= 0 && p.material_b < materials, at + ".material_b", p.material_b,
          "must index materials (0.." + std::to_string(materials - 1) + ")");
  const auto& r = p.restitution;
  if (!r.model && r.table_speeds_m_s.empty()) {
    v.check(within(r.constant, kMinRestitution, 1.0), at + ".restitution.constant", r.constant, kRestitutionRule);
  }
  if (!r.model && !r.table_speeds_m_s.empty()) {
    v.check(r.table_speeds_m_s.size() >= 2, at + ".restitution.table_speeds_m_s size", r.table_speeds_m_s.size(),
            "must be >= 2");
    v.check(r.table_values.size() == r.table_speeds_m_s.size(), at + ".restitution.table_values size",
            r.table_values.size(), "must equal the number of speeds (" + std::to_string(r.table_speeds_m_s.size()) + ")");
    for (std::size_t k = 0; k < r.table_speeds_m_s.size(); ++k) {
      const double s = r.table_speeds_m_s[k];
      v.check(finite_at_least(s, 0.0) && (k == 0 || s > r.table_speeds_m_s[k - 1]),
              index(at + ".restitution.table_speeds_m_s", k), s, "must be >= 0 and strictly increasing");
    }
    // The monotone interpolation never leaves the range of the nodes and is clamped to
    // the end values outside the table: checking the nodes checks every speed.
    for (std::size_t k = 0; k < r.table_values.size(); ++k) {
      v.check(within(r.table_values[k], kMinRestitution, 1.0), index(at + ".restitution.table_values", k),
              r.table_values[k], kRestitutionRule);
    }
  }
  if (r.model && std::isfinite(max_impact_speed_m_s) && max_impact_speed_m_s > 0.0) {
    // A law of any shape: sampled over the speeds the run is set up for (see
    // model_check_speeds). A law that throws is reported, not propagated.
    std::string problem;
    for (const double speed : model_check_speeds(max_impact_speed_m_s)) {
      std::ostringstream what;
      try {
        const double e = r.model->restitution(speed);
        if (within(e, kMinRestitution, 1.0)) continue;
        what << "gives " << e << " at " << speed << " m/s";
      } catch (const std::exception& e) {
        what << "throws at " << speed << " m/s (" << e.what() << ")";
      }
      problem = what.str();
      break;
    }
    v.check(problem.empty(), at + ".restitution.model", r.model->describe(),
            "must give a restitution in " + interval(kMinRestitution, 1.0) + " at impact speeds 0 to " +
                std::to_string(max_impact_speed_m_s) + " m/s (integration.max_impact_speed_m_s), " + problem);
  }
  v.check(within(p.friction, 0.0, limits::kMaxFriction), at + ".friction", p.friction,
          "must be in " + interval(0.0, limits::kMaxFriction));
  v.check(within(p.rolling_friction, 0.0, limits::kMaxRollingFriction), at + ".rolling_friction", p.rolling_friction,
          "must be in " + interval(0.0, limits::kMaxRollingFriction));
}

bool material_ok(int m, int materials) { return m >= 0 && m < materials; }

double smallest_inner_half(const formulas::Container& c) {
  if (c.shape == formulas::ContainerShape::kBox) {
    return 0.5 * std::min({c.box_inner_size_m[0], c.box_inner_size_m[1], c.box_inner_size_m[2]});
  }
  return std::min(c.cylinder_inner_radius_m, 0.5 * c.cylinder_inner_length_m);
}

/// An axis-aligned extent [lo, hi] per axis, compartment frame, m.
struct Extent {
  Vec3 lo{0.0, 0.0, 0.0};
  Vec3 hi{0.0, 0.0, 0.0};
};

std::string describe(const Extent& e) {
  std::ostringstream s;
  const char* names[3] = {"x", "y", "z"};
  for (std::size_t a = 0; a < 3; ++a) s << (a ? ", " : "") << names[a] << " " << interval(e.lo[a], e.hi[a]);
  s << " m";
  return s.str();
}

/// Bounding box of the container's inside (compartment frame).
Extent container_extent(const formulas::Container& c) {
  Extent e;
  for (std::size_t a = 0; a < 3; ++a) {
    const double half = c.shape == formulas::ContainerShape::kBox ? 0.5 * c.box_inner_size_m[a]
                        : static_cast<int>(a) == c.cylinder_axis  ? 0.5 * c.cylinder_inner_length_m
                                                                  : c.cylinder_inner_radius_m;
    e.lo[a] = -half;
    e.hi[a] = half;
  }
  return e;
}

/// Whether the box `s` shares volume with the container's inside. For a cylinder the
/// cross-section is the disk: the rectangle of `s` across the axis must come closer
/// to the axis than the radius.
bool reaches_inside(const formulas::Container& c, const Extent& s) {
  const Extent box = container_extent(c);
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(s.lo[a] < box.hi[a] && s.hi[a] > box.lo[a])) return false;
  }
  if (c.shape == formulas::ContainerShape::kBox) return true;
  double d2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    if (static_cast<int>(a) == c.cylinder_axis) continue;
    const double d = std::max({s.lo[a], -s.hi[a], 0.0});
    d2 += d * d;
  }
  return d2 < c.cylinder_inner_radius_m * c.cylinder_inner_radius_m;
}

/// Whether the box `s` contains the container's whole inside (nothing left for the bed).
bool fills_inside(const formulas::Container& c, const Extent& s) {
  const Extent box = container_extent(c);
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(s.lo[a] <= box.lo[a] && s.hi[a] >= box.hi[a])) return false;
  }
  return true;
}

/// Inner structures against their container. A plate or pin may run through a wall:
/// a baffle welded to the wall or a pin fixed in both walls is modelled that way, and
/// the part outside is never touched (spheres stay inside; the grid does not need it).
/// Refused: a structure that does not reach into the container (no sphere can ever
/// touch it: almost always a frame or unit mistake, e.g. body-frame coordinates given
/// in the compartment frame), and a plate that covers the whole inside (no room for a
/// single sphere; a bed that does not fit beside the structures is refused when the
/// particles are placed, with the lattice site and the structure). For a pin the test
/// uses its bounding box: a pin whose box reaches in but whose round side does not
/// (a corner of a box container) passes and simply is never touched.
void validate_structures(Violations& v, const CompartmentOptions& c, const std::string& at) {
  if (!c.container.validate("").empty()) return;
  const std::string inside = describe(container_extent(c.container));
  for (std::size_t k = 0; k < c.plates.size(); ++k) {
    const auto& p = c.plates[k];
    Extent e;
    bool finite = true;
    for (std::size_t a = 0; a < 3; ++a) {
      e.lo[a] = p.centre_m[a] - 0.5 * p.size_m[a];
      e.hi[a] = p.centre_m[a] + 0.5 * p.size_m[a];
      finite = finite && std::isfinite(e.lo[a]) && std::isfinite(e.hi[a]) && p.size_m[a] > 0.0;
    }
    if (!finite) continue;
    const std::string where = "plate " + std::to_string(k) + " spans " + describe(e) + ", the container's inside " +
                              inside + " (compartment frame)";
    v.check(reaches_inside(c.container, e), index(at + ".plates", k) + ".centre_m", vec3(p.centre_m),
            where + ": the plate must reach into the container");
    v.check(!fills_inside(c.container, e), index(at + ".plates", k) + ".size_m", vec3(p.size_m),
            where + ": the plate must leave room for the bed");
  }
  for (std::size_t k = 0; k < c.pins.size(); ++k) {
    const auto& p = c.pins[k];
    if (p.axis < 0 || p.axis > 2 || !finite_above(p.radius_m, 0.0) || !finite_above(p.length_m, 0.0)) continue;
    Extent e;
    bool finite = true;
    for (std::size_t a = 0; a < 3; ++a) {
      const double half = static_cast<int>(a) == p.axis ? 0.5 * p.length_m : p.radius_m;
      e.lo[a] = p.centre_m[a] - half;
      e.hi[a] = p.centre_m[a] + half;
      finite = finite && std::isfinite(e.lo[a]) && std::isfinite(e.hi[a]);
    }
    if (!finite) continue;
    v.check(reaches_inside(c.container, e), index(at + ".pins", k) + ".centre_m", vec3(p.centre_m),
            "pin " + std::to_string(k) + " spans " + describe(e) + ", the container's inside " + inside +
                " (compartment frame): the pin must reach into the container");
  }
}

void validate_compartment(Violations& v, const CompartmentOptions& c, const std::string& at, int materials,
                          long long& particles) {
  v.append(c.container.validate(at + ".container"));
  const std::string range = "must index materials (0.." + std::to_string(materials - 1) + ")";
  for (std::size_t a = 0; a < 3; ++a) {
    v.check(std::isfinite(c.offset_m[a]), index(at + ".offset_m", a), c.offset_m[a], "must be finite");
  }
  v.check(material_ok(c.wall_material, materials), at + ".wall_material", c.wall_material, range);
  v.check(!c.particles.empty(), at + ".particles size", c.particles.size(), "must be >= 1");
  for (std::size_t g = 0; g < c.particles.size(); ++g) {
    const auto& p = c.particles[g];
    const std::string pg = index(at + ".particles", g);
    v.check(p.count >= 1, pg + ".count", p.count, "must be >= 1");
    if (p.count >= 1) {
      const bool was_ok = particles <= limits::kMaxParticles;
      particles += p.count;
      // Reported once, at the group that crosses the limit.
      v.check(!was_ok || particles <= limits::kMaxParticles, pg + ".count", p.count,
              "the world's particle count (" + std::to_string(particles) + " so far) must be <= " +
                  std::to_string(limits::kMaxParticles));
    }
    v.check(within(p.radius_m, limits::kMinRadius_m, limits::kMaxRadius_m), pg + ".radius_m", p.radius_m,
            "must be in " + interval(limits::kMinRadius_m, limits::kMaxRadius_m) + " m");
    v.check(std::isfinite(p.radius_spread) && p.radius_spread >= 0.0 && p.radius_spread < 0.5,
            pg + ".radius_spread", p.radius_spread, "must be in [0, 0.5)");
    v.check(material_ok(p.material, materials), pg + ".material", p.material, range);
    v.check(within(p.lot_diameter_variation_m, 0.0, limits::kMaxLotDiameterVariation_m),
            pg + ".lot_diameter_variation_m", p.lot_diameter_variation_m,
            "must be in " + interval(0.0, limits::kMaxLotDiameterVariation_m) + " m");
  }
  v.check(c.collect_axis >= 0 && c.collect_axis <= 2, at + ".collect_axis", c.collect_axis, "must be 0, 1 or 2");
  v.check(c.collect_side == -1 || c.collect_side == 1, at + ".collect_side", c.collect_side, "must be -1 or +1");
  v.check(c.lattice_counts.empty() || c.lattice_counts.size() == 3, at + ".lattice_counts size",
          c.lattice_counts.size(), "must be 0 (automatic) or 3");
  for (std::size_t a = 0; a < c.lattice_counts.size(); ++a) {
    v.check(c.lattice_counts[a] >= 1, index(at + ".lattice_counts", a), c.lattice_counts[a], "must be >= 1");
  }
  v.check(finite_at_least(c.lane_gap_m, 0.0), at + ".lane_gap_m", c.lane_gap_m, "must be >= 0 m");
  if (c.container.shape != formulas::ContainerShape::kBox) {
    v.check(c.lane_gap_m == 0.0 || !std::isfinite(c.lane_gap_m), at + ".lane_gap_m", c.lane_gap_m,
            "must be 0 in a cylinder (lane gaps are for box containers)");
    v.check(!c.lane_gap_auto, at + ".lane_gap_auto", "true", "must be false in a cylinder (lane gaps are for box containers)");
  } else {
    v.check(!c.staggered_lattice, at + ".staggered_lattice", "true", "must be false in a box (staggered slabs are for cylinders)");
  }
  v.check(!c.staggered_lattice || c.lattice_counts.empty(), at + ".staggered_lattice", "true",
          "must be false with lattice_counts (the staggered lattice takes the automatic sites)");
  for (std::size_t k = 0; k < c.plates.size(); ++k) {
    const auto& p = c.plates[k];
    const std::string pk = index(at + ".plates", k);
    for (std::size_t a = 0; a < 3; ++a) {
      v.check(finite_above(p.size_m[a], 0.0), index(pk + ".size_m", a), p.size_m[a], "must be > 0");
      v.check(std::isfinite(p.centre_m[a]), index(pk + ".centre_m", a), p.centre_m[a], "must be finite");
    }
    v.check(p.material == -1 || material_ok(p.material, materials), pk + ".material", p.material,
            "must be -1 (wall material) or " + range.substr(5));
  }
  for (std::size_t k = 0; k < c.pins.size(); ++k) {
    const auto& p = c.pins[k];
    const std::string pk = index(at + ".pins", k);
    v.check(p.axis >= 0 && p.axis <= 2, pk + ".axis", p.axis, "must be 0, 1 or 2");
    v.check(finite_above(p.radius_m, 0.0), pk + ".radius_m", p.radius_m, "must be > 0");
    v.check(finite_above(p.length_m, 0.0), pk + ".length_m", p.length_m, "must be > 0");
    for (std::size_t a = 0; a < 3; ++a) {
      v.check(std::isfinite(p.centre_m[a]), index(pk + ".centre_m", a), p.centre_m[a], "must be finite");
    }
    v.check(p.material == -1 || material_ok(p.material, materials), pk + ".material", p.material,
            "must be -1 (wall material) or " + range.substr(5));
  }
  validate_structures(v, c, at);
  const auto& layer = c.layer;
  v.check(finite_at_least(layer.thickness_m, 0.0), at + ".layer.thickness_m", layer.thickness_m, "must be >= 0");
  if (layer.thickness_m > 0.0) {
    v.check(material_ok(layer.material, materials), at + ".layer.material", layer.material, range);
    v.check(layer.axis >= -1 && layer.axis <= 2, at + ".layer.axis", layer.axis, "must be -1 (all walls), 0, 1 or 2");
    const double half = smallest_inner_half(c.container);
    if (half > 0.0) {
      v.check(layer.thickness_m < 0.5 * half, at + ".layer.thickness_m", layer.thickness_m,
              "must be < a quarter of the smallest inner size (" + std::to_string(0.5 * half) + " m)");
    }
  }
}

}  // namespace

std::vector<std::string> WorldOptions::validate(const std::string& prefix) const {
  std::vector<std::string> errors;
  Violations v(errors);
  const int count = static_cast<int>(materials.size());
  const auto& in = integration;
  v.check(!materials.empty(), prefix + "materials size", materials.size(), "must be >= 1");
  for (std::size_t m = 0; m < materials.size(); ++m) {
    v.append(materials[m].material.validate(index(prefix + "materials", m)));
  }
  if (count > 0) {
    validate_pair(v, default_pair, prefix + "default_pair", count, in.max_impact_speed_m_s);
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      validate_pair(v, pairs[p], index(prefix + "pairs", p), count, in.max_impact_speed_m_s);
    }
    v.check(!compartments.empty(), prefix + "compartments size", compartments.size(), "must be >= 1");
    long long particles = 0;
    for (std::size_t c = 0; c < compartments.size(); ++c) {
      validate_compartment(v, compartments[c], index(prefix + "compartments", c), count, particles);
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    v.check(within(gravity_m_s2[a], -limits::kMaxGravity_m_s2, limits::kMaxGravity_m_s2),
            index(prefix + "gravity_m_s2", a), gravity_m_s2[a],
            "must be in " + interval(-limits::kMaxGravity_m_s2, limits::kMaxGravity_m_s2) + " m/s^2");
  }
  const std::string ip = prefix + "integration.";
  v.check(in.time_step_s == 0.0 || within(in.time_step_s, limits::kMinTimeStep_s, limits::kMaxTimeStep_s),
          ip + "time_step_s", in.time_step_s,
          "must be 0 (automatic) or in " + interval(limits::kMinTimeStep_s, limits::kMaxTimeStep_s) + " s");
  v.check(in.steps_per_contact == 0 ||
              (in.steps_per_contact >= limits::kMinStepsPerContact && in.steps_per_contact <= limits::kMaxStepsPerContact),
          ip + "steps_per_contact", in.steps_per_contact,
          "must be 0 (automatic) or in [" + std::to_string(limits::kMinStepsPerContact) + ", " +
              std::to_string(limits::kMaxStepsPerContact) + "]");
  v.check(std::isfinite(in.rayleigh_fraction) && in.rayleigh_fraction > 0.0 && in.rayleigh_fraction <= 1.0,
          ip + "rayleigh_fraction", in.rayleigh_fraction, "must be in (0, 1]");
  v.check(finite_above(in.max_impact_speed_m_s, 0.0) && in.max_impact_speed_m_s <= limits::kMaxImpactSpeed_m_s,
          ip + "max_impact_speed_m_s", in.max_impact_speed_m_s,
          "must be in " + interval(0.0, limits::kMaxImpactSpeed_m_s, "(") + " m/s");
  v.check(within(in.skin_fraction, limits::kMinSkinFraction, limits::kMaxSkinFraction), ip + "skin_fraction",
          in.skin_fraction, "must be in " + interval(limits::kMinSkinFraction, limits::kMaxSkinFraction));
  v.check(std::isfinite(in.max_overlap_fraction) && in.max_overlap_fraction > 0.0 && in.max_overlap_fraction < 1.0,
          ip + "max_overlap_fraction", in.max_overlap_fraction, "must be in (0, 1)");
  v.check(threads >= 0 && threads <= limits::kMaxThreads, prefix + "threads", threads,
          "must be in [0, " + std::to_string(limits::kMaxThreads) + "] (0 = all available)");
  return errors;
}

}  // namespace pdamp::dem_reference
