// The variants of a sensitivity study (case.hpp, sensitivity_variants): the case's JSON with
// one value changed, read again by the case reader.
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "pdamp/case_file/case.hpp"
#include "pdamp/base/input_file.hpp"

namespace pdamp::case_file {

namespace {

using nlohmann::json;
constexpr double kPi = 3.14159265358979323846;

/// Where a parameter lives in the case's JSON, and its unit.
struct Parameter {
  std::string name;
  std::string unit;
};

/// The JSON of the damper's only layer: /damper (format 1) or /dampers/0/layers/0.
json& layer_json(json& document, int format) {
  return format == 1 ? document["damper"] : document["dampers"][0]["layers"][0];
}
json& damper_json(json& document, int format) { return format == 1 ? document["damper"] : document["dampers"][0]; }

/// The contact object of /dem, created as the reader's defaults would be.
json& contact_json(json& document) {
  json& dem = document["dem"];
  if (!dem.is_object()) dem = json::object();
  json& contact = dem["contact"];
  if (!contact.is_object()) contact = json::object();
  return contact;
}

/// Rodrigues rotation of v about the unit container axis `axis` by `degrees`.
std::array<double, 3> rotated(const std::array<double, 3>& v, int axis, double degrees) {
  const double a = degrees * kPi / 180.0, c = std::cos(a), s = std::sin(a);
  const int i = (axis + 1) % 3, j = (axis + 2) % 3;
  std::array<double, 3> out = v;
  out[static_cast<std::size_t>(i)] = c * v[static_cast<std::size_t>(i)] - s * v[static_cast<std::size_t>(j)];
  out[static_cast<std::size_t>(j)] = s * v[static_cast<std::size_t>(i)] + c * v[static_cast<std::size_t>(j)];
  return out;
}

/// The case's JSON with `name` set to `value`.
json with_value(const json& original, const Case& c, const std::string& name, double value) {
  json doc = original;
  const int format = c.format_version;
  if (name == "friction" || name == "rolling_friction") {
    contact_json(doc)[name] = value;
  } else if (name == "restitution") {
    contact_json(doc)["restitution"] = value;
  } else if (name == "particle_radius_m") {
    layer_json(doc, format)["particles"]["radius_m"] = value;
  } else if (name == "particle_count") {
    layer_json(doc, format)["particles"]["count"] = value;
  } else if (name == "youngs_modulus_factor") {
    if (!doc["dem"].is_object()) doc["dem"] = json::object();
    doc["dem"]["stiffness_softening"] = c.dem.stiffness_softening * value;
  } else {  // tilt_<axis>_deg: gravity in the container frame turned about that axis
    const int axis = name[5] - 'x';
    const auto& g = c.dampers.front().gravity_m_s2;
    const auto turned = rotated({g[0], g[1], g[2]}, axis, value);
    damper_json(doc, format)["gravity_m_s2"] = {turned[0], turned[1], turned[2]};
  }
  return doc;
}

std::string unit_of(const std::string& name) {
  if (name == "particle_radius_m") return "m";
  if (name.rfind("tilt_", 0) == 0) return "deg";
  if (name == "youngs_modulus_factor") return "factor";
  return "";
}

/// The default values of every parameter around the baseline (sensitivity_variants).
std::vector<SensitivityParameter> default_parameters(const Case& c, bool constant_restitution) {
  const auto& pair = c.dem.simulation.world.default_pair;
  const LayerSpec& layer = c.dampers.front().layers.front();
  std::vector<SensitivityParameter> out = {{"friction", {0.5 * pair.friction, 1.5 * pair.friction}}};
  if (constant_restitution)
    out.push_back({"restitution", {std::max(0.05, pair.restitution.constant - 0.1), std::min(0.99, pair.restitution.constant + 0.1)}});
  out.push_back({"particle_radius_m", {0.9 * layer.particle_radius_m, 1.1 * layer.particle_radius_m}});
  out.push_back({"particle_count", {std::round(0.9 * layer.particle_count), std::round(1.1 * layer.particle_count)}});
  out.push_back({"youngs_modulus_factor", {0.5, 2.0}});
  for (const char* tilt : {"tilt_x_deg", "tilt_y_deg", "tilt_z_deg"}) out.push_back({tilt, {-5.0, 5.0}});
  return out;
}

/// The baseline's value of a parameter (for the report).
double baseline_value(const Case& c, const std::string& name) {
  const auto& pair = c.dem.simulation.world.default_pair;
  const LayerSpec& layer = c.dampers.front().layers.front();
  if (name == "friction") return pair.friction;
  if (name == "rolling_friction") return pair.rolling_friction;
  if (name == "restitution") return pair.restitution.constant;
  if (name == "particle_radius_m") return layer.particle_radius_m;
  if (name == "particle_count") return layer.particle_count;
  if (name == "youngs_modulus_factor") return 1.0;
  return 0.0;  // tilts
}

}  // namespace

std::vector<SensitivityVariant> sensitivity_variants(const Case& c, std::vector<std::string>& skipped) {
  if (c.dampers.size() != 1 || c.dampers.front().layers.size() != 1)
    throw CaseError(c.path, "/dampers", "pdamp sensitivity studies one damper of one layer (this case has " +
                                            std::to_string(c.dampers.size()) + " dampers)");
  const json& original = c.document;
  const bool constant_restitution = c.resolved.contains("dem") && c.resolved["dem"].contains("contact") &&
                                    c.resolved["dem"]["contact"].value("restitution", json()).is_number();
  const bool given = c.sensitivity && !c.sensitivity->parameters.empty();
  const auto parameters = given ? c.sensitivity->parameters : default_parameters(c, constant_restitution);

  std::vector<SensitivityVariant> out;
  out.push_back({"baseline", 0.0, "", c});
  for (std::size_t i = 0; i < parameters.size(); ++i) {
    const auto& p = parameters[i];
    if (p.name == "restitution" && !constant_restitution)
      throw CaseError(c.path, "/sensitivity/parameters/" + std::to_string(i) + "/name",
                      "restitution can be varied only where /dem/contact/restitution is a constant");
    for (std::size_t j = 0; j < p.values.size(); ++j) {
      const double value = p.values[j];
      const std::string at = "/sensitivity/parameters/" + std::to_string(i) + "/values/" + std::to_string(j);
      if (p.name == "particle_count" && value != std::floor(value))
        throw CaseError(c.path, at, "= " + std::to_string(value) + ": a particle count must be a whole number");
      try {
        out.push_back({p.name, value, unit_of(p.name), load_case_document(with_value(original, c, p.name, value), c.path)});
      } catch (const CaseError& e) {
        std::ostringstream why;
        why << p.name << " = " << value << ": the case refuses it (" << e.what() << ")";
        if (given) throw CaseError(c.path, at, why.str());
        skipped.push_back(why.str() + "; left out of the default study");
      }
    }
  }
  return out;
}

double sensitivity_baseline_value(const Case& c, const std::string& parameter) { return baseline_value(c, parameter); }

}  // namespace pdamp::case_file
