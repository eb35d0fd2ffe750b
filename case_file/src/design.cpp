// Designs of a filling_ratios case, clearances of a clearance case and patched documents as
// cases of their own (case.hpp: with_design, with_clearance, with_merge_patch).
#include <limits>
#include <string>
#include <vector>

#include "pdamp/case_file/case.hpp"

namespace pdamp::case_file {

using nlohmann::json;

long long other_seed(const Case& c) {
  const auto seed = static_cast<long long>(c.dem.simulation.world.seed);
  return seed < std::numeric_limits<int>::max() ? seed + 1 : seed - 1;
}

Case with_merge_patch(const Case& c, const json& patch) {
  json document = c.document;
  document.merge_patch(patch);
  return load_case_document(document, c.path);
}

Case with_design(const Case& c, const std::vector<long>& slabs, double stiffness_softening, bool other_seed) {
  if (!c.task.filling_ratios || c.format_version != 2)
    throw CaseError(c.path, "/task", "a design needs a format-2 case of task kind filling_ratios");
  const auto& damper = c.dampers.front();
  if (slabs.size() != damper.layers.size())
    throw CaseError(c.path, "/dampers/0/layers",
                    "a design gives " + std::to_string(slabs.size()) + " slab counts for " +
                        std::to_string(damper.layers.size()) + " layers");
  json document = c.document;
  json& layers = document["dampers"][0]["layers"];
  json kept = json::array();
  for (std::size_t k = 0; k < slabs.size(); ++k) {
    if (slabs[k] <= 0) continue;
    json layer = layers.at(k);
    // The name as resolved: leaving a layer out must not rename the ones after it.
    layer["name"] = damper.layers[k].name;
    layer["particles"]["count"] = slabs[k] * c.task.filling_ratios->spheres_per_slab.at(k);
    if (layer["particles"].contains("lattice") && layer["particles"]["lattice"].is_array())
      layer["particles"]["lattice"][static_cast<std::size_t>(damper.drive_axis)] = slabs[k];
    kept.push_back(std::move(layer));
  }
  layers = std::move(kept);
  if (stiffness_softening != 1.0) {
    if (!document["dem"].is_object()) document["dem"] = json::object();
    document["dem"]["stiffness_softening"] = c.dem.stiffness_softening * stiffness_softening;
  }
  if (other_seed) {
    if (!document["dem"].is_object()) document["dem"] = json::object();
    document["dem"]["seed"] = case_file::other_seed(c);
  }
  return load_case_document(document, c.path);
}

}  // namespace pdamp::case_file

namespace pdamp::case_file {

nlohmann::json clearance_patch(const Case& c, double clearance_m) {
  const DamperSpec& damper = c.dampers.front();
  const LayerSpec& layer = damper.layers.front();
  const double change_m = clearance_m - layer.clearance_m;
  json dampers = c.document.at("dampers");
  json& layer_json = dampers[0]["layers"][0];
  json& container = layer_json["container"];
  if (layer.container.shape == formulas::ContainerShape::kBox) {
    json& size = container["inner_size_m"][static_cast<std::size_t>(damper.drive_axis)];
    size = size.get<double>() + change_m;
  } else if (layer.container.cylinder_axis == damper.drive_axis) {
    container["inner_length_m"] = container["inner_length_m"].get<double>() + change_m;
  } else {
    throw CaseError(c.path, "/dampers/0/layers/0/container/axis",
                    "a cylinder across the drive has no length to change: a clearance variant needs a box, or a "
                    "cylinder along the drive");
  }
  if (layer_json.contains("clearance_m")) layer_json["clearance_m"] = clearance_m;
  return {{"dampers", dampers}};  // a merge patch replaces arrays whole
}

json wall_layer_patch(const Case& c, double thickness_m) {
  json dampers = c.document.at("dampers");
  json& layer_json = dampers[0]["layers"][0];
  if (!layer_json.contains("wall_layer"))
    throw CaseError(c.path, "/dampers/0/layers/0/wall_layer",
                    "is absent: a wall-layer thickness variant needs the layer's buffered wall");
  layer_json["wall_layer"]["thickness_m"] = thickness_m;
  return {{"dampers", dampers}};
}

Case with_clearance(const Case& c, double clearance_m) {
  if (!c.task.clearance || c.format_version != 2)
    throw CaseError(c.path, "/task", "a clearance variant needs a format-2 case of task kind clearance");
  json document = c.document;
  document.merge_patch(clearance_patch(c, clearance_m));
  const FrfTask& band = c.task.clearance->band;
  document["task"] = json{{"kind", "frf"},
                          {"min_frequency_hz", band.min_frequency_hz},
                          {"max_frequency_hz", band.max_frequency_hz},
                          {"points", band.points},
                          {"excitation", {{"kind", "base"},
                                          {"amplitude_m", band.base_amplitude_m},
                                          {"direction", {band.direction[0], band.direction[1]}}}}};
  return load_case_document(document, c.path);
}

}  // namespace pdamp::case_file
