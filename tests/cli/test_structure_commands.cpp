// Level III commands (pdamp modes, frf, decay, and pdamp run on their tasks): exit codes,
// JSON keys, files in -o DIR, the /task and field_file errors, and two closed-form numbers.
// Runs the built pdamp binary (support/run_pdamp.hpp); the solvers' physics is tested in
// tests/structure/.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::string data(const std::string& name) { return std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/" + name; }

/// Runs `args` with --json, requires exit 0 and returns the one JSON object on stdout.
json run_json(const std::string& args, double time_limit_s = 900.0) {
  RunOptions options;
  options.time_limit_s = time_limit_s;
  const auto r = run_pdamp(args + " --json", options);
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return json::parse(r.out);
}

void require_files(const fs::path& dir, const std::vector<std::string>& names) {
  for (const auto& name : names) {
    INFO(name);
    CHECK(fs::is_regular_file(dir / name));
  }
}

}  // namespace

TEST_CASE("pdamp modes gives frequencies with containers and bare, shapes, mass ratios and backbones", "[cli][structure]") {
  const TempDir dir("modes");
  const json r = run_json("modes " + data("cantilever_modes.json") + " -o " + dir.path.string());
  for (const char* key : {"task", "case", "method", "modes", "file", "backbone", "warnings", "outputs", "outcome"})
    CHECK(r.contains(key));
  CHECK(r["task"] == "modes");
  CHECK(r["method"] == "formulas");
  REQUIRE(r["modes"].size() == 2);  // the task's mode_count
  for (const auto& m : r["modes"]) {
    for (const char* key : {"mode", "frequency_hz", "bare_frequency_hz", "damping_ratio", "modal_mass_ratio",
                            "modal_mass_ratio_per_damper", "shapes", "backbone"})
      CHECK(m.contains(key));
    // The 0.3 kg container lowers every frequency.
    CHECK(m["frequency_hz"].get<double>() < m["bare_frequency_hz"].get<double>());
    CHECK(m["shapes"].contains("tip"));
    CHECK(m["shapes"]["tip"].contains("rotation"));
    CHECK(m["backbone"]["points"] == 12);
  }
  CHECK(r["backbone"]["amplitude_source"] == "task");
  CHECK(r["file"] == (dir.path / "modes.csv").string());
  require_files(dir.path, {"modes.csv", "backbone_mode1.csv", "backbone_mode2.csv", "backbone.gp", "modes.json",
                           "case_resolved.json"});
}

// Independent reference: the Euler-Bernoulli cantilever, f_1 = 1.8751²/(2πL²)·√(EI/ρA), with
// L = 0.5 m, E = 206 GPa, ρ = 7850 kg/m³, 30 mm x 2 mm. 20 elements give 1.3e-7 (docs/structures.md);
// 0.1% is the brief's tolerance. bare_frequency_hz is the structure without the container.
TEST_CASE("pdamp modes: the first bare frequency of the cantilever is 1.8751^2/(2 pi L^2) sqrt(EI/rho A)", "[cli][structure]") {
  const json r = run_json("modes " + data("cantilever_modes.json"));
  const double length = 0.5, b = 0.03, d = 0.002, youngs = 206e9, density = 7850.0;
  const double ei = youngs * b * d * d * d / 12.0, rho_a = density * b * d;
  const double beta = 1.875104068711961;
  const double expected = beta * beta / (2.0 * kPi * length * length) * std::sqrt(ei / rho_a);
  CHECK(r["modes"][0]["bare_frequency_hz"].get<double>() == Approx(expected).epsilon(1e-3));
  CHECK(r["file"].is_null());  // no -o: no files
}

// Independent reference: one mode of modal mass m = 0.5 kg at 2 Hz with shape 1 at the tip, a
// 0.3 kg container there: f = 2 Hz·√(m/(m + m_c)) = 1.5811 Hz (exact for one mode).
TEST_CASE("pdamp modes on one imported mode adds the container to the modal mass", "[cli][structure]") {
  const json r = run_json("modes " + data("modal_data_tip_damper.json"));
  REQUIRE(r["modes"].size() == 1);
  CHECK(r["modes"][0]["bare_frequency_hz"].get<double>() == Approx(2.0).epsilon(1e-12));
  CHECK(r["modes"][0]["frequency_hz"].get<double>() == Approx(2.0 * std::sqrt(0.5 / 0.8)).epsilon(1e-9));
  // μ = b² m_bed / m_j with b = 1 and the 36-sphere bed (0.14797 kg).
  CHECK(r["modes"][0]["modal_mass_ratio"].get<double>() == Approx(36 * 4.0 / 3.0 * kPi * 1.25e-7 * 7850.0 / 0.5).epsilon(1e-9));
  CHECK(r["backbone"]["amplitude_source"] == "default");
  CHECK(r["backbone"]["max_amplitude_m"].get<double>() == Approx(0.2).epsilon(1e-9));  // 2 x clearance 0.1 m
}

TEST_CASE("pdamp frf reports peaks, branches, jumps and the response without beds", "[cli][structure]") {
  const TempDir dir("frf");
  const json r = run_json("frf " + data("cantilever_frf.json") + " -o " + dir.path.string());
  for (const char* key : {"task", "method", "file", "peaks", "branches", "warnings", "outputs", "frf"}) CHECK(r.contains(key));
  const json& frf = r["frf"];
  for (const char* key : {"file", "peaks", "linear_peaks", "jumps", "branches", "warnings", "method", "outcome"})
    CHECK(frf.contains(key));
  CHECK(frf["method"] == "formulas");
  REQUIRE(!frf["peaks"].empty());
  for (const char* key : {"frequency_hz", "magnitude", "damping_ratio"}) CHECK(frf["peaks"][0].contains(key));
  REQUIRE(!frf["linear_peaks"].empty());
  // The beds damp the resonance: the peak with dampers is far lower than without beds.
  CHECK(frf["peaks"][0]["magnitude"].get<double>() < frf["linear_peaks"][0]["magnitude"].get<double>());
  CHECK(frf["file"] == (dir.path / "frf.csv").string());
  require_files(dir.path, {"frf.csv", "frf_branches.csv", "frf.gp", "frf.json", "case_resolved.json"});
}

TEST_CASE("pdamp frf on a case whose task is not frf is exit 2 naming /task", "[cli][structure]") {
  const TempDir dir("frf_not");
  const auto r = run_pdamp("frf " + data("modal_data_tip_damper.json") + " -o " + (dir.path / "out").string());
  require_one_line_error(r, "modal_data_tip_damper.json: /task: pdamp frf needs a task of kind frf");
  CHECK(!fs::exists(dir.path / "out" / "frf.csv"));  // nothing written
  require_one_line_error(run_pdamp("decay " + data("cantilever_frf.json")), "/task: pdamp decay needs a task of kind decay");
}

