// Hostile and nonsensical input (docs/bad_inputs.md): no command runs from a
// case file or a path, nothing hangs, every refusal is exit 2 with one line naming the
// file or flag and the key, and an interrupted run leaves no partial result.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <chrono>
#include <iterator>
#include <map>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "cli/cli_support.hpp"
#include "support/temp_dir.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace pdamp::test;

namespace {

/// Shell and gnuplot payloads that would create `marker` if anything expanded them:
/// backquotes (gnuplot and sh), $(...), quotes closing a string, gnuplot's system(),
/// a newline starting a new gnuplot command, a macro.
std::vector<std::string> payloads(const fs::path& marker) {
  const std::string m = marker.string();
  return {"`touch " + m + "`",
          "$(touch " + m + ")",
          "'; system('touch " + m + "'); '",
          "\"; system(\"touch " + m + "\"); \"",
          "x\nsystem(\"touch " + m + "\")\nset title 'y",
          "a'b\"c`d$(e) @f \\",
          "'`touch " + m + "`'"};
}

/// stdout is exactly one JSON object.
void require_one_json_object(const std::string& out) {
  json value;
  REQUIRE_NOTHROW(value = json::parse(out));
  CHECK(value.is_object());
}

void require_plot(const fs::path& dir, const std::string& name) {
  if (!gnuplot_installed()) return;  // without gnuplot the scripts are written instead
  INFO(dir / name);
  REQUIRE(fs::exists(dir / name));
  CHECK(fs::file_size(dir / name) > 100);
}

pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

}  // namespace

TEST_CASE("a case name cannot run a command through the plots", "[cli]") {
  TempDir tmp("hostile_names");
  const fs::path marker = tmp.path / "MARK";
  int i = 0;
  for (const auto& name : payloads(marker)) {
    INFO(name);
    const auto path = edited_case("pdamp_hostile_name.json", [&](json& c) { c["name"] = name; });
    const fs::path out = tmp.path / ("run" + std::to_string(i++));
    const auto r = run_pdamp({"run", path, "-o", out.string(), "--json"});
    REQUIRE(r.exit_code == 0);
    require_one_json_object(r.out);
    require_plot(out, "eta_curve.png");
    CHECK(!fs::exists(marker));
    // The DEM picture and the field pictures carry the name as well.
    const auto field = run_pdamp({"field", path, "--source", "formulas", "-o", (out / "field").string(), "--json"});
    REQUIRE(field.exit_code == 0);
    require_one_json_object(field.out);
    require_plot(out / "field", "field_cuts.png");
    CHECK(!fs::exists(marker));
  }
}

TEST_CASE("an output path cannot run a command and still gets its plots", "[cli]") {
  TempDir tmp("hostile_paths");
  const fs::path marker = tmp.path / "MARK";
  const std::string m = marker.string();
  const std::vector<std::string> names = {"o'; touch " + m + "; '", "$(touch " + m + ")", "`touch " + m + "`",
                                          "new\nline", "sp ace", "quote\"d"};
  for (const auto& name : names) {
    INFO(name);
    const fs::path out = tmp.path / name;
    const auto r = run_pdamp({"loss", "--model", "rolling", "--clearance", "0.1", "--amplitude", "0.04", "--frequency",
                              "2", "-o", out.string(), "--json"});
    REQUIRE(r.exit_code == 0);
    require_one_json_object(r.out);
    require_plot(out, "eta_curve.png");
    CHECK(!fs::exists(marker));
  }
  // A relative folder whose name starts with '-' (given after -o, so it is a value).
  RunOptions in_tmp;
  in_tmp.directory = tmp.path;
  const auto r = run_pdamp({"run", case_path("low_intensity_36_spheres.json"), "-o", "-dash", "--json"}, in_tmp);
  REQUIRE(r.exit_code == 0);
  require_plot(tmp.path / "-dash", "eta_curve.png");
  CHECK(!fs::exists(marker));
}

TEST_CASE("a case name cannot steer the default output folder", "[cli]") {
  TempDir tmp("hostile_default_dir");
  fs::create_directories(tmp.path / "work");
  RunOptions in_work;
  in_work.directory = tmp.path / "work";
  for (const std::string name : {"../../escaped", "/tmp/absolute_escape", ".."}) {
    INFO(name);
    const auto path = edited_case("pdamp_steer.json", [&](json& c) { c["name"] = name; });
    const auto r = run_pdamp({"field", path, "--source", "formulas", "--json"}, in_work);
    REQUIRE(r.exit_code == 0);
    const json f = json::parse(r.out);
    const fs::path written = fs::weakly_canonical(in_work.directory / f["file"].get<std::string>());
    // Inside work/out/, whatever the name says.
    CHECK(written.string().rfind(fs::weakly_canonical(in_work.directory / "out").string() + "/", 0) == 0);
    CHECK_THAT(r.err, Catch::Contains("not a safe folder name"));
  }
  CHECK(!fs::exists(tmp.path.parent_path() / "escaped_field_formulas"));
  CHECK(!fs::exists("/tmp/absolute_escape_field_formulas"));
}

TEST_CASE("a FIFO or a directory given as an input file is refused at once", "[cli]") {
  TempDir tmp("fifo");
  const fs::path fifo = tmp.path / "case.fifo";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  const fs::path folder = tmp.path / "folder.json";
  fs::create_directories(folder);
  RunOptions quick;
  quick.time_limit_s = 30.0;  // a hang (the old behaviour) is a time-out, exit_code -2
  for (const fs::path& input : {fifo, folder}) {
    INFO(input);
    const std::string kind = input == fifo ? "FIFO" : "directory";
    for (const std::string command : {"validate", "run", "dem", "field"}) {
      std::vector<std::string> args = {command, input.string()};
      if (command == "field") args.insert(args.end(), {"--source", "formulas"});
      require_one_line_error(run_pdamp(args, quick), input.string() + ": is a " + kind);
    }
    require_one_line_error(run_pdamp({"field", case_path("low_intensity_36_spheres.json"), "--source", "measured",
                                      "--measured", input.string(), "-o", (tmp.path / "m").string()},
                                     quick),
                           "is a " + kind);
    require_one_line_error(run_pdamp({"loss", "--model", "rolling", "--clearance", "0.1", "--amplitude", "0.03",
                                      "--frequency", "2", "--scattered-fit", input.string()},
                                     quick),
                           "is a " + kind);
  }
  require_one_line_error(run_pdamp({"validate", (tmp.path / "missing.json").string()}, quick), "missing.json: no such file");
}

