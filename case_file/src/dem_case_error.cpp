// dem_case_error(): the DEM's option names ("compartments[0].pins[1].radius_m") as the
// JSON pointers of the case keys they come from.
#include <iterator>
#include <regex>
#include <utility>
#include <vector>

#include "pdamp/case_file/case.hpp"

namespace pdamp::case_file {

namespace {

/// Where the keys of damper `d`, layer `k` sit in the case: the damper's own keys, the
/// layer's bed (container, particles) and its DEM geometry (format 1: under /dem).
struct LayerPointers {
  std::string damper;
  std::string bed;
  std::string geometry;
};

LayerPointers layer_pointers(const Case& c, std::size_t d, std::size_t k) {
  if (c.format_version == 1) return {"/damper", "/damper", "/dem"};
  const std::string damper = "/dampers/" + std::to_string(d);
  const std::string layer = damper + "/layers/" + std::to_string(k);
  return {damper, layer, layer};
}

/// "/a//b/" -> "/a/b": optional groups that did not match leave empty tokens behind.
std::string tidy_pointer(std::string pointer) {
  pointer = std::regex_replace(pointer, std::regex("/+"), "/");
  if (pointer.size() > 1 && pointer.back() == '/') pointer.pop_back();
  return pointer;
}

}  // namespace

CaseError dem_case_error(const Case& c, std::size_t damper_index, const std::string& problem) {
  // "<path> = <value>: <rule>" (dem_reference's validate(); "dem." before the path in
  // the time-step bound's message) or "<path> size = <n>: <rule>".
  std::string line = problem.rfind("dem.", 0) == 0 ? problem.substr(4) : problem;
  // Placement: "compartments[k]: lattice site 0 at (...) overlaps inner structure 0" —
  // named after what the user changes to make the bed fit.
  static const std::regex kPlacement(R"(^compartments\[(\d+)\]: (.*)$)");
  std::smatch match;
  if (std::regex_match(line, match, kPlacement)) {
    const auto at = layer_pointers(c, damper_index, std::stoul(match[1]));
    const std::string what = match[2];
    const std::string key = what.find("inner structure") != std::string::npos ? at.geometry + "/inner_structures"
                            : what.find("layer") != std::string::npos        ? at.geometry + "/wall_layer"
                                                                             : at.bed + "/particles";
    return CaseError(c.path, key, what);
  }
  const auto cut = line.find(" = ");
  if (cut == std::string::npos) return CaseError(c.path, "/dem", line);
  std::string path = line.substr(0, cut);
  const std::string rest = line.substr(cut + 1);
  if (path.size() > 5 && path.compare(path.size() - 5, 5, " size") == 0) path.resize(path.size() - 5);
  // Indices "[i]" become pointer tokens "/i".
  path = std::regex_replace(path, std::regex(R"(\[(\d+)\])"), ".$1");

  // Keys of a compartment (a layer): {bed} and {geometry} stand for the layer's pointers.
  static const std::vector<std::pair<std::regex, std::string>> kLayerKeys = {
      {std::regex(R"(^plates\.(\d+)(\.(\w+))?(\.(\d+))?$)"), "{geometry}/inner_structures/plates/$1/$3/$5"},
      {std::regex(R"(^pins\.(\d+)(\.(\w+))?(\.(\d+))?$)"), "{geometry}/inner_structures/pins/$1/$3/$5"},
      {std::regex(R"(^layer\.(\w+)$)"), "{geometry}/wall_layer/$1"},
      {std::regex(R"(^particles\.0\.radius_spread$)"), "/dem/radius_spread"},
      {std::regex(R"(^particles\.0\.(\w+)$)"), "{bed}/particles/$1"},
      {std::regex(R"(^container.*$)"), "{bed}/container"},
      {std::regex(R"(^wall_material$)"), "{geometry}/wall_material"},
      {std::regex(R"(^offset_m.*$)"), "{geometry}/offset_m"},
      {std::regex(R"(^lattice_counts.*$)"), "{bed}/particles/lattice"},
      {std::regex(R"(^staggered_lattice.*$)"), "{bed}/particles/lattice"},
  };
  // Internal names of the world options and the case keys they come from (read_dem).
  static const std::vector<std::pair<std::regex, std::string>> kKeys = {
      {std::regex(R"(^integration\.(\w+)$)"), "/dem/$1"},
      {std::regex(R"(^default_pair\.restitution\.table_speeds_m_s(\.(\d+))?$)"), "/dem/contact/restitution/speeds_m_s/$2"},
      {std::regex(R"(^default_pair\.restitution\.table_values(\.(\d+))?$)"), "/dem/contact/restitution/values/$2"},
      {std::regex(R"(^default_pair\.restitution\.\w+$)"), "/dem/contact/restitution"},
      {std::regex(R"(^default_pair\.(\w+)$)"), "/dem/contact/$1"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.table_speeds_m_s(\.(\d+))?$)"), "/dem/pairs/$1/restitution/speeds_m_s/$3"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.table_values(\.(\d+))?$)"), "/dem/pairs/$1/restitution/values/$3"},
      {std::regex(R"(^pairs\.(\d+)\.restitution\.\w+$)"), "/dem/pairs/$1/restitution"},
      {std::regex(R"(^pairs\.(\d+)\.(\w+)$)"), "/dem/pairs/$1/$2"},
      {std::regex(R"(^gravity_m_s2\.(\d+)$)"), "{damper}/gravity_m_s2/$1"},
      {std::regex(R"(^(amplitude_m|frequency_hz)$)"), "/excitation/$1"},
      {std::regex(R"(^approach_(amplitude_m|hold_periods|ramp_periods)$)"), "/dem/approach/$1"},
      {std::regex(R"(^drive_axis$)"), "{damper}/drive_axis"},
      {std::regex(R"(^(\w+)$)"), "/dem/$1"},
  };
  const auto apply = [](const std::vector<std::pair<std::regex, std::string>>& table, const std::string& key,
                        const LayerPointers& at) -> std::optional<std::string> {
    for (const auto& [pattern, replacement] : table) {
      if (!std::regex_match(key, pattern)) continue;
      std::string pointer = std::regex_replace(key, pattern, replacement);
      pointer = std::regex_replace(pointer, std::regex(R"(\{damper\})"), at.damper);
      pointer = std::regex_replace(pointer, std::regex(R"(\{bed\})"), at.bed);
      pointer = std::regex_replace(pointer, std::regex(R"(\{geometry\})"), at.geometry);
      return tidy_pointer(pointer);
    }
    return std::nullopt;
  };

  std::string pointer = "/dem";
  static const std::regex kMaterial(R"(^materials\.(\d+)\.(\w+)$)");
  static const std::regex kCompartment(R"(^compartments\.(\d+)\.(.*)$)");
  if (std::regex_match(path, match, kMaterial)) {
    const auto i = std::stoul(match[1]);
    auto it = c.materials.begin();
    if (i < c.materials.size()) std::advance(it, i);
    pointer = i < c.materials.size() ? "/materials/" + it->first + "/" + match[2].str() : "/materials";
  } else if (std::regex_match(path, match, kCompartment)) {
    const auto at = layer_pointers(c, damper_index, std::stoul(match[1]));
    pointer = apply(kLayerKeys, match[2], at).value_or(at.geometry);
  } else {
    pointer = apply(kKeys, path, layer_pointers(c, damper_index, 0)).value_or("/dem");
  }
  return CaseError(c.path, pointer, rest);
}

}  // namespace pdamp::case_file