TEST_CASE("pdamp decay reports the settling time, damping ratio and per-layer energies", "[cli][structure]") {
  const TempDir dir("decay");
  const json r = run_json("decay " + data("cantilever_decay.json") + " -o " + dir.path.string());
  for (const char* key : {"task", "file", "settling_time_s", "damping_ratio", "warnings", "decay"}) CHECK(r.contains(key));
  const json& decay = r["decay"];
  for (const char* key : {"file", "settling_time_s", "damping_ratio", "dominant_mode", "outcome", "warnings", "layers"})
    CHECK(decay.contains(key));
  CHECK(decay["outcome"] == "settled");
  CHECK(decay["settling_time_s"].get<double>() > 0.0);
  CHECK(decay["settling_time_s"].get<double>() < 30.0);
  CHECK(decay["dominant_mode"] == 1);
  require_files(dir.path, {"decay.csv", "decay_without_beds.csv", "decay.gp", "decay.json", "case_resolved.json"});
  // One imported mode released from a static load: runs; a decay that does not settle says so.
  const TempDir one_mode("decay_one_mode");
  const json m = run_json("decay " + data("modal_data_tip_damper.json") + " -o " + one_mode.path.string());
  CHECK(m["decay"]["outcome"] == "not_settled");
  CHECK(m["settling_time_s"].is_null());

  // Without particles: the same release with the containers empty. The beds only take
  // energy out, so it ends higher; and it is linear: with modal damping c = 2 ζ ω_b m on
  // the bare mode and the containers adding mass only (stiffness k unchanged, so
  // m_eff / m = ω_b² / ω²), the envelope decays as exp(-c t / (2 m_eff)) = exp(-ζ ω² t / ω_b)
  // with ω the frequency with the empty containers (pdamp modes).
  CHECK(decay["without_beds"]["final_envelope_m"].get<double>() > decay["final_envelope_m"].get<double>());
  CHECK(m["decay"]["without_beds"]["final_envelope_m"].get<double>() > m["decay"]["final_envelope_m"].get<double>());
  const json mode = run_json("modes " + data("modal_data_tip_damper.json"))["modes"][0];
  const double w = 2.0 * M_PI * mode["frequency_hz"].get<double>(), w_bare = 2.0 * M_PI * mode["bare_frequency_hz"].get<double>();
  const double rate = mode["damping_ratio"].get<double>() * w * w / w_bare;
  std::ifstream csv(one_mode.path / "decay_without_beds.csv");
  std::string line;
  std::getline(csv, line);
  CHECK(line == "time_s,envelope_m");
  std::vector<std::pair<double, double>> envelope;
  for (double t, e; std::getline(csv, line) && std::sscanf(line.c_str(), "%lf,%lf", &t, &e) == 2;) envelope.push_back({t, e});
  REQUIRE(envelope.size() > 10);
  const double measured = -std::log(envelope.back().second / envelope.front().second) / (envelope.back().first - envelope.front().first);
  CHECK(measured == Approx(rate).epsilon(1e-6));  // RK4 on a smooth exponential: round-off only (4e-10 measured)
}

TEST_CASE("method field needs each layer's field_file and runs with one", "[cli][structure]") {
  require_one_line_error(run_pdamp("frf " + data("cantilever_frf.json") + " --method field"),
                         "cantilever_frf.json: /dampers/0/layers/0/field_file: required with --method field");
  require_one_line_error(run_pdamp("modes " + data("cantilever_frf.json") + " --method dem"),
                         "--method: 'dem': pdamp modes takes formulas or field");
  require_one_line_error(run_pdamp("frf " + data("cantilever_frf.json") + " --method des"),
                         "--method: 'des': must be formulas, field or dem");
  // The layer is the shipped 36-sphere layer, so the shipped formulas field fits it.
  const json r = run_json("frf " + data("cantilever_frf_field.json") + " --method field");
  CHECK(r["method"] == "field");
  CHECK(!r["frf"]["peaks"].empty());
  CHECK(r["warnings"].is_array());
}

// A decay reaches each stroke from above; a DEM field built from rest (no
// provenance.approach_amplitude_m) may hold the other branch, and the decay says so per
// layer. Here the narrow layer's field is marked as built from above; the others are not.
TEST_CASE("decay on DEM fields warns of each layer whose field was built from rest", "[cli][structure]") {
  TempDir dir("decay_branch_warning");
  const fs::path cases = fs::path(PDAMP_SOURCE_DIR) / "cases";
  json narrow = json::parse(std::ifstream(cases / "fields/link_narrow_dem/field.json"));
  narrow["provenance"]["approach_amplitude_m"] = 0.025;
  std::ofstream(dir.path / "narrow_from_above.json") << narrow.dump();
  json link = json::parse(std::ifstream(cases / "manipulator_link_decay.json"));
  for (auto& layer : link["dampers"][0]["layers"]) {
    layer["field_file"] = layer["name"] == "narrow" ? (dir.path / "narrow_from_above.json").string()
                                                    : (cases / layer["field_file"].get<std::string>()).string();
  }
  std::ofstream(dir.path / "link.json") << link.dump();
  const json r = run_json("decay " + (dir.path / "link.json").string() + " --method field");
  const auto warned = [&](const std::string& layer) {
    return std::any_of(r["warnings"].begin(), r["warnings"].end(), [&](const json& w) {
      const auto text = w.get<std::string>();
      return text.rfind("hybrid_damper/" + layer + ": its DEM field was built from rest", 0) == 0;
    });
  };
  CHECK(warned("wide"));
  CHECK(warned("medium"));
  CHECK_FALSE(warned("narrow"));
}

TEST_CASE("pdamp run on a format-2 frf case equals pdamp frf", "[cli][structure]") {
  const json run = run_json("run " + data("cantilever_frf.json"));
  const json frf = run_json("frf " + data("cantilever_frf.json"));
  CHECK(run["task"] == "frf");
  CHECK(run["peaks"] == frf["peaks"]);
  CHECK(run["frf"]["linear_peaks"] == frf["frf"]["linear_peaks"]);
  CHECK(run["frf"]["jumps"] == frf["frf"]["jumps"]);
  CHECK(run["method"] == "formulas");  // run defaults to formulas
  CHECK(run.contains("outputs"));
  CHECK(run_json("run " + data("cantilever_modes.json"))["task"] == "modes");
  CHECK(run_json("run " + data("cantilever_decay.json"))["task"] == "decay");
}

// The shipped Level III cases run end to end with their own task (the closed forms), and
// the base-excited beam also with its layer's field. What is checked is the outcome and
// that the dampers act: each resonance the dampers' site sees is damped far more than the
// structure alone (ζ ≥ 10× the structural 0.1-0.3%), and the link settles within its
// duration (the bare link, ζ = 0.3%, would need about 44 s to fall to 5%).
TEST_CASE("the shipped structure cases run end to end", "[cli][structure]") {
  const std::string cases = std::string(PDAMP_SOURCE_DIR) + "/cases/";
  for (const std::string name : {"beam_base_excited", "free_free_beam_shaker"}) {
    INFO(name);
    const json out = run_json("run " + cases + name + ".json");
    REQUIRE(!out["frf"]["peaks"].empty());
    for (const auto& peak : out["frf"]["peaks"]) CHECK(peak["damping_ratio"].get<double>() > 0.01);
    for (const auto& peak : out["frf"]["linear_peaks"]) CHECK(peak["damping_ratio"].get<double>() < 0.004);
  }
  const json field = run_json("frf " + cases + "beam_base_excited.json --method field");
  CHECK(field["frf"]["peaks"].size() == 1);
  const json decay = run_json("run " + cases + "manipulator_link_decay.json");
  CHECK(decay["decay"]["outcome"] == "settled");
  CHECK(decay["decay"]["settling_time_s"].get<double>() < 30.0);
  CHECK(decay["decay"]["layers"].size() == 3);
}