TEST_CASE("the output directory is checked before any work", "[cli]") {
  TempDir tmp("bad_out");
  const fs::path file = tmp.path / "a_file";
  std::ofstream(file) << "x";
  const std::string low = case_path("low_intensity_36_spheres.json");
  require_one_line_error(run_pdamp({"run", low, "-o", file.string()}), "exists and is not a directory");
  require_one_line_error(run_pdamp({"run", low, "-o", ""}), "-o: '': an empty path");
  require_one_line_error(run_pdamp({"run", low, "-o", (file / "below").string()}), "cannot create the output directory");
  // /proc refuses new entries even to root (CI runs as root, so permissions prove nothing).
  require_one_line_error(run_pdamp({"run", low, "-o", "/proc/pdamp_out"}), "-o: '/proc/pdamp_out'");
  // The DEM finds out before it starts: no progress line was printed.
  const auto dem = run_pdamp({"dem", low, "-o", "/proc/pdamp_out"});
  require_one_line_error(dem, "-o: '/proc/pdamp_out'");
  CHECK(dem.err.find("pdamp dem:") == std::string::npos);
  const auto field = run_pdamp({"field", low, "--source", "dem", "-o", file.string()});
  require_one_line_error(field, "exists and is not a directory");
  CHECK(field.err.find("pdamp field:") == std::string::npos);
}

TEST_CASE("a reused output folder holds one run's set, and stale staging folders are removed", "[cli]") {
  TempDir tmp("reuse");
  const fs::path out = tmp.path / "out";
  fs::create_directories(out);
  const fs::path stale = out / (".pdamp-staging-" + std::to_string(dead_pid()));
  fs::create_directories(stale);
  std::ofstream(stale / "big.vtk") << "partial";
  const fs::path alive = out / (".pdamp-staging-" + std::to_string(::getpid()));  // this test is alive
  fs::create_directories(alive);
  std::ofstream(out / "notes.txt") << "the user's own file";

  const fs::path csv = tmp.path / "measured.csv";
  std::ofstream(csv) << "frequency_hz,amplitude_m,eta_star,eta_star_stderr\n"
                        "2,0.02,0.10,0.02\n2,0.04,0.80,0.05\n2,0.06,0.70,0.04\n"
                        "3,0.02,0.12,0.02\n3,0.04,0.75,0.05\n3,0.06,0.66,0.04\n";
  const std::string low = case_path("low_intensity_36_spheres.json");
  REQUIRE(run_pdamp({"field", low, "--source", "measured", "--measured", csv.string(), "-o", out.string()}).exit_code == 0);
  CHECK(!fs::exists(stale));
  CHECK(fs::exists(alive));
  const bool had_fit = fs::exists(out / "scattered_fit.json");
  REQUIRE(run_pdamp({"field", low, "--source", "formulas", "-o", out.string()}).exit_code == 0);
  // The measured run's fit does not stay beside the formulas field.
  if (had_fit) CHECK(!fs::exists(out / "scattered_fit.json"));
  std::ifstream in(out / "field.json");
  CHECK(json::parse(in).dump().find("\"formulas\"") != std::string::npos);
  CHECK(fs::exists(out / "notes.txt"));
  fs::remove_all(alive);
}

TEST_CASE("an interrupted run exits non-zero and leaves no partial result", "[cli]") {
  // A formulas field of 40 x 60 points with pictures takes about a second; signals at
  // delays across its run hit the computation, gnuplot and the commit. Whatever the
  // moment: either the run completed (exit 0, every listed file whole) or it exited
  // non-zero and no result file is in the folder.
  TempDir tmp("interrupt");
  const auto path = edited_case("pdamp_interrupt.json", [](json& c) {
    c["field"] = {{"axis0", {{"min", 1.0}, {"max", 5.0}, {"count", 40}}},
                  {"axis1", {{"min", 0.005}, {"max", 0.12}, {"count", 60}}}};
  });
  int interrupted = 0;
  for (int k = 0; k < 12; ++k) {
    const int signal_number = k % 2 == 0 ? SIGINT : SIGTERM;
    const int delay_ms = 40 + 90 * k;
    INFO("signal " << signal_number << " after " << delay_ms << " ms");
    const fs::path out = tmp.path / ("out" + std::to_string(k));
    RunOptions options;
    options.while_running = [&](pid_t pid) {
      std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
      ::kill(-pid, signal_number);  // the process group: pdamp and a running gnuplot
    };
    const auto r = run_pdamp({"field", path, "--source", "formulas", "-o", out.string()}, options);
    if (r.exit_code == 0) {
      for (const auto& entry : fs::directory_iterator(out))
        if (entry.is_regular_file()) CHECK(fs::file_size(entry.path()) > 0);
      continue;
    }
    ++interrupted;
    CHECK(r.exit_code == 128 + signal_number);
    // A signal that arrives once the commit has begun is delivered after it: the set is
    // then complete (every file its manifest lists, none empty), and pdamp says so.
    if (r.err.find("interrupted after the results were written") != std::string::npos) {
      std::ifstream manifest(out / ".pdamp-outputs.json");
      const json listed = json::parse(manifest);
      REQUIRE(!listed["files"].empty());
      for (const auto& name : listed["files"]) {
        INFO(name);
        CHECK(fs::file_size(out / name.get<std::string>()) > 0);
      }
      continue;
    }
    if (fs::exists(out))
      for (const auto& entry : fs::directory_iterator(out)) {
        INFO(entry.path());
        CHECK(!entry.is_regular_file());  // at most a staging folder, removed by the next run
      }
  }
  CHECK(interrupted > 0);
}

TEST_CASE("flags take physical ranges and whole numbers where counts are meant", "[cli]") {
  require_one_line_error(run_pdamp("buffer --frequency 60 --intensity 20 --radius 0.0025 --layer-modulus 60e6 "
                                   "--impact-velocity 1e308 --json"),
                         "--impact-velocity: '1e308': must be a finite number > 0 and <= 1000");
  require_one_line_error(run_pdamp("size --model bouncing --stroke 1e308 --json"), "--stroke: '1e308'");
  require_one_line_error(run_pdamp("loss --model auto --clearance 0.1 --amplitude 0.04 --frequency 1e308"),
                         "--frequency: '1e308': must be a finite number >= 0.01 and <= 10000");
  // A subnormal is a number, too small for a clearance (not "not > 0").
  require_one_line_error(run_pdamp("optimum --model rolling --clearance 1e-320"),
                         "--clearance: '1e-320': must be a finite number >= 1e-06");
  require_one_line_error(run_pdamp("dem " + case_path("low_intensity_36_spheres.json") + " --periods 1.5"),
                         "--periods: '1.5': must be a whole number");
  require_one_line_error(run_pdamp(std::vector<std::string>{}), "missing the command");
  // With --json an error is still only the error line (stdout stays empty).
  require_one_line_error(run_pdamp("optimum --model rolling --clearance -1 --json"), "--clearance");
}

