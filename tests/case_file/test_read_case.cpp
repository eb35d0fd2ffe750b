// Format-1 cases through the library (case_file/src/read_case.cpp and the section
// readers): the shipped cases, resolved defaults, physics_hash, and one test per error
// class, each naming file, JSON pointer and rule (CaseError).
#include <catch2/catch.hpp>
#include <algorithm>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "pdamp/case_file/case.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "case_file/case_error_check.hpp"
#include "support/temp_dir.hpp"

using nlohmann::json;
using pdamp::case_file::Case;
using pdamp::case_file::CaseError;
using pdamp::case_file::load_case;
using pdamp::test::require_case_error;

namespace {

std::string shipped(const std::string& name) { return std::string(PDAMP_SOURCE_DIR) + "/cases/" + name; }

json read_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

/// The shipped low-intensity case with one edit, written into `dir`.
std::string edited(const pdamp::test::TempDir& dir, const std::function<void(json&)>& edit) {
  json c = read_json(shipped("low_intensity_36_spheres.json"));
  edit(c);
  const std::string path = (dir.path / "case.json").string();
  std::ofstream(path) << c.dump(2);
  return path;
}

/// The case at `path` is refused, its error naming that file, `pointer` and `rule`.
void require_refused(const std::string& path, const std::string& pointer, const std::string& rule) {
  require_case_error(path, path, pointer, rule);
}

}  // namespace

TEST_CASE("every shipped format-1 case reads as one damper of one layer", "[case_file]") {
  for (const char* name : {"low_intensity_36_spheres.json", "high_intensity_cylinder.json", "buffered_wall_60hz.json"}) {
    const Case c = load_case(shipped(name));
    CHECK(c.format_version == 1);
    REQUIRE(c.dampers.size() == 1);
    CHECK(c.dampers.front().layers.size() == 1);
    CHECK_FALSE(c.structure.has_value());
    CHECK(c.task.kind == pdamp::case_file::TaskKind::kDamperDesign);
  }
  // 160 mm inner length minus 6 slabs of 10 mm spheres (docs/theory.md §9, clearance of a real bed); exact in binary to 1e-12.
  const Case low = load_case(shipped("low_intensity_36_spheres.json"));
  CHECK(low.dampers.front().layers.front().clearance_m == Approx(0.100).margin(1e-12));
  // The buffered case's /dem/wall_layer is the geometry of its one compartment.
  const Case buffered = load_case(shipped("buffered_wall_60hz.json"));
  CHECK(buffered.dampers.front().layers.front().compartment.layer.thickness_m ==
        read_json(shipped("buffered_wall_60hz.json"))["dem"]["wall_layer"]["thickness_m"].get<double>());
  CHECK(buffered.buffer.has_value());
  // The shipped layer is the sizing to the allowable strain 0.3 (ν = 0.48: 0.740 mm to the
  // µm the case gives, docs/hertz_and_buffer.md).
  CHECK(buffered.buffer->input.allowable_strain == 0.3);
  CHECK(pdamp::formulas::size_buffer_layer(buffered.buffer->input).layer_thickness_m ==
        Approx(buffered.dampers.front().layers.front().compartment.layer.thickness_m).margin(1e-6));
}

TEST_CASE("the buffer's allowable strain defaults to 0.3 and is refused outside (0, 1]", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_allowable_strain");
  const auto with_buffer = [&](const std::function<void(json&)>& edit) {
    return edited(dir, [&](json& c) {
      c["materials"] = {{"pu", {{"density_kg_m3", 1200.0}, {"youngs_modulus_pa", 60e6}, {"poisson_ratio", 0.48}}}};
      c["buffer"] = {{"layer_material", "pu"}, {"design_frequency_hz", 60.0}, {"design_intensity", 20.0}};
      edit(c);
    });
  };
  const Case c = load_case(with_buffer([](json&) {}));
  CHECK(c.buffer->input.allowable_strain == pdamp::formulas::kDefaultAllowableStrain);
  CHECK(c.resolved["buffer"]["allowable_strain"] == 0.3);
  CHECK(load_case(with_buffer([](json& j) { j["buffer"]["allowable_strain"] = 1.0; })).buffer->input.allowable_strain == 1.0);
  for (const double bad : {0.0, 1.5})
    require_refused(with_buffer([&](json& j) { j["buffer"]["allowable_strain"] = bad; }), "/buffer/allowable_strain",
                    "must be a finite number > 0 and <= 1");
}

