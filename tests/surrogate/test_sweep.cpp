// Tests of the sweep engine: parallel evaluation, results file, resume after a kill, stale files.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>

#include "support/temp_dir.hpp"
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/sweep.hpp"
#include "surrogate/hostile_files.hpp"

namespace {

using namespace pdamp::surrogate;
namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;  // standard gravity, m/s^2

using pdamp::test::TempDir;

std::string read_text(const fs::path& path) {
  std::ostringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

std::size_t line_count(const fs::path& path) {
  const std::string text = read_text(path);
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

/// A deterministic stand-in for a DEM run that records every call (thread-safe) and can
/// be told to "die" (throw) on its n-th call, as a killed process would stop.
class RecordingEvaluator {
 public:
  explicit RecordingEvaluator(int die_on_call = 0) : die_on_call_(die_on_call) {}

  FieldPoint operator()(double f, double x) {
    const int call = ++calls_;
    if (call == die_on_call_) throw std::runtime_error("simulated kill");
    FieldPoint p;
    p.eta_star = 0.5 + 0.1 * std::sin(f) + 3.0 * x;
    p.eta_star_stderr = 0.01 * f;
    p.apparent_mass_kg = 0.1 * x;
    p.motion_mode = f < 2.0 ? "rolling" : "scattered";
    p.status = PointStatus::kOk;
    std::lock_guard lock(mutex_);
    finished_.insert({f, x});
    return p;
  }
  int calls() const { return calls_; }
  std::set<std::pair<double, double>> finished() const {
    std::lock_guard lock(mutex_);
    return finished_;
  }

 private:
  int die_on_call_;
  std::atomic<int> calls_{0};
  mutable std::mutex mutex_;
  std::set<std::pair<double, double>> finished_;
};

PointEvaluator by_reference(RecordingEvaluator& evaluator) {
  return [&evaluator](double f, double x) { return evaluator(f, x); };
}

Grid sweep_grid() {
  return Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.0, 3, AxisSpacing::kLinear},
                           {0.005, 0.04, 6, AxisSpacing::kLog});
}

SweepOptions sweep_options(const fs::path& results) {
  SweepOptions options;
  options.results_path = results;
  options.source = FieldSource::kDem;
  options.case_hash = "feedc0ffee123456";
  options.model_version = 4;
  options.clearance_m = 0.04;
  options.bed_mass_kg = 0.74;
  options.threads = 2;
  return options;
}

/// Hooks that hand the progress reports and the stop polls to the test.
struct TestHooks : pdamp::base::RunHooks {
  std::function<void(const pdamp::base::Progress&)> on_progress = [](const pdamp::base::Progress&) {};
  std::function<int()> on_stop = [] { return 0; };
  void progress(const pdamp::base::Progress& p) override { on_progress(p); }
  int stop_requested() override { return on_stop(); }
};

/// The field an uninterrupted run without a results file gives.
EffectiveField reference_field() {
  RecordingEvaluator evaluator;
  SweepOptions options = sweep_options({});
  options.threads = 1;
  return run_sweep(sweep_grid(), by_reference(evaluator), options).field;
}

}  // namespace

TEST_CASE("a sweep evaluates every node once and fills the derived columns", "[surrogate]") {
  RecordingEvaluator evaluator;
  TempDir dir("sweep_plain");
  std::vector<std::size_t> done;
  double first_eta = 0.0;
  SweepOptions options = sweep_options(dir.path / "sweep.jsonl");
  TestHooks hooks;
  hooks.on_progress = [&](const pdamp::base::Progress& p) {
    if (done.empty()) first_eta = p.eta_s;
    done.push_back(static_cast<std::size_t>(p.done));
    CHECK(p.total == 18);
    CHECK(p.counts_points);
    CHECK(p.stage == "points");
    CHECK(p.label.empty());  // the caller names the sweep
  };
  const SweepResult result = run_sweep(sweep_grid(), by_reference(evaluator), options, hooks);
  CHECK(evaluator.calls() == 18);
  CHECK(evaluator.finished().size() == 18);
  CHECK(result.summary.points_computed == 18);
  CHECK(result.summary.points_resumed == 0);
  CHECK(done.size() == 19);  // once at the start, then once per point
  CHECK(done.back() == 18);
  CHECK(std::isnan(first_eta));
  CHECK(line_count(options.results_path) == 19);  // header + one line per point
  CHECK(result.field.validate().empty());
  CHECK(result.field.provenance.case_hash == "feedc0ffee123456");
  CHECK(result.field.provenance.model_version == 4);
  CHECK(result.field.points == reference_field().points);
  CHECK(result.field.clearance_m == 0.04);
  CHECK(result.field.bed_mass_kg == 0.74);
  // Derived columns (docs/theory.md §1): E_diss = η*·½ m_bed (XΩ)², m_app/m_bed.
  const Grid grid = sweep_grid();
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const FieldPoint& p = result.field.points[k];
    const double v = 2 * kPi * grid.coordinate0(k) * grid.coordinate1(k);
    CHECK(p.e_diss_j == Approx(p.eta_star * 0.5 * 0.74 * v * v).epsilon(1e-14));
    CHECK(p.apparent_mass_fraction == Approx(p.apparent_mass_kg / 0.74).epsilon(1e-15));
  }
  CHECK_THAT(result.summary.brief_report(), Catch::StartsWith("18 points: 0 resumed, 18 computed (0 failed)"));
}

