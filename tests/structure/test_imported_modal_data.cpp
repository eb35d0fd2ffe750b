// Tests of imported modal data: the strict JSON reader, its errors, ModalModel::validate()
// and the round trip of a beam model through JSON.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>
#include <nlohmann/json.hpp>

#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/imported_modal_data.hpp"

namespace {

using namespace pdamp::structure;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;

json two_modes() {
  return json::parse(R"({
    "frequencies_hz": [12.5, 80.0],
    "damping_ratios": [0.01, 0.02],
    "points": {"tip": {"translation_y": [1.2, -0.8], "rotation": [1.9, 4.1]}}
  })");
}

/// Expects the import of `document` to fail with ModalDataError at `pointer`, saying `rule`.
void check_rejected(const json& document, const std::string& pointer, const std::string& rule) {
  try {
    modal_model_from_json(document);
    FAIL("accepted a document that should fail at " << pointer);
  } catch (const ModalDataError& error) {
    CHECK(error.pointer() == pointer);
    CHECK_THAT(error.what(), Catch::StartsWith((pointer.empty() ? "/" : pointer) + ": ") && Catch::Contains(rule));
    CHECK(std::string(error.what()).find('\n') == std::string::npos);
  }
}

/// Receptance at point p under a y force at p: Σ_j φ_j(p)² / (m_j(ω_j² − ω² + 2iζ_jω_jω)).
std::complex<double> tip_receptance(const ModalModel& model, const std::string& point, double omega) {
  const auto& shape = model.point(point).translation.row(1);
  std::complex<double> h = 0.0;
  for (Eigen::Index j = 0; j < model.mode_count(); ++j) {
    const double w = 2.0 * kPi * model.natural_frequencies_hz[j];
    h += shape[j] * shape[j] /
         (model.modal_masses_kg[j] * std::complex<double>(w * w - omega * omega, 2.0 * model.damping_ratios[j] * w * omega));
  }
  return h;
}

}  // namespace

TEST_CASE("a 1-DOF oscillator is one mode with default modal mass and zero missing components", "[structure]") {
  const json oscillator = json::parse(R"({
    "frequencies_hz": [10.0], "damping_ratios": 0.02, "modal_masses_kg": [3.5],
    "points": {"mass": {"translation_y": [1.0]}}
  })");
  const ModalModel model = modal_model_from_json(oscillator);
  REQUIRE(model.mode_count() == 1);
  CHECK(model.validate().empty());
  CHECK(model.damping_ratios[0] == 0.02);
  CHECK(model.modal_masses_kg[0] == 3.5);
  CHECK(model.point("mass").translation(0, 0) == 0.0);
  CHECK(model.point("mass").translation(1, 0) == 1.0);
  CHECK(model.point("mass").rotation[0] == 0.0);
  CHECK(model.base_participation.cols() == 0);
  CHECK(model.mode_shapes.size() == 0);

  const ModalModel defaults = modal_model_from_json(two_modes());
  CHECK(defaults.modal_masses_kg == Eigen::Vector2d(1.0, 1.0));
  json base_y = two_modes();
  base_y["base_participation_y_kg"] = {0.7, 0.2};
  const ModalModel with_base = modal_model_from_json(base_y);
  REQUIRE(with_base.base_participation.cols() == 2);
  CHECK(with_base.base_participation.col(0).isZero());  // x not given: 0
  CHECK(with_base.base_participation(1, 1) == 0.2);
}

TEST_CASE("modal data errors name the JSON pointer and the allowed range", "[structure]") {
  json doc = two_modes();
  SECTION("unknown keys at the root and in a point") {
    doc["frequency_hz"] = {1.0};
    check_rejected(doc, "/frequency_hz", "unknown key (allowed here: ");
    doc = two_modes();
    doc["points"]["tip"]["translation_z"] = {0.0, 0.0};
    check_rejected(doc, "/points/tip/translation_z", "unknown key (allowed here: rotation, translation_x, translation_y)");
  }
  SECTION("wrong lengths") {
    doc["points"]["tip"]["translation_y"] = {1.0};
    check_rejected(doc, "/points/tip/translation_y", "has 1 entries, must have 2 (one per mode");
    doc = two_modes();
    doc["damping_ratios"] = {0.01, 0.02, 0.03};
    check_rejected(doc, "/damping_ratios", "has 3 entries, must have 2");
    doc = two_modes();
    doc["frequencies_hz"] = json::array();
    check_rejected(doc, "/frequencies_hz", "at least one mode");
  }
  SECTION("out-of-range values") {
    doc["frequencies_hz"][1] = -80.0;
    check_rejected(doc, "/frequencies_hz/1", "-80 must be in [0.001, 100000] (in Hz)");
    doc = two_modes();
    doc["frequencies_hz"] = {80.0, 12.5};
    check_rejected(doc, "/frequencies_hz/1", "must be >= the previous frequency 80 Hz (ascending order)");
    doc = two_modes();
    doc["damping_ratios"] = -0.1;
    check_rejected(doc, "/damping_ratios", "-0.1 must be in [0, 1]");
    doc = two_modes();
    doc["modal_masses_kg"] = {1.0, 0.0};
    check_rejected(doc, "/modal_masses_kg/1", "0 must be in [1e-06, 1000000000] (in kg)");
  }
  SECTION("NaN, infinity and wrong types") {
    // JSON text cannot spell NaN, but a document built in code (a case file's reader, a
    // binding) can hold one.
    doc["damping_ratios"][0] = std::numeric_limits<double>::quiet_NaN();
    check_rejected(doc, "/damping_ratios/0", "must be a finite number");
    doc = two_modes();
    doc["points"]["tip"]["rotation"][1] = std::numeric_limits<double>::infinity();
    check_rejected(doc, "/points/tip/rotation/1", "must be a finite number (in rad per unit q)");
    doc = two_modes();
    doc["frequencies_hz"] = "12.5";
    check_rejected(doc, "/frequencies_hz", "must be a JSON array, got string");
    doc = two_modes();
    doc["frequencies_hz"][0] = true;
    check_rejected(doc, "/frequencies_hz/0", "must be a finite number (in Hz), got boolean");
    doc = two_modes();
    doc["points"]["tip"] = {1.0, 2.0};
    check_rejected(doc, "/points/tip", "must be a JSON object, got array");
    check_rejected(json::array(), "", "must be a JSON object, got array");
  }
  SECTION("missing keys and names that need escaping") {
    doc.erase("points");
    check_rejected(doc, "/points", "missing (required key)");
    doc = two_modes();
    doc["points"]["arm/tip~1"] = {{"rotation", {0.0}}};
    check_rejected(doc, "/points/arm~1tip~01/rotation", "has 1 entries, must have 2");
  }
  CHECK_THROWS_AS(modal_model_from_json(json::array()), std::invalid_argument);
}

