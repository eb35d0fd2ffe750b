// Validation of the DEM world options: every violation, one line each.
#include "pdamp/dem_reference/world_options.hpp"

#include <algorithm>
#include <cmath>
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

void validate_pair(Violations& v, const ContactPairOptions& p, const std::string& at, int materials) {
  v.check(p.material_a >= 0 && p.material_a < materials, at + ".material_a", p.material_a,
          "must index materials (0.." + std::to_string(materials - 1) + ")");
  v.check(p.material_b >= 0 && p.material_b < materials, at + ".material_b", p.material_b,
          "must index materials (0.." + std::to_string(materials - 1) + ")");
  const auto& r = p.restitution;
  if (!r.model && r.table_speeds_m_s.empty()) {
    v.check(std::isfinite(r.constant) && r.constant > 0.0 && r.constant <= 1.0, at + ".restitution.constant",
            r.constant, "must be in (0, 1]");
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
    for (std::size_t k = 0; k < r.table_values.size(); ++k) {
      const double e = r.table_values[k];
      v.check(std::isfinite(e) && e > 0.0 && e <= 1.0, index(at + ".restitution.table_values", k), e,
              "must be in (0, 1]");
    }
  }
  v.check(finite_at_least(p.friction, 0.0), at + ".friction", p.friction, "must be >= 0");
  v.check(finite_at_least(p.rolling_friction, 0.0), at + ".rolling_friction", p.rolling_friction, "must be >= 0");
}

bool material_ok(int m, int materials) { return m >= 0 && m < materials; }

double smallest_inner_half(const formulas::Container& c) {
  if (c.shape == formulas::ContainerShape::kBox) {
    return 0.5 * std::min({c.box_inner_size_m[0], c.box_inner_size_m[1], c.box_inner_size_m[2]});
  }
  return std::min(c.cylinder_inner_radius_m, 0.5 * c.cylinder_inner_length_m);
}

void validate_compartment(Violations& v, const CompartmentOptions& c, const std::string& at, int materials) {
  v.append(c.container.validate(at + ".container"));
  const std::string range = "must index materials (0.." + std::to_string(materials - 1) + ")";
  v.check(material_ok(c.wall_material, materials), at + ".wall_material", c.wall_material, range);
  v.check(!c.particles.empty(), at + ".particles size", c.particles.size(), "must be >= 1");
  for (std::size_t g = 0; g < c.particles.size(); ++g) {
    const auto& p = c.particles[g];
    const std::string pg = index(at + ".particles", g);
    v.check(p.count >= 1, pg + ".count", p.count, "must be >= 1");
    v.check(finite_above(p.radius_m, 0.0), pg + ".radius_m", p.radius_m, "must be > 0");
    v.check(std::isfinite(p.radius_spread) && p.radius_spread >= 0.0 && p.radius_spread < 0.5,
            pg + ".radius_spread", p.radius_spread, "must be in [0, 0.5)");
    v.check(material_ok(p.material, materials), pg + ".material", p.material, range);
  }
  v.check(c.collect_axis >= 0 && c.collect_axis <= 2, at + ".collect_axis", c.collect_axis, "must be 0, 1 or 2");
  v.check(c.collect_side == -1 || c.collect_side == 1, at + ".collect_side", c.collect_side, "must be -1 or +1");
  v.check(c.lattice_counts.empty() || c.lattice_counts.size() == 3, at + ".lattice_counts size",
          c.lattice_counts.size(), "must be 0 (automatic) or 3");
  for (std::size_t a = 0; a < c.lattice_counts.size(); ++a) {
    v.check(c.lattice_counts[a] >= 1, index(at + ".lattice_counts", a), c.lattice_counts[a], "must be >= 1");
  }
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
  v.check(!materials.empty(), prefix + "materials size", materials.size(), "must be >= 1");
  for (std::size_t m = 0; m < materials.size(); ++m) {
    v.append(materials[m].material.validate(index(prefix + "materials", m)));
  }
  if (count > 0) {
    validate_pair(v, default_pair, prefix + "default_pair", count);
    for (std::size_t p = 0; p < pairs.size(); ++p) validate_pair(v, pairs[p], index(prefix + "pairs", p), count);
    v.check(!compartments.empty(), prefix + "compartments size", compartments.size(), "must be >= 1");
    for (std::size_t c = 0; c < compartments.size(); ++c) {
      validate_compartment(v, compartments[c], index(prefix + "compartments", c), count);
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    v.check(std::isfinite(gravity_m_s2[a]), index(prefix + "gravity_m_s2", a), gravity_m_s2[a], "must be finite");
  }
  const auto& in = integration;
  const std::string ip = prefix + "integration.";
  v.check(finite_at_least(in.time_step_s, 0.0), ip + "time_step_s", in.time_step_s, "must be >= 0 (0 = automatic)");
  v.check(in.steps_per_contact >= 40, ip + "steps_per_contact", in.steps_per_contact, "must be >= 40");
  v.check(std::isfinite(in.rayleigh_fraction) && in.rayleigh_fraction > 0.0 && in.rayleigh_fraction <= 1.0,
          ip + "rayleigh_fraction", in.rayleigh_fraction, "must be in (0, 1]");
  v.check(finite_above(in.max_impact_speed_m_s, 0.0), ip + "max_impact_speed_m_s", in.max_impact_speed_m_s,
          "must be > 0");
  v.check(std::isfinite(in.skin_fraction) && in.skin_fraction > 0.0 && in.skin_fraction <= 2.0,
          ip + "skin_fraction", in.skin_fraction, "must be in (0, 2]");
  v.check(std::isfinite(in.max_overlap_fraction) && in.max_overlap_fraction > 0.0 && in.max_overlap_fraction < 1.0,
          ip + "max_overlap_fraction", in.max_overlap_fraction, "must be in (0, 1)");
  v.check(threads >= 0, prefix + "threads", threads, "must be >= 0 (0 = all available)");
  return errors;
}

}  // namespace pdamp::dem_reference