TEST_CASE("a killed sweep resumes without recomputing any finished point", "[surrogate]") {
  TempDir dir("sweep_kill");
  const fs::path results = dir.path / "sweep.jsonl";
  const SweepOptions options = sweep_options(results);

  RecordingEvaluator dying(8);  // the 8th call "kills" the run
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(dying), options), "simulated kill");
  const auto first_run = dying.finished();
  // Everything finished before or alongside the kill is on disk (the other thread's
  // point in flight finishes and is saved): 7 or more, one line each after the header.
  CHECK(first_run.size() >= 7);
  CHECK(line_count(results) == 1 + first_run.size());

  RecordingEvaluator second;
  const SweepResult resumed = run_sweep(sweep_grid(), by_reference(second), options);
  CHECK(static_cast<std::size_t>(second.calls()) == 18 - first_run.size());
  for (const auto& point : second.finished()) CHECK(first_run.count(point) == 0);
  CHECK(resumed.summary.points_resumed == first_run.size());
  CHECK(resumed.field.points == reference_field().points);

  // A third run finds everything done and evaluates nothing.
  RecordingEvaluator third;
  CHECK(run_sweep(sweep_grid(), by_reference(third), options).field.points == reference_field().points);
  CHECK(third.calls() == 0);
}

TEST_CASE("a last line cut by a kill is dropped and only that point is recomputed", "[surrogate]") {
  TempDir dir("sweep_truncated");
  const fs::path results = dir.path / "sweep.jsonl";
  RecordingEvaluator first;
  run_sweep(sweep_grid(), by_reference(first), sweep_options(results));
  fs::resize_file(results, fs::file_size(results) - 25);  // mid-way through the last line

  RecordingEvaluator second;
  const SweepResult result = run_sweep(sweep_grid(), by_reference(second), sweep_options(results));
  CHECK(second.calls() == 1);
  CHECK(result.field.points == reference_field().points);
  CHECK(line_count(results) == 19);  // the cut line replaced, not appended after
  CHECK(read_text(results).back() == '\n');
}

TEST_CASE("a results file of another case, model version or grid is refused", "[surrogate]") {
  TempDir dir("sweep_stale");
  const fs::path results = dir.path / "sweep.jsonl";
  RecordingEvaluator first;
  run_sweep(sweep_grid(), by_reference(first), sweep_options(results));
  const std::string before = read_text(results);

  RecordingEvaluator never;
  SweepOptions newer = sweep_options(results);
  newer.model_version = 5;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), newer),
                    Catch::StartsWith(results.string() + ": line 1: this results file belongs to another sweep") &&
                        Catch::Contains("model_version: file 4, this sweep 5") && Catch::Contains("delete or move it"));
  SweepOptions other_case = sweep_options(results);
  other_case.case_hash = "0000000000000000";
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), other_case), Catch::Contains("case_hash"));
  const Grid finer = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.0, 5, AxisSpacing::kLinear},
                                       {0.005, 0.04, 6, AxisSpacing::kLog});
  CHECK_THROWS_WITH(run_sweep(finer, by_reference(never), sweep_options(results)),
                    Catch::Contains("axes: file other axes"));
  CHECK(never.calls() == 0);
  CHECK(read_text(results) == before);  // a refused file is left as it was
}

TEST_CASE("a damaged line inside the results file is an error, not silently skipped", "[surrogate]") {
  TempDir dir("sweep_damaged");
  const fs::path results = dir.path / "sweep.jsonl";
  RecordingEvaluator first;
  run_sweep(sweep_grid(), by_reference(first), sweep_options(results));
  const std::string original = read_text(results);
  std::string text = original;
  const auto third_line = text.find('\n', text.find('\n') + 1) + 1;
  text.replace(third_line, 10, "#garbage##");
  std::ofstream(results) << text;
  RecordingEvaluator never;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(results)),
                    Catch::Contains("line 3: malformed JSON") && Catch::Contains("damaged"));

  // A complete line for a node the grid does not have.
  std::ofstream(results) << original << R"({"index": 99})"
                         << "\n";
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(results)),
                    Catch::Contains("line 20: /index: 99 must be in [0, 17]") && Catch::Contains("damaged"));
  CHECK(never.calls() == 0);

  // A point whose η* is outside the field's physical range (field_value_problem): refused as
  // the field file's reader refuses it, so no merge or resume takes it in.
  std::string out_of_range = original;
  const auto eta = out_of_range.find("\"eta_star\":", third_line);
  const auto end = out_of_range.find(',', eta);
  out_of_range.replace(eta, end - eta, "\"eta_star\":1e300");
  std::ofstream(results) << out_of_range;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(results)),
                    Catch::Contains("line 3: /eta_star") && Catch::Contains("must be in [-1, 100]"));
}

