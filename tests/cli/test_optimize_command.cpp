// pdamp optimize and pdamp run on task kind filling_ratios (cases/manipulator_link_optimize.json):
// exit codes, JSON keys, files in -o DIR, bad budgets and layers, the physics claim that
// the optimised three-layer design settles faster than the best single layer of the same mass,
// and the DEM verification (cut short here; the shipped case's full one is in docs/optimizer.md).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
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

const std::string kCase = "manipulator_link_optimize.json";

/// The optimisation case with one edit, written into `dir`.
std::string edited(const TempDir& dir, const std::function<void(json&)>& edit) {
  return edited_shipped_case(dir.path, kCase, edit);
}

}  // namespace

TEST_CASE("pdamp optimize chooses whole slabs per layer and reports the relaxed, chosen and baseline designs",
          "[cli][optimizer]") {
  const TempDir dir("optimize");
  const json r = run_json({"optimize", case_path(kCase), "--method", "formulas", "--no-verify", "-o", dir.path.string()});
  CHECK(r["method"] == "formulas");
  CHECK(r["calibration"].is_null());
  for (const char* key : {"task", "case", "design", "designs", "objective", "solver", "rounding", "baseline_layer",
                          "mass_budget_kg", "warnings", "outputs", "file"})
    CHECK(r.contains(key));
  CHECK(r["task"] == "filling_ratios");
  for (const char* key : {"backend", "iterations", "evaluations", "outcome"}) CHECK(r["solver"].contains(key));
  for (const char* design : {"chosen", "relaxed", "baseline", "initial"}) {
    const auto& d = r["designs"][design];
    REQUIRE(d["layers"].size() == 3);
    for (const auto& l : d["layers"])
      for (const char* key : {"slabs", "filling_ratio", "clearance_m", "bed_mass_kg", "volume_fraction"})
        CHECK(l.contains(key));
    CHECK(d["total_mass_kg"].get<double>() <= r["mass_budget_kg"].get<double>() * (1.0 + 1e-9));
  }
  // Whole slabs in the chosen design. A slab is 8 across and 2 high, so its 2 spheres per
  // lane settle onto the base: h = L − 2n·2r with 2r = 5 mm, and every design keeps its
  // settled bed one layer with at least 2r of travel (2n <= floor(L/2r) − 1).
  const double lengths[3] = {0.07, 0.04, 0.028};
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& l = r["design"]["layers"][k];
    const double n = l["slabs"].get<double>();
    CHECK(n == std::round(n));
    CHECK(l["clearance_m"].get<double>() == Approx(lengths[k] - 2.0 * 0.005 * n).margin(1e-12));
    CHECK(2.0 * n <= std::floor(lengths[k] / 0.005 + 1e-9) - 1.0);
  }
  for (const char* name : {"optimize.json", "designs.csv", "decay_compare.csv", "decay_compare.gp", "case_resolved.json"})
    CHECK(fs::is_regular_file(dir.path / name));
}

TEST_CASE("the optimised three-layer design settles faster than the best single layer of the same mass",
          "[cli][optimizer]") {
  // Independent reference: the baseline is the exhaustive best over layer and slab count
  // with all the budget in one layer; the chosen design must beat it outright (the design's
  // claim, docs/theory.md §7.7: layers of different clearance take over one after another).
  // By the closed forms with room for every layer (98.7 g: the shipped budget of six slabs
  // puts the closed forms' best in one layer, docs/optimizer.md).
  const TempDir dir("optimize_layers");
  const json r = run_json({"optimize", edited(dir, [](json& c) {
                             c["task"]["mass_budget_kg"] = 0.0987;
                             c["task"].erase("calibration");
                           }),
                           "--no-verify"});
  const double chosen = r["designs"]["chosen"]["settling_time_s"].get<double>();
  const double single = r["designs"]["baseline"]["settling_time_s"].get<double>();
  INFO("chosen " << chosen << " s, best single layer (" << r["baseline_layer"] << ") " << single << " s");
  CHECK(chosen < single);
  int layers_used = 0;
  for (const auto& l : r["design"]["layers"]) layers_used += l["slabs"].get<double>() > 0.0 ? 1 : 0;
  CHECK(layers_used >= 2);
}

