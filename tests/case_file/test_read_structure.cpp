// Format-2 cases (case_file/src/read_structure.cpp, read_damper.cpp, read_task.cpp): the
// example structures and dampers of tests/case_file/data/, and their error paths.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/beam.hpp"
#include "case_file/case_error_check.hpp"
#include "support/temp_dir.hpp"

using nlohmann::json;
using pdamp::case_file::Case;
using pdamp::case_file::CaseError;
using pdamp::case_file::load_case;
using pdamp::test::require_case_error;
using pdamp::case_file::StructureSpec;
using pdamp::case_file::TaskKind;

namespace {

std::string data(const std::string& name) { return std::string(PDAMP_SOURCE_DIR) + "/tests/case_file/data/" + name; }

/// The cantilever example with one edit, written into `dir` (with the modal file beside it).
std::string edited(const pdamp::test::TempDir& dir, const std::string& example, const std::function<void(json&)>& edit) {
  std::ifstream in(data(example));
  json c = json::parse(in);
  edit(c);
  const std::string path = (dir.path / example).string();
  std::ofstream(path) << c.dump(2);
  return path;
}

constexpr const char* kCantilever = "vertical_cantilever_tip_damper.json";
constexpr const char* kModalData = "modal_data_tip_damper.json";

}  // namespace

TEST_CASE("the format-2 cantilever example reads its beam, damper and frf task", "[case_file]") {
  const Case c = load_case(data(kCantilever));
  CHECK(c.format_version == 2);
  REQUIRE(c.structure.has_value());
  const StructureSpec& s = *c.structure;
  CHECK(s.kind == StructureSpec::Kind::kBeam);
  REQUIRE(s.beam.segments.size() == 1);
  CHECK(s.beam.segments[0].section.shape == pdamp::structure::SectionShape::kSolidRectangle);
  CHECK(s.beam.segments[0].material.youngs_modulus_pa == 206e9);  // from the named material
  CHECK(s.beam.geometric_stiffness);
  CHECK(s.beam.axial_gravity_m_s2 == -9.80665);
  CHECK(s.mode_count == 3);
  CHECK(s.damping.ratios == std::vector<double>{0.002});
  REQUIRE(c.dampers.size() == 1);
  const auto& d = c.dampers[0];
  CHECK(d.site == "tip");
  CHECK(d.container_mass_kg == 0.3);
  REQUIRE(d.layers.size() == 1);
  CHECK(d.layers[0].clearance_m == Approx(0.1).margin(1e-12));  // the 36-sphere bed of the shipped low-intensity case
  CHECK(c.resolved["dampers"][0]["layers"][0]["wall_material"] == "steel");  // DEM geometry moved to the layer
  CHECK_FALSE(c.resolved["dem"].contains("wall_material"));
  CHECK(c.task.kind == TaskKind::kFrf);
  REQUIRE(c.task.frf.has_value());
  CHECK(c.task.frf->points == 301);
  CHECK(c.task.frf->excitation == pdamp::case_file::FrfTask::Excitation::kBase);
  CHECK(pdamp::case_file::dem_options(c, 0, 0.04, 2.0).validate("").empty());
}

TEST_CASE("the cantilever example's bare beam has the Euler-Bernoulli first mode, 2 Hz coming from its tip damper", "[case_file]") {
  // Euler-Bernoulli estimate: k = 3EI/L^3 = 98.9 N/m with EI = 206e9 * 0.03 * 0.002^3 / 12,
  // tip mass 0.3 kg container + 0.148 kg bed + 0.236 of the 0.236 kg beam: 2.2 Hz, gravity's
  // compression lowers it by ~5% (P/P_cr ~ 0.1). The example is built for 2 Hz; the beam
  // model here carries only the beam (the damper's masses are the coupling's), so its
  // first mode is that of the bare beam: 1.875^2/(2 pi L^2) sqrt(EI/(rho A)) = 6.7 Hz.
  const Case c = load_case(data(kCantilever));
  const auto result = pdamp::structure::beam_modal_model(c.structure->beam, c.structure->mode_count, c.structure->damping);
  // 10%: the gravity softening of the bare beam (its own weight, 0.02 of buckling) and the mesh.
  CHECK(result.modal.natural_frequencies_hz[0] == Approx(6.7).epsilon(0.1));
}