TEST_CASE("a second sweep on the same results file at the same time is refused", "[surrogate]") {
  TempDir dir("sweep_lock");
  const fs::path results = dir.path / "sweep.jsonl";
  std::string nested_error;
  PointEvaluator evaluator = [&](double f, double x) {
    if (nested_error.empty()) {
      RecordingEvaluator inner;
      try {
        run_sweep(sweep_grid(), by_reference(inner), sweep_options(results));
        nested_error = "none";
      } catch (const std::runtime_error& e) {
        nested_error = e.what();
      }
    }
    return RecordingEvaluator()(f, x);
  };
  SweepOptions options = sweep_options(results);
  options.threads = 1;
  run_sweep(sweep_grid(), evaluator, options);
  CHECK_THAT(nested_error, Catch::Contains("another sweep is writing this results file"));
}

TEST_CASE("failed points are recorded, kept on resume and counted", "[surrogate]") {
  TempDir dir("sweep_failed");
  const fs::path results = dir.path / "sweep.jsonl";
  std::atomic<int> calls{0};
  const PointEvaluator evaluator = [&](double f, double x) {
    ++calls;
    FieldPoint p = RecordingEvaluator()(f, x);
    if (f == 3.0 && x == 0.04) {
      p.status = PointStatus::kFailed;
      p.motion_mode = "unstable time step";
    }
    return p;
  };
  const SweepResult result = run_sweep(sweep_grid(), evaluator, sweep_options(results));
  CHECK(result.summary.points_failed == 1);
  const FieldPoint& failed = result.field.points.back();
  CHECK(failed.status == PointStatus::kFailed);
  CHECK(std::isnan(failed.eta_star));
  CHECK(failed.motion_mode == "unstable time step");
  const SweepResult again = run_sweep(sweep_grid(), evaluator, sweep_options(results));
  CHECK(calls == 18);
  CHECK(again.field.points == result.field.points);
}

TEST_CASE("an evaluator breaking its contract stops the sweep with a clear error", "[surrogate]") {
  SweepOptions options = sweep_options({});
  const PointEvaluator nan_ok = [](double, double) {
    FieldPoint p;
    p.status = PointStatus::kOk;
    return p;
  };
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), nan_ok, options),
                    Catch::Contains("returned status \"ok\" with eta_star = nan"));
  const PointEvaluator missing = [](double, double) { return FieldPoint{}; };
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), missing, options), Catch::Contains("returned status \"missing\""));
  options.threads = 0;
  options.bed_mass_kg = -1.0;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), missing, options), Catch::Contains("bed_mass_kg = -1: must be > 0") &&
                                                                   Catch::Contains("threads = 0: must be in [1, 256]"));
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), PointEvaluator{}, sweep_options({})), Catch::Contains("must be callable"));
}

TEST_CASE("an intensity-stroke sweep drives the evaluator at the nodes' gamma and X/h", "[surrogate]") {
  const Grid grid = Grid::from_ranges(GridAxes::kIntensityStrokeOverClearance, {0.2, 2.0, 3, AxisSpacing::kLog},
                                      {0.1, 0.6, 4, AxisSpacing::kLinear});
  const double h = 0.05;
  const PointEvaluator evaluator = [&](double f, double x) {
    FieldPoint p;
    // Record the evaluator's view of Γ and X/h, computed from the definitions.
    p.eta_star = x * (2 * kPi * f) * (2 * kPi * f) / kG;
    p.apparent_mass_kg = x / h;
    p.status = PointStatus::kOk;
    return p;
  };
  SweepOptions options = sweep_options({});
  options.clearance_m = h;
  const SweepResult result = run_sweep(grid, evaluator, options);
  for (std::size_t k = 0; k < grid.size(); ++k) {
    CHECK(result.field.points[k].eta_star == Approx(grid.coordinate0(k)).epsilon(1e-13));
    CHECK(result.field.points[k].apparent_mass_kg == Approx(grid.coordinate1(k)).epsilon(1e-15));
  }
}

