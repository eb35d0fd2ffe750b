// Distributed sweeps (docs/distributed.md). The unit part runs in every
// build; the [mpi] part exists in an MPI build (-DPDAMP_MPI=ON) and runs pdamp under
// mpirun with 2 ranks on this machine (loopback; CTest label `mpi`, run by .ci/run).
#include <signal.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

bool mpi_build() { return run_pdamp(std::vector<std::string>{"--help"}).out.find("(MPI build)") != std::string::npos; }

}  // namespace

// A build without MPI started by mpirun as 2 processes would have both write the same
// files: it refuses (the launcher's variables are what mpirun sets in each process).
TEST_CASE("a pdamp built without MPI refuses to run as several mpirun processes", "[cli]") {
  if (mpi_build()) {
    WARN("an MPI build: its launch is tested under mpirun by the [mpi] cases");
    return;
  }
  RunOptions two_ranks;
  two_ranks.environment = {"OMPI_COMM_WORLD_SIZE=2", "OMPI_COMM_WORLD_RANK=0"};
  require_one_line_error(run_pdamp({"optimum", "--model", "rolling", "--clearance", "0.01"}, two_ranks),
                         "built without MPI");
  two_ranks.environment = {"OMPI_COMM_WORLD_SIZE=2", "OMPI_COMM_WORLD_RANK=1"};
  const auto other = run_pdamp({"optimum", "--model", "rolling", "--clearance", "0.01"}, two_ranks);
  CHECK(other.exit_code == 2);
  CHECK(other.err.empty());  // rank 0 says it once
  two_ranks.environment = {"OMPI_COMM_WORLD_SIZE=1", "OMPI_COMM_WORLD_RANK=0"};
  CHECK(run_pdamp({"optimum", "--model", "rolling", "--clearance", "0.01"}, two_ranks).exit_code == 0);
}