TEST_CASE("pdamp run on task kind filling_ratios is pdamp optimize, and --backend ipopt chooses the same design",
          "[cli][optimizer]") {
  const json a = run_json({"run", case_path(kCase), "--method", "formulas", "--no-verify"});
  const json b = run_json({"optimize", case_path(kCase), "--method", "formulas", "--backend", "ipopt", "--no-verify"});
  CHECK(a["task"] == "filling_ratios");
  CHECK(a["solver"]["backend"] == "nlopt");
  CHECK(b["solver"]["backend"] == "ipopt");
  for (std::size_t k = 0; k < 3; ++k)
    CHECK(a["design"]["layers"][k]["slabs"] == b["design"]["layers"][k]["slabs"]);
}

TEST_CASE("pdamp optimize exits 2 naming the key for a bad budget, layer or backend", "[cli][optimizer]") {
  const TempDir dir("optimize_bad");
  // One slab is 16 spheres of 0.514 g (8.2 g): 5 g cannot hold one.
  require_one_line_error(run_pdamp({"optimize", edited(dir, [](json& c) { c["task"]["mass_budget_kg"] = 0.005; })}),
                         "/task/mass_budget_kg");
  require_one_line_error(run_pdamp({"optimize", edited(dir, [](json& c) { c["task"]["mass_budget_kg"] = -1.0; })}),
                         "/task/mass_budget_kg");
  require_one_line_error(run_pdamp({"optimize", edited(dir, [](json& c) {
                                      auto& layer = c["dampers"][0]["layers"][1];
                                      layer["container"] = {{"shape", "cylinder"}, {"inner_radius_m", 0.02},
                                                            {"inner_length_m", 0.04}, {"axis", "x"}};
                                    })}),
                         "/dampers/0/layers/1/container");
  require_one_line_error(run_pdamp({"optimize", case_path(kCase), "--backend", "cobyla"}), "--backend");
  require_one_line_error(run_pdamp({"optimize", case_path("manipulator_link_decay.json")}), "/task");
}