TEST_CASE("a last line cut at any byte by a kill is dropped with a warning and its point recomputed", "[surrogate]") {
  TempDir dir("sweep_cut_anywhere");
  const fs::path results = dir.path / "sweep.jsonl";
  RecordingEvaluator first;
  const SweepResult complete = run_sweep(sweep_grid(), by_reference(first), sweep_options(results));
  CHECK(complete.summary.warnings.empty());
  const std::string original = read_text(results);
  const std::size_t last_line = original.rfind('\n', original.size() - 2) + 1;
  // Every cut a SIGTERM during the append can leave: from 1 byte of the line to all of
  // it but the newline (a write is never reordered, so only a prefix reaches the file).
  for (std::size_t kept = 1; kept < original.size() - last_line; ++kept) {
    std::ofstream(results, std::ios::binary | std::ios::trunc) << original.substr(0, last_line + kept);
    RecordingEvaluator again;
    const SweepResult result = run_sweep(sweep_grid(), by_reference(again), sweep_options(results));
    INFO("kept " << kept << " bytes of the last line");
    CHECK(again.calls() == 1);
    CHECK(result.summary.points_resumed == 17);
    CHECK(result.field.points == reference_field().points);
    REQUIRE(result.summary.warnings.size() == 1);
    CHECK_THAT(result.summary.warnings[0],
               Catch::Equals(results.string() + ": line 19: cut short (" + std::to_string(kept) +
                             " bytes without a newline, the write of a killed run); dropped, its point is computed "
                             "again"));
    CHECK(line_count(results) == 19);
    CHECK(read_text(results).back() == '\n');
  }
  // A header cut short: nothing was saved, the file starts again.
  std::ofstream(results, std::ios::binary | std::ios::trunc) << original.substr(0, 30);
  RecordingEvaluator restart;
  const SweepResult restarted = run_sweep(sweep_grid(), by_reference(restart), sweep_options(results));
  CHECK(restart.calls() == 18);
  REQUIRE(restarted.summary.warnings.size() == 1);
  CHECK_THAT(restarted.summary.warnings[0], Catch::Contains("line 1: cut short (30 bytes") &&
                                                Catch::EndsWith("dropped, the sweep starts again"));
  CHECK(line_count(results) == 19);
}

TEST_CASE("a damaged line before a cut last line is still an error, as is a repeated key", "[surrogate]") {
  TempDir dir("sweep_damaged_and_cut");
  const fs::path results = dir.path / "sweep.jsonl";
  RecordingEvaluator first;
  run_sweep(sweep_grid(), by_reference(first), sweep_options(results));
  const std::string original = read_text(results);
  // Line 5 emptied of its closing brace (a torn write in the middle cannot come from a
  // kill of the appending process) and the last line cut.
  std::string text = original.substr(0, original.size() - 10);
  std::size_t line5 = 0;
  for (int k = 0; k < 4; ++k) line5 = text.find('\n', line5) + 1;
  const std::size_t end5 = text.find('\n', line5);
  text.erase(end5 - 1, 1);
  std::ofstream(results, std::ios::binary | std::ios::trunc) << text;
  RecordingEvaluator never;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(results)),
                    Catch::StartsWith(results.string() + ": line 5: malformed JSON: ") &&
                        Catch::EndsWith("the results file is damaged; delete or move it to start the sweep again"));
  CHECK_THROWS_WITH(pending_sweep_points(sweep_grid(), sweep_options(results)),
                    Catch::Contains("line 5: malformed JSON"));
  CHECK(read_text(results) == text);  // a refused file is left as it was, cut line included

  // A repeated key: the parser would keep the second value silently.
  text = original;
  const std::size_t line3 = text.find('\n', text.find('\n') + 1) + 1;
  text.insert(line3 + 1, R"("index":0,)");
  std::ofstream(results, std::ios::binary | std::ios::trunc) << text;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(results)),
                    Catch::Contains("line 3: /index: duplicate key") && Catch::Contains("damaged"));
  CHECK(never.calls() == 0);
}

TEST_CASE("progress is reported once before the first point is evaluated", "[surrogate]") {
  TempDir dir("sweep_first_progress");
  const fs::path results = dir.path / "sweep.jsonl";
  struct Call {
    std::size_t done, total;
    double eta_s;
    int evaluations_before;
  };
  std::vector<Call> calls;
  std::atomic<int> evaluations{0};
  const PointEvaluator evaluator = [&](double f, double x) {
    ++evaluations;
    return RecordingEvaluator()(f, x);
  };
  SweepOptions options = sweep_options(results);
  options.threads = 1;
  TestHooks hooks;
  hooks.on_progress = [&](const pdamp::base::Progress& p) {
    calls.push_back({static_cast<std::size_t>(p.done), static_cast<std::size_t>(p.total), p.eta_s, evaluations.load()});
  };
  run_sweep(sweep_grid(), evaluator, options, hooks);
  REQUIRE(calls.size() == 19);
  CHECK(calls[0].done == 0);
  CHECK(calls[0].total == 18);
  CHECK(std::isnan(calls[0].eta_s));
  CHECK(calls[0].evaluations_before == 0);  // the user sees "0 of 18" before the first (long) point
  // Resumed with 4 points missing: the first line says what is already done.
  std::string text = read_text(results);
  for (int k = 0; k < 4; ++k) text.erase(text.rfind('\n', text.size() - 2) + 1);
  std::ofstream(results, std::ios::binary | std::ios::trunc) << text;
  calls.clear();
  evaluations = 0;
  run_sweep(sweep_grid(), evaluator, options, hooks);
  REQUIRE(calls.size() == 5);
  CHECK(calls[0].done == 14);
  CHECK(calls[0].evaluations_before == 0);
  CHECK(calls[4].done == 18);
}

