// Checkpointed DEM runs from the command line: pdamp decay --method dem killed
// mid-way and resumed gives the uninterrupted run's result to the bit; checkpoints of another
// case or settings, damaged ones and misplaced flags are exit 2 naming the file or flag.
#include <catch2/catch.hpp>

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

/// The shipped link decay, 6 s, contacts softened 1e-3 (about 1 s of work on this machine).
std::string short_decay(const TempDir& dir, double duration_s = 6.0) {
  std::ifstream in(case_path("manipulator_link_decay.json"));
  json c = json::parse(in);
  c["task"]["duration_s"] = duration_s;
  c["dem"] = {{"stiffness_softening", 1e-3}};
  const fs::path path = dir.path / ("link_" + std::to_string(duration_s) + ".json");
  std::ofstream(path) << c.dump(2);
  return path.string();
}

json without_timings(json j) {
  for (const char* key : {"solve_time_s", "file", "outputs", "wall_time_s", "plot"}) j.erase(key);
  for (auto& [key, value] : j.items())
    if (value.is_object()) value = without_timings(value);
  return j;
}

}  // namespace

// Reference: the uninterrupted run of the same command. SIGINT arrives once the first
// checkpoint exists (--checkpoint-interval 0: one after every segment); pdamp writes one more
// at the segment's end and ends by the signal; --resume completes the run, removes the
// checkpoint, and its decay_dem.csv and result equal the uninterrupted run's (times,
// displacements, settling, energy ledger).
TEST_CASE("pdamp decay --method dem killed mid-way and resumed equals the uninterrupted run", "[cli][cosimulation]") {
  const TempDir dir("checkpoint_resume");
  const std::string c = short_decay(dir);
  const fs::path whole = dir.path / "whole", parts = dir.path / "parts";
  const auto reference = run_pdamp({"decay", c, "--method", "dem", "-o", whole.string(), "--json"});
  INFO(reference.err);
  REQUIRE(reference.exit_code == 0);

  RunOptions options;
  options.while_running = [&](pid_t pid) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(parts / "decay_dem.checkpoint") && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGINT);
  };
  const auto killed = run_pdamp({"decay", c, "--method", "dem", "-o", parts.string(), "--json", "--checkpoint-interval",
                                 "0"},
                                options);
  INFO(killed.err);
  REQUIRE(killed.exit_code == 128 + SIGINT);
  CHECK_THAT(killed.err, Catch::Contains("--resume to continue"));
  REQUIRE(fs::exists(parts / "decay_dem.checkpoint"));
  CHECK_FALSE(fs::exists(parts / "decay.json"));

  const auto resumed = run_pdamp({"decay", c, "--method", "dem", "-o", parts.string(), "--json", "--resume"});
  INFO(resumed.err);
  REQUIRE(resumed.exit_code == 0);
  CHECK_THAT(resumed.err, Catch::Contains("resuming at t = "));
  CHECK_FALSE(fs::exists(parts / "decay_dem.checkpoint"));
  CHECK(slurp(whole / "decay_dem.csv") == slurp(parts / "decay_dem.csv"));
  CHECK(without_timings(json::parse(reference.out)) == without_timings(json::parse(resumed.out)));
}