TEST_CASE("case keys take physical ranges and validate makes every check", "[cli]") {
  const auto check = [](const std::string& name, const std::function<void(json&)>& edit, const std::string& message) {
    INFO(name);
    const auto path = edited_case(name, edit);
    require_one_line_error(run_pdamp({"validate", path}), name + ": " + message);
    // run refuses it the same way
    require_one_line_error(run_pdamp({"run", path}), name + ": " + message);
  };
  check("pdamp_tiny_radius.json", [](json& c) { c["damper"]["particles"]["radius_m"] = 1e-300; },
        "/damper/particles/radius_m: = 1e-300: must be a finite number >= 1e-05");
  check("pdamp_huge_frequency.json", [](json& c) { c["excitation"]["frequency_hz"] = 1e308; },
        "/excitation/frequency_hz: = 1e+308");
  check("pdamp_fast_impact.json", [](json& c) { c["dem"]["max_impact_speed_m_s"] = 1e200; },
        "/dem/max_impact_speed_m_s: = 1e+200: must be a finite number > 0 and <= 1000");
  check("pdamp_big_clearance.json", [](json& c) { c["damper"]["clearance_m"] = 100.0; },
        "/damper/clearance_m: = 100: must be <= the free length along the drive");
  check("pdamp_empty_table.json",
        [](json& c) { c["dem"]["contact"] = {{"restitution", {{"speeds_m_s", json::array()}, {"values", json::array()}}}}; },
        "/dem/contact/restitution/speeds_m_s: has 0 entries: needs at least 2");
  check("pdamp_low_cor.json", [](json& c) { c["dem"]["contact"] = {{"restitution", 0.001}}; },
        "/dem/contact/restitution: = 0.001: must be a finite number >= 0.01");
  check("pdamp_table_order.json",
        [](json& c) { c["dem"]["contact"] = {{"restitution", {{"speeds_m_s", {1.0, 0.5}}, {"values", {0.9, 0.8}}}}}; },
        "/dem/contact/restitution/speeds_m_s/1: speeds must increase strictly");
  check("pdamp_soft.json", [](json& c) { c["dem"]["stiffness_softening"] = 1e-300; },
        "/dem/stiffness_softening: = 1e-300: must be a finite number >= 1e-06 and <= 1");
  // null is not "absent": a half-edited value must not silently become the default.
  check("pdamp_null.json", [](json& c) { c["damper"]["clearance_m"] = nullptr; },
        "/damper/clearance_m: must be a number m (omit the key for the default), got null");
  check("pdamp_empty_name.json", [](json& c) { c["name"] = ""; }, "/name: must not be empty");
  check("pdamp_empty_material.json", [](json& c) { c["materials"] = {{"", {{"density_kg_m3", 1000.0}}}}; },
        "/materials: a material needs a name");
  check("pdamp_pairs_twice.json",
        [](json& c) {
          c["dem"]["pairs"] = {{{"material_a", "steel"}, {"material_b", "steel"}, {"restitution", 0.3}},
                               {{"material_a", "steel"}, {"material_b", "steel"}, {"restitution", 0.95}}};
        },
        "/dem/pairs/1: the pair steel/steel is already given by /dem/pairs/0");
  // Checks made by the DEM's own validation come back with the case key's pointer.
  check("pdamp_pin_outside.json",
        [](json& c) { c["dem"]["inner_structures"] = {{"pins", {{{"centre_m", {1.0, 0.0, 0.0}}, {"radius_m", 0.005}, {"length_m", 0.05}}}}}; },
        "/dem/inner_structures/pins/0/centre_m: = [1, 0, 0]: pin 0 spans x [0.995, 1.005]");
  check("pdamp_samples.json", [](json& c) { c["dem"]["samples_per_period"] = 100000; c["dem"]["analysed_periods"] = 1000; },
        "/dem/samples_per_period: = 100000: samples_per_period x analysed_periods = 100000000 recorded samples must be <= 10000000");
  check("pdamp_drive_speed.json", [](json& c) { c["excitation"] = {{"frequency_hz", 100.0}, {"amplitude_m", 10.0}}; },
        "/excitation/amplitude_m: = 10: the drive's impact speed");
}

TEST_CASE("validate builds the DEM's bed: a pin through the collected bed is refused before any output", "[cli]") {
  TempDir tmp("pin_in_bed");
  const auto path = edited_case("pdamp_pin_in_bed.json", [](json& c) {
    c["dem"]["inner_structures"] = {{"pins", {{{"centre_m", {-0.075, 0.0, 0.0}}, {"radius_m", 0.004}, {"length_m", 0.04}}}}};
  });
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"validate", path}, {"dem", path, "-o", (tmp.path / "dem").string()},
        {"field", path, "--source", "dem", "-o", (tmp.path / "field").string()}}) {
    INFO(args[0]);
    const auto r = run_pdamp(args);
    require_one_line_error(r, "pdamp_pin_in_bed.json: /dem/inner_structures: lattice site");
  }
  CHECK(!fs::exists(tmp.path / "dem"));  // refused before the output folder was made
  CHECK(!fs::exists(tmp.path / "field"));
}

TEST_CASE("a result name taken by a folder is refused before any file moves", "[cli]") {
  TempDir tmp("commit_blocked");
  fs::create_directories(tmp.path / "design.json");
  const auto r = run_pdamp({"run", case_path("low_intensity_36_spheres.json"), "-o", tmp.path.string()});
  require_one_line_error(r, "design.json' exists and is not a file");
  for (const char* name : {"case_resolved.json", "eta_curve.csv", "eta_curve.png"}) CHECK(!fs::exists(tmp.path / name));
}

TEST_CASE("numbers too large for a double, hexadecimal flags and absurd measured values are refused", "[cli]") {
  TempDir tmp("overflow");
  const fs::path huge = tmp.path / "huge.json";
  std::ofstream(huge) << R"({"name": 1e400})";
  require_one_line_error(run_pdamp({"validate", huge.string()}), "huge.json: malformed JSON: number overflow");
  require_one_line_error(run_pdamp("optimum --model rolling --clearance 0x10 --json"), "--clearance: '0x10'");
  require_one_line_error(run_pdamp("optimum --model rolling --clearance inf"), "--clearance: 'inf'");
  const fs::path csv = tmp.path / "rig.csv";
  std::ofstream(csv) << "frequency_hz,amplitude_m,eta_star\n2,0.03,1e300\n";
  require_one_line_error(run_pdamp({"field", case_path("low_intensity_36_spheres.json"), "--source", "measured",
                                    "--measured", csv.string(), "-o", (tmp.path / "m").string()}),
                         "--measured: " + csv.string() + ": line 2, column eta_star: 1e+300: must be in [0, 100]");
}