TEST_CASE("a stop request or a throwing progress report stops new points, and the sweep resumes", "[surrogate]") {
  TempDir dir("sweep_stop");
  const fs::path results = dir.path / "sweep.jsonl";
  const SweepOptions options = sweep_options(results);
  // Asked to stop (a signal arrived) once 5 points are saved: no point starts after that, the
  // points in flight finish and are saved, and the sweep throws Interrupted with the signal.
  RecordingEvaluator first;
  TestHooks hooks;
  std::atomic<std::size_t> saved{0};
  hooks.on_progress = [&](const pdamp::base::Progress& p) { saved = static_cast<std::size_t>(p.done); };
  hooks.on_stop = [&] { return saved >= 5 ? 2 : 0; };
  try {
    run_sweep(sweep_grid(), by_reference(first), options, hooks);
    FAIL("the sweep did not stop");
  } catch (const pdamp::base::Interrupted& e) {
    CHECK(e.signal_number() == 2);
    CHECK_THAT(e.what(), Catch::Contains("finished points are saved in") && Catch::Contains("sweep.jsonl"));
  }
  const auto first_run = first.finished();
  CHECK(first_run.size() >= 5);
  CHECK(first_run.size() <= 6);  // the other thread's point in flight
  CHECK(line_count(results) == 1 + first_run.size());
  // Without a results file the sweep says nothing was kept.
  TestHooks stopping;
  stopping.on_stop = [] { return 15; };
  RecordingEvaluator none;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(none), sweep_options({}), stopping),
                    Catch::Contains("signal 15") && Catch::Contains("nothing was kept"));
  CHECK(none.calls() == 0);

  // A progress report that throws stops new points the same way; its exception reaches the caller.
  RecordingEvaluator second;
  TestHooks throwing;
  int reports = 0;
  throwing.on_progress = [&](const pdamp::base::Progress&) {
    if (++reports == 3) throw std::runtime_error("progress says stop");
  };
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(second), options, throwing), "progress says stop");
  CHECK(first.finished().size() + second.finished().size() < 18);

  // Resumed: only the points never saved are computed, and the field is the serial run's.
  RecordingEvaluator third;
  const SweepResult resumed = run_sweep(sweep_grid(), by_reference(third), options);
  CHECK(resumed.summary.points_resumed == first.finished().size() + second.finished().size());
  for (const auto& point : third.finished()) CHECK(first_run.count(point) == 0);
  CHECK(resumed.field.points == reference_field().points);
}

TEST_CASE("pending_sweep_points counts the nodes a run would still evaluate", "[surrogate]") {
  TempDir dir("sweep_pending");
  const fs::path results = dir.path / "sweep.jsonl";
  CHECK(pending_sweep_points(sweep_grid(), sweep_options({})) == 18);
  CHECK(pending_sweep_points(sweep_grid(), sweep_options(results)) == 18);  // no file yet
  CHECK_FALSE(fs::exists(results));                                         // and none created
  RecordingEvaluator dying(8);
  CHECK_THROWS(run_sweep(sweep_grid(), by_reference(dying), sweep_options(results)));
  const std::size_t saved = line_count(results) - 1;
  CHECK(pending_sweep_points(sweep_grid(), sweep_options(results)) == 18 - saved);
  fs::resize_file(results, fs::file_size(results) - 5);  // the last saved point cut: computed again
  const std::string cut = read_text(results);
  CHECK(pending_sweep_points(sweep_grid(), sweep_options(results)) == 18 - saved + 1);
  CHECK(read_text(results) == cut);  // read only: the cut line is still there
  SweepOptions other = sweep_options(results);
  other.model_version = 5;
  CHECK_THROWS_WITH(pending_sweep_points(sweep_grid(), other), Catch::Contains("belongs to another sweep"));
  other = sweep_options(results);
  other.threads = 0;
  CHECK_THROWS_WITH(pending_sweep_points(sweep_grid(), other), Catch::Contains("threads = 0"));
  Grid huge = sweep_grid();
  huge.axis0 = Axis::from_range(AxisQuantity::kFrequencyHz, {1.0, 3.0, 2000, AxisSpacing::kLinear});
  huge.axis1 = Axis::from_range(AxisQuantity::kAmplitudeM, {0.005, 0.04, 2000, AxisSpacing::kLog});
  CHECK_THROWS_WITH(pending_sweep_points(huge, sweep_options({})),
                    Catch::Contains("2000 x 2000 = 4000000 nodes: must be <= 1000000"));
  CHECK_THROWS_WITH(run_sweep(huge, by_reference(dying), sweep_options({})),
                    Catch::Contains("2000 x 2000 = 4000000 nodes: must be <= 1000000"));
}