TEST_CASE("ModalModel::validate reports sizes, ranges and non-finite shapes one line each", "[structure]") {
  ModalModel model = modal_model_from_json(two_modes());
  REQUIRE(model.validate().empty());
  model.natural_frequencies_hz[0] = -1.0;
  model.damping_ratios.conservativeResize(1);  // keeps the first value (resize would leave it undefined)
  model.modal_masses_kg[1] = 0.0;
  model.points[0].translation(1, 1) = std::nan("");
  model.base_participation = Eigen::MatrixXd::Zero(2, 1);
  const std::vector<std::string> expected{
      "natural_frequencies_hz/0 = -1: must be > 0 Hz and finite",
      "damping_ratios has 1 entries, must have 2 (one per mode)",
      "modal_masses_kg/1 = 0: must be > 0 kg and finite",
      "points/0/translation/1/1 = nan: must be finite",
      "base_participation has 1 columns, must have 2 (x, y) or 0 (no base motion)"};
  CHECK(model.validate() == expected);
  CHECK_THROWS_WITH(modal_model_to_json(model), Catch::StartsWith("modal model export: natural_frequencies_hz/0"));

  ModalModel descending = modal_model_from_json(two_modes());
  descending.natural_frequencies_hz = Eigen::Vector2d(80.0, 12.5);
  CHECK(descending.validate() ==
        std::vector<std::string>{"natural_frequencies_hz/1 = 12.5: must be >= the previous frequency (ascending order)"});
  CHECK(ModalModel{}.validate() ==
        std::vector<std::string>{"natural_frequencies_hz is empty: a modal model needs at least one mode"});
}

// Reference: the FE model itself. JSON numbers are written with round-trip precision
// (nlohmann::json dumps the shortest exact representation), so the re-imported model
// equals the original bit for bit and its receptance agrees to round-off (1e-12).
TEST_CASE("a beam model exported to JSON and re-imported reproduces its modal response", "[structure]") {
  BeamModel beam;
  BeamSegment segment;
  segment.length_m = 0.8;
  segment.section.width_m = 0.03;
  segment.section.depth_m = 0.004;
  segment.elements = 16;
  beam.segments = {segment};
  Support clamp;
  beam.supports = {clamp};
  beam.point_masses = {{"container", 0.8, 0.15, 2e-5}};
  beam.points = {{"middle", 0.4}};
  ModalDamping damping;
  damping.ratios = {0.005, 0.01};
  const ModalModel original = beam_modal_model(beam, 4, damping).modal;

  const std::string text = modal_model_to_json(original).dump(2);
  const ModalModel imported = modal_model_from_json(json::parse(text));
  REQUIRE(imported.validate().empty());
  CHECK(imported.natural_frequencies_hz == original.natural_frequencies_hz);
  CHECK(imported.damping_ratios == original.damping_ratios);
  CHECK(imported.modal_masses_kg == original.modal_masses_kg);
  CHECK(imported.base_participation == original.base_participation);
  REQUIRE(imported.points.size() == original.points.size());
  for (const auto& p : original.points) {
    INFO(p.name);
    CHECK(imported.point(p.name).translation == p.translation);
    CHECK(imported.point(p.name).rotation == p.rotation);
  }
  for (const double f : {1.0, 9.7, 40.0, 150.0}) {
    const double omega = 2.0 * kPi * f;
    const auto fe = tip_receptance(original, "container", omega);
    const auto data = tip_receptance(imported, "container", omega);
    CHECK(std::abs(data - fe) <= 1e-12 * std::abs(fe));
  }
}