TEST_CASE("the bed models' keys reach each layer's model options; absent, they keep today's closed forms",
          "[case_file]") {
  const pdamp::test::TempDir dir("case_file_bed_models");
  const Case plain = load_case(shipped("low_intensity_36_spheres.json"));
  const auto& options = plain.dampers.front().model_options;
  CHECK(options.bed_restitution == 0.0);
  CHECK(options.below_onset == pdamp::formulas::BelowOnsetModel::kScatteredFit);
  CHECK(options.below_onset_from_above == pdamp::formulas::BelowOnsetModel::kRollingTail);
  CHECK(options.rolling_resistance == plain.dem.simulation.world.default_pair.rolling_friction);
  CHECK_FALSE(plain.resolved["damper"]["model_options"].contains("bed_restitution"));
  // The DEM contact's constant restitution, for the one-sphere bound's warning.
  CHECK(options.particle_restitution == plain.dem.simulation.world.default_pair.restitution.constant);
  // One sphere high: not nested; its rows along the drive are the lattice's slabs.
  const auto plain_layer = pdamp::case_file::layer_model_options(plain.dampers.front(), plain.dampers.front().layers.front());
  CHECK_FALSE(plain_layer.nested_bed);
  CHECK(plain_layer.rows_along_drive == plain.dampers.front().layers.front().bed.slabs);
  // Two high across gravity, a slab settles into two rows (docs/theory.md §9): the link's
  // starting layers of two slabs lie in four rows.
  const Case link = load_case(shipped("manipulator_link_optimize.json"));
  for (const auto& layer : link.dampers.front().layers) {
    CAPTURE(layer.name);
    CHECK(pdamp::case_file::layer_model_options(link.dampers.front(), layer).rows_along_drive == 2.0 * layer.bed.slabs);
  }
  const Case c = load_case(edited(dir, [](json& j) {
    j["damper"]["model_options"] = {
        {"bed_restitution", 0.2}, {"below_onset", "impact_map"}, {"below_onset_from_above", "scattered_fit"}};
    j["dem"]["contact"]["rolling_friction"] = 0.05;  // the rolling tail's resistance (docs/theory.md §3.4)
  }));
  const auto& d = c.dampers.front();
  const auto layer = pdamp::case_file::layer_model_options(d, d.layers.front());
  CHECK(layer.bed_restitution == 0.2);
  CHECK(layer.below_onset == pdamp::formulas::BelowOnsetModel::kImpactMap);
  CHECK(layer.below_onset_from_above == pdamp::formulas::BelowOnsetModel::kScatteredFit);
  CHECK(layer.rolling_resistance == 0.05);
  CHECK(c.resolved["damper"]["model_options"]["bed_restitution"] == 0.2);
  CHECK(c.resolved["damper"]["model_options"]["below_onset"] == "impact_map");
  CHECK(pdamp::case_file::physics_hash(c, "formulas") != pdamp::case_file::physics_hash(plain, "formulas"));
}

TEST_CASE("a layer of one particle per lane or a few particles is warned about; a collected bed is not",
          "[case_file]") {
  const pdamp::test::TempDir dir("case_file_single_particle");
  const auto has = [](const std::vector<std::string>& warnings, const std::string& text) {
    return std::any_of(warnings.begin(), warnings.end(),
                       [&](const std::string& w) { return w.find(text) != std::string::npos; });
  };
  CHECK_FALSE(has(pdamp::case_file::settled_bed_warnings(load_case(shipped("low_intensity_36_spheres.json"))),
                  "single spheres rebound"));
  const Case one_slab = load_case(edited(dir, [](json& j) {
    j["damper"]["particles"]["count"] = 6;
    j["damper"]["particles"]["lattice"] = {1, 6, 1};
  }));
  const auto warnings = pdamp::case_file::settled_bed_warnings(one_slab);
  CHECK(has(warnings, "one particle per lane along the drive"));
  CHECK(has(warnings, "rolling: bed_restitution between "));
  const Case few = load_case(edited(dir, [](json& j) {
    j["damper"]["particles"]["count"] = 3;
    j["damper"]["particles"]["lattice"] = {3, 1, 1};
  }));
  CHECK(has(pdamp::case_file::settled_bed_warnings(few), "3 particles"));
}

