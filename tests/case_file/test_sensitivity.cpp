// The sensitivity section and its variants (case_file/src/sensitivity.cpp): each variant is the
// case with one value changed (checked against the case reader's own result), the defaults,
// and refusals naming /sensitivity/... .
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "case_file/case_error_check.hpp"
#include "pdamp/case_file/case.hpp"
#include "support/temp_dir.hpp"

namespace {

using nlohmann::json;
using namespace pdamp::case_file;

/// The shipped low-intensity case with a sensitivity section (or an edit), written into `dir`.
std::string study(const pdamp::test::TempDir& dir, const std::function<void(json&)>& edit) {
  std::ifstream in(std::string(PDAMP_SOURCE_DIR) + "/cases/low_intensity_36_spheres.json");
  json c = json::parse(in);
  edit(c);
  const std::string path = (dir.path / "study.json").string();
  std::ofstream(path) << c.dump(2);
  return path;
}

const SensitivityVariant& find(const std::vector<SensitivityVariant>& v, const std::string& parameter, double value) {
  for (const auto& x : v)
    if (x.parameter == parameter && x.value == value) return x;
  FAIL("no variant " << parameter << " = " << value);
  return v.front();
}

}  // namespace

// Reference: the case reader on the edited value (friction and softening read back as
// given), and a rotation by hand: gravity (0, 0, −g) turned +90° about the container's y
// axis is (−g, 0, 0); turned 30° about x, (0, g sin 30°, −g cos 30°). Exact to 1e-12 g.
TEST_CASE("a sensitivity variant is the case with one value changed", "[case_file]") {
  const pdamp::test::TempDir dir("sensitivity_variants");
  const std::string path = study(dir, [](json& c) {
    c["sensitivity"] = {{"amplitude_m", 0.03},
                        {"parameters", {{{"name", "friction"}, {"values", {0.1}}},
                                        {{"name", "youngs_modulus_factor"}, {"values", {4}}},
                                        {{"name", "tilt_y_deg"}, {"values", {90}}},
                                        {{"name", "tilt_x_deg"}, {"values", {30}}},
                                        {{"name", "particle_count"}, {"values", {30}}}}}};
  });
  const Case c = load_case(path);
  REQUIRE(c.sensitivity.has_value());
  CHECK(c.sensitivity->amplitude_m == 0.03);
  CHECK(c.sensitivity->frequency_hz == 2.0);  // the excitation's
  std::vector<std::string> skipped;
  const auto v = sensitivity_variants(c, skipped);
  REQUIRE(v.size() == 6);
  CHECK(skipped.empty());
  CHECK(v.front().parameter == "baseline");
  CHECK(find(v, "friction", 0.1).variant.dem.simulation.world.default_pair.friction == 0.1);
  CHECK(find(v, "youngs_modulus_factor", 4).variant.dem.stiffness_softening == Approx(4 * c.dem.stiffness_softening));
  const double g = 9.80665;
  const auto& gy = find(v, "tilt_y_deg", 90).variant.dampers.front().gravity_m_s2;
  CHECK(gy[0] == Approx(-g).margin(1e-12 * g));
  CHECK(gy[2] == Approx(0.0).margin(1e-12 * g));
  const auto& gx = find(v, "tilt_x_deg", 30).variant.dampers.front().gravity_m_s2;
  CHECK(gx[1] == Approx(g * 0.5).margin(1e-12 * g));
  CHECK(gx[2] == Approx(-g * std::cos(3.14159265358979323846 / 6)).margin(1e-12 * g));
  const auto& fewer = find(v, "particle_count", 30).variant.dampers.front().layers.front();
  CHECK(fewer.particle_count == 30);
  CHECK(fewer.bed_mass_kg == Approx(30.0 / 36.0 * c.dampers.front().layers.front().bed_mass_kg).epsilon(1e-12));
  CHECK(sensitivity_baseline_value(c, "friction") == 0.3);
}

TEST_CASE("the default study varies every parameter and leaves out the values the case refuses", "[case_file]") {
  const Case c = load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/low_intensity_36_spheres.json");
  std::vector<std::string> skipped;
  const auto v = sensitivity_variants(c, skipped);
  // 8 parameters × 2 values; the 6 × 6 lattice holds neither 40 spheres nor 5.5 mm ones.
  CHECK(v.size() == 1 + 16 - 2);
  REQUIRE(skipped.size() == 2);
  CHECK_THAT(skipped[0], Catch::Contains("particle_radius_m = 0.0055"));
  CHECK_THAT(skipped[1], Catch::Contains("particle_count = 40"));
}

TEST_CASE("a bad sensitivity section is refused naming the key", "[case_file]") {
  const pdamp::test::TempDir dir("sensitivity_bad");
  const auto refused = [&](const json& section, const std::string& pointer, const std::string& rule) {
    const std::string path = study(dir, [&](json& c) { c["sensitivity"] = section; });
    pdamp::test::require_case_error(path, path, pointer, rule);
  };
  refused({{"parameters", {{{"name", "colour"}, {"values", {1}}}}}}, "/sensitivity/parameters/0/name", "is not allowed");
  refused({{"parameters", {{{"name", "friction"}, {"values", {0.1}}}, {{"name", "friction"}, {"values", {0.2}}}}}},
          "/sensitivity/parameters/1/name", "given twice");
  refused({{"threads", 0}}, "/sensitivity/threads", "must be in [1, 256]");
  refused({{"amplitude_m", -1}}, "/sensitivity/amplitude_m", "");

  // A value the case refuses: named by its place in the study.
  const std::string path = study(dir, [](json& c) {
    c["sensitivity"] = {{"parameters", {{{"name", "particle_radius_m"}, {"values", {0.005, 0.05}}}}}};
  });
  const Case c = load_case(path);
  std::vector<std::string> skipped;
  try {
    (void)sensitivity_variants(c, skipped);
    FAIL("no error");
  } catch (const CaseError& e) {
    CHECK(e.pointer() == "/sensitivity/parameters/0/values/1");
    CHECK_THAT(e.rule(), Catch::Contains("particle_radius_m = 0.05: the case refuses it"));
  }
}
