// Designs of a filling_ratios case as cases of their own (case.hpp, with_design).
#include <limits>
#include <string>
#include <vector>

#include "pdamp/case_file/case.hpp"

namespace pdamp::case_file {

using nlohmann::json;

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
    const auto seed = static_cast<long long>(c.dem.simulation.world.seed);
    document["dem"]["seed"] = seed < std::numeric_limits<int>::max() ? seed + 1 : seed - 1;
  }
  return load_case_document(document, c.path);
}

}  // namespace pdamp::case_file