TEST_CASE("a modal-data structure reads its file relative to the case and normalises the drive direction",
          "[case_file]") {
  const Case c = load_case(data(kModalData));
  REQUIRE(c.structure.has_value());
  CHECK(c.structure->kind == StructureSpec::Kind::kModalData);
  CHECK(c.structure->modal_data_file == data("one_mode_tip.json"));
  REQUIRE(c.structure->modal_data.has_value());
  CHECK(c.structure->modal_data->natural_frequencies_hz[0] == 2.0);
  CHECK(c.dampers[0].drive_direction[0] == 0.0);
  CHECK(c.dampers[0].drive_direction[1] == 1.0);  // [0, 2] normalised
  CHECK(c.resolved["dampers"][0]["drive_direction"][1] == 1.0);
  REQUIRE(c.task.decay.has_value());
  CHECK(c.task.decay->load_point == "tip");
  CHECK(c.task.decay->settling_threshold == 0.05);  // the default
}

TEST_CASE("format-2 errors name the file, the pointer and the rule", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_v2_errors");
  const auto cantilever = [&](const std::function<void(json&)>& edit) { return edited(dir, kCantilever, edit); };
  const std::string file = (dir.path / kCantilever).string();
  // structure::BeamModel::validate() owns the beam's ranges.
  require_case_error(cantilever([](json& c) { c["structure"]["segments"][0]["length_m"] = -0.5; }), file,
                     "/structure/segments/0/length_m", "must be in [0.0001, 10000] m");
  require_case_error(cantilever([](json& c) { c["structure"]["points"][0]["position_m"] = 2.0; }), file,
                     "/structure/points/0/position_m", "on the beam");
  require_case_error(cantilever([](json& c) { c["structure"]["damping"] = {{"ratios", {-0.1}}}; }), file,
                     "/structure/damping/ratios/0", "must be in [0, 1]");
  require_case_error(cantilever([](json& c) { c["structure"]["segments"][0]["section"]["diameter_m"] = 0.01; }), file,
                     "/structure/segments/0/section/diameter_m", "unknown key");
  require_case_error(cantilever([](json& c) { c["structure"]["kind"] = "plate"; }), file, "/structure/kind",
                     "'plate' is not allowed");
  require_case_error(cantilever([](json& c) { c["dampers"][0]["site"] = "root"; }), file, "/dampers/0/site",
                     "'root' is no named point of the structure (known: tip, middle)");
  require_case_error(cantilever([](json& c) { c["dampers"][0]["drive_direction"] = {0.0, 0.0}; }), file,
                     "/dampers/0/drive_direction", "must be a non-zero direction");
  require_case_error(cantilever([](json& c) { c["dampers"][0]["layers"] = json::array(); }), file, "/dampers/0/layers",
                     "is empty");
  require_case_error(cantilever([](json& c) { c["dampers"][0]["layers"][0]["particles"]["count"] = 500; }), file,
                     "/dampers/0/layers/0/particles", "");
  require_case_error(cantilever([](json& c) { c["dem"]["wall_material"] = "steel"; }), file, "/dem/wall_material",
                     "unknown key");  // format 2 keeps the geometry in the layers
  require_case_error(cantilever([](json& c) { c["task"]["excitation"]["kind"] = "shaker"; }), file,
                     "/task/excitation/kind", "is not allowed");
  require_case_error(cantilever([](json& c) { c["task"]["max_frequency_hz"] = 0.5; }), file, "/task/max_frequency_hz",
                     "must be > min_frequency_hz");
  require_case_error(cantilever([](json& c) { c["task"] = {{"kind", "modes"}, {"mode_count", 5}, {"backbone_min_amplitude_m", 1e-3}, {"backbone_max_amplitude_m", 1e-2}}; }),
                     file, "/task/mode_count", "must be in [1, 3]");
  require_case_error(cantilever([](json& c) { c["damper"] = json::object(); }), file, "/damper", "unknown key");
}

TEST_CASE("an invalid modal data file is named with its own pointer", "[case_file]") {
  const pdamp::test::TempDir dir("case_file_modal_errors");
  const std::string modal = (dir.path / "one_mode_tip.json").string();
  std::ofstream(modal) << R"({"frequencies_hz": [-2.0], "damping_ratios": 0.0, "points": {"tip": {"translation_y": [1.0]}}})";
  const std::string path = edited(dir, kModalData, [](json&) {});
  require_case_error(path, modal, "/frequencies_hz/0", "");
  std::filesystem::remove(modal);
  require_case_error(path, modal, "", "no such file");
}