TEST_CASE("omitted keys are resolved to their defaults", "[case_file]") {
  const Case c = load_case(shipped("low_intensity_36_spheres.json"));
  CHECK(c.resolved["dem"]["steps_per_contact"] == 0);  // automatic
  CHECK(c.resolved["dem"]["wall_material"] == "steel");
  CHECK(c.resolved["design"]["sweep_points"] == 301);
  CHECK(c.resolved["damper"]["model_options"]["rolling_calibration"] == 0.8976);
  CHECK(c.resolved["damper"]["particles"]["lot_diameter_variation_m"] == 5e-6);
  CHECK(c.resolved["format_version"] == 1);
  CHECK(c.dem.simulation.world.integration.steps_per_contact == 0);
}

TEST_CASE("the DEM options of a format-1 case carry its compartment, gravity and drive", "[case_file]") {
  const Case c = load_case(shipped("low_intensity_36_spheres.json"));
  const auto options = pdamp::case_file::dem_options(c, 0, 0.04, 2.0);
  REQUIRE(options.world.compartments.size() == 1);
  CHECK(options.world.compartments.front().particles.front().count == 36);
  CHECK(options.world.gravity_m_s2[2] == -9.80665);
  CHECK(options.drive_axis[0] == 1.0);
  CHECK(options.validate("").empty());
}

TEST_CASE("physics_hash of the shipped format-1 cases is unchanged", "[case_file]") {
  // The values the CLI wrote into field.json before the case schema became a library
  // (pdamp field --source formulas at that version): fields made then stay valid. (The
  // buffered-wall case is being redesigned, so its hash is not pinned here.)
  CHECK(pdamp::case_file::physics_hash(load_case(shipped("low_intensity_36_spheres.json")), "formulas") == "6472e9c05df9a26c");
  CHECK(pdamp::case_file::physics_hash(load_case(shipped("high_intensity_cylinder.json")), "formulas") == "c35c51bd0de93d11");
}

TEST_CASE("a case file that cannot be read or parsed names the file", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_unreadable");
  const std::string missing = (dir.path / "missing.json").string();
  require_case_error(missing, missing, "", "no such file");
  const std::string malformed = (dir.path / "malformed.json").string();
  std::ofstream(malformed) << "{ \"name\": \"x\", ";
  require_case_error(malformed, malformed, "", "malformed JSON");
  const std::string duplicate = (dir.path / "duplicate.json").string();
  std::ofstream(duplicate) << R"({"name": "a", "name": "b"})";
  require_case_error(duplicate, duplicate, "/name", "duplicate key");
  const std::string array = (dir.path / "array.json").string();
  std::ofstream(array) << "[]";
  require_case_error(array, array, "", "must be a JSON object, got array");
}

TEST_CASE("keys, types and ranges are checked with the key's pointer", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_rules");
  require_refused(edited(dir, [](json& c) { c["damper"]["particles"]["radus_m"] = 0.005; }),
                     "/damper/particles/radus_m", "unknown key (allowed here: collect_side, count,");
  require_refused(edited(dir, [](json& c) { c["excitation"]["frequency_hz"] = "2"; }), "/excitation/frequency_hz",
                     "must be a number Hz, got string");
  require_refused(edited(dir, [](json& c) { c["damper"]["particles"]["radius_m"] = -0.005; }),
                     "/damper/particles/radius_m", "= -0.005: must be a finite number >= 1e-05 and <= 1");
  require_refused(edited(dir, [](json& c) { c["damper"].erase("particles"); }), "/damper/particles",
                     "required (a JSON object)");
  require_refused(edited(dir, [](json& c) { c["format_version"] = 3; }), "/format_version", "must be in [1, 2]");
  require_refused(edited(dir, [](json& c) { c["damper"]["particles"]["material"] = "gold"; }),
                     "/damper/particles/material", "'gold' is not defined in /materials");
  require_refused(edited(dir, [](json& c) { c["structure"] = json::object(); }), "/structure",
                     "unknown key (allowed here:");
}