// --method dem: the structure co-simulated with each damper's bed as a DEM world
// (structure::cosimulate). One imported 2 Hz mode, 8 softened spheres: each run well under
// a few seconds. The physics of the co-simulation is tested in tests/structure/.
TEST_CASE("pdamp decay --method dem: settling time, damping ratio, energy error and files", "[cli][structure][dem]") {
  const TempDir dir("decay_dem");
  const auto r = run_pdamp("decay " + data("one_mode_dem_decay.json") + " --method dem --json -o " + dir.path.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  CHECK(r.err.find("pdamp decay (dem):") != std::string::npos);  // progress on stderr
  for (const char* key : {"task", "case", "method", "file", "settling_time_s", "damping_ratio", "energy_balance_error",
                          "decay", "warnings", "outputs"})
    CHECK(out.contains(key));
  CHECK(out["method"] == "dem");
  const json& d = out["decay"];
  for (const char* key : {"file", "plot", "settling_time_s", "damping_ratio", "dominant_mode", "outcome", "warnings",
                          "energy_error", "steps", "time_step_s", "threshold_m", "initial_envelope_m", "energy"})
    CHECK(d.contains(key));
  CHECK(d["outcome"] == "settled");
  CHECK(d["dominant_mode"] == 1);
  CHECK(d["energy_error"].get<double>() < 0.01);
  CHECK(d["steps"].get<long long>() > 0);
  // Released from q = 20 mm at unit shape, threshold 0.5 of it.
  CHECK(d["initial_envelope_m"].get<double>() == Approx(0.02));
  CHECK(d["threshold_m"].get<double>() == Approx(0.01));
  const double t_s = out["settling_time_s"].get<double>();
  CHECK(t_s > 0.5);
  CHECK(t_s < 8.0);
  // The beds damp: ζ_eq above the structure's 1%.
  CHECK(out["damping_ratio"].get<double>() > 0.01);
  CHECK(d["energy"]["dem_dissipated_j"].get<double>() > 0.0);
  require_files(dir.path, {"decay_dem.csv", "decay_dem.gp", "decay.json", "case_resolved.json"});
}

TEST_CASE("pdamp frf --method dem: a stepped sine of --dem-points frequencies, up and down", "[cli][structure][dem]") {
  const TempDir dir("frf_dem");
  const auto r = run_pdamp("frf " + data("one_mode_dem_frf.json") + " --method dem --dem-points 3 --json -o " +
                           dir.path.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  for (const char* key : {"file", "peaks", "branches", "warnings", "frf", "outputs"}) CHECK(out.contains(key));
  CHECK(out["method"] == "dem");
  const json& points = out["frf"]["points"];
  REQUIRE(points.size() == 6);
  // Up, then down in frequency, each from the previous final state (bed included); the
  // frequency run is the nearest whole number of the sweep's step per period (within
  // 1/(2N), N ~ 6e4 here).
  CHECK(out["bed_carried_over"] == true);
  CHECK(out["frf"]["stepped_sine"]["sweeps"] == json::array({"up", "down"}));
  for (int k = 0; k < 3; ++k) {
    CHECK(points[k]["sweep"] == "up");
    CHECK(points[3 + k]["sweep"] == "down");
    CHECK(points[k]["requested_frequency_hz"].get<double>() == Approx(1.2 + 0.4 * k));
    CHECK(points[3 + k]["requested_frequency_hz"].get<double>() == Approx(2.0 - 0.4 * k));
  }
  CHECK(points[0]["frequency_hz"].get<double>() == Approx(1.2).epsilon(1e-4));
  CHECK(points[0]["time_step_s"] == points[2]["time_step_s"]);  // one step for the sweep
  for (const auto& p : points) {
    CHECK(p["energy_error"].get<double>() < 0.01);
    CHECK(p["magnitude"]["damper_1"].get<double>() > 0.0);
    // The bed's in-loop complex power: finite everywhere (over 3 periods a bed still
    // settling from the resonance may give energy back, η* < 0: the down sweep's 1.2 Hz).
    CHECK(std::isfinite(p["bed_eta_star"]["damper_1"].get<double>()));
    CHECK(std::abs(p["bed_apparent_mass_fraction"]["damper_1"].get<double>()) < 2.0);
  }
  // At the resonance the bed is stationary and dissipates.
  CHECK(points[1]["bed_eta_star"]["damper_1"].get<double>() > 0.0);
  CHECK(points[4]["bed_eta_star"]["damper_1"].get<double>() > 0.0);
  // The mode with the container (2 Hz·√(0.5/0.8) = 1.58 Hz) is nearest the middle point;
  // the parabola through the three points puts the peak within their span, and a 0.4 Hz
  // spacing on a peak places it to about 10%.
  REQUIRE(out["peaks"].size() == 2);
  for (const auto& peak : out["peaks"]) {
    CHECK(peak["largest_point_frequency_hz"].get<double>() == Approx(1.6).epsilon(1e-4));
    CHECK(peak["frequency_hz"].get<double>() == Approx(1.58).epsilon(0.1));
    CHECK(peak["magnitude"].get<double>() > points[0]["magnitude"]["damper_1"].get<double>());
    CHECK(peak["indistinguishable_low_hz"].get<double>() <= peak["largest_point_frequency_hz"].get<double>());
    // Three points, the largest in the middle: the maximum lies between the grid's ends.
    CHECK(peak["maximum_low_hz"].get<double>() == Approx(1.2).epsilon(1e-4));
    CHECK(peak["maximum_high_hz"].get<double>() == Approx(2.0).epsilon(1e-4));
  }
  require_files(dir.path, {"frf_dem.csv", "frf_dem.gp", "frf.json", "case_resolved.json"});
  // The structure without particles beside the DEM's points: the same linear response as
  // pdamp frf's (formulas) without-beds columns, frequency by frequency.
  const TempDir formulas_dir("frf_formulas_linear");
  REQUIRE(run_pdamp("frf " + data("one_mode_dem_frf.json") + " -o " + formulas_dir.path.string()).exit_code == 0);
  std::ifstream bare(dir.path / "frf_without_particles.csv"), linear(formulas_dir.path / "frf.csv");
  std::string bare_line, linear_line;
  std::getline(bare, bare_line);
  CHECK(bare_line == "frequency_hz,magnitude_damper_1,phase_deg_damper_1");
  std::getline(linear, linear_line);
  std::size_t rows = 0;
  while (std::getline(bare, bare_line) && std::getline(linear, linear_line)) {
    ++rows;
    // frf.csv starts frequency_hz, linear_magnitude, linear_phase_deg: the same three numbers.
    CHECK(bare_line == linear_line.substr(0, bare_line.size()));
    CHECK(linear_line[bare_line.size()] == ',');
  }
  CHECK(rows > 10);
  // Bad input is exit 2: --dem-points out of range, an unknown direction, an empty band.
  CHECK(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --method dem --dem-points 1").exit_code == 2);
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --method dem --dem-sweep sideways"),
                         "--dem-sweep: 'sideways': must be up, down or both");
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") +
                                   " --method dem --dem-min-frequency 2 --dem-max-frequency 1.5"),
                         "--dem-max-frequency: 1.5 Hz: must exceed the lowest frequency 2 Hz");
  // Points on one frequency, refused before the run: an empty band, or points closer than a
  // step per period of the sweep's step.
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") +
                                   " --method dem --dem-points 3 --dem-min-frequency 1.5 --dem-max-frequency 1.5"),
                         "--dem-points, --dem-min-frequency, --dem-max-frequency: the band [1.5, 1.5] Hz is one frequency");
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") +
                                   " --method dem --dem-points 1000 --dem-min-frequency 1.5 --dem-max-frequency 1.500001"),
                         "--dem-points, --dem-min-frequency, --dem-max-frequency: 1000 points over [1.5, 1.500001] Hz");
}

