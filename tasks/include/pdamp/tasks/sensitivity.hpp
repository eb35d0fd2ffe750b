// pdamp sensitivity as a study: eta* and the motion mode of a case's damper with one
// parameter changed at a time (the case's sensitivity section or a default study), each
// variant a DEM run (or the closed form) at one drive, as a resumable, shardable sweep
// whose variants an Executor spreads.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/record.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/surrogate/sweep.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// A study: its drive, its variants and the sweep's points.
struct SensitivityStudy {
  double frequency_hz = 0.0;  ///< the section's, else the excitation's, Hz
  double amplitude_m = 0.0;   ///< the section's, else the excitation's stroke, else the design stroke, m
  std::vector<case_file::SensitivityVariant> variants;  ///< the baseline first
  surrogate::SweepPoints points;
  std::vector<std::string> warnings;  ///< default values the case refuses, left out
};
SensitivityStudy sensitivity_study(const case_file::Case& c);

struct SensitivityOptions {
  std::string source = "dem";           ///< "dem" or "formulas"
  std::filesystem::path results_log;   ///< the sweep's JSON-lines log (dem or sharded; resume), else empty
  bool sharded = false;                 ///< --shard I/N given
  int shard_index = 0;
  int shard_count = 1;
  std::string label = "pdamp sensitivity";
  bool accept_long_runs = false;        ///< a run estimated beyond kMaxDemWallTime_s may start
};

/// A study checked before any output: every variant's DEM options and cost.
struct SensitivityPlan {
  SensitivityOptions options;
  SensitivityStudy study;
  surrogate::SweepOptions sweep;
  std::string estimate;  ///< dem: the runs still to do and their cost
};
SensitivityPlan plan_sensitivity(const case_file::Case& c, const SensitivityOptions& options, const base::Executor& executor);

/// One variant's row (NaN where a value is not defined: the baseline's value, a failed run).
struct SensitivityRow {
  std::string parameter;  ///< "baseline" first, then friction, restitution, ...
  double value = 0.0;     ///< the parameter's value (NaN for the baseline)
  std::string unit;
  std::string status;     ///< ok, failed or missing (another shard's)
  double eta_star = 0.0, eta_star_stderr = 0.0, delta_eta_star = 0.0;
  std::string motion_mode;
  double apparent_mass_fraction = 0.0;
  double closed_form_eta_star = 0.0;
  std::string closed_form_regime;
  double clearance_m = 0.0, bed_mass_kg = 0.0, intensity = 0.0;
  static const base::Fields<SensitivityRow>& fields();
};

struct SensitivityResult {
  std::string case_name;
  std::string source;
  double frequency_hz = 0.0, amplitude_m = 0.0;
  std::vector<SensitivityRow> rows;
  double baseline_eta_star = 0.0;  ///< NaN when the baseline failed
  std::string sweep_report;
  std::vector<std::string> warnings;
  nlohmann::json mpi;  ///< how the variants spread over processes, or null
};
/// One parameter's bar of the tornado plot: the lowest and highest η* over its values, the
/// values that gave them and their standard errors, and its effect, the farthest either
/// moves η* from the baseline's.
struct TornadoBar {
  std::string parameter;
  double low = 0.0, high = 0.0;                 ///< η*
  double value_at_low = 0.0, value_at_high = 0.0;
  double stderr_at_low = 0.0, stderr_at_high = 0.0;
  double effect = 0.0;                          ///< max |η* − η*_baseline| over the values
  static const base::Fields<TornadoBar>& fields();
};
struct Tornado {
  std::vector<TornadoBar> bars;                 ///< with an effect, smallest first (drawn bottom up)
  /// Parameters whose every value gives the baseline's η* to round-off: the closed forms
  /// (source formulas) do not depend on them, so they get no flat bar.
  std::vector<std::string> without_effect;
};
/// The bars of `result`'s rows (the failed and missing ones left out).
Tornado tornado(const SensitivityResult& result);

SensitivityResult run_sensitivity(const case_file::Case& c, const SensitivityPlan& plan, base::RunHooks& hooks,
                                  base::Executor& executor);
/// The shards of one study joined into the rows a single run gives.
SensitivityResult merge_sensitivity(const case_file::Case& c, const std::string& source,
                                    const std::vector<std::filesystem::path>& logs);
/// The result keys (case, source, frequency_hz, amplitude_m, rows, tornado, without_effect, sweep).
nlohmann::json to_json(const SensitivityResult& result);

}  // namespace pdamp::tasks
