// Tests of the CSV import of measured fields: columns, grid assembly, clear errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pdamp/surrogate/measured_import.hpp"

namespace {

using namespace pdamp::surrogate;

constexpr double kPi = 3.14159265358979323846;

MeasuredImportOptions rig() {
  MeasuredImportOptions options;
  options.clearance_m = 0.1;
  options.bed_mass_kg = 0.74;
  return options;
}

/// Expects the import of `text` to fail with "rig.csv: line N[, column C]: ..." containing `rule`.
void check_rejected(const std::string& text, const std::string& where, const std::string& rule) {
  CHECK_THROWS_AS(measured_field_from_csv(text, "rig.csv", rig()), std::invalid_argument);
  CHECK_THROWS_WITH(measured_field_from_csv(text, "rig.csv", rig()),
                    Catch::StartsWith("rig.csv: " + where + ": ") && Catch::Contains(rule));
}

}  // namespace

TEST_CASE("a measured CSV in any row order becomes a full grid with derived columns", "[surrogate]") {
  const std::string csv =
      "# test rig, 36 spheres, 2024-05-06\n"
      "amplitude_m, frequency_hz, eta_star, eta_star_stderr, apparent_mass_kg, motion_mode\n"
      "0.02, 2, 0.30, 0.01, 0.21, rolling\n"
      "0.01, 2, 0.10, 0.02, 0.22, scattered\n"
      "\n"
      "0.02, 3, 0.50, , 0.20, collect_and_collide\n"
      "0.01, 3, 0.20, 0.01, , scattered\n";
  const EffectiveField field = measured_field_from_csv(csv, "rig.csv", rig());
  REQUIRE(field.validate().empty());
  CHECK(field.grid.axis0.values == std::vector<double>{2.0, 3.0});
  CHECK(field.grid.axis1.values == std::vector<double>{0.01, 0.02});
  CHECK(field.provenance.source == FieldSource::kMeasured);
  const FieldPoint& p = field.points[field.grid.index(1, 1)];  // 3 Hz, 0.02 m
  CHECK(p.eta_star == 0.5);
  CHECK(std::isnan(p.eta_star_stderr));  // empty cell: not given
  CHECK(p.motion_mode == "collect_and_collide");
  // Reference: E_diss = η*·½ m_bed (2πfX)² and m_app/m_bed (PHYSICS.md §1).
  const double v = 2 * kPi * 3.0 * 0.02;
  CHECK(p.e_diss_j == Approx(0.5 * 0.5 * 0.74 * v * v).epsilon(1e-14));
  CHECK(p.apparent_mass_fraction == Approx(0.20 / 0.74).epsilon(1e-15));
  CHECK(std::isnan(field.points[field.grid.index(1, 0)].apparent_mass_kg));
  CHECK(field.points[field.grid.index(0, 0)].eta_star_stderr == 0.02);
}

TEST_CASE("only the three required columns are needed", "[surrogate]") {
  const EffectiveField field =
      measured_field_from_csv("frequency_hz,amplitude_m,eta_star\n2,0.01,0.1\n2,0.03,0.4\n", "rig.csv", rig());
  CHECK(field.grid.size() == 2);
  CHECK(field.grid.axis0.values.size() == 1);
  CHECK(field.points[1].motion_mode.empty());
}

TEST_CASE("measured CSV errors name the file, line and column", "[surrogate]") {
  check_rejected("frequency_hz,amplitude_m\n2,0.01\n", "line 1, column eta_star", "missing from the header");
  check_rejected("frequency_hz,amplitude_m,eta_star,phase\n", "line 1, column phase", "unknown column");
  check_rejected("frequency_hz,amplitude_m,eta_star,eta_star\n", "line 1, column eta_star", "appears twice");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,0.01\n", "line 2", "2 cells, the header has 3");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,0.01,high\n", "line 2, column eta_star",
                 "\"high\" is not a finite number");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,0.01,nan\n", "line 2, column eta_star", "not a finite number");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,-0.01,0.1\n", "line 2, column amplitude_m", "must be > 0");
  check_rejected("frequency_hz,amplitude_m,eta_star,eta_star_stderr\n2,0.01,0.1,-1\n", "line 2, column eta_star_stderr",
                 "must be >= 0");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,0.01,0.1\n2,0.01,0.2\n", "line 3", "repeats line 2");
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,0.01,0.1\n3,0.02,0.2\n", "line 4",
                 "do not form a full grid: 2 frequencies x 2 amplitudes need 4 rows");
  check_rejected("# nothing\n", "line 2", "no header line");
  check_rejected("frequency_hz,amplitude_m,eta_star\n", "line 2", "no data rows");
  MeasuredImportOptions bad = rig();
  bad.bed_mass_kg = 0.0;
  CHECK_THROWS_WITH(measured_field_from_csv("", "rig.csv", bad), Catch::Contains("bed_mass_kg = 0: must be > 0"));
  CHECK_THROWS_WITH(import_measured_csv("/nonexistent/rig.csv", rig()), Catch::Contains("cannot be read"));
}