TEST_CASE("a DEM run announces its cost first and one that cannot fit in memory is refused", "[cli]") {
  // A million 0.1 mm spheres with 10,000 snapshots: 1e6 x 1e4 x 84 bytes = 840 GB.
  const auto big = edited_case("pdamp_memory.json", [](json& c) {
    // One sphere high (100 lanes of 10,000 along the 2.5 m drive): a bed stacked high would settle and jam.
    c["damper"]["container"] = {{"shape", "box"}, {"inner_size_m", {2.5, 0.02, 0.0002}}};
    c["damper"]["particles"] = {{"count", 1000000}, {"radius_m", 1e-4}};
    c["excitation"] = {{"frequency_hz", 50.0}, {"amplitude_m", 0.001}};
    c["dem"] = {{"snapshots", 10000}};
  });
  for (const std::string command : {"validate", "dem"}) {
    const auto r = run_pdamp({command, big});
    require_one_line_error(r, "pdamp_memory.json: /dem: the DEM needs about 841 GB (1000000 particles");
    CHECK_THAT(r.err, Catch::Contains("reduce /dem/samples_per_period, /dem/analysed_periods, /dem/snapshots"));
  }
  // A run that fits says what it will cost before its first step.
  const auto quick = edited_case("pdamp_quick_estimate.json", [](json& c) {
    c["dem"] = {{"stiffness_softening", 1e-3}, {"transient_periods", 0}, {"analysed_periods", 1}};
  });
  const auto r = run_pdamp({"dem", quick, "--json"});
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.rfind("pdamp dem: 36 particles, ", 0) == 0);
  CHECK_THAT(r.err, Catch::Contains("particle-steps, about"));
  const json d = json::parse(r.out);
  // The estimate's steps are the run's (estimate_run plans the run exactly).
  CHECK_THAT(r.err, Catch::Contains(std::to_string(d["run"]["steps"].get<long long>()) + " steps of"));
}

TEST_CASE("duplicate keys and binary bytes in a case file are refused on one line", "[cli]") {
  TempDir tmp("dup");
  const fs::path dup = tmp.path / "dup.json";
  std::ofstream(dup) << R"({"name": "a", "damper": {"model": "auto", "model": "rolling"}})";
  require_one_line_error(run_pdamp({"validate", dup.string()}), "dup.json: /damper/model: duplicate key");
  const fs::path binary = tmp.path / "binary.json";
  std::ofstream(binary, std::ios::binary) << std::string("{\"name\": \"a\0b\n\x1b[31m\", \x01}", 22);
  const auto r = run_pdamp({"validate", binary.string()});
  require_one_line_error(r, "binary.json: malformed JSON");
  CHECK(r.err.find('\x1b') == std::string::npos);  // no terminal escape reaches the screen
}

// Reference: the strict reader's nesting limit (64 levels), met before the rest is read: a
// 20 MB file of "[" is refused at once (parsed whole it took 68 s and 2.2 GB).
TEST_CASE("JSON nested deeper than the limit is refused where it is met", "[cli]") {
  TempDir tmp("deep");
  const fs::path deep = tmp.path / "deep.json";
  std::ofstream(deep) << std::string(20'000'000, '[');
  require_one_line_error(run_pdamp({"validate", deep.string()}), "deep.json: /0/0/0");
  const auto r = run_pdamp({"validate", deep.string()});
  CHECK_THAT(r.err, Catch::Contains("nested deeper than 64 levels"));
  const fs::path fine = tmp.path / "fine.json";
  std::ofstream(fine) << std::string(60, '[') << std::string(60, ']');
  const auto shallow = run_pdamp({"validate", fine.string()});
  CHECK(shallow.err.find("nested deeper") == std::string::npos);  // refused for what it is, not its depth
}