TEST_CASE("ranges owned by an option struct come from its validate()", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_owned_ranges");
  // formulas::ModelOptions::validate(): rolling_calibration in (0, 2].
  require_refused(edited(dir, [](json& c) { c["damper"]["model_options"] = {{"rolling_calibration", 3.0}}; }),
                     "/damper/model_options/rolling_calibration", "= 3: must be in (0, 2]");
  require_refused(
      edited(dir, [](json& c) { c["damper"]["model_options"] = {{"scattered", {{"s_min", 0.5}, {"s_max", 0.4}}}}; }),
      "/damper/model_options/scattered/s_max", "must be in [s_min, 1]");
  // The bed models' keys (docs/cases.md): bed_restitution in [0, 0.9], below_onset a name.
  require_refused(edited(dir, [](json& c) { c["damper"]["model_options"] = {{"bed_restitution", 0.95}}; }),
                  "/damper/model_options/bed_restitution", "= 0.95: must be in [0, 0.9]");
  require_refused(edited(dir, [](json& c) { c["damper"]["model_options"] = {{"bed_restitution", -0.1}}; }),
                  "/damper/model_options/bed_restitution", "= -0.1: must be in [0, 0.9]");
  require_refused(edited(dir, [](json& c) { c["damper"]["model_options"] = {{"below_onset", "map"}}; }),
                  "/damper/model_options/below_onset", "impact_map");
  require_refused(edited(dir, [](json& c) { c["damper"]["model_options"] = {{"below_onset_from_above", "tail"}}; }),
                  "/damper/model_options/below_onset_from_above", "rolling_tail");
  // dem_reference's validate(): a pin of the case, named by its pointer under /dem.
  require_refused(edited(dir, [](json& c) { c["dem"]["restitution_typo"] = 1; }), "/dem/restitution_typo",
                     "unknown key");
  // Steps per contact: 0 (automatic) or a resolved impact's 20 and more.
  require_refused(edited(dir, [](json& c) { c["dem"]["steps_per_contact"] = 10; }), "/dem/steps_per_contact",
                  "= 10: must be 0 (automatic) or in [20, 10000]");
  require_refused(edited(dir, [](json& c) { c["dem"]["steps_per_contact"] = -1; }), "/dem/steps_per_contact", "-1");
}

TEST_CASE("the DEM's option names become the case keys they come from", "[case_file]") {
  const Case c = load_case(shipped("low_intensity_36_spheres.json"));
  const auto check = [&](const std::string& line, const std::string& pointer, const std::string& rule) {
    const CaseError e = pdamp::case_file::dem_case_error(c, 0, line);
    CHECK(e.file() == c.path);
    CHECK(e.pointer() == pointer);
    CHECK(e.rule() == rule);
  };
  check("integration.time_step_s = 0.001: must be <= 1e-4", "/dem/time_step_s", "= 0.001: must be <= 1e-4");
  check("compartments[0].pins[1].radius_m = -1: must be > 0", "/dem/inner_structures/pins/1/radius_m", "= -1: must be > 0");
  check("compartments[0].particles[0].count = 0: must be >= 1", "/damper/particles/count", "= 0: must be >= 1");
  check("compartments[0]: lattice site 3 overlaps inner structure 0", "/dem/inner_structures",
        "lattice site 3 overlaps inner structure 0");
  check("pairs[0].restitution.table_values[1] = 2: must be <= 1", "/dem/pairs/0/restitution/values/1", "= 2: must be <= 1");
  check("gravity_m_s2[2] = 1e9: too large", "/damper/gravity_m_s2/2", "= 1e9: too large");
}

TEST_CASE("a CLI flag's buffer model name is refused naming the flag", "[case_file]") {
  CHECK(pdamp::case_file::buffer_model("half_space", "--layer-model", "") == pdamp::formulas::BufferModel::kHalfSpace);
  try {
    (void)pdamp::case_file::buffer_model("winkler", "--layer-model", "");
    FAIL("winkler accepted");
  } catch (const CaseError& e) {
    CHECK(std::string(e.what()) == "--layer-model: 'winkler': must be layered or half_space");
  }
}