// `task.verify` of kind filling_ratios: the DEM check of the optimised design.
namespace {

/// The shipped optimisation case with one edit of its task, written into `dir`.
std::string edited_optimize_case(const pdamp::test::TempDir& dir, const std::function<void(json&)>& edit) {
  std::ifstream in(std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_optimize.json");
  json c = json::parse(in);
  edit(c["task"]);
  const std::string path = (dir.path / "optimize_case.json").string();
  std::ofstream(path) << c.dump(2);
  return path;
}

}  // namespace

TEST_CASE("a filling_ratios task reads its verify block, with defaults for the keys left out", "[case_file]") {
  const pdamp::test::TempDir dir("verify_block");
  // Empty block: the documented defaults; the duration is the task's own (20 s in the case).
  const Case defaults = load_case(edited_optimize_case(dir, [](json& t) { t["verify"] = json::object(); }));
  REQUIRE(defaults.task.filling_ratios.has_value());
  REQUIRE(defaults.task.filling_ratios->verify.has_value());
  const auto& v = *defaults.task.filling_ratios->verify;
  CHECK(v.tolerance_relative == 0.3);
  CHECK(v.duration_s == defaults.task.filling_ratios->decay.duration_s);
  CHECK(v.duration_s == 20.0);
  CHECK(v.stiffness_softening == 1.0);
  CHECK(v.require_ranking);
  CHECK(v.softening_check);
  CHECK(v.rounds == 3);
  CHECK(defaults.resolved["task"]["verify"]["softening_check"] == true);
  CHECK(defaults.resolved["task"]["verify"]["tolerance_relative"] == 0.3);
  CHECK(defaults.resolved["task"]["verify"]["duration_s"] == 20.0);
  CHECK(defaults.resolved["task"]["verify"]["require_ranking"] == true);

  const Case given = load_case(edited_optimize_case(dir, [](json& t) {
    t["verify"] = {{"tolerance_relative", 0.5}, {"duration_s", 12.5}, {"stiffness_softening", 0.01},
                   {"require_ranking", false}, {"softening_check", false}, {"rounds", 1}};
  }));
  const auto& g = *given.task.filling_ratios->verify;
  CHECK(g.tolerance_relative == 0.5);
  CHECK(g.duration_s == 12.5);
  CHECK(g.stiffness_softening == 0.01);
  CHECK_FALSE(g.require_ranking);
  CHECK_FALSE(g.softening_check);
  CHECK(g.rounds == 1);

  // Absent: no verification asked.
  const Case none = load_case(edited_optimize_case(dir, [](json& t) { t.erase("verify"); }));
  CHECK_FALSE(none.task.filling_ratios->verify.has_value());
}

TEST_CASE("a filling_ratios task reads its calibration block, its defaults the verification's", "[case_file]") {
  const pdamp::test::TempDir dir("calibration_block");
  // Empty: the verify block's duration and softening (the shipped case's: 20 s, 1e-3).
  const Case shipped = load_case(edited_optimize_case(dir, [](json& t) { t["calibration"] = json::object(); }));
  REQUIRE(shipped.task.filling_ratios->calibration.has_value());
  const auto& c = *shipped.task.filling_ratios->calibration;
  CHECK(c.duration_s == 20.0);
  CHECK(c.stiffness_softening == 0.001);
  CHECK(c.strokes_per_decade == 8);
  CHECK(shipped.resolved["task"]["calibration"]["strokes_per_decade"] == 8);
  // Without a verify block: the task's duration and full stiffness.
  const Case bare = load_case(edited_optimize_case(dir, [](json& t) {
    t.erase("verify");
    t["calibration"] = json::object();
  }));
  CHECK(bare.task.filling_ratios->calibration->duration_s == 20.0);
  CHECK(bare.task.filling_ratios->calibration->stiffness_softening == 1.0);
  const Case given = load_case(edited_optimize_case(dir, [](json& t) {
    t["calibration"] = {{"duration_s", 7.5}, {"stiffness_softening", 0.01}, {"strokes_per_decade", 4}};
  }));
  CHECK(given.task.filling_ratios->calibration->duration_s == 7.5);
  CHECK(given.task.filling_ratios->calibration->stiffness_softening == 0.01);
  CHECK(given.task.filling_ratios->calibration->strokes_per_decade == 4);
  // Absent: the closed forms.
  const Case none = load_case(edited_optimize_case(dir, [](json& t) { t.erase("calibration"); }));
  CHECK_FALSE(none.task.filling_ratios->calibration.has_value());
  const auto refused = [&](const json& calibration, const std::string& pointer, const std::string& rule) {
    const std::string path = edited_optimize_case(dir, [&](json& t) { t["calibration"] = calibration; });
    require_case_error(path, path, pointer, rule);
  };
  refused({{"strokes_per_decade", 0}}, "/task/calibration/strokes_per_decade", "[1, 100]");
  refused({{"stiffness_softening", 2.0}}, "/task/calibration/stiffness_softening", "1");
  refused({{"duration_s", 0.0}}, "/task/calibration/duration_s", "> 0");
  refused({{"seconds", 1.0}}, "/task/calibration/seconds", "unknown");
}

TEST_CASE("a bad verify block is refused naming its key and the allowed range", "[case_file]") {
  const pdamp::test::TempDir dir("verify_errors");
  const auto refused = [&](const json& verify, const std::string& pointer, const std::string& rule) {
    const std::string path = edited_optimize_case(dir, [&](json& t) { t["verify"] = verify; });
    require_case_error(path, path, pointer, rule);
  };
  refused({{"tolerance_relative", 0.0}}, "/task/verify/tolerance_relative", "> 0 and <= 10");
  refused({{"tolerance_relative", 11.0}}, "/task/verify/tolerance_relative", "<= 10");
  refused({{"duration_s", -1.0}}, "/task/verify/duration_s", "> 0");
  refused({{"rounds", 0}}, "/task/verify/rounds", "[1, 10]");
  refused({{"stiffness_softening", 0.0}}, "/task/verify/stiffness_softening", ">= 1e-06 and <= 1");
  refused({{"stiffness_softening", 2.0}}, "/task/verify/stiffness_softening", "<= 1");
  refused({{"require_ranking", "yes"}}, "/task/verify/require_ranking", "must be true or false");
  refused({{"softening_check", 1}}, "/task/verify/softening_check", "must be true or false");
  refused({{"tolerance", 0.3}}, "/task/verify/tolerance", "tolerance_relative");  // unknown key: the allowed ones named
  refused(json::array(), "/task/verify", "must be a JSON object");
}

TEST_CASE("a damper's container_rotary_inertia_kg_m2 defaults to 0, is read in kg m^2 and refuses a negative value",
          "[case_file]") {
  CHECK(load_case(data(kCantilever)).dampers[0].container_rotary_inertia_kg_m2 == 0.0);
  const pdamp::test::TempDir dir("rotary_inertia");
  const std::string good = edited(dir, kCantilever, [](json& c) { c["dampers"][0]["container_rotary_inertia_kg_m2"] = 2.5e-4; });
  CHECK(load_case(good).dampers[0].container_rotary_inertia_kg_m2 == 2.5e-4);
  const std::string bad = edited(dir, kCantilever, [](json& c) { c["dampers"][0]["container_rotary_inertia_kg_m2"] = -1.0; });
  require_case_error(bad, bad, "/dampers/0/container_rotary_inertia_kg_m2", ">= 0");
}

// The beds' modal mass ratio μ_j = Σ b_dj² m_bed / m_j (pdamp modes): above 0.1 the structure
// setup warns and names the mode (docs/theory.md §7.8). The shipped three-layer decay case
// carries 0.16 in its first mode, the optimisation case's starting design 0.08.
TEST_CASE("a modal mass ratio above 0.1 gets a warning sending the user to the DEM in the loop", "[case_file]") {
  const auto warning = [](const std::string& name) {
    const Case c = load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/" + name);
    const auto setup = pdamp::case_file::structure_setup(c, pdamp::case_file::LossMethod::kFormulas);
    for (const std::string& w : setup.warnings)
      if (w.find("modal mass ratio") != std::string::npos) return w;
    return std::string();
  };
  const std::string decay = warning("manipulator_link_decay.json");
  CHECK(decay.find("is 0.16 in mode 1 (above 0.1)") != std::string::npos);
  CHECK(decay.find("DEM in the loop") != std::string::npos);
  CHECK(warning("manipulator_link_optimize.json").empty());
}