TEST_CASE("a checkpoint of another case, settings or a damaged one is refused naming the file", "[cli][cosimulation]") {
  const TempDir dir("checkpoint_refusals");
  const std::string c = short_decay(dir, 4.0);
  const fs::path out = dir.path / "out";
  RunOptions options;
  options.while_running = [&](pid_t pid) {
    while (!fs::exists(out / "decay_dem.checkpoint")) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGTERM);
  };
  const auto killed = run_pdamp({"decay", c, "--method", "dem", "-o", out.string(), "--checkpoint-interval", "0"}, options);
  REQUIRE(killed.exit_code == 128 + SIGTERM);
  const std::string checkpoint = slurp(out / "decay_dem.checkpoint");

  SECTION("another duration") {
    require_one_line_error(run_pdamp({"decay", short_decay(dir, 5.0), "--method", "dem", "-o", out.string(), "--resume"}),
                           "decay_dem.checkpoint: /settings");
  }
  SECTION("another bed") {
    std::ifstream in(c);
    json other = json::parse(in);
    other["dem"]["contact"] = {{"friction", 0.2}};
    const fs::path path = dir.path / "other.json";
    std::ofstream(path) << other.dump(2);
    require_one_line_error(run_pdamp({"decay", path.string(), "--method", "dem", "-o", out.string(), "--resume"}),
                           "decay_dem.checkpoint: /case_hash");
  }
  SECTION("a damaged checkpoint") {
    std::string bad = checkpoint;
    bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x40);
    std::ofstream(out / "decay_dem.checkpoint", std::ios::binary) << bad;
    require_one_line_error(run_pdamp({"decay", c, "--method", "dem", "-o", out.string(), "--resume"}),
                           "/payload_fnv1a64");
  }
  SECTION("a truncated checkpoint") {
    std::ofstream(out / "decay_dem.checkpoint", std::ios::binary) << checkpoint.substr(0, checkpoint.size() / 3);
    require_one_line_error(run_pdamp({"decay", c, "--method", "dem", "-o", out.string(), "--resume"}), "truncated");
  }
  SECTION("no checkpoint, no folder, another method") {
    fs::remove(out / "decay_dem.checkpoint");
    require_one_line_error(run_pdamp({"decay", c, "--method", "dem", "-o", out.string(), "--resume"}),
                           "--resume: no checkpoint");
    require_one_line_error(run_pdamp({"decay", c, "--method", "dem", "--resume"}), "--resume: needs -o DIR");
    require_one_line_error(run_pdamp({"decay", c, "--method", "formulas", "-o", out.string(), "--resume"}),
                           "--resume: applies to --method dem");
    require_one_line_error(run_pdamp({"decay", c, "--method", "dem", "-o", out.string(), "--checkpoint-interval", "-1"}),
                           "--checkpoint-interval");
  }
}

// Reference: the uninterrupted verification of the same (cut short) optimisation. Both DEM
// decays checkpoint on their own (verify_chosen.checkpoint, verify_baseline.checkpoint) and
// stop at the signal; --resume continues each (or reruns one that had completed) and the
// verification equals the uninterrupted one.
TEST_CASE("a killed DEM verification resumes both designs and equals the uninterrupted one", "[cli][optimizer]") {
  const TempDir dir("checkpoint_verify");
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  json c = json::parse(in);
  c["task"]["global_evaluations"] = 30;
  c["task"]["max_evaluations"] = 120;
  c["task"]["verify"] = {{"duration_s", 1.0}, {"stiffness_softening", 1e-4}};
  c["task"].erase("calibration");
  const fs::path path = dir.path / "case.json";
  std::ofstream(path) << c.dump(2);
  const fs::path whole = dir.path / "whole", parts = dir.path / "parts";
  const auto reference = run_pdamp({"optimize", path.string(), "-o", whole.string(), "--json"});
  INFO(reference.err);
  REQUIRE(reference.exit_code == 0);

  RunOptions options;
  options.while_running = [&](pid_t pid) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(parts / "verify_chosen.checkpoint") && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGINT);
  };
  const auto killed =
      run_pdamp({"optimize", path.string(), "-o", parts.string(), "--json", "--checkpoint-interval", "0"}, options);
  INFO(killed.err);
  REQUIRE(killed.exit_code == 128 + SIGINT);
  REQUIRE(fs::exists(parts / "verify_chosen.checkpoint"));
  const auto resumed = run_pdamp({"optimize", path.string(), "-o", parts.string(), "--json", "--resume"});
  INFO(resumed.err);
  REQUIRE(resumed.exit_code == 0);
  CHECK_THAT(resumed.err, Catch::Contains("pdamp optimize --verify (chosen): resuming at t = "));
  CHECK_FALSE(fs::exists(parts / "verify_chosen.checkpoint"));
  CHECK_FALSE(fs::exists(parts / "verify_baseline.checkpoint"));
  const json a = without_timings(json::parse(reference.out)), b = without_timings(json::parse(resumed.out));
  CHECK(a["verification"] == b["verification"]);
  CHECK(slurp(whole / "verify_decay.csv") == slurp(parts / "verify_decay.csv"));
}