// A point whose transient is cut before it can converge (at most the case's 5 periods, fewer
// than the 8 of the window) is analysed, marked converged = false in the JSON and the CSV,
// warned in one line naming its frequency and scatter, and drawn off the stable curve.
TEST_CASE("pdamp frf --method dem: an unconverged point is marked, warned and plotted apart", "[cli][structure][dem]") {
  const TempDir dir("frf_dem_unconverged");
  const auto r = run_pdamp("frf " + data("one_mode_dem_frf.json") +
                           " --method dem --dem-sweep up --dem-points 2 --dem-min-frequency 1.5 --dem-max-frequency 1.7"
                           " --dem-max-periods 0 --json -o " + dir.path.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  const json& points = out["frf"]["points"];
  REQUIRE(points.size() == 2);
  CHECK(out["frf"]["stepped_sine"]["min_transient_periods"] == 5);
  CHECK(out["frf"]["stepped_sine"]["max_transient_periods"] == 5);  // raised to the case's least
  CHECK(out["frf"]["stepped_sine"]["stable_tolerance"] == 0.05);
  for (const auto& p : points) {
    CHECK(p["converged"] == false);
    CHECK(p["stable"] == false);
    CHECK(p["transient_periods"] == 5);
    CHECK(p["periods"] == 5 + 3);
    CHECK(p["convergence"]["window_periods"] == 5);
    CHECK(p["convergence"]["period_magnitudes"].size() == 8);
    const std::string f = p["frequency_hz"].get<double>() < 1.6 ? "1.5 Hz" : "1.7 Hz";
    std::size_t warned = 0;
    for (const auto& w : out["warnings"])
      if (w.get<std::string>().find("up sweep at " + f + ": not converged after 5 transient periods") != std::string::npos)
        ++warned;
    CHECK(warned == 1);
  }
  std::ifstream csv(dir.path / "frf_dem.csv");
  std::string header, row;
  std::getline(csv, header);
  CHECK_THAT(header, Catch::Contains(",converged,periods,convergence_max_relative_change"));
  std::getline(csv, row);
  CHECK(std::count(row.begin(), row.end(), ',') == std::count(header.begin(), header.end(), ','));
  std::ifstream gp(dir.path / "frf_dem.gp");
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  CHECK_THAT(script, Catch::Contains("unconverged (not on the curve)"));
  // Bad settling flags are exit 2.
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --method dem --dem-tolerance 0"),
                         "--dem-tolerance");
  require_one_line_error(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --method dem --dem-max-periods -1"),
                         "--dem-max-periods");
}