#ifdef PDAMP_MPIEXEC
namespace {

/// mpirun -n RANKS pdamp ARGS on this machine: more ranks than cores allowed, as root too
/// (CI runs as root; Open MPI refuses root unless told).
RunResult run_mpi(int ranks, const std::vector<std::string>& args, RunOptions options = {}) {
  std::vector<std::string> argv{PDAMP_MPIEXEC, "-n", std::to_string(ranks), "--oversubscribe"};
  if (::geteuid() == 0) argv.push_back("--allow-run-as-root");
  argv.push_back(PDAMP_BINARY);
  argv.insert(argv.end(), args.begin(), args.end());
  // A hang guard, not a timing: about ten times the longest idle run here (under a minute:
  // the killed-and-resumed DEM field), so a loaded machine does not fail the test.
  if (options.time_limit_s > 600.0) options.time_limit_s = 600.0;
  return run_program(argv, options);
}

json parse_result(const RunResult& r) {
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return json::parse(r.out);
}

/// field.json without its creation time.
json field_values(const fs::path& dir) {
  std::ifstream in(dir / "field.json");
  json field = json::parse(in);
  field["provenance"].erase("created_utc");
  return field;
}

/// The shipped 36-sphere case on a 2 x 4 grid, short runs (about 0.5 s a point: long
/// enough for the kill below to land mid-sweep, short enough for CI).
std::string small_dem_field(const TempDir& dir) {
  return edited_case((dir.path.filename().string() + ".json"), [](json& c) {
    c["field"] = {{"axis0", {{"min", 1.5}, {"max", 2.5}, {"count", 2}}},
                  {"axis1", {{"min", 0.015}, {"max", 0.07}, {"count", 4}}},
                  {"threads", 1}};
    c["dem"]["transient_periods"] = 1;
    c["dem"]["analysed_periods"] = 3;
  });
}

std::size_t lines_in(const fs::path& file) {
  std::ifstream in(file);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

}  // namespace

// Reference: the serial sweep of the same case. Each point is one deterministic DEM run
// from the same inputs (sent as raw doubles), so the fields agree to the bit, not to a tolerance.
TEST_CASE("a DEM field on 2 ranks equals the serial one point for point, and a killed run resumes", "[mpi]") {
  const TempDir dir("mpi_field");
  const std::string c = small_dem_field(dir);
  const auto serial = run_pdamp({"field", c, "--source", "dem", "-o", (dir.path / "serial").string()});
  REQUIRE(serial.exit_code == 0);

  const json spread = parse_result(run_mpi(2, {"field", c, "--source", "dem", "-o", (dir.path / "mpi").string(), "--json"}));
  CHECK(field_values(dir.path / "mpi") == field_values(dir.path / "serial"));
  REQUIRE(spread.contains("mpi"));
  CHECK(spread["mpi"]["ranks"] == 2);
  const auto& points = spread["mpi"]["points"];
  CHECK(points[0].get<int>() + points[1].get<int>() == 8);
  CHECK(points[1].get<int>() >= 1);  // rank 1 took part
  for (const auto& busy : spread["mpi"]["busy_fraction"]) CHECK((busy.get<double>() > 0.0 && busy.get<double>() <= 1.0));

  // Killed (SIGTERM to mpirun, which passes it on) once 2 points are saved, then rerun:
  // it resumes from the log and ends with the same field.
  const fs::path killed = dir.path / "killed";
  RunOptions kill_midway;
  kill_midway.while_running = [&](pid_t pid) {
    for (int i = 0; i < 3000 && lines_in(killed / "field_sweep.jsonl") < 3; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ::kill(-pid, SIGTERM);
  };
  const auto first = run_mpi(2, {"field", c, "--source", "dem", "-o", killed.string()}, kill_midway);
  CHECK(first.exit_code != 0);
  CHECK_FALSE(fs::exists(killed / "field.json"));
  const std::size_t saved = lines_in(killed / "field_sweep.jsonl") - 1;
  REQUIRE(saved >= 2);
  const json resumed = parse_result(run_mpi(2, {"field", c, "--source", "dem", "-o", killed.string(), "--json"}));
  CHECK_THAT(resumed["sweep"].get<std::string>(), Catch::Contains(std::to_string(saved) + " resumed"));
  CHECK(field_values(killed) == field_values(dir.path / "serial"));
}

TEST_CASE("a sensitivity study on 2 ranks equals the serial one", "[mpi]") {
  const TempDir dir("mpi_sensitivity");
  const std::string c = case_path("low_intensity_36_spheres.json");
  const json serial = parse_result(run_pdamp({"sensitivity", c, "--source", "formulas", "-o", (dir.path / "s").string(), "--json"}));
  const json spread = parse_result(run_mpi(2, {"sensitivity", c, "--source", "formulas", "-o", (dir.path / "m").string(), "--json"}));
  CHECK(spread["rows"] == serial["rows"]);
  CHECK(spread["mpi"]["points"][1].get<int>() >= 1);
}

// The stepped sine's two directions (up, down) are two tasks: serially they run on two
// threads, under mpirun on two ranks, each the same deterministic co-simulation from the
// same inputs, so the points agree to the bit (frf_dem.csv has no wall times).
TEST_CASE("a stepped-sine DEM FRF on 2 ranks equals the serial one", "[mpi]") {
  const TempDir dir("mpi_frf");
  const std::string c = std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/one_mode_dem_frf.json";
  const auto frf = [&](const std::string& out) {
    return std::vector<std::string>{"frf", c, "--method", "dem", "--dem-points", "3", "-o", (dir.path / out).string(), "--json"};
  };
  const json serial = parse_result(run_pdamp(frf("serial")));
  const auto spread = run_mpi(2, frf("mpi"));
  const json result = parse_result(spread);
  CHECK_THAT(spread.err, Catch::Contains("2 sweep direction(s) over 2 MPI ranks"));
  CHECK(slurp(dir.path / "mpi" / "frf_dem.csv") == slurp(dir.path / "serial" / "frf_dem.csv"));
  REQUIRE(result["frf"]["points"].size() == 6);
  CHECK(result["peaks"] == serial["peaks"]);
  CHECK(result["mpi"]["points"] == json::array({1, 1}));  // a direction each
  CHECK_FALSE(serial.contains("mpi"));
}

// The optimisation runs on every rank (NLopt's seed is fixed), each rank checks that it chose
// rank 0's design, and the chosen and baseline DEM decays run on the two ranks: the same
// deterministic runs as the serial two threads, so verify_decay.csv agrees to the bit.
TEST_CASE("the DEM verification of an optimisation on 2 ranks equals the serial one", "[mpi]") {
  const TempDir dir("mpi_verify");
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  json edited = json::parse(in);
  edited["task"]["global_evaluations"] = 30;
  edited["task"]["max_evaluations"] = 120;
  edited["task"]["verify"] = {{"duration_s", 0.7}, {"stiffness_softening", 1e-4}, {"tolerance_relative", 0.3}};
  edited["task"].erase("calibration");
  const fs::path c = dir.path / "case.json";
  std::ofstream(c) << edited.dump(2);
  const auto optimize = [&](const std::string& out) {
    return std::vector<std::string>{"optimize", c.string(), "-o", (dir.path / out).string(), "--json"};
  };
  const json serial = parse_result(run_pdamp(optimize("serial")));
  const json spread = parse_result(run_mpi(2, optimize("mpi")));
  CHECK(slurp(dir.path / "mpi" / "verify_decay.csv") == slurp(dir.path / "serial" / "verify_decay.csv"));
  for (const char* name : {"chosen", "baseline"}) {
    json a = spread["verification"]["designs"][name], b = serial["verification"]["designs"][name];
    for (json* d : {&a, &b}) {
      (*d)["dem"].erase("solve_time_s");
      (*d)["softening_check"]["dem"].erase("solve_time_s");
    }
    CHECK(a == b);
  }
  CHECK(spread["design"] == serial["design"]);
  // Four decays (each design at the judged softening and ten times stiffer), rank 1 taking
  // the first (how many more it takes depends on the machine's load: rank 0 takes whichever
  // job comes up while rank 1 is busy).
  const auto& points = spread["verification"]["mpi"]["points"];
  CHECK(points[0].get<int>() + points[1].get<int>() == 4);
  CHECK(points[1].get<int>() >= 1);
}

namespace {

/// Lines of `text` holding both `what` and `also`.
std::size_t lines_with(const std::string& text, const std::string& what, const std::string& also) {
  std::istringstream in(text);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    n += line.find(what) != std::string::npos && line.find(also) != std::string::npos ? 1 : 0;
  return n;
}

/// `value` without the keys of wall times and paths, which differ between two runs.
json without_times(json value) {
  if (value.is_object()) {
    for (const char* key : {"solve_time_s", "wall_time_s", "global_stage_s", "local_stage_s", "report", "file",
                            "cache_dir", "outputs", "mpi"})
      value.erase(key);
  }
  if (value.is_structured())
    for (auto& item : value) item = without_times(item);
  return value;
}

}  // namespace

// The design loop on calibrated beds: the beds' calibration, each round's verification and
// the recalibration are batches of the one executor, spread over the ranks; between them
// every rank optimises on the beds rank 0 shares at each batch's end. Each bed's decay and
// each verification decay is one deterministic DEM run from the same inputs, so the outcome
// equals the serial run's to the bit. Short runs (1.5 s decays), and a tolerance no decay
// meets, so that round 1 fails and the loop recalibrates (as the tasks test of the loop).
TEST_CASE("a filling-ratio optimisation on calibrated beds on 2 ranks equals the serial one", "[mpi]") {
  const TempDir dir("mpi_calibrated");
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  json edited = json::parse(in);
  edited["task"]["calibration"] = {{"duration_s", 1.5}, {"stiffness_softening", 1e-3}};
  edited["task"]["verify"] = {{"duration_s", 1.5}, {"stiffness_softening", 1e-3}, {"softening_check", false},
                              {"tolerance_relative", 1e-6}, {"rounds", 2}};
  const fs::path c = dir.path / "case.json";
  std::ofstream(c) << edited.dump(2);
  // A cache each: the second run would otherwise read every bed the first calibrated.
  const auto optimize = [&](const std::string& out) {
    return std::vector<std::string>{"optimize", c.string(), "--calibration-cache", (dir.path / (out + "_cache")).string(),
                                    "-o", (dir.path / out).string(), "--json"};
  };
  const auto serial_run = run_pdamp(optimize("serial"));
  const json serial = parse_result(serial_run);
  const auto spread_run = run_mpi(2, optimize("mpi"));
  const json spread = parse_result(spread_run);
  for (const char* file : {"designs.csv", "verify_decay.csv", "decay_compare.csv"}) {
    INFO(file);
    CHECK(slurp(dir.path / "mpi" / file) == slurp(dir.path / "serial" / file));
  }
  REQUIRE(serial["design_loop"]["rounds"].size() == 2);
  CHECK(spread["calibration"]["runs"] == serial["calibration"]["runs"]);  // 11 beds, 2 recalibrated
  CHECK(without_times(spread) == without_times(serial));
  // Each bed that runs notes its estimate where it runs: rank 1's are silent, so rank 0
  // noted fewer than the serial run did (rank 1 calibrated some beds).
  const auto bed_notes = [](const RunResult& r) {
    return lines_with(r.err, "pdamp optimize: calibration (", "particle-steps");
  };
  const std::size_t serial_beds = bed_notes(serial_run), spread_beds = bed_notes(spread_run);
  CHECK(serial_beds == serial["calibration"]["runs"].get<std::size_t>());
  CHECK(spread_beds < serial_beds);
  CHECK(spread_beds >= 1);
}

TEST_CASE("under mpirun, bad input is one error line and a command without a sweep runs once", "[mpi]") {
  const TempDir dir("mpi_errors");
  const std::string bad = edited_case("mpi_bad.json", [](json& c) { c["field"]["threads"] = 0; });
  const auto r = run_mpi(2, {"field", bad, "--source", "dem", "-o", dir.path.string()});
  INFO(r.err);
  CHECK(r.exit_code == 2);
  CHECK(r.out.empty());
  std::size_t errors = 0;
  for (std::size_t at = r.err.find("pdamp: error:"); at != std::string::npos; at = r.err.find("pdamp: error:", at + 1)) ++errors;
  CHECK(errors == 1);  // the other rank is silent
  CHECK_THAT(r.err, Catch::Contains("threads"));

  const auto once = run_mpi(2, {"optimum", "--model", "rolling", "--clearance", "0.01", "--json"});
  REQUIRE(once.exit_code == 0);
  CHECK(json::parse(once.out)["clearance_m"] == 0.01);  // one JSON document: rank 1 printed nothing
  // A command that spreads only its DEM part (frf) runs its harmonic balance once.
  const auto frf = run_mpi(2, {"frf", std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/one_mode_dem_frf.json", "--json"});
  INFO(frf.err);
  REQUIRE(frf.exit_code == 0);
  CHECK(json::parse(frf.out)["method"] == "formulas");
}
#endif