TEST_CASE("a directory or a FIFO given as the results file is refused at once, naming it", "[surrogate]") {
  TempDir dir("sweep_hostile");
  RecordingEvaluator never;
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(dir.path)),
                    Catch::Equals(dir.path.string() + ": is a directory, not a sweep results file"));
  CHECK_THROWS_WITH(pending_sweep_points(sweep_grid(), sweep_options(dir.path)),
                    Catch::Equals(dir.path.string() + ": is a directory, not a file"));
  const fs::path fifo = dir.path / "sweep.jsonl";
  pdamp::test::make_fifo(fifo);
  // The old sweep opened the FIFO read-write, then blocked reading it; the guard turns that
  // into a failure instead of a hung test.
  CHECK(pdamp::test::invalid_argument_within_timeout(
            [&] { run_sweep(sweep_grid(), by_reference(never), sweep_options(fifo)); }, fifo) ==
        fifo.string() + ": is not a regular file (a FIFO, socket or device); a sweep results file must be one");
  CHECK(pdamp::test::invalid_argument_within_timeout(
            [&] { pending_sweep_points(sweep_grid(), sweep_options(fifo)); }, fifo) ==
        fifo.string() + ": is a FIFO (named pipe), not a file");
  CHECK(never.calls() == 0);
}

// ---------------------------------------------------------------- shards (job arrays)

