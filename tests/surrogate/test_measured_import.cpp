// Tests of the CSV import of measured fields: columns, grid assembly, clear errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "pdamp/surrogate/measured_import.hpp"
#include "support/temp_dir.hpp"
#include "surrogate/hostile_files.hpp"

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
  // Reference: E_diss = η*·½ m_bed (2πfX)² and m_app/m_bed (docs/theory.md §1).
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
  check_rejected("frequency_hz,amplitude_m,eta_star\n2,-0.01,0.1\n", "line 2, column amplitude_m", "must be in [1e-07, 10] (in m)");
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
  CHECK_THROWS_WITH(import_measured_csv("/nonexistent/rig.csv", rig()),
                    Catch::Equals("/nonexistent/rig.csv: no such file"));
}

TEST_CASE("physically meaningless measured values are refused with line and column", "[surrogate]") {
  const std::string header = "frequency_hz,amplitude_m,eta_star,eta_star_stderr,apparent_mass_kg\n";
  // η* = E_diss/(½ m_bed V²) >= 0 for a passive damper (docs/complex_power.md); the old
  // import accepted -5.
  check_rejected(header + "2,0.01,-5,0.01,0.1\n", "line 2, column eta_star", "-5: must be in [0, 100]");
  check_rejected(header + "2,0.01,-1e-9,0.01,0.1\n", "line 2, column eta_star", "must be in [0, 100]");
  check_rejected(header + "2,0.01,0.3,-0.01,0.1\n", "line 2, column eta_star_stderr", "-0.01: must be >= 0");
  check_rejected(header + "2,0.01,0.3,0.01,-0.1\n", "line 2, column apparent_mass_kg", "-0.1: must be >= 0");
  check_rejected(header + "0,0.01,0.3,0.01,0.1\n", "line 2, column frequency_hz", "0: must be in [0.01, 10000] (in Hz)");
  check_rejected(header + "1e308,0.01,0.3,0.01,0.1\n", "line 2, column frequency_hz", "must be in [0.01, 10000] (in Hz)");
  check_rejected(header + "2,1e-320,0.3,0.01,0.1\n", "line 2, column amplitude_m", "must be in [1e-07, 10] (in m)");
  // 1e300 would give E_diss ~ 1e298 J: a column or unit mistake, not a damper.
  check_rejected(header + "2,0.01,1e300,0.01,0.1\n", "line 2, column eta_star", "must be in [0, 100]");
  check_rejected(header + "2,0,0.3,0.01,0.1\n", "line 2, column amplitude_m", "0: must be in [1e-07, 10] (in m)");
  check_rejected(header + "2,0.01,inf,0.01,0.1\n", "line 2, column eta_star", "\"inf\" is not a finite number");
  check_rejected(header + "2,0.01,0.3,0.01,-inf\n", "line 2, column apparent_mass_kg", "not a finite number");
  check_rejected(header + "2,0.01,0.3,nan,0.1\n", "line 2, column eta_star_stderr", "not a finite number");
  check_rejected(header + "2,1e999,0.3,0.01,0.1\n", "line 2, column amplitude_m", "not a finite number");
  check_rejected("frequency_hz,amplitude_m,eta_star,motion_mode\n2,0.01,0.3,roll\x1b[2Jing\n",
                 "line 2, column motion_mode", "\"roll\\x1b[2Jing\" holds control characters");
  // η* = 0 (a locked bed) and large η* (an elastic bed can exceed the ideal 4/π) are data.
  const EffectiveField field =
      measured_field_from_csv(header + "2,0.01,0,0,0.74\n2,0.02,3.5,0.2,0\n", "rig.csv", rig());
  CHECK(field.points[0].eta_star == 0.0);
  CHECK(field.points[1].eta_star == 3.5);
}

TEST_CASE("a binary measured CSV gives one line naming the NUL byte, not a message cut at it", "[surrogate]") {
  std::string binary = "frequency_hz,amplitude_m,eta_star\n";
  binary += std::string("PK\x03\x04\0\0\x08\0rest of a zip", 21);
  std::string message;
  try {
    measured_field_from_csv(binary, "rig.xlsx", rig());
  } catch (const std::invalid_argument& e) {
    message = e.what();  // what() is a C string: an unescaped NUL would end it here
  }
  CHECK_THAT(message, Catch::StartsWith("rig.xlsx: line 2: byte 5 is NUL: this is a binary file, not CSV text") &&
                          Catch::Contains("the line starts \"PK\\x03\\x04\\0\\0\\x08\\0rest of a zip\""));
  CHECK(message.find('\n') == std::string::npos);
  // A NUL in the header line (UTF-16 text) is caught before the column names are checked.
  CHECK_THROWS_WITH(measured_field_from_csv(std::string("f\0r\0e\0q", 7), "rig.csv", rig()),
                    Catch::StartsWith("rig.csv: line 1: byte 2 is NUL"));
  // A file name with a newline stays on one line too.
  CHECK_THROWS_WITH(measured_field_from_csv("eta\n", "rig\n.csv", rig()), Catch::StartsWith("rig\\n.csv: line 1"));
}

TEST_CASE("a UTF-8 byte-order mark before the header is skipped", "[surrogate]") {
  const EffectiveField field =
      measured_field_from_csv("\xEF\xBB\xBF" "frequency_hz,amplitude_m,eta_star\n2,0.01,0.1\n", "rig.csv", rig());
  CHECK(field.points.size() == 1);
}

TEST_CASE("a directory or a FIFO given as the measured CSV is refused at once, naming it", "[surrogate]") {
  pdamp::test::TempDir dir("measured_hostile");
  // The old import reported a directory as "no header line".
  CHECK_THROWS_WITH(import_measured_csv(dir.path, rig()),
                    Catch::Equals(dir.path.string() + ": is a directory, not a file"));
  const auto fifo = dir.path / "rig.csv";
  pdamp::test::make_fifo(fifo);
  // The old import blocked in open() forever (no writer); the guard turns that into a failure.
  CHECK(pdamp::test::invalid_argument_within_timeout([&] { import_measured_csv(fifo, rig()); }, fifo) ==
        fifo.string() + ": is a FIFO (named pipe), not a file");
}