// Reference: the uninterrupted pdamp dem of the shipped case. Its checkpoints come at period
// ends (--checkpoint-interval 0: every one); SIGTERM after the first, --resume to the end:
// the same time series and result (η*, its error, apparent mass, energy balance, mode).
TEST_CASE("pdamp dem killed at a checkpoint and resumed equals the uninterrupted run", "[cli][dem_reference]") {
  const TempDir dir("checkpoint_dem");
  const std::string c = case_path("low_intensity_36_spheres.json");
  const fs::path whole = dir.path / "whole", parts = dir.path / "parts";
  const auto reference = run_pdamp({"dem", c, "-o", whole.string(), "--json"});
  INFO(reference.err);
  REQUIRE(reference.exit_code == 0);
  RunOptions options;
  options.while_running = [&](pid_t pid) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(parts / "dem.checkpoint") && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ::kill(pid, SIGTERM);
  };
  const auto killed = run_pdamp({"dem", c, "-o", parts.string(), "--json", "--checkpoint-interval", "0"}, options);
  INFO(killed.err);
  REQUIRE(killed.exit_code == 128 + SIGTERM);
  CHECK_THAT(killed.err, Catch::Contains("wrote " + (parts / "dem.checkpoint").string()));
  const auto resumed = run_pdamp({"dem", c, "-o", parts.string(), "--json", "--resume"});
  INFO(resumed.err);
  REQUIRE(resumed.exit_code == 0);
  CHECK_FALSE(fs::exists(parts / "dem.checkpoint"));
  CHECK(slurp(whole / "time_series.csv") == slurp(parts / "time_series.csv"));
  json a = json::parse(reference.out), b = json::parse(resumed.out);
  for (json* j : {&a, &b})
    for (const char* key : {"files", "particle_steps_per_s", "run", "wall_time_s"}) j->erase(key);
  CHECK(a == b);
  // Another stroke is another run: its checkpoint is not this one's.
  const auto again = run_pdamp({"dem", c, "-o", parts.string(), "--checkpoint-interval", "0"}, options);
  REQUIRE(again.exit_code == 128 + SIGTERM);
  require_one_line_error(run_pdamp({"dem", c, "--amplitude", "0.05", "-o", parts.string(), "--resume"}),
                         "dem.checkpoint: /settings");
}

// The ending of a checkpointed DEM run: SIGTERM once the run is complete (before any file is
// staged), once the set is staged (before the first rename), and once it is committed (before
// the checkpoint goes). Each time the results are committed whole, the checkpoint is gone
// (nothing is left to resume), and pdamp says the results are complete and ends by the
// signal. Before, a signal before the commit abandoned the staged results, and a run shorter
// than the checkpoint interval had no checkpoint either: the run was lost.
TEST_CASE("a signal at every point of a DEM run's ending loses nothing", "[cli][cosimulation]") {
  const TempDir dir("ending_signals");
  const std::string decay_case = short_decay(dir, 4.0);
  const fs::path reference = dir.path / "reference";
  REQUIRE(run_pdamp({"decay", decay_case, "--method", "dem", "-o", reference.string()}).exit_code == 0);
  struct Command {
    std::vector<std::string> args;
    std::string result, checkpoint;
  };
  const std::vector<Command> commands = {
      {{"decay", decay_case, "--method", "dem"}, "decay.json", "decay_dem.checkpoint"},
      {{"dem", case_path("low_intensity_36_spheres.json"), "--periods", "2"}, "summary.json", "dem.checkpoint"}};
  for (const auto& command : commands) {
    for (const std::string point : {"run-ended", "commit", "committed"}) {
      INFO(command.args.front() << " at " << point);
      const fs::path out = dir.path / (command.args.front() + "_" + point);
      const fs::path marker = dir.path / (command.args.front() + "_" + point + ".marker");
      RunOptions options;
      options.environment = {"PDAMP_TEST_PAUSE_AT=" + point + ":" + marker.string()};
      options.while_running = [&](pid_t pid) {
        // A hang guard only: the run takes a few seconds.
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(600);
        while (!fs::exists(marker) && std::chrono::steady_clock::now() < until)
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        ::kill(pid, SIGTERM);
      };
      std::vector<std::string> args = command.args;
      args.insert(args.end(), {"-o", out.string()});
      const auto r = run_pdamp(args, options);
      INFO(r.err);
      CHECK(r.exit_code == 128 + SIGTERM);
      CHECK_THAT(r.err, Catch::Contains("interrupted after the results were written (they are complete)"));
      REQUIRE(fs::exists(out / command.result));
      CHECK_FALSE(fs::exists(out / command.checkpoint));
      const json record = json::parse(slurp(out / ".pdamp-outputs.json"));
      for (const auto& name : record["files"]) CHECK(fs::exists(out / name.get<std::string>()));
      if (command.args.front() == "decay") CHECK(slurp(out / "decay_dem.csv") == slurp(reference / "decay_dem.csv"));
    }
  }
}