namespace {

/// Runs shard `index` of `count` of the test sweep into `results` and returns it.
SweepResult run_shard(RecordingEvaluator& evaluator, const fs::path& results, int index, int count) {
  SweepOptions options = sweep_options(results);
  options.shard_index = index;
  options.shard_count = count;
  return run_sweep(sweep_grid(), by_reference(evaluator), options);
}

/// "s<i>.jsonl", built with += (GCC 12 warns falsely, -Wrestrict, on "s" + to_string(i)).
std::string shard_log_name(int i) {
  std::string name = "s";
  name += std::to_string(i);
  name += ".jsonl";
  return name;
}

/// The three shard logs of the test sweep, each run to the end, in dir/s<i>.jsonl.
std::vector<fs::path> three_shards(const fs::path& dir) {
  std::vector<fs::path> logs;
  for (int i = 0; i < 3; ++i) {
    RecordingEvaluator evaluator;
    logs.push_back(dir / shard_log_name(i));
    run_shard(evaluator, logs.back(), i, 3);
  }
  return logs;
}

/// `path` with every occurrence of `from` in its first line replaced by `to`.
void edit_header(const fs::path& path, const std::string& from, const std::string& to) {
  std::string text = read_text(path);
  const std::size_t at = text.find(from);
  REQUIRE(at < text.find('\n'));
  text.replace(at, from.size(), to);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

}  // namespace

TEST_CASE("shards partition the grid: every node in exactly one, interleaved", "[surrogate]") {
  TempDir dir("sweep_shards");
  std::set<std::pair<double, double>> seen;
  std::size_t evaluated = 0;
  for (int i = 0; i < 4; ++i) {  // 18 nodes over 4 shards: 5, 5, 4, 4
    RecordingEvaluator evaluator;
    const SweepResult result = run_shard(evaluator, dir.path / shard_log_name(i), i, 4);
    CHECK(result.summary.points_total == (i < 2 ? 5u : 4u));
    CHECK(static_cast<std::size_t>(evaluator.calls()) == result.summary.points_total);
    evaluated += evaluator.finished().size();
    for (const auto& point : evaluator.finished()) CHECK(seen.insert(point).second);  // disjoint
    for (std::size_t k = 0; k < 18; ++k) {
      // The shard's nodes are filled, the others left missing (not a full field).
      CHECK((result.field.points[k].status == PointStatus::kMissing) == !in_shard(k, i, 4));
    }
  }
  CHECK(evaluated == 18);
  CHECK(seen.size() == 18);  // the union is the grid
}

TEST_CASE("merging the shard logs gives the serial sweep's field point for point", "[surrogate]") {
  TempDir dir("sweep_merge");
  std::vector<fs::path> logs = three_shards(dir.path);
  std::reverse(logs.begin(), logs.end());  // any order
  const SweepResult merged = merge_sweep_shards(sweep_grid(), sweep_options({}), logs);
  CHECK(merged.field.points == reference_field().points);
  CHECK(merged.field.validate().empty());
  CHECK(merged.field.provenance.case_hash == "feedc0ffee123456");
  CHECK(merged.field.provenance.model_version == 4);
  CHECK(merged.summary.points_total == 18);
  CHECK(merged.summary.points_computed == 0);
  // A log of the whole grid is a merge of one shard (0/1).
  RecordingEvaluator whole;
  run_sweep(sweep_grid(), by_reference(whole), sweep_options(dir.path / "whole.jsonl"));
  CHECK(merge_sweep_shards(sweep_grid(), sweep_options({}), {dir.path / "whole.jsonl"}).field.points ==
        reference_field().points);
}

TEST_CASE("a stopped shard resumes as the same shard only", "[surrogate]") {
  TempDir dir("sweep_shard_resume");
  const fs::path log = dir.path / "s1.jsonl";
  RecordingEvaluator dying(4);
  CHECK_THROWS_WITH(run_shard(dying, log, 1, 3), "simulated kill");
  const std::size_t saved = dying.finished().size();
  CHECK(saved >= 3);
  // Another shard, or the whole grid, on its log is refused: its points are not theirs.
  RecordingEvaluator never;
  CHECK_THROWS_WITH(run_shard(never, log, 2, 3), Catch::Contains("belongs to another sweep") && Catch::Contains("shard"));
  CHECK_THROWS_WITH(run_sweep(sweep_grid(), by_reference(never), sweep_options(log)), Catch::Contains("shard"));
  CHECK(never.calls() == 0);
  SweepOptions options = sweep_options(log);
  options.shard_index = 1;
  options.shard_count = 3;
  CHECK(pending_sweep_points(sweep_grid(), options) == 6 - saved);
  RecordingEvaluator second;
  const SweepResult resumed = run_shard(second, log, 1, 3);
  CHECK(resumed.summary.points_resumed == saved);
  CHECK(static_cast<std::size_t>(second.calls()) == 6 - saved);
}

TEST_CASE("shard options outside their range are refused", "[surrogate]") {
  SweepOptions options = sweep_options({});
  options.shard_count = 3;
  options.shard_index = 3;
  CHECK_THAT(options.validate().at(0), Catch::Contains("shard_index = 3: must be in [0, 2]"));
  options.shard_count = 0;
  CHECK_THAT(options.validate().at(0), Catch::Contains("shard_count = 0: must be in [1, 100000]"));
  options.shard_count = kMaxShards + 1;
  CHECK(options.validate().size() == 1);
}

TEST_CASE("merge refuses shards of different sweeps naming both files", "[surrogate]") {
  TempDir dir("sweep_merge_mismatch");
  const std::vector<fs::path> logs = three_shards(dir.path);
  const std::string a = logs[0].string(), b = logs[1].string(), c = logs[2].string();

  SECTION("model version") {
    edit_header(logs[1], "\"model_version\":4", "\"model_version\":5");
    CHECK_THROWS_WITH(merge_sweep_shards(sweep_grid(), sweep_options({}), logs),
                      Catch::StartsWith(a + " and " + b + ": are not shards of one sweep") &&
                          Catch::Contains("model_version: " + a + " 4, " + b + " 5"));
  }
  SECTION("case hash") {
    edit_header(logs[2], "feedc0ffee123456", "0000000000000000");
    CHECK_THROWS_WITH(merge_sweep_shards(sweep_grid(), sweep_options({}), logs),
                      Catch::Contains(a + " and " + c) && Catch::Contains("case_hash"));
  }
  SECTION("grid") {
    RecordingEvaluator evaluator;
    SweepOptions options = sweep_options(dir.path / "other_grid.jsonl");
    options.shard_index = 1;
    options.shard_count = 3;
    const Grid other = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.5, 3, AxisSpacing::kLinear},
                                         {0.005, 0.04, 6, AxisSpacing::kLog});
    run_sweep(other, by_reference(evaluator), options);
    CHECK_THROWS_WITH(merge_sweep_shards(sweep_grid(), sweep_options({}), {logs[0], options.results_path, logs[2]}),
                      Catch::Contains(a + " and " + options.results_path.string()) &&
                          Catch::Contains("axes: " + a + " other axes"));
  }
  SECTION("the expected sweep") {
    SweepOptions expected = sweep_options({});
    expected.case_hash = "1111111111111111";
    CHECK_THROWS_WITH(merge_sweep_shards(sweep_grid(), expected, logs, "case.json"),
                      Catch::StartsWith(a + ": line 1: is a shard of another sweep than case.json") &&
                          Catch::Contains("case_hash: " + a + " \"feedc0ffee123456\", case.json \"1111111111111111\""));
  }
}