TEST_CASE("pdamp frf --method dem --dem-sweep up: one direction over the given band", "[cli][structure][dem]") {
  const auto r = run_pdamp("frf " + data("one_mode_dem_frf.json") +
                           " --method dem --dem-sweep up --dem-points 2 --dem-min-frequency 1.5 --dem-max-frequency 1.7 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  const json& points = out["frf"]["points"];
  REQUIRE(points.size() == 2);
  CHECK(points[0]["requested_frequency_hz"].get<double>() == 1.5);
  CHECK(points[1]["requested_frequency_hz"].get<double>() == 1.7);
  CHECK(out["frf"]["stepped_sine"]["parallel"] == false);
}

// --compare: formulas, field (skipped here: the layer has no field_file) and the DEM stepped
// sine on one case, one figure and table; the agreement is each method's peak against DEM's.
TEST_CASE("pdamp frf --compare: formulas, field and DEM in one figure with the peaks' agreement", "[cli][structure][dem]") {
  const TempDir dir("frf_compare");
  // At most 20 transient periods per point (the test's time; a point not converged by then is
  // marked, which this test does not look at).
  const auto r = run_pdamp("frf " + data("one_mode_dem_frf.json") + " --compare --dem-points 3 --dem-max-periods 20 --json -o " +
                           dir.path.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  for (const char* key : {"file", "peaks", "branches", "warnings", "compare", "outputs"}) CHECK(out.contains(key));
  CHECK(out["method"] == "compare");
  const json& c = out["compare"];
  REQUIRE(c["formulas"]["peaks"].size() == 1);
  CHECK(c["field"].is_null());
  CHECK(r.err.find("the field curve is skipped") != std::string::npos);
  REQUIRE(c["dem"]["points"].size() == 6);  // up and down
  REQUIRE(c["dem"]["peaks"].size() == 2);
  REQUIRE(c["agreement"].size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    const json& peak = c["dem"]["peaks"][k];
    CHECK(peak["largest_point_frequency_hz"].get<double>() == Approx(1.6).epsilon(1e-4));
    CHECK(peak["magnitude"].get<double>() > 0.0);
    const json& a = c["agreement"][k]["formulas"];
    CHECK(c["agreement"][k]["reference"] == (k == 0 ? "dem up" : "dem down"));
    for (const char* key : {"frequency_relative_difference", "magnitude_relative_difference",
                            "band_centre_relative_difference", "frequency_within_dem_indistinguishable",
                            "frequency_within_dem_maximum"})
      CHECK(a.contains(key));
    // The bracket of the maximum holds the largest points' range.
    CHECK((!a["frequency_within_dem_indistinguishable"].get<bool>() || a["frequency_within_dem_maximum"].get<bool>()));
    const double f_formulas = c["formulas"]["peaks"][0]["frequency_hz"].get<double>();
    const double f_dem = peak["frequency_hz"].get<double>();
    CHECK(a["frequency_relative_difference"].get<double>() == Approx((f_formulas - f_dem) / f_dem));
    CHECK(std::abs(a["frequency_relative_difference"].get<double>()) < 0.1);  // both near the 1.58 Hz mode
    CHECK(c["agreement"][k]["field"].is_null());
  }
  require_files(dir.path, {"frf_compare.csv", "frf_compare.gp", "frf.json", "case_resolved.json"});
  // The closed forms' states held at a jump are on the curve (a gap there before), and the
  // structure without particles is drawn: one row per frequency of the formulas' sweep, the
  // same as pdamp frf's linear columns.
  const std::string table = slurp(dir.path / "frf_compare.csv");
  const json plain = run_json("frf " + data("one_mode_dem_frf.json"));
  const auto rows_of = [&](const std::string& start) {
    std::size_t count = 0;
    for (std::size_t at = table.find("\n" + start); at != std::string::npos; at = table.find("\n" + start, at + 1)) ++count;
    return count;
  };
  CHECK(rows_of("formulas,-1,") == plain["frf"]["held_at_jump_points"].get<std::size_t>());
  CHECK(rows_of("formulas,-1,") > 0);
  CHECK(rows_of("without_beds,0,") == plain["frf"]["frequencies"]["points"].get<std::size_t>());
  CHECK(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --compare --method dem").exit_code == 2);
}

// --dem-signal linear: per direction the steady state at the band's start, then a linear sine
// sweep to the other end; each drive cycle's first harmonic is a point. 0.1 Hz/s over
// [1.4, 1.8] Hz is 4 s and ∫f dt = 6.4 cycles, so 6 whole cycles per direction.
TEST_CASE("pdamp frf --method dem --dem-signal linear: a linear sine sweep up and down, a point per cycle",
          "[cli][structure][dem]") {
  const TempDir dir("frf_dem_linear");
  const std::string sweep = "frf " + data("one_mode_dem_frf.json") + " --method dem --dem-signal linear";
  const auto r = run_pdamp(sweep + " --dem-sweep-rate 0.1 --dem-min-frequency 1.4 --dem-max-frequency 1.8 --json -o " +
                           dir.path.string());
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  CHECK(out["signal"] == "linear_sweep");
  const json& frf = out["frf"];
  REQUIRE(frf["sweeps"].size() == 2);
  std::map<std::string, std::vector<double>> frequencies;
  for (const auto& p : frf["points"]) {
    frequencies[p["sweep"].get<std::string>()].push_back(p["frequency_hz"].get<double>());
    CHECK(p["magnitude"]["damper_1"].get<double>() > 0.0);
  }
  for (const auto& s : frf["sweeps"]) {
    CHECK(s["cycles"] == 6);
    CHECK(s["duration_s"].get<double>() == Approx(4.0));
    CHECK(s["energy_error"].get<double>() < 0.01);
    CHECK(s["start_stable"] == true);
  }
  // Cycle frequencies rise on the up sweep and fall on the down sweep, inside the band.
  REQUIRE(frequencies["up"].size() == 6);
  REQUIRE(frequencies["down"].size() == 6);
  CHECK(std::is_sorted(frequencies["up"].begin(), frequencies["up"].end()));
  CHECK(std::is_sorted(frequencies["down"].rbegin(), frequencies["down"].rend()));
  CHECK(frequencies["up"].front() > 1.4);
  CHECK(frequencies["down"].front() < 1.8);
  REQUIRE(out["peaks"].size() == 2);
  require_files(dir.path, {"frf_dem_sweep.csv", "frf_dem_sweep.gp", "frf.json"});

  // The default rate: 4πζ²f²/100 at the formulas' largest peak (pdamp frf's own figures).
  const json formulas = json::parse(run_pdamp("frf " + data("one_mode_dem_frf.json") + " --json").out);
  const double f = formulas["peaks"][0]["frequency_hz"].get<double>(), zeta = formulas["peaks"][0]["damping_ratio"].get<double>();
  const auto slow = run_pdamp(sweep + " --dem-sweep up --dem-min-frequency 1.55 --dem-max-frequency 1.551 --json");
  INFO(slow.err);
  REQUIRE(slow.exit_code == 0);
  const json slow_out = json::parse(slow.out);
  CHECK(slow_out["frf"]["rate_hz_per_s"].get<double>() == Approx(4 * 3.14159265358979 * zeta * zeta * f * f / 100).epsilon(1e-9));
  CHECK_THAT(slow_out["frf"]["rate_basis"].get<std::string>(), Catch::Contains("formulas"));

  // Bad input is exit 2 with one line.
  require_one_line_error(run_pdamp(sweep.substr(0, sweep.size() - 6) + "chirp"),
                         "--dem-signal: 'chirp': must be stepped or linear");
  CHECK(run_pdamp(sweep + " --dem-sweep-rate 0").exit_code == 2);
  require_one_line_error(run_pdamp(sweep + " --dem-sweep-rate 1e-9"), "would take");
}

// Two dampers: every output gets the stepped sine's resonance measures (the second without
// standard errors: only the first site's per-period amplitudes are kept).
TEST_CASE("pdamp frf --method dem with two dampers gives each output its peak", "[cli][structure][dem]") {
  const TempDir dir("frf_dem_two");
  std::ifstream in(data("one_mode_dem_frf.json"));
  json c = json::parse(in);
  c["structure"]["file"] = data("one_mode_dem.json");
  c["dampers"].push_back(c["dampers"][0]);
  c["dampers"][1]["container_mass_kg"] = 0.1;
  const std::string path = (dir.path / "two.json").string();
  std::ofstream(path) << c.dump(2);
  const auto r = run_pdamp("frf " + path + " --method dem --dem-sweep up --dem-points 3 --dem-max-periods 20 --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const json out = json::parse(r.out);
  REQUIRE(out["peaks"].size() == 2);
  CHECK(out["peaks"][0]["output"] == "damper_1");
  CHECK(out["peaks"][1]["output"] == "damper_2");
  for (const auto& peak : out["peaks"]) {
    CHECK(peak["magnitude"].get<double>() > 0.0);
    CHECK(peak.contains("band_centre_hz"));
    CHECK(peak["largest_point_frequency_hz"].get<double>() > 0.0);
  }
  CHECK(out["peaks"][1]["magnitude_standard_error"].is_null());
}

/// The [long] runs' time limit, s: a minute or two on an idle 2-core machine, several times
/// that on a loaded one.
constexpr double kLongTimeLimit_s = 900.0;

// The cross-method agreement on the shipped cases, the reduced version CI runs.
// Beam: the shipped case (E/100; the full-stiffness sweep gives the same plateau within the
// bed's chaos, docs/structure_cli.md), 10 points over 1.3-2.2 Hz up and down, each point at
// most 40 periods past its transient (--dem-max-periods 40: 2 min 51 s on two cores; to
// convergence, up to 200 periods, 11-17 min). The checked quantities do not change with
// it: peak magnitude differences formulas +1.6/+2.9 %, field −11.4/−10.3 % (up/down) against
// +2.1/+2.5 % and −11.0/−10.6 % to convergence, frequencies inside the DEM's range both ways;
// the points themselves differ within the bed's scatter (one bistable point 11 %). The DEM's
// top is flat (a damping ratio near 0.2) and its realisations differ: with the bed seeded 1,
// 2, 3 (DEM physics version 4) the down sweep peaks at 1.80, 1.82 and 1.70 Hz, the shipped
// seed's up sweep at 1.89 Hz with its points >= 0.9 of the largest over 1.50-2.13 Hz, while
// its down sweep's band of such points starts at 1.707 Hz (version 3's realisations: argmax
// 1.55-1.84 Hz, docs/structure_cli.md). On a top this flat a peak frequency is only known
// to lie on the plateau, which no single sweep maps (each is one realisation): the check
// asks each model's peak to lie in the union of the two sweeps' bands >= 0.9 of their
// largest, and its magnitude within 20 % of each sweep's (the required agreement; measured
// formulas -8 % to +6 %, field -11 % to 0 %). The formulas peak at 1.677 Hz (1-11 % below
// the DEM's argmax), the field, made for the 36-sphere layer at h = 100 mm and reused here
// at h = 11.3 mm at equal X/h, at 1.578 Hz (7-13 % below).
TEST_CASE("shipped beam: the harmonic balance's peaks agree with the DEM stepped sine", "[cli][structure][dem][long]") {
  const std::string cases = std::string(PDAMP_SOURCE_DIR) + "/cases/";
  const json out = run_json("frf " + cases + "beam_base_excited.json --compare --dem-points 10 --dem-min-frequency 1.3 "
                            "--dem-max-frequency 2.2 --dem-max-periods 40", kLongTimeLimit_s);
  const json& agreement = out["compare"]["agreement"];
  const json& dem_peaks = out["compare"]["dem"]["peaks"];
  REQUIRE(agreement.size() == 2);
  REQUIRE(dem_peaks.size() == 2);
  double plateau_low_hz = INFINITY, plateau_high_hz = 0.0;
  for (const auto& p : dem_peaks) {
    plateau_low_hz = std::min(plateau_low_hz, p["band_low_hz"].get<double>());
    plateau_high_hz = std::max(plateau_high_hz, p["band_high_hz"].get<double>());
  }
  for (const auto& a : agreement) {
    for (const char* method : {"formulas", "field"}) {
      INFO(a["reference"] << " " << method << ": " << a[method].dump() << "; DEM " << dem_peaks.dump());
      REQUIRE(a[method].is_object());
      CHECK(std::abs(a[method]["magnitude_relative_difference"].get<double>()) < 0.2);
      CHECK(a[method]["frequency_hz"].get<double>() >= plateau_low_hz);
      CHECK(a[method]["frequency_hz"].get<double>() <= plateau_high_hz);
    }
  }
}

// Link: the decay by averaging on the layers' DEM fields against the DEM in the loop, at full
// stiffness as shipped (about a minute): settling time within the required 25% (measured
// +23%). The closed forms settle later (+60% measured): below their rolling onset (0.376 h)
// they see no dissipation where the packed 2 × 4 lattices already collect and collide at
// 0.27-0.29 h (docs/structure_cli.md) — the known bias this checks the sign of.
TEST_CASE("shipped link: decay by averaging on the DEM fields agrees with the DEM in the loop", "[cli][structure][dem][long]") {
  const std::string link = std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_decay.json";
  const json dem = run_json("decay " + link + " --method dem", kLongTimeLimit_s);
  const json field = run_json("decay " + link + " --method field");
  const json formulas = run_json("decay " + link);
  const double t_dem = dem["settling_time_s"].get<double>(), t_field = field["settling_time_s"].get<double>();
  const double t_formulas = formulas["settling_time_s"].get<double>();
  INFO("settling: DEM " << t_dem << " s, field " << t_field << " s, formulas " << t_formulas << " s");
  CHECK(dem["decay"]["energy_error"].get<double>() < 0.01);
  CHECK(std::abs(t_field - t_dem) < 0.25 * t_dem);
  CHECK(t_formulas > t_dem);
}

// The plumbing of a modes task's dem_check (its physics: the placement's DEM check in
// tests/cli/test_placement_command.cpp, and docs/optimizer.md): one mode, one amplitude and
// 4 periods of the 141 Hz mode (a 28 ms decay of the DEM) give one check with both damping
// ratios, its CSV and the points on the backbone plot; bad dem_check blocks are exit 2.
TEST_CASE("pdamp modes runs the task's dem_check: each mode's decay by the loss models and the DEM", "[cli][structure]") {
  const TempDir dir("modes_dem_check");
  const std::string path = edited_shipped_case(dir.path, "free_free_beam_damping.json", [](json& c) {
    c["task"]["dem_check"] = {{"modes", {4}}, {"amplitudes_m", {0.0015}}, {"periods", 4}};
    c["task"].erase("calibration");  // the loss models' prediction (the calibrated one: below)
  });
  const json r = run_json("modes " + path + " -o " + (dir.path / "out").string());
  REQUIRE(r["dem_check"].size() == 1);
  const json& check = r["dem_check"][0];
  CHECK(check["mode"] == 4);
  CHECK(check["damper_amplitude_m"].get<double>() == Approx(0.0015).epsilon(1e-9));
  CHECK(check["predicted_damping_ratio"].get<double>() > 0.0);
  CHECK(check["dem_damping_ratio"].is_number());
  CHECK(check["whole_relative_difference"].is_number());
  CHECK(check["passed"].is_boolean());
  CHECK(r["dem_check_outcome"].is_string());
  // 4 periods of a mode that loses a few per cent a period end far above half: said.
  CHECK_THAT(r["warnings"].dump(), Catch::Contains("above the 0.5 it is measured down to"));
  std::ifstream csv(dir.path / "out" / "dem_check.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header.rfind("mode,frequency_hz,damper_amplitude_m,predicted_damping_ratio,dem_damping_ratio", 0) == 0);
  std::ifstream gp(dir.path / "out" / "backbone.gp");
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  CHECK(script.find("dem_check.csv") != std::string::npos);

  const std::vector<std::pair<std::function<void(json&)>, std::string>> bad = {
      {[](json& c) { c["task"]["dem_check"]["modes"] = {0}; }, "/task/dem_check/modes"},
      {[](json& c) { c["task"]["dem_check"]["modes"] = {3, 3}; }, "/task/dem_check/modes/1"},
      {[](json& c) { c["task"]["dem_check"]["modes"] = {5}; }, "/task/dem_check/modes"},
      {[](json& c) { c["task"]["dem_check"]["amplitudes_m"] = {0.002, 0.001}; }, "/task/dem_check/amplitudes_m"},
      {[](json& c) { c["task"]["dem_check"].erase("amplitudes_m"); }, "/task/dem_check/amplitudes_m"},
      {[](json& c) { c["task"]["dem_check"]["periods"] = 2; }, "/task/dem_check/periods"},
      {[](json& c) { c["task"]["dem_check"]["tolerance_relative"] = 0; }, "/task/dem_check/tolerance_relative"},
  };
  for (const auto& [edit, key] : bad) {
    INFO(key);
    require_one_line_error(run_pdamp({"modes", edited_shipped_case(dir.path, "free_free_beam_damping.json", edit)}), key);
  }
}

// The plumbing of a modes task's calibration (its physics against the DEM decays: the
// [long] test below and docs/optimizer.md): mode 4's bed as a field of 2 strokes x 2
// frequencies (contacts softened 100 times, 1 + 2 periods a point, an approach of one
// ramp period). The field is cached under its key: a second run
// reads it and gives the same backbone; a file of another bed is run again; the other
// modes keep the closed forms; --method formulas takes none.
TEST_CASE("pdamp modes calibrates the bed of the task's modes by DEM steady states, cached under a key",
          "[cli][structure]") {
  const TempDir dir("modes_calibration");
  const auto cache = dir.path / "cache";
  const auto edit = [](json& c) {
    c["task"]["backbone_min_amplitude_m"] = 0.001;
    c["task"]["backbone_max_amplitude_m"] = 0.002;
    c["task"]["backbone_points"] = 5;
    c["task"].erase("dem_check");  // its decays: the test above and the [long] one below
    c["task"]["calibration"] = {{"modes", {4}}, {"strokes_per_decade", 1}, {"stiffness_softening", 0.01}};
    c["dem"] = {{"transient_periods", 1},
                {"analysed_periods", 2},
                {"approach", {{"amplitude_m", 0.002}, {"hold_periods", 0}, {"ramp_periods", 1}}}};
  };
  const std::string path = edited_shipped_case(dir.path, "free_free_beam_damping.json", edit);
  const std::string cache_flag = "--calibration-cache=" + cache.string();
  const json first = run_json({"modes", path, cache_flag, "-o", (dir.path / "first").string()});
  REQUIRE(first["calibration"]["modes"].size() == 1);
  const json& bed = first["calibration"]["modes"][0];
  CHECK(bed["mode"] == 4);
  CHECK(bed["cached"] == false);
  CHECK(bed["amplitude_points"] == 2);
  // The frequencies bracket the mode's with the empty containers: the bed carried whole lowers it.
  const double f4 = first["modes"][3]["frequency_hz"].get<double>();
  CHECK(bed["min_frequency_hz"].get<double>() < f4);
  CHECK(bed["max_frequency_hz"].get<double>() == Approx(1.01 * f4).epsilon(1e-9));
  CHECK(std::filesystem::exists(bed["file"].get<std::string>()));
  CHECK(first["modes"][3]["loss_model"] == "calibrated");
  CHECK(first["modes"][2]["loss_model"] == "formulas");

  const auto backbone = [&](const std::string& out) {
    std::ifstream in(dir.path / out / "backbone_mode4.csv");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const json second = run_json({"modes", path, cache_flag, "-o", (dir.path / "second").string()});
  CHECK(second["calibration"]["modes"][0]["cached"] == true);
  CHECK(second["calibration"]["modes"][0]["key"] == bed["key"]);
  CHECK(backbone("second") == backbone("first"));

  {  // two states at one stroke (the frequencies' motion modes differ): both take the lower branch
    const std::string file = bed["file"].get<std::string>();
    std::ifstream in(file);
    json field = json::parse(in);
    json& table = field["table"];  // rows frequency-major: (f0, X0), (f0, X1), (f1, X0), (f1, X1)
    const std::size_t mode_column = 7, eta_column = 2;
    table[0][mode_column] = "upper_state";
    table[0][eta_column] = 10.0 * table[2][eta_column].get<double>();
    in.close();
    std::ofstream(file) << field.dump();
    const json mixed = run_json({"modes", path, cache_flag, "-o", (dir.path / "mixed").string()});
    const json& strokes = mixed["calibration"]["modes"][0]["lower_branch_strokes_m"];
    REQUIRE(strokes.size() == 1);
    CHECK(strokes[0].get<double>() == Approx(0.001).epsilon(1e-9));
    // Node (f0, X0) took (f1, X0)'s point: the backbone equals that of a field holding it there.
    for (std::size_t c = 2; c < table[0].size(); ++c) table[0][c] = table[2][c];
    std::ofstream(file) << field.dump();
    run_json({"modes", path, cache_flag, "-o", (dir.path / "lower").string()});
    CHECK(backbone("lower") == backbone("mixed"));
    CHECK(backbone("mixed") != backbone("first"));
  }

  {  // a field under this key's name that is another bed's is run again, with a note
    const std::string file = bed["file"].get<std::string>();
    std::ifstream in(file);
    json field = json::parse(in);
    field["provenance"]["case_hash"] = "0123456789abcdef";
    std::ofstream(file) << field.dump();
  }
  const auto again = run_pdamp({"modes", path, cache_flag, "--json"});
  REQUIRE(again.exit_code == 0);
  CHECK(json::parse(again.out)["calibration"]["modes"][0]["cached"] == false);
  CHECK_THAT(again.err, Catch::Contains("is run again: it belongs to another bed (case hash 0123456789abcdef)"));

  CHECK(run_json({"modes", path, "--method", "formulas"})["calibration"].is_null());
  require_one_line_error(run_pdamp({"modes", path, "--method", "formulas", cache_flag}), "--calibration-cache");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> bad = {
      {[](json& c) { c["task"]["calibration"]["modes"] = {0}; }, "/task/calibration/modes"},
      {[](json& c) { c["task"]["calibration"]["strokes_per_decade"] = 0; }, "/task/calibration/strokes_per_decade"},
      {[](json& c) { c["task"]["calibration"]["stiffness_softening"] = 2; }, "/task/calibration/stiffness_softening"},
      {[](json& c) { c["task"]["calibration"].erase("modes"); }, "/task/calibration/modes"},  // no dem_check either
  };
  for (const auto& entry : bad) {
    INFO(entry.second);
    const auto edited = [&](json& c) {
      edit(c);
      entry.first(c);
    };
    require_one_line_error(
        run_pdamp({"modes", edited_shipped_case(dir.path, "free_free_beam_damping.json", edited), cache_flag}),
        entry.second);
  }
}

// The calibrated bed against the DEM in the loop, on the shipped free-free beam's cylinder:
// mode 3 (51.5 Hz, the first bending mode) released at 1.5 mm decays by friction of the
// floating bed, which the closed forms' bouncing orbit misses (docs/optimizer.md, "Damping
// against amplitude"). Here the calibration covers 0.7-1.5 mm only with 10 analysed periods
// a point, and every contact is softened 10 times (calibration and decay alike): at this
// mode and stroke the calibrations at full stiffness or E/10, with 10 or 30 periods, all
// lie within 2 % of the full-stiffness DEM decay (the table in the docs). 15 %: the case's
// tolerance on the mode's whole damping ratio.
TEST_CASE("shipped free-free beam: the calibrated bed predicts the DEM decay of mode 3", "[cli][structure][dem][long]") {
  const TempDir dir("modes_calibration_dem");
  const std::string path = edited_shipped_case(dir.path, "free_free_beam_damping.json", [](json& c) {
    c["task"]["backbone_min_amplitude_m"] = 0.0007;
    c["task"]["backbone_max_amplitude_m"] = 0.0015;
    c["task"]["dem_check"]["modes"] = {3};
    c["task"]["dem_check"]["amplitudes_m"] = {0.0015};
    c["task"]["dem_check"]["periods"] = 40;  // down to half within 35
    c["dem"] = {{"stiffness_softening", 0.1}, {"analysed_periods", 10}};
    c["task"]["calibration"].erase("stiffness_softening");
  });
  const json r = run_json({"modes", path, "--calibration-cache=" + (dir.path / "cache").string()});
  REQUIRE(r["dem_check"].size() == 1);
  const json& check = r["dem_check"][0];
  INFO(check.dump());
  CHECK(std::abs(check["whole_relative_difference"].get<double>()) <= 0.15);
  CHECK(r["dem_check_outcome"] == "passed");
}

// The clearance search's plumbing on the shipped case's bed (its physics: the shipped case's
// DEM check, docs/optimizer.md): three clearances, each bed a field of 2 strokes x 2
// frequencies at E/100 with 1 + 2 periods a point, and the DEM decay of mode 3 from 2 mm for
// the chosen clearance and its neighbours (4 periods: too short to measure down to half, which
// the warnings say). The chosen clearance has the largest objective; the verdict follows
// from the DEM means as documented; a second run reads every bed from the cache.
namespace {

/// The long tests' clearance search: strokes 1-2 mm at 2 points, each bed 2 strokes x 2
/// frequencies at E/100 with 1 + 2 periods a point, decays from 2 mm of 4 periods.
void short_clearance_search(json& c) {
  json& s = c["task"]["clearance_search"];
  s["min_amplitude_m"] = 0.001;
  s["max_amplitude_m"] = 0.002;
  s["amplitude_points"] = 2;
  s["calibration"] = {{"strokes_per_decade", 1}, {"stiffness_softening", 0.01}};
  s["verify"] = {{"amplitudes_m", {0.002}}, {"periods", 4}};
  json& dem = c["dem"];
  dem["transient_periods"] = 1;
  dem["analysed_periods"] = 2;
  dem["approach"] = {{"amplitude_m", 0.002}, {"hold_periods", 0}, {"ramp_periods", 1}};
}

}  // namespace

TEST_CASE("pdamp modes searches the clearance for a mode's damping on calibrated beds", "[cli][structure][dem][long]") {
  const TempDir dir("modes_clearance_search");
  const auto cache = dir.path / "cache";
  const std::string path = edited_shipped_case(dir.path, "free_free_beam_mode_clearance.json", [](json& c) {
    short_clearance_search(c);
    c["task"]["clearance_search"]["clearances_m"] = {0.002, 0.008, 0.016};
  });
  const std::string cache_flag = "--calibration-cache=" + cache.string();
  const json r = run_json({"modes", path, cache_flag, "-o", (dir.path / "out").string()});
  const json& s = r["clearance_search"];
  REQUIRE(s.is_object());
  CHECK(s["mode"] == 3);
  REQUIRE(s["candidates"].size() == 3);
  std::size_t best = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    const json& candidate = s["candidates"][k];
    CHECK(candidate["added_damping_ratios"].size() == 2);
    const auto& zeta = candidate["added_damping_ratios"];
    CHECK(candidate["objective"].get<double>() == Approx(0.5 * (zeta[0].get<double>() + zeta[1].get<double>())));
    CHECK(candidate["calibration"]["cached"] == false);
    // The clearance is the length beyond the staggered lattice: every inner length minus h is that extent.
    CHECK(candidate["inner_length_m"].get<double>() - candidate["clearance_m"].get<double>() ==
          Approx(20.0 * std::sqrt(2.0) * 0.0025 + 0.005).epsilon(1e-9));
    if (candidate["objective"].get<double>() > s["candidates"][best]["objective"].get<double>()) best = k;
  }
  CHECK(s["chosen_clearance_m"] == s["candidates"][best]["clearance_m"]);
  // The chosen clearance and its neighbours in the list were decayed by the DEM.
  for (std::size_t k = 0; k < 3; ++k)
    CHECK(s["candidates"][k]["dem_check"].size() == (k + 1 >= best && k <= best + 1 ? 1u : 0u));
  const json& v = s["verification"];
  CHECK(v["chosen_agrees"] == s["candidates"][best]["checks_passed"]);
  CHECK(v["outcome"] == (v["chosen_agrees"].get<bool>() && v["ranking_agrees"].get<bool>() ? "passed" : "failed"));
  CHECK_THAT(r["warnings"].dump(), Catch::Contains("clearance search, h = "));
  for (const char* file : {"clearance_search.csv", "clearance_search_checks.csv", "clearance_search.gp"})
    CHECK(std::filesystem::exists(dir.path / "out" / file));
  std::ifstream csv(dir.path / "out" / "clearance_search.csv");
  std::string header;
  std::getline(csv, header);
  CHECK(header.rfind("clearance_m,inner_length_m,wall_layer_thickness_m,layer_tip_strain,buildable,objective,"
                     "predicted_check_mean,dem_check_mean,added_damping_ratio_at_",
                     0) == 0);

  const json again = run_json({"modes", path, cache_flag});
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(again["clearance_search"]["candidates"][k]["calibration"]["cached"] == true);
    CHECK(again["clearance_search"]["candidates"][k]["objective"] == s["candidates"][k]["objective"]);
  }
}

// The search over a buffered wall's lining on the shipped buffered case's bed (its physics: that
// case's DEM check, docs/optimizer.md), at the long test's settings above: linings of 1 and 2 mm
// with clearances of 4 and 8 mm. The buffer's design impact strains the 1 mm lining to 0.45
// (formulas::layer_tip_strain, checked against the sizing there), beyond the allowable 0.3:
// those two candidates are not run, never chosen, never checked; the verification takes the
// chosen candidate's clearance neighbour only. Each inner length is the lattice, both linings
// and h.
TEST_CASE("pdamp modes searches a buffered wall's lining with the clearance, building only linings that survive",
          "[cli][structure][dem][long]") {
  const TempDir dir("modes_lining_search");
  const std::string path = edited_shipped_case(dir.path, "free_free_beam_buffered_clearance.json", [](json& c) {
    short_clearance_search(c);
    c["task"]["clearance_search"]["clearances_m"] = {0.004, 0.008};
    c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.001, 0.002};
  });
  const json r = run_json({"modes", path, "--calibration-cache=" + (dir.path / "cache").string(), "-o",
                           (dir.path / "out").string()});
  const json& s = r["clearance_search"];
  REQUIRE(s["candidates"].size() == 4);
  const double extent = 20.0 * std::sqrt(2.0) * 0.0025 + 0.005;
  for (std::size_t k = 0; k < 4; ++k) {
    const json& candidate = s["candidates"][k];
    INFO(candidate.dump());
    const double t = k < 2 ? 0.001 : 0.002, h = k % 2 == 0 ? 0.004 : 0.008;
    CHECK(candidate["wall_layer_thickness_m"] == t);
    CHECK(candidate["clearance_m"] == h);
    CHECK(candidate["inner_length_m"].get<double>() == Approx(extent + 2.0 * t + h).epsilon(1e-9));
    CHECK(candidate["buildable"] == (t == 0.002));
    CHECK((t == 0.002 ? candidate["layer_tip_strain"].get<double>() < 0.3 : candidate["layer_tip_strain"].get<double>() > 0.3));
    CHECK(candidate["objective"].is_null() == (t == 0.001));
    CHECK(candidate["added_damping_ratios"].size() == (t == 0.002 ? 2u : 0u));
    CHECK(candidate["dem_check"].size() == (t == 0.002 ? 1u : 0u));
  }
  CHECK(s["chosen_wall_layer_thickness_m"] == 0.002);
  const std::size_t best =
      s["candidates"][2]["objective"].get<double>() >= s["candidates"][3]["objective"].get<double>() ? 2 : 3;
  CHECK(s["chosen_clearance_m"] == s["candidates"][best]["clearance_m"]);
  CHECK_THAT(r["warnings"].dump(), Catch::Contains("lining 1 mm: its tip strain"));
  std::ifstream gp(dir.path / "out" / "clearance_search.gp");
  const std::string script((std::istreambuf_iterator<char>(gp)), std::istreambuf_iterator<char>());
  CHECK_THAT(script, Catch::Contains("lining 2 mm") && !Catch::Contains("lining 1 mm"));
}

TEST_CASE("a clearance_search and a staggered lattice refuse bad keys with exit 2", "[cli][structure]") {
  const TempDir dir("modes_clearance_search_bad");
  const std::vector<std::pair<std::function<void(json&)>, std::string>> bad = {
      {[](json& c) { c["task"]["clearance_search"]["mode"] = 0; }, "/task/clearance_search/mode"},
      {[](json& c) { c["task"]["clearance_search"]["mode"] = 2.5; }, "/task/clearance_search/mode"},
      {[](json& c) { c["task"]["clearance_search"]["max_amplitude_m"] = 0.0004; }, "/task/clearance_search/max_amplitude_m"},
      {[](json& c) { c["task"]["clearance_search"]["amplitude_points"] = 1; }, "/task/clearance_search/amplitude_points"},
      {[](json& c) { c["task"]["clearance_search"]["objective"] = "best"; }, "/task/clearance_search/objective"},
      {[](json& c) {
         json& s = c["task"]["clearance_search"];
         s.erase("clearances_m");
         s["min_clearance_m"] = 0.004;
         s["max_clearance_m"] = 0.002;
       },
       "/task/clearance_search/max_clearance_m"},
      {[](json& c) {
         json& s = c["task"]["clearance_search"];
         s.erase("clearances_m");
         s["min_clearance_m"] = 0.002;
         s["max_clearance_m"] = 0.004;
         s["candidates"] = 21;
       },
       "/task/clearance_search/candidates"},
      {[](json& c) { c["task"]["clearance_search"]["min_clearance_m"] = 0.002; }, "/task/clearance_search/min_clearance_m"},
      {[](json& c) { c["task"]["clearance_search"]["clearances_m"] = {0.004, 0.002}; }, "/task/clearance_search/clearances_m"},
      {[](json& c) { c["task"]["clearance_search"]["verify"]["forced_start_periods"] = -1; },
       "/task/clearance_search/verify/forced_start_periods"},
      {[](json& c) { c["task"]["clearance_search"]["verify"]["amplitudes_m"] = {0.0008, 0.002}; },
       "/task/clearance_search/verify/amplitudes_m/0"},
      {[](json& c) { c["task"]["clearance_search"]["verify"]["amplitudes_m"] = {0.002, 0.005}; },
       "/task/clearance_search/verify/amplitudes_m/1"},
      {[](json& c) { c["task"]["clearance_search"]["calibration"]["strokes_per_decade"] = 0; },
       "/task/clearance_search/calibration/strokes_per_decade"},
      {[](json& c) { c["task"]["clearance_search"]["unknown"] = 1; }, "/task/clearance_search/unknown"},
      {[](json& c) { c["dampers"][0]["layers"][0]["particles"]["lattice"] = "dense"; },
       "/dampers/0/layers/0/particles/lattice"},
      {[](json& c) { c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.001}; },
       "/task/clearance_search/wall_layer_thicknesses_m"},  // the layer has no wall_layer
      // The staggered lattice of 260 spheres is 75.7 mm long.
      {[](json& c) { c["dampers"][0]["layers"][0]["container"]["inner_length_m"] = 0.075; }, "/dampers/0/layers/0"},
  };
  for (const auto& [edit, key] : bad) {
    INFO(key);
    require_one_line_error(run_pdamp({"modes", edited_shipped_case(dir.path, "free_free_beam_mode_clearance.json", edit)}),
                           key);
  }
  // The buffered case: linings out of order, too many pairs, and linings none of which survive
  // the buffer's design impact (refused before any DEM work).
  const std::vector<std::pair<std::function<void(json&)>, std::string>> lining = {
      {[](json& c) { c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.002, 0.001}; },
       "/task/clearance_search/wall_layer_thicknesses_m"},
      {[](json& c) { c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.001, 0.002, 0.003, 0.004, 0.005, 0.006, 0.007}; },
       "/task/clearance_search/wall_layer_thicknesses_m"},
      {[](json& c) { c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.0005, 0.001}; },
       "/task/clearance_search/wall_layer_thicknesses_m"},
      // A lining that leaves the container no room: the search names that lining.
      {[](json& c) { c["task"]["clearance_search"]["wall_layer_thicknesses_m"] = {0.002, 0.05}; },
       "/task/clearance_search/wall_layer_thicknesses_m/1"},
      {[](json& c) { c["dampers"][0]["layers"][0]["wall_layer"]["thickness_m"] = 0.05; },
       "/dampers/0/layers/0/wall_layer/thickness_m"},
  };
  for (const auto& [edit, key] : lining) {
    INFO(key);
    require_one_line_error(
        run_pdamp({"modes", edited_shipped_case(dir.path, "free_free_beam_buffered_clearance.json", edit)}), key);
  }
}