TEST_CASE("round two of the hostile inputs: bytes after the JSON, huge lattices, grids validate must see", "[cli]") {
  TempDir tmp("round_two");
  // Text after a NUL byte was ignored by the parser: "{valid case}\0garbage" passed.
  std::ifstream in(case_path("low_intensity_36_spheres.json"));
  const std::string valid{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const fs::path trailing = tmp.path / "trailing.json";
  std::ofstream(trailing, std::ios::binary) << valid << std::string("\0garbage {{{", 12);
  require_one_line_error(run_pdamp({"validate", trailing.string()}), "trailing.json: malformed JSON: a NUL byte at offset");
  // A key with a NUL is named whole (the message is not cut at it) and escaped.
  const fs::path nul_key = tmp.path / "nul_key.json";
  std::ofstream(nul_key, std::ios::binary) << std::string("{\"task\\u0000x\": 1, \"a/b~c\": 2}");
  const auto r = run_pdamp({"validate", nul_key.string()});
  CHECK(r.exit_code == 2);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  // The automatic lattice of a 100 m box of 5 mm spheres (4e8 sites a slab) took 50 s
  // and 2.3 GB; now it is refused at once, naming the fix.
  RunOptions quick;
  quick.time_limit_s = 20.0;
  const auto huge = edited_case("pdamp_huge_box.json", [](json& c) {
    c["damper"]["container"]["inner_size_m"] = {100.0, 100.0, 100.0};
    c["damper"]["particles"].erase("lattice");
  });
  require_one_line_error(run_pdamp({"validate", huge}, quick), "give lattice_counts");
  // Nodes a rounding apart (count 3 between 2 and 2 + 4e-16) are refused by validate
  // as by field; a stroke-over-clearance node far below the drive range as well.
  require_one_line_error(run_pdamp({"validate", edited_case("pdamp_equal_nodes.json", [](json& c) {
                                      c["field"] = {{"axis0", {{"min", 2.0}, {"max", 2.0000000000000004}, {"count", 3}}}};
                                    })}),
                         "/field: ");
  require_one_line_error(run_pdamp({"validate", edited_case("pdamp_tiny_node.json", [](json& c) {
                                      c["field"] = {{"axes", "intensity_stroke_over_clearance"},
                                                    {"axis1", {{"min", 1e-300}, {"max", 0.5}, {"count", 2}}}};
                                    })}),
                         "drives at frequency_hz = ");
  // A bed that leaves no room (1e-12 m) is no damper.
  require_one_line_error(run_pdamp({"validate", edited_case("pdamp_no_room.json", [](json& c) {
                                      c["damper"]["container"]["inner_size_m"] = {0.120000000001, 0.061, 0.04};
                                      c["damper"]["particles"]["lattice"] = {12, 6, 1};
                                      c["damper"]["particles"]["count"] = 72;
                                    })}),
                         "/damper/particles: the collected bed leaves a clearance of");
  // Whole numbers written 36.0 are integers; 2^64 - 1 is not read as -1.
  CHECK(run_pdamp({"validate", edited_case("pdamp_float_count.json", [](json& c) { c["damper"]["particles"]["count"] = 36.0; })})
            .exit_code == 0);
  const fs::path seed = tmp.path / "seed.json";
  {
    json c = json::parse(valid);
    c["dem"]["seed"] = 18446744073709551615ULL;
    std::ofstream(seed) << c.dump();
  }
  require_one_line_error(run_pdamp({"validate", seed.string()}), "/dem/seed: = 1.844674407e+19: must be in [0, 2147483647]");
}

TEST_CASE("round two: the manifest name, a full stdout, many cuts", "[cli]") {
  TempDir tmp("round_two_out");
  fs::create_directories(tmp.path / "o" / ".pdamp-outputs.json");
  const std::string low = case_path("low_intensity_36_spheres.json");
  require_one_line_error(run_pdamp({"run", low, "-o", (tmp.path / "o").string()}), ".pdamp-outputs.json' exists and is not a file");
  for (const auto& entry : fs::directory_iterator(tmp.path / "o")) CHECK(!entry.is_regular_file());
  // stdout that cannot take the result is a failure, not a silent 0.
  if (fs::exists("/dev/full")) {
    const pid_t child = ::fork();
    if (child == 0) {
      const int out = ::open("/dev/full", O_WRONLY);
      const int err = ::open("/dev/null", O_WRONLY);
      ::dup2(out, 1);
      ::dup2(err, 2);
      ::execl(PDAMP_BINARY, PDAMP_BINARY, "validate", low.c_str(), "--json", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    CHECK(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 1);
  }
  // 2000 frequency nodes: the cuts plot draws at most 12 of them (before: one gnuplot
  // curve per node, which ran for minutes); the field is still complete.
  const auto many = edited_case("pdamp_many_cuts.json", [](json& c) {
    c["field"] = {{"axis0", {{"min", 1.0}, {"max", 3.0}, {"count", 2000}}}, {"axis1", {{"min", 0.01}, {"max", 0.08}, {"count", 2}}}};
  });
  RunOptions bounded;
  bounded.time_limit_s = 60.0;  // a hang guard, not a timing: a few seconds are expected
  const auto r = run_pdamp({"field", many, "--source", "formulas", "-o", (tmp.path / "cuts").string(), "--json"}, bounded);
  REQUIRE(r.exit_code == 0);
  CHECK(json::parse(r.out)["points"] == 4000);
  require_plot(tmp.path / "cuts", "field_cuts.png");
}

// Reference: the output folder's contract (report::OutputDir): a commit replaces the
// previous set, so a folder holding another command's or another case's outputs is refused
// (exit 2, naming them) unless --overwrite; the same command on the same case replaces its
// own set as before.
TEST_CASE("an output folder holding another command's or case's outputs is refused unless --overwrite", "[cli]") {
  TempDir tmp("owner");
  const std::string dir = (tmp.path / "out").string();
  const std::string low = case_path("low_intensity_36_spheres.json"), high = case_path("high_intensity_cylinder.json");
  REQUIRE(run_pdamp({"run", low, "-o", dir}).exit_code == 0);
  REQUIRE(fs::exists(fs::path(dir) / "design.json"));
  // The same command on the same case (another spelling of its path): replaced as before.
  const std::string other_spelling = (fs::path(low).parent_path() / "." / fs::path(low).filename()).string();
  CHECK(run_pdamp({"run", other_spelling, "-o", dir}).exit_code == 0);
  // Another command: refused before any work, the earlier set intact.
  const auto loss = run_pdamp({"loss", "--model", "rolling", "--clearance", "0.1", "--amplitude", "0.04",
                               "--frequency", "3", "-o", dir});
  require_one_line_error(loss, "holds the outputs of pdamp run on");
  CHECK_THAT(loss.err, Catch::Contains("design.json"));
  CHECK_THAT(loss.err, Catch::Contains("--overwrite"));
  CHECK(fs::exists(fs::path(dir) / "design.json"));
  // Another case: refused the same way.
  require_one_line_error(run_pdamp({"run", high, "-o", dir}), "holds the outputs of pdamp run on " + low);
  // --overwrite: replaced, and the folder is the new owner's.
  CHECK(run_pdamp({"loss", "--model", "rolling", "--clearance", "0.1", "--amplitude", "0.04", "--frequency", "3",
                   "-o", dir, "--overwrite"})
            .exit_code == 0);
  CHECK_FALSE(fs::exists(fs::path(dir) / "design.json"));
  require_one_line_error(run_pdamp({"run", low, "-o", dir}), "holds the outputs of pdamp loss");
}

// Reference: a flag that would do nothing is refused, as a class: the DEM stepped sine's
// flags without the DEM (frf), or on a task that has no stepped sine (run on a decay case).
TEST_CASE("the DEM stepped sine's flags are refused where they would do nothing", "[cli]") {
  const std::string beam = case_path("beam_base_excited.json"), link = case_path("manipulator_link_decay.json");
  require_one_line_error(run_pdamp({"frf", beam, "--dem-points", "5"}), "--dem-points: applies to --method dem");
  require_one_line_error(run_pdamp({"frf", beam, "--method", "field", "--dem-tolerance", "0.01"}), "--dem-tolerance");
  require_one_line_error(run_pdamp({"run", link, "--dem-points", "5"}), "--dem-points: applies to task kind frf");
  require_one_line_error(run_pdamp({"run", link, "--calibration-cache", "x"}), "--calibration-cache: applies to task kinds filling_ratios and modes");
}

// Reference: the field file's value ranges (surrogate::field_value_problem: η* in [−1, 100],
// m_app/m_bed in [−10, 10]), applied by the reader: a field with η* = 1e300 or −5 is bad
// input (exit 2 naming the file and the cell), not a numerical failure later.
TEST_CASE("a field whose values are out of their physical range is refused naming the cell", "[cli]") {
  TempDir tmp("field_ranges");
  std::ifstream in(case_path("fields/link_narrow_dem/field.json"));
  const json field = json::parse(in);
  std::ifstream case_in(case_path("manipulator_link_decay.json"));
  const json link = json::parse(case_in);
  const std::size_t eta = 2;  // the table's columns: frequency_hz, amplitude_m, eta_star, ...
  for (const double bad : {1e300, -5.0}) {
    json edited = field;
    edited["table"][3][eta] = bad;
    const fs::path file = tmp.path / "field.json";
    std::ofstream(file) << edited.dump();
    json c = link;
    for (auto& layer : c["dampers"][0]["layers"]) layer["field_file"] = file.string();
    const fs::path case_file = tmp.path / "case.json";
    std::ofstream(case_file) << c.dump();
    const auto r = run_pdamp({"decay", case_file.string(), "--method", "field"});
    require_one_line_error(r, "field.json: /table/3/2: eta_star");
    CHECK_THAT(r.err, Catch::Contains("must be in [-1, 100]"));
  }
}

// Reference: XML 1.0 §2.4 ("]]>" may not appear in text content): gnuplot's SVG writes the
// case name into titles as text, so a name holding it made an ill-formed picture.
TEST_CASE("a case name holding the CDATA end leaves the SVG pictures well-formed", "[cli]") {
  TempDir tmp("cdata_name");
  const auto path = edited_case("pdamp_cdata_name.json", [](json& c) { c["name"] = "a ]]> <b> & c"; });
  const fs::path out = tmp.path / "out";
  REQUIRE(run_pdamp({"run", path, "-o", out.string()}).exit_code == 0);
  if (!fs::exists(out / "eta_curve.svg")) return;  // no gnuplot here: no picture to check
  std::ifstream in(out / "eta_curve.svg");
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(svg.find("]]>") == std::string::npos);
  CHECK(svg.find("]] >") != std::string::npos);  // the name is still there, readable
}

// Reference: what stands where a checkpoint goes is named before any work (exit 2), not met
// as a raw filesystem error: a link to itself, a link to nothing, a folder.
TEST_CASE("a checkpoint path taken by a looping link, a dangling link or a folder is refused naming it", "[cli]") {
  TempDir tmp("checkpoint_in_the_way");
  const fs::path out = tmp.path / "out";
  fs::create_directories(out);
  const fs::path checkpoint = out / "decay_dem.checkpoint";
  const std::string link = case_path("manipulator_link_decay.json");
  const auto refused = [&](const std::string& why) {
    const auto r = run_pdamp({"decay", link, "--method", "dem", "-o", out.string(), "--resume"});
    require_one_line_error(r, "decay_dem.checkpoint' is in the way of the checkpoint");
    CHECK_THAT(r.err, Catch::Contains(why));
  };
  fs::create_symlink(checkpoint, checkpoint);
  refused("symbolic links");
  fs::remove(checkpoint);
  fs::create_symlink(tmp.path / "nowhere", checkpoint);
  refused("a link to nothing");
  fs::remove(checkpoint);
  fs::create_directory(checkpoint);
  refused("not a regular file");
}

// Reference: one run writes a folder at a time (report::OutputDir flocks the folder for its
// life): a second run into a folder another holds is refused before any work, naming it,
// and runs once the first has ended. The lock is held here as a running pdamp holds it.
TEST_CASE("a folder another run is writing into is refused until that run ends", "[cli]") {
  TempDir tmp("folder_lock");
  const fs::path out = tmp.path / "out";
  fs::create_directories(out);
  const std::string low = case_path("low_intensity_36_spheres.json");
  const int fd = ::open(out.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  REQUIRE(fd >= 0);
  REQUIRE(::flock(fd, LOCK_EX | LOCK_NB) == 0);
  require_one_line_error(run_pdamp({"run", low, "-o", out.string()}), "another pdamp run is writing into this folder");
  CHECK_FALSE(fs::exists(out / "design.json"));
  ::close(fd);
  CHECK(run_pdamp({"run", low, "-o", out.string()}).exit_code == 0);
  CHECK(fs::exists(out / "design.json"));
}

// Reference: JSON holds UTF-8 only (RFC 8259 §8.1), and results record their paths in it: a
// folder or case path that is not UTF-8 is refused before any work (exit 2, the bytes
// escaped), not met as the JSON library's error after the computation.
TEST_CASE("an output folder or case path that is not UTF-8 is refused before any work", "[cli]") {
  TempDir tmp("not_utf8");
  const std::string bad_dir = (tmp.path / "out\xff").string();
  require_one_line_error(run_pdamp({"loss", "--model", "rolling", "--clearance", "0.1", "--amplitude", "0.04",
                                    "--frequency", "3", "-o", bad_dir}),
                         "-o: '" + (tmp.path / "out\\xff").string() + "' is not valid UTF-8");
  CHECK_FALSE(fs::exists(bad_dir));
  const fs::path bad_case = tmp.path / "case\xfe.json";
  fs::copy_file(case_path("low_intensity_36_spheres.json"), bad_case);
  require_one_line_error(run_pdamp({"run", bad_case.string(), "-o", (tmp.path / "out").string()}),
                         "the file's path is not valid UTF-8");
}

// Reference: the sensitivity study's bound (case_file::kMaxSensitivityValues = 50 values a
// parameter): 10,000 values were 10,000 cases held at once (3 GB, 45 s before any run).
TEST_CASE("a sensitivity parameter with more values than a study can use is refused at once", "[cli]") {
  const auto path = edited_case("pdamp_many_values.json", [](json& c) {
    json values = json::array();
    for (int i = 0; i < 10000; ++i) values.push_back(0.1 + 1e-5 * i);
    c["sensitivity"] = {{"parameters", json::array({{{"name", "friction"}, {"values", values}}})}};
  });
  require_one_line_error(run_pdamp({"validate", path}), "/sensitivity/parameters/0/values: has 10000 entries: at most 50");
}

namespace {

/// Every file of `dir` (hidden ones too) with its contents.
std::map<std::string, std::string> folder_contents(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) files[entry.path().filename().string()] = slurp(entry.path());
  return files;
}

/// A failed write must leave the folder's earlier set byte for byte, no staging folder and
/// no temporary, and say so: exit 1, one error line naming a file of the set.
void require_earlier_set_kept(const RunResult& r, const fs::path& dir, const std::map<std::string, std::string>& before) {
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("pdamp: error: ") != std::string::npos);
  CHECK((r.err.find("write failed") != std::string::npos || r.err.find("incomplete") != std::string::npos));
  const auto after = folder_contents(dir);
  for (const auto& [name, text] : after) {
    INFO(name);
    CHECK(name.find(".tmp.") == std::string::npos);
    CHECK(name.rfind(".pdamp-staging-", 0) != 0);
  }
  CHECK(after == before);
}

/// A size-limited tmpfs mounted for the test's life (root only; a container may still
/// refuse: then `mounted` is false and the caller skips).
struct SmallFileSystem {
  fs::path point;
  bool mounted = false;
  SmallFileSystem(fs::path where, std::uintmax_t bytes) : point(std::move(where)) {
    fs::create_directories(point);
    if (::geteuid() != 0) return;
    const auto r = run_program({"/bin/mount", "-t", "tmpfs", "-o", "size=" + std::to_string(bytes), "tmpfs", point.string()});
    mounted = r.exit_code == 0;
  }
  ~SmallFileSystem() {
    if (mounted) run_program({"/bin/umount", point.string()});
  }
};

}  // namespace

TEST_CASE("a write that fails (a file-size limit, a full disk) keeps the folder's earlier set and leaves no temporary", "[cli]") {
  TempDir tmp("write_failure");
  const fs::path out = tmp.path / "field";
  const std::vector<std::string> field_args = {"field", case_path("low_intensity_36_spheres.json"), "--source", "formulas",
                                               "-o", out.string()};
  REQUIRE(run_pdamp(field_args).exit_code == 0);
  const auto before = folder_contents(out);
  std::uintmax_t set_bytes = 0;
  for (const auto& [name, text] : before) set_bytes += text.size();
  // Limits that cut the first staged file (field.json, 4 KB), a data file written by the
  // folder itself (the 15 KB curve CSV; an ofstream used to lose this failure at close),
  // and gnuplot's pictures (50 KB PNG, 4 MB SVG). Before: SIGXFSZ killed pdamp mid-run
  // (exit 153) with its staging folder left, or gnuplot's cut pictures replaced good ones.
  for (const unsigned long limit : {3000UL, 10000UL, 20000UL, 1000000UL}) {
    INFO("file-size limit " << limit);
    RunOptions limited;
    limited.file_size_limit_bytes = limit;
    require_earlier_set_kept(run_pdamp(field_args, limited), out, before);
  }
  // A checkpoint that cannot be written: exit 1 naming it, no temporary beside it.
  RunOptions limited;
  limited.file_size_limit_bytes = 1000;
  const fs::path dem = tmp.path / "dem";
  const auto r = run_pdamp({"dem", case_path("low_intensity_36_spheres.json"), "-o", dem.string(), "--checkpoint-interval", "0"},
                           limited);
  CHECK(r.exit_code == 1);
  CHECK_THAT(r.err, Catch::Contains("dem.checkpoint: write failed"));
  for (const auto& entry : fs::directory_iterator(dem)) CHECK(entry.path().filename().string().find(".tmp.") == std::string::npos);

  // A real full disk: a file system that holds the earlier set and 64 KB more.
  SmallFileSystem small(tmp.path / "small", set_bytes + (64u << 10));
  if (!small.mounted) {
    WARN("no size-limited tmpfs here (needs root and mount rights): the full-disk part is skipped");
    return;
  }
  fs::copy(out, small.point, fs::copy_options::recursive);
  REQUIRE(folder_contents(small.point) == before);
  std::vector<std::string> args = field_args;
  args.back() = small.point.string();
  require_earlier_set_kept(run_pdamp(args), small.point, before);
}

// A DEM-in-the-loop run whose estimate is beyond a week (kMaxDemWallTime_s) does not start
// unless the user accepts it; validate reports the cost. The link decay with 2016 spheres
// over 1e5 s: about 160 days at the benchmark rate (before, it started and ran for months).
// The verification of a filling_ratios task at full stiffness and 200 steps per contact
// over 1e5 s: about 60 days, refused before the optimisation.
TEST_CASE("a DEM run estimated beyond a week is refused before it starts unless --accept-long-run", "[cli]") {
  TempDir tmp("long_runs");
  const fs::path big = tmp.path / "big_bed_decay.json";
  {
    json c = json::parse(slurp(case_path("manipulator_link_decay.json")));
    c["task"]["duration_s"] = 1e5;
    json& layer = c["dampers"][0]["layers"][0];
    layer["container"]["inner_size_m"] = {0.5, 1.01, 0.012};
    layer["particles"]["count"] = 2000;
    layer["particles"]["lattice"] = {20, 100, 1};
    layer.erase("field_file");
    std::ofstream(big) << c.dump(2);
    fs::copy(std::string(PDAMP_SOURCE_DIR) + "/cases/fields", tmp.path / "fields", fs::copy_options::recursive);
  }
  require_one_line_error(run_pdamp({"decay", big.string(), "--method", "dem"}), "/task/duration_s");
  const auto refused = run_pdamp({"decay", big.string(), "--method", "dem"});
  CHECK_THAT(refused.err, Catch::Contains("more than the limit of 7 days") && Catch::Contains("--accept-long-run"));
  const auto checked = run_pdamp({"validate", big.string()});
  CHECK(checked.exit_code == 0);
  CHECK_THAT(checked.err, Catch::Contains("2016 particles in 1 bed") && Catch::Contains("particle-steps"));
  // Accepted, it starts (and is ended by the signal, not refused).
  RunOptions accepted;
  accepted.while_running = [](pid_t pid) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    ::kill(pid, SIGTERM);
  };
  CHECK(run_pdamp({"decay", big.string(), "--method", "dem", "--accept-long-run"}, accepted).exit_code == 128 + SIGTERM);
  // --accept-long-run does nothing without the DEM: refused like the checkpoint flags.
  require_one_line_error(run_pdamp({"decay", big.string(), "--accept-long-run"}), "--accept-long-run");

  // pdamp dem: 100,000 periods at 0.01 Hz (about 44 days), refused and then accepted.
  const std::string dem_case = edited_case("pdamp_dem_long.json", [](json& c) { c["dem"]["samples_per_period"] = 16; });
  const std::vector<std::string> dem_args = {"dem", dem_case, "--frequency", "0.01", "--periods", "100000", "--amplitude", "0.5"};
  require_one_line_error(run_pdamp(dem_args), "more than the limit of 7 days");
  std::vector<std::string> accepted_dem = dem_args;
  accepted_dem.push_back("--accept-long-run");
  CHECK(run_pdamp(accepted_dem, accepted).exit_code == 128 + SIGTERM);

  // A DEM field whose every point is such a run (a point is saved only when it ends):
  // refused by field and by validate, accepted by validate with the flag; the flag without
  // the DEM is refused.
  const std::string field_case = edited_case("pdamp_field_long.json", [](json& c) {
    c["dem"]["samples_per_period"] = 16;
    c["dem"]["analysed_periods"] = 100000;
    c["field"] = {{"axis0", {{"min", 0.01}, {"max", 0.02}, {"count", 2}}}, {"axis1", {{"min", 0.4}, {"max", 0.5}, {"count", 2}}}};
  });
  require_one_line_error(run_pdamp({"field", field_case, "--source", "dem", "-o", (tmp.path / "field").string()}),
                         "a point of the DEM field sweep is estimated at about");
  require_one_line_error(run_pdamp({"validate", field_case}), "more than the limit of 7 days");
  CHECK(run_pdamp({"validate", field_case, "--accept-long-run"}).exit_code == 0);
  require_one_line_error(run_pdamp({"field", field_case, "--source", "formulas", "--accept-long-run"}), "--accept-long-run");

  const fs::path verify = tmp.path / "long_verify.json";
  {
    json c = json::parse(slurp(case_path("manipulator_link_optimize.json")));
    c["task"]["verify"]["duration_s"] = 1e5;
    c["task"]["verify"]["stiffness_softening"] = 1.0;
    c["dem"]["steps_per_contact"] = 200;
    std::ofstream(verify) << c.dump(2);
  }
  require_one_line_error(run_pdamp({"optimize", verify.string(), "--method", "formulas"}), "/task/verify/duration_s");
}

namespace {

/// `validate` on the test data case `name` copied into `dir` with `edit` applied (its modal
/// data file copied beside it, edited by `edit_modal`).
RunResult validate_edited(const fs::path& dir, const std::string& name, const std::function<void(json&)>& edit,
                          const std::function<void(json&)>& edit_modal = {}) {
  const fs::path data = fs::path(PDAMP_SOURCE_DIR) / "tests" / "cli" / "data";
  json c = json::parse(slurp(data / name));
  edit(c);
  const fs::path path = dir / ("edited_" + name);
  std::ofstream(path) << c.dump(2);
  if (c["structure"]["kind"] == "modal_data") {
    json m = json::parse(slurp(data / c["structure"]["file"].get<std::string>()));
    if (edit_modal) edit_modal(m);
    std::ofstream(dir / c["structure"]["file"].get<std::string>()) << m.dump(2);
  }
  RunOptions bounded;
  bounded.time_limit_s = 60.0;  // a hang guard: each is refused at once
  return run_pdamp({"validate", path.string()}, bounded);
}

}  // namespace

// Every structure and modal-data number has a physical range, and validate builds the modal
// model as a run does (after the size checks), so it refuses what a run would. Before: each of
// these passed validate and either failed at run time with exit 1 and no key ("the generalized
// eigenproblem failed", "out of memory"), or ran to exit 0 with overflowing results.
TEST_CASE("every structure and modal-data number has a range, and validate builds the modal model", "[cli]") {
  TempDir tmp("structure_ranges");
  const auto beam = [&](const std::function<void(json&)>& edit) { return validate_edited(tmp.path, "cantilever_decay.json", edit); };
  require_one_line_error(beam([](json& c) { c["structure"]["segments"][0]["length_m"] = 1e308; }),
                         "/structure/segments/0/length_m");
  require_one_line_error(beam([](json& c) { c["structure"]["segments"][0]["section"]["width_m"] = 1e300; }),
                         "/structure/segments/0/section/width_m");
  require_one_line_error(beam([](json& c) { c["structure"]["segments"][0]["section"]["depth_m"] = 1e-320; }),
                         "/structure/segments/0/section/depth_m");
  require_one_line_error(beam([](json& c) { c["structure"]["segments"][0]["elements"] = 20000; }),
                         "/structure/segments/0/elements");
  require_one_line_error(beam([](json& c) {
                           json s = c["structure"]["segments"][0];
                           s["elements"] = 400;
                           s["length_m"] = 0.25;
                           c["structure"]["segments"] = {s, s};
                         }),
                         "800 elements in all");
  require_one_line_error(beam([](json& c) {
                           c["structure"]["point_masses"] = {{{"name", "heavy"}, {"position_m", 0.5}, {"mass_kg", 1e300}}};
                         }),
                         "/structure/point_masses/0/mass_kg");
  require_one_line_error(beam([](json& c) {
                           json supports = json::array();
                           for (int k = 0; k < 200000; ++k) supports.push_back({{"kind", "pinned"}, {"position_m", 0.0}});
                           c["structure"]["supports"] = supports;
                         }),
                         "at most 100");
  require_one_line_error(beam([](json& c) { c["structure"]["damping"]["ratios"] = {1e300}; }), "ratios/0");
  // Checks only the model's construction makes: more modes than one element has, initial
  // amplitudes for more modes than the model keeps.
  require_one_line_error(beam([](json& c) {
                           c["structure"]["segments"][0]["elements"] = 1;
                           c["structure"]["mode_count"] = 100;
                         }),
                         "/structure");
  require_one_line_error(beam([](json& c) {
                           c["task"]["initial_state"] = {{"kind", "modal_amplitudes"}, {"values", std::vector<double>(50, 0.001)}};
                         }),
                         "/task/initial_state");

  const auto modal = [&](const std::function<void(json&)>& edit) {
    return validate_edited(tmp.path, "modal_data_tip_damper.json", [](json&) {}, edit);
  };
  require_one_line_error(modal([](json& m) { m["modal_masses_kg"] = {1e-300}; }), "one_mode_tip.json: /modal_masses_kg/0");
  require_one_line_error(modal([](json& m) { m["frequencies_hz"] = {1e308}; }), "/frequencies_hz/0");
  require_one_line_error(modal([](json& m) { m["damping_ratios"] = 1e300; }), "/damping_ratios");
  require_one_line_error(modal([](json& m) { m["points"]["tip"]["translation_y"] = {1e300}; }), "/points/tip/translation_y/0");
  require_one_line_error(modal([](json& m) { m["frequencies_hz"] = std::vector<double>(200000, 2.0); }), "at most 100");
  // Each number in range, their product not: a 1 mHz mode of 1 mg with a shape of 1e6 released
  // from a 2 N load starts the site 5e22 m out (before, the decay ran to exit 0 with a
  // 2.5e21 m threshold). Refused naming the release, the site and the quantities to check.
  const auto out_of_scale = modal([](json& m) {
    m["frequencies_hz"] = {1e-3};
    m["modal_masses_kg"] = {1e-6};
    m["points"]["tip"]["translation_y"] = {1e6};
  });
  require_one_line_error(out_of_scale, "/task/initial_state");
  CHECK_THAT(out_of_scale.err, Catch::Contains("site 'tip'") && Catch::Contains("modal masses and shapes"));
}

// Reference: a calibration cache that cannot hold the beds is refused before any DEM work,
// naming the flag (once: exit 1 after the whole calibration, or the default cache silently
// used for an empty value).
TEST_CASE("a calibration cache that is a file, empty or not writable is refused before any DEM work", "[cli]") {
  TempDir tmp("calibration_cache_faults");
  const std::string link = case_path("manipulator_link_optimize.json");
  const fs::path file = tmp.path / "a_file";
  { std::ofstream(file) << "x"; }
  require_one_line_error(run_pdamp({"optimize", link, "--calibration-cache", file.string()}),
                         "--calibration-cache: '" + file.string() + "' exists and is not a folder");
  require_one_line_error(run_pdamp({"optimize", link, "--calibration-cache="}), "--calibration-cache: must name a folder");
  require_one_line_error(run_pdamp({"optimize", link, "--calibration-cache", (file / "below").string()}),
                         "--calibration-cache: cannot create");
  // A folder nobody can write in, root included: /proc (a file cannot be created there).
  require_one_line_error(run_pdamp({"optimize", link, "--calibration-cache", "/proc"}),
                         "--calibration-cache: '/proc' is not writable");
}

// Reference: a DEM decay shorter than one period of the fastest mode it releases is refused
// naming the key and the shortest duration (once: exit 3 "the co-simulation returned no
// history" for a verification of 1e-6 s).
TEST_CASE("a DEM decay shorter than a period of the released modes is refused naming its key", "[cli]") {
  TempDir tmp("short_verify");
  std::ifstream in(case_path("cantilever_two_layer_optimize.json"));
  json c = json::parse(in);
  c["task"]["verify"]["duration_s"] = 1e-6;
  c["task"].erase("calibration");
  const fs::path path = tmp.path / "short_verify.json";
  std::ofstream(path) << c.dump(2);
  require_one_line_error(run_pdamp({"optimize", path.string()}), "/task/verify/duration_s: = 1e-06 s: shorter than one period");
}