TEST_CASE("merge refuses a missing, repeated, foreign-count, incomplete or damaged shard", "[surrogate]") {
  TempDir dir("sweep_merge_shards");
  const std::vector<fs::path> logs = three_shards(dir.path);
  const auto merge = [](const std::vector<fs::path>& files) {
    return merge_sweep_shards(sweep_grid(), sweep_options({}), files);
  };
  CHECK_THROWS_WITH(merge({logs[0], logs[2]}), "shard 1 of 3 is missing (2 of 3 shard files given)");
  CHECK_THROWS_WITH(merge({logs[0], logs[1], logs[1], logs[2]}),
                    logs[1].string() + " and " + logs[1].string() + ": both are shard 1/3; give each shard once");
  RecordingEvaluator evaluator;
  const fs::path quarter = dir.path / "q.jsonl";
  run_shard(evaluator, quarter, 1, 4);
  CHECK_THROWS_WITH(merge({logs[0], quarter}), logs[0].string() + " is shard 0/3 but " + quarter.string() +
                                                   " is shard 1/4: the shard counts differ");
  SECTION("incomplete") {
    fs::resize_file(logs[1], fs::file_size(logs[1]) - 25);  // a cut last line: that point is not saved
    CHECK_THROWS_WITH(merge(logs), Catch::StartsWith(logs[1].string() + ": shard 1/3 is incomplete (5 of 6 points saved)"));
  }
  SECTION("damaged line") {
    std::string text = read_text(logs[2]);
    const std::size_t third_line = text.find('\n', text.find('\n') + 1) + 1;
    text.replace(third_line, 1, "[");
    std::ofstream(logs[2], std::ios::binary | std::ios::trunc) << text;
    CHECK_THROWS_WITH(merge(logs), Catch::StartsWith(logs[2].string() + ": line 3"));
  }
  SECTION("a node of another shard") {
    // Shard 1's first point (node 1) copied into shard 0's log.
    const std::string one = read_text(logs[1]);
    const std::size_t begin = one.find('\n') + 1;
    std::ofstream(logs[0], std::ios::binary | std::ios::app) << one.substr(begin, one.find('\n', begin) + 1 - begin);
    CHECK_THROWS_WITH(merge(logs), Catch::StartsWith(logs[0].string() + ": line 8") &&
                                       Catch::Contains("is not a node of shard 0/3"));
  }
  SECTION("not a sweep log") {
    std::ofstream(logs[0], std::ios::trunc) << "{\"format\": \"pdamp.effective_field\"}\n";
    CHECK_THROWS_WITH(merge(logs), Catch::StartsWith(logs[0].string() + ": line 1: not a sweep results file"));
    std::ofstream(logs[0], std::ios::trunc) << "";
    CHECK_THROWS_WITH(merge(logs), Catch::Contains("no complete sweep header"));
  }
}

// A list of points (a sensitivity study's variants) instead of a grid: the same machinery.
namespace {

SweepPoints five_variants() {
  SweepPoints points;
  points.identity = nlohmann::json::array();
  for (int k = 0; k < 5; ++k) {
    points.drives.push_back({2.0, 0.04});  // one design drive for every variant
    points.identity.push_back({{"parameter", "friction"}, {"value", 0.1 * (k + 1)}});
  }
  return points;
}

/// η* = the variant's index, so every saved point names its variant.
FieldPoint variant_point(std::size_t k) {
  FieldPoint p;
  p.eta_star = static_cast<double>(k);
  p.eta_star_stderr = 0.0;
  p.motion_mode = "variant " + std::to_string(k);
  p.status = PointStatus::kOk;
  return p;
}

}  // namespace

// Reference: the index itself (variant_point): a killed study resumes without recomputing,
// its log refuses another list, and its shards merge into the serial result.
TEST_CASE("a list of points sweeps, resumes, shards and merges like a grid", "[surrogate]") {
  const TempDir dir("point_sweep");
  const SweepPoints points = five_variants();
  SweepOptions options = sweep_options(dir.path / "study.jsonl");
  std::atomic<int> calls{0};
  const auto dying = [&](std::size_t k) {
    if (++calls == 3) throw std::runtime_error("simulated kill");
    return variant_point(k);
  };
  options.threads = 1;
  CHECK_THROWS_WITH(run_point_sweep(points, dying, options), "simulated kill");
  CHECK(pending_point_sweep(points, options) == 3);
  calls = 10;  // no more kills
  const PointSweepResult r = run_point_sweep(points, dying, options);
  CHECK(r.summary.points_resumed == 2);
  CHECK(r.summary.points_computed == 3);
  REQUIRE(r.points.size() == 5);
  for (std::size_t k = 0; k < 5; ++k) CHECK(r.points[k].eta_star == static_cast<double>(k));

  // Another list (one value changed) does not resume this log.
  SweepPoints other = points;
  other.identity[4]["value"] = 0.55;
  CHECK_THROWS_WITH(run_point_sweep(other, variant_point, options), Catch::Contains("belongs to another sweep"));

  // Two shards, merged: the serial result.
  std::vector<fs::path> logs;
  for (int shard = 0; shard < 2; ++shard) {
    SweepOptions part = sweep_options(dir.path / ("shard" + std::to_string(shard) + ".jsonl"));
    part.shard_index = shard;
    part.shard_count = 2;
    const PointSweepResult s = run_point_sweep(points, variant_point, part);
    CHECK(s.summary.points_total == (shard == 0 ? 3u : 2u));
    logs.push_back(part.results_path);
  }
  const PointSweepResult merged = merge_point_sweep_shards(points, sweep_options({}), logs, "the study");
  for (std::size_t k = 0; k < 5; ++k) CHECK(merged.points[k].eta_star == static_cast<double>(k));
  CHECK_THROWS_WITH(merge_point_sweep_shards(other, sweep_options({}), logs, "the other study"),
                    Catch::Contains("is a shard of another sweep than the other study"));
  SweepPoints empty;
  CHECK_THROWS_WITH(run_point_sweep(empty, variant_point, options), Catch::Contains("drives: must hold at least one point"));
}