// DEM verification on the shipped case cut short: 0.7 s of decay (2.5 periods
// of the 3.6 Hz first mode) with the contacts softened 1e-4, and a short relaxed solve, so
// that both DEM runs (chosen and baseline) take about a second each. Independent
// references: the static tip deflection of the cantilever F L³/(3EI) (the initial
// envelope), passivity (the envelope never exceeds its initial value), an upper bound on the
// damping the beds can add in 2.5 periods (so neither decay can settle to 10 %), and
// conservation of energy (the co-simulation's ledger).
TEST_CASE("pdamp optimize --verify runs the DEM on the chosen and baseline designs and reports them side by side",
          "[cli][optimizer][dem]") {
  const TempDir dir("optimize_verify");
  const std::string path = edited(dir, [](json& c) {
    c["task"]["global_evaluations"] = 30;
    c["task"]["max_evaluations"] = 120;
    c["task"]["verify"] = {{"duration_s", 0.7}, {"stiffness_softening", 1e-4}, {"tolerance_relative", 0.3}};
    c["task"].erase("calibration");
  });
  // One run: the readable table on stdout, the result JSON in optimize.json.
  const auto run = run_pdamp({"optimize", path, "-o", (dir.path / "out").string()});
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  // The readable table says "not settled" rather than a time.
  CHECK(run.out.find("DEM not settled") != std::string::npos);
  // Progress of both DEM runs on stderr.
  CHECK(run.err.find("pdamp optimize --verify (chosen): decay") != std::string::npos);
  CHECK(run.err.find("pdamp optimize --verify (baseline): decay") != std::string::npos);
  // Verified without calibration: one plain note before the runs, with the command that calibrates.
  const std::string note = "a design chosen on the closed forms";
  const auto note_at = run.err.find(note);
  REQUIRE(note_at != std::string::npos);
  CHECK(run.err.find(note, note_at + 1) == std::string::npos);
  CHECK(note_at < run.err.find("pdamp optimize --verify (chosen): decay"));
  CHECK(run.err.find(path + " --method calibrated") != std::string::npos);
  const json r = json::parse(slurp(dir.path / "out" / "optimize.json"));
  REQUIRE(r["verification"].is_object());
  const json& v = r["verification"];
  CHECK(v["duration_s"] == 0.7);
  CHECK(v["effective_stiffness_softening"].get<double>() == Approx(1e-4));
  // Static deflection of the 0.5 m, 40 x 3 mm spring-steel cantilever under the 10 N tip
  // load: F L³/(3 E I) with I = b d³/12 = 9e-11 m⁴: 22.47 mm; three modes and the sum
  // Σ|b_j q_j| give it within 2 %.
  const double static_tip = 10.0 * 0.125 / (3.0 * 206e9 * (0.04 * 0.003 * 0.003 * 0.003 / 12.0));
  for (const char* name : {"chosen", "baseline"}) {
    INFO(name);
    const json& d = v["designs"][name];
    const json& dem = d["dem"];
    CHECK(dem["initial_envelope_m"].get<double>() == Approx(static_tip).epsilon(0.02));
    // Bed mass ≤ 49.4 g on a tip carrying 0.75 kg (plus the beam's share): μ ≲ 0.07, so
    // ζ_add ≤ ½·η*_max·μ ≈ 0.045 and 2.5 periods leave at least e^(−2π·0.045·2.5) = 0.49
    // of the envelope: far above the 10 % threshold.
    CHECK(dem["settled"] == false);
    CHECK(dem["outcome"] == "not_settled");
    CHECK(dem["settling_time_s"].is_null());
    CHECK(d["predicted"]["settled"] == false);
    CHECK(d["compared"] == "end_envelope");
    const double initial = dem["initial_envelope_m"].get<double>();
    for (const json* side : {&dem, &d["predicted"]}) {
      const double end = (*side)["end_envelope_m"].get<double>();
      CHECK(end <= initial * 1.01);  // passive: no more than the release
      CHECK(end >= initial * 0.3);
    }
    CHECK(dem["energy_error"].get<double>() < 0.01);
    const double pred = d["predicted"]["end_envelope_m"].get<double>();
    const double diff = (dem["end_envelope_m"].get<double>() - pred) / pred;
    CHECK(d["relative_difference"].get<double>() == Approx(diff).margin(1e-12));
    CHECK(d["passed"] == (std::abs(diff) <= 0.3));
  }
  // The ranking is the DEM's own: the chosen design ahead means its envelope at the end is lower.
  const bool chosen_lower = v["designs"]["chosen"]["dem"]["end_envelope_m"].get<double>() <
                            v["designs"]["baseline"]["dem"]["end_envelope_m"].get<double>();
  CHECK(v["ranking"]["dem_chosen_ahead"] == chosen_lower);
  CHECK(v["passed"] == (v["designs"]["chosen"]["passed"].get<bool>() && v["designs"]["baseline"]["passed"].get<bool>() &&
                        chosen_lower));
  CHECK(fs::is_regular_file(dir.path / "out" / "verify_decay.csv"));
  require_plain_csv_tables(dir.path / "out");
}

TEST_CASE("the task's verification is skipped with --no-verify, and --verify with --no-verify is exit 2", "[cli][optimizer]") {
  const TempDir dir("optimize_no_verify");
  const std::string path = edited(dir, [](json& c) {
    c["task"]["global_evaluations"] = 30;
    c["task"]["max_evaluations"] = 120;
    c["task"]["verify"] = {{"duration_s", 0.7}, {"stiffness_softening", 1e-4}};
    c["task"].erase("calibration");
  });
  const auto unverified = run_pdamp({"optimize", path, "--no-verify", "--json"});
  REQUIRE(unverified.exit_code == 0);
  CHECK(json::parse(unverified.out)["verification"].is_null());
  CHECK(unverified.err.find("closed forms") == std::string::npos);  // nothing verified: no note
  CHECK(run_json({"run", path, "--no-verify"})["verification"].is_null());
  require_one_line_error(run_pdamp({"optimize", path, "--verify", "--no-verify"}), "--verify");
}

