// pdamp sensitivity: rows per variant, files, the DEM study resumed from its
// log, a tilt about gravity that changes nothing, and bad input as exit 2.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

/// A quick DEM study: the shipped 36-sphere case, 1 transient and 1 analysed period.
std::string quick_study(const TempDir& dir) {
  std::ifstream in(case_path("low_intensity_36_spheres.json"));
  json c = json::parse(in);
  c["dem"]["transient_periods"] = 1;
  c["dem"]["analysed_periods"] = 2;
  c["sensitivity"] = {{"parameters", {{{"name", "friction"}, {"values", {0.15}}},
                                      {{"name", "tilt_z_deg"}, {"values", {5}}}}}};
  const fs::path path = dir.path / "study.json";
  std::ofstream(path) << c.dump(2);
  return path.string();
}

}  // namespace

TEST_CASE("pdamp sensitivity --source formulas gives a row per variant and the closed forms", "[cli]") {
  const TempDir dir("sensitivity_formulas");
  const json r = run_json({"sensitivity", case_path("low_intensity_36_spheres.json"), "--source", "formulas", "-o",
                           dir.path.string()});
  for (const char* key : {"file", "rows", "frequency_hz", "amplitude_m", "source", "warnings", "outputs"})
    CHECK(r.contains(key));
  const auto& rows = r["rows"];
  REQUIRE(rows.size() == 15);  // the default study: 16 values, 2 refused by the 6 x 6 lattice
  CHECK(rows[0]["parameter"] == "baseline");
  const double base = rows[0]["closed_form_eta_star"].get<double>();
  for (const auto& row : rows) {
    // The closed forms see the clearance only: a smaller radius moves h, nothing else does.
    INFO(row.dump());
    CHECK(row["eta_star"] == row["closed_form_eta_star"]);
    if (row["parameter"] == "particle_radius_m") CHECK(row["closed_form_eta_star"].get<double>() != base);
    else CHECK(row["closed_form_eta_star"].get<double>() == base);
  }
  for (const char* file : {"sensitivity.json", "sensitivity.csv", "sensitivity_tornado.csv", "sensitivity.gp"})
    CHECK(fs::exists(dir.path / file));
  // The tornado: the parameters the closed forms do not take are named, not drawn as flat bars.
  REQUIRE(r["tornado"].size() == 1);
  CHECK(r["tornado"][0]["parameter"] == "particle_radius_m");
  for (const auto& row : rows)
    if (row["parameter"] == "particle_radius_m")
      CHECK(r["tornado"][0]["effect"].get<double>() == std::abs(row["eta_star"].get<double>() - base));
  CHECK(r["without_effect"].size() == 7);
  CHECK_THAT(slurp(dir.path / "sensitivity.gp"), Catch::Contains("no effect in the closed forms: friction, restitution"));
}

// Reference: a tilt about the container's z axis, along which gravity points, changes no
// input of the DEM: its η* is the baseline's to the bit. A second run resumes every variant.
TEST_CASE("a DEM sensitivity study resumes from its log and a tilt about gravity changes nothing", "[cli]") {
  const TempDir dir("sensitivity_dem");
  const std::string path = quick_study(dir);
  const json first = run_json({"sensitivity", path, "-o", dir.path.string()});
  const auto& rows = first["rows"];
  REQUIRE(rows.size() == 3);
  CHECK(rows[2]["parameter"] == "tilt_z_deg");
  CHECK(rows[2]["eta_star"] == rows[0]["eta_star"]);
  CHECK(rows[1]["eta_star"] != rows[0]["eta_star"]);  // friction does change the bed
  CHECK(first["without_effect"] == json::array({"tilt_z_deg"}));
  REQUIRE(first["tornado"].size() == 1);
  CHECK(first["tornado"][0]["parameter"] == "friction");
  CHECK(fs::exists(dir.path / "sensitivity_sweep.jsonl"));
  const json again = run_json({"sensitivity", path, "-o", dir.path.string()});
  CHECK_THAT(again["sweep"].get<std::string>(), Catch::Contains("3 resumed, 0 computed"));
  CHECK(again["rows"] == rows);
}

TEST_CASE("pdamp sensitivity refuses a bad source, a multi-damper case and a bad shard", "[cli]") {
  require_one_line_error(run_pdamp({"sensitivity", case_path("low_intensity_36_spheres.json"), "--source", "field"}),
                         "--source");
  require_one_line_error(run_pdamp({"sensitivity", case_path("manipulator_link_decay.json")}), "one damper of one layer");
  require_one_line_error(run_pdamp({"sensitivity", case_path("low_intensity_36_spheres.json"), "--shard", "3/2"}),
                         "--shard");
}

// Job arrays: the shards of a DEM study, merged, are the serial study to the bit (each
// variant is one deterministic DEM run, wherever it runs).
TEST_CASE("pdamp sensitivity merge joins the shards of a DEM study into the serial table", "[cli]") {
  const TempDir dir("sensitivity_merge");
  const std::string path = quick_study(dir);
  const json serial = run_json({"sensitivity", path, "-o", (dir.path / "serial").string()});
  for (const auto& [shard, folder] : {std::pair{"0/2", "s0"}, std::pair{"1/2", "s1"}}) {
    const json part = run_json({"sensitivity", path, "--shard", shard, "-o", (dir.path / folder).string()});
    CHECK(part["shard"] == shard);
    CHECK(fs::exists(dir.path / folder / "shard_case.json"));
  }
  const json merged = run_json({"sensitivity", "merge", (dir.path / "s0").string(), (dir.path / "s1").string(), "-o",
                                (dir.path / "merged").string()});
  CHECK(merged["rows"] == serial["rows"]);
  CHECK(merged["shards"] == 2);
  CHECK(fs::exists(dir.path / "merged" / "sensitivity.png"));

  // One shard missing, a shard's folder as the output, a shard of another study.
  require_one_line_error(run_pdamp({"sensitivity", "merge", (dir.path / "s0").string(), "-o",
                                    (dir.path / "m1").string()}), "missing");
  require_one_line_error(run_pdamp({"sensitivity", "merge", (dir.path / "s0").string(), (dir.path / "s1").string(),
                                    "-o", (dir.path / "s1").string()}), "holds the shard file");
  std::ifstream in(path);
  json other = json::parse(in);
  other["sensitivity"]["parameters"][0]["values"] = {0.2};
  const fs::path other_path = dir.path / "other.json";
  std::ofstream(other_path) << other.dump(2);
  (void)run_json({"sensitivity", other_path.string(), "--shard", "1/2", "-o", (dir.path / "t1").string()});
  require_one_line_error(run_pdamp({"sensitivity", "merge", (dir.path / "s0").string(), (dir.path / "t1").string(),
                                    "-o", (dir.path / "m2").string()}), "t1");
}
