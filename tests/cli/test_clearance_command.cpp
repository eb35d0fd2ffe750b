// pdamp optimize and pdamp run on task kind clearance (cases/beam_clearance.json): the chosen
// clearance against the closed form and the peak-against-h scan, JSON keys, files, and bad
// tasks as exit 2 naming the key.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

const std::string kCase = "beam_clearance.json";

/// The clearance case with one edit, written into `dir`.
std::string edited(const TempDir& dir, const std::function<void(json&)>& edit) {
  return edited_shipped_case(dir.path, kCase, edit);
}

}  // namespace

// References: the single-mode closed form for h (docs/optimizer.md; on this beam the
// lowest-peak h lies within 1 % of it, the other modes' share and the heavily damped peak
// being small: 6 % asked, as in tests/optimizer), and the 41 clearances the task evaluates
// itself for its picture: the solver's peak is no higher than any of theirs (to the solver's
// xtol 1e-3 in h on a flat minimum: 0.1 % asked). The 30 mm case clearance is held at the
// onset, |X/U| = X_onset/U = 0.376 · 30 mm / 1.33 mm = 8.5 (docs/optimizer.md).
TEST_CASE("pdamp optimize sizes the beam's clearance for the lowest resonant peak", "[cli][optimizer]") {
  const TempDir dir("clearance");
  const json r = run_json({"optimize", case_path(kCase), "--no-verify", "-o", dir.path.string()});
  for (const char* key : {"task", "case", "damper", "mode", "objective", "design", "current", "estimate", "solver",
                          "verification", "warnings", "outputs", "file"})
    CHECK(r.contains(key));
  CHECK(r["task"] == "clearance");
  CHECK(r["verification"].is_null());
  const double h = r["design"]["clearance_m"].get<double>();
  CHECK(h == Approx(r["estimate"]["clearance_m"].get<double>()).epsilon(0.06));
  const double peak = r["design"]["peak_transmissibility"].get<double>();
  CHECK(r["current"]["clearance_m"].get<double>() == Approx(0.030).epsilon(1e-9));
  CHECK(r["current"]["held_at_onset"] == true);
  CHECK(r["current"]["peak_transmissibility"].get<double>() == Approx(0.376 * 30.0 / 1.33).epsilon(0.01));
  std::ifstream scan(dir.path / "clearance.csv");
  std::string line;
  std::getline(scan, line);
  CHECK(line.rfind("clearance_m,peak_transmissibility,", 0) == 0);
  int rows = 0;
  while (std::getline(scan, line)) {
    ++rows;
    const double scanned_peak = std::stod(line.substr(line.find(',') + 1));
    CHECK(peak <= scanned_peak * (1.0 + 1e-3));
  }
  CHECK(rows == 41);
  for (const char* file : {"clearance.json", "clearance.gp", "case_resolved.json"}) CHECK(fs::exists(dir.path / file));
  CHECK((fs::exists(dir.path / "clearance.png") || fs::exists(dir.path / "clearance.svg") || !gnuplot_installed()));
  CHECK_FALSE(fs::exists(dir.path / "clearance_verify.csv"));
  require_plain_csv_tables(dir.path);

  // pdamp run does the same and writes the report, whose answer gives the clearance.
  const fs::path out = dir.path / "run";
  const auto run = run_pdamp({"run", case_path(kCase), "--no-verify", "-o", out.string()});
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  std::ifstream page(out / "report.html");
  const std::string html((std::istreambuf_iterator<char>(page)), std::istreambuf_iterator<char>());
  CHECK_THAT(html, Catch::Contains("Make the clearance"));
}

TEST_CASE("pdamp optimize exits 2 naming the key for a bad clearance task", "[cli][optimizer]") {
  const TempDir dir("clearance_bad");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> cases = {
      {[](json& c) { c["task"].erase("mode"); }, "/task/mode"},
      {[](json& c) { c["task"]["mode"] = 4; }, "/task/mode"},
      {[](json& c) { c["task"]["points"] = 4; }, "/task/points"},
      {[](json& c) { c["task"]["spacing"] = "log"; }, "/task/spacing"},
      {[](json& c) { c["task"]["excitation"] = {{"kind", "force"}, {"point", "tip"}, {"amplitude_n", 1.0}}; },
       "/task/excitation/kind"},
      {[](json& c) { c["task"]["objective"] = "fastest"; }, "/task/objective"},
      {[](json& c) { c["task"]["min_clearance_m"] = 0.02, c["task"]["max_clearance_m"] = 0.01; }, "/task/max_clearance_m"},
      {[](json& c) { c["task"]["verify"]["clearance_factors"] = {0.7, 1.0}; }, "/task/verify/clearance_factors/1"},
      {[](json& c) { c["task"]["verify"]["clearance_factors"] = {0.5, 0.7, 1.2, 1.4, 2.0}; },
       "/task/verify/clearance_factors"},
      {[](json& c) { c["task"]["verify"]["clearance_factors"] = {20.0}; }, "/task/verify/clearance_factors"},
      {[](json& c) { c["task"]["verify"]["dem_max_frequency_hz"] = 1.0; }, "/task/verify/dem_max_frequency_hz"},
      {[](json& c) { c["task"]["verify"]["tolerance_relative"] = 0.0; }, "/task/verify/tolerance_relative"},
      {[](json& c) { c["task"]["verify"]["dem_points"] = 1; }, "/task/verify/dem_points"},
      {[](json& c) { c["task"]["verify"]["rounds"] = 2; }, "rounds"},
      {[](json& c) { c["dampers"][0]["model"] = "auto"; }, "/dampers/0/model"},
      {[](json& c) { c["dampers"][0]["layers"].push_back(c["dampers"][0]["layers"][0]); }, "/dampers/0/layers"},
      {[](json& c) {
         c["dampers"].push_back(c["dampers"][0]);
         c["dampers"][1]["name"] = "second";
       },
       "/dampers"},
  };
  for (const auto& [edit, key] : cases) {
    INFO(key);
    require_one_line_error(run_pdamp({"optimize", edited(dir, edit)}), key);
  }
  require_one_line_error(run_pdamp({"optimize", case_path(kCase), "--method", "field"}), "--method");
  require_one_line_error(run_pdamp({"optimize", case_path(kCase), "--backend", "cplex"}), "--backend");
  require_one_line_error(run_pdamp({"optimize", case_path(kCase), "--calibration-cache", dir.path.string()}),
                         "--calibration-cache");
}