namespace {

/// `pdamp optimize` on shipped case `name` with its calibration (into a fresh cache) and
/// its verification without the softening check: the result JSON.
json calibrated_and_verified(const TempDir& dir, const std::string& name) {
  std::ifstream in(case_path(name));
  json c = json::parse(in);
  c["task"]["verify"]["softening_check"] = false;
  const fs::path path = dir.path / name;
  std::ofstream(path) << c.dump(2);
  return run_json({"optimize", path.string(), "--calibration-cache", (dir.path / "cache").string(), "-o",
                   (dir.path / "out").string()});
}

/// Both designs predicted within the case's 15 % of the DEM, both settled, ranked as the DEM ranks them.
void require_confirmed(const json& r) {
  CHECK(r["method"] == "calibrated");
  const json& v = r["verification"];
  REQUIRE(v.is_object());
  CHECK(v["ranking"]["predicted_chosen_ahead"] == true);
  CHECK(v["ranking"]["dem_chosen_ahead"] == true);
  for (const char* name : {"chosen", "baseline"}) {
    INFO(name);
    const json& d = v["designs"][name];
    CHECK(d["dem"]["energy_error"].get<double>() < 0.01);
    CHECK(d["dem"]["settled"] == true);
    CHECK(d["compared"] == "objective");
    CHECK(std::abs(d["relative_difference"].get<double>()) <= 0.15);
    CHECK(d["passed"] == true);
  }
  CHECK(v["passed"] == true);
}

}  // namespace

// Reference: the DEM in the loop. The shipped optimisations on calibrated beds (each
// candidate bed's own DEM decay, seeded apart from the verification's runs) must predict the
// DEM-in-the-loop decays of the chosen design and of the baseline within the cases' 15 % and
// rank them as the DEM does: the reduced closing of the design loop CI runs (docs/optimizer.md,
// "Calibrated beds": the link −3 % and +4 %, the cantilever −4 % and −1 %, the checks at 1e-2
// within 6 %). The softening check is off here: it runs each design again 2.5 times as long,
// and its logic is tested in tests/tasks (docs/optimizer.md records the cases' checks).
TEST_CASE("the shipped optimisations on calibrated beds predict the DEM within their tolerance",
          "[cli][optimizer][long]") {
  {
    const TempDir dir("optimize_link_verify");
    const json r = calibrated_and_verified(dir, kCase);
    CHECK(r["calibration"]["runs"] == 11);
    require_confirmed(r);
    // The chosen design spends the budget: six slabs of 8.2 g. Not asked of the baseline,
    // the best single layer over its slab count (tests/optimizer): a lighter layer may
    // settle sooner (on other realisations of the calibrating decays the medium layer's
    // three slabs, 24.7 g, were the best).
    CHECK(r["designs"]["chosen"]["total_mass_kg"].get<double>() > r["mass_budget_kg"].get<double>() - 0.0083);
    // The baseline is the best single layer: no enumerated one-layer design settles sooner.
    REQUIRE(r["rounding"]["enumerated"] == true);
    int single_layers = 0;
    for (const auto& d : r["rounding"]["neighbours"]) {
      const auto& slabs = d["slabs"];
      if (std::count_if(slabs.begin(), slabs.end(), [](const json& n) { return n.get<double>() > 0.0; }) != 1) continue;
      ++single_layers;
      CHECK(r["designs"]["baseline"]["objective"].get<double>() <= d["objective"].get<double>() * (1.0 + 1e-12));
    }
    CHECK(single_layers > 0);
  }
  {
    const TempDir dir("optimize_cantilever_verify");
    const json r = calibrated_and_verified(dir, "cantilever_two_layer_optimize.json");
    CHECK(r["calibration"]["runs"] == 5);
    require_confirmed(r);
  }
}
