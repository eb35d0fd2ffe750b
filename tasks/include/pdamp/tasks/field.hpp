// pdamp field as a study: an effective field of a case's damper over the case's grid, from
// the closed forms, the DEM (a resumable, shardable sweep whose points an Executor spreads)
// or a test rig's CSV; the merge of a sharded sweep; the scattered-state fit of the result.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/scattered_fit.hpp"
#include "pdamp/surrogate/sweep.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// The sweep identity of the case's field for `source` ("formulas" or "dem"): what guards
/// the results log, so a run and a merge of the same field agree on it.
surrogate::SweepOptions field_sweep_options(const case_file::Case& c, const std::string& source);

/// A DEM field's sweep checked before it starts: every point's run as check_dem_run, the
/// memory of `at_once` runs at once, and no point beyond kMaxDemWallTime_s unless
/// `accept_long_runs` (a point is saved only when it ends). Returns the estimate of the work
/// still to do (the points already in the results log of `sweep` excluded; all without `sweep`).
std::string check_dem_field(const case_file::Case& c, std::size_t damper, const surrogate::Grid& grid,
                            const surrogate::SweepOptions* sweep, double at_once, bool accept_long_runs = false);

struct FieldOptions {
  std::string source = "formulas";            ///< "formulas" or "dem"
  std::filesystem::path results_log;          ///< the sweep's JSON-lines log (dem or sharded; resume), else empty
  bool sharded = false;                       ///< --shard I/N given: the log is the result, no field
  int shard_index = 0;                        ///< the nodes k with k % shard_count == shard_index
  int shard_count = 1;
  std::string label = "pdamp field";          ///< names the sweep in notes and progress
  bool accept_long_runs = false;              ///< a point estimated beyond kMaxDemWallTime_s may start
};

/// A field sweep checked before any output.
struct FieldPlan {
  FieldOptions options;
  surrogate::Grid grid;
  surrogate::SweepOptions sweep;
  std::string estimate;  ///< dem: the work still to do
};
/// Every check of the sweep: a grid, a stale or foreign results log, each DEM point's options
/// and memory (InputError naming the case key). `executor` sets how many points run at once.
FieldPlan plan_field(const case_file::Case& c, const FieldOptions& options, const base::Executor& executor);

struct FieldResult {
  std::string case_name;
  surrogate::EffectiveField field;  ///< every node (a shard's: of its own nodes only)
  std::string sweep_report;         ///< "18 points: 6 resumed, 12 computed (0 failed) in 12.3 s"
  surrogate::SweepSummary summary;
  /// dem and measured fields: the scattered-state law fitted to the points below the onset.
  std::optional<surrogate::ScatteredFitResult> scattered_fit;
  std::vector<std::string> warnings;
  nlohmann::json mpi;  ///< how the points spread over processes, or null
};
/// Runs the sweep: the points through `executor` (on a process that serves another:
/// JobsServedElsewhere), progress through `hooks`.
FieldResult run_field(const case_file::Case& c, const FieldPlan& plan, base::RunHooks& hooks, base::Executor& executor);
/// A test rig's CSV on the case's grid spacing and damper (docs/effective_fields.md), read on
/// the primary process alone (on another: base::JobsServedElsewhere).
FieldResult import_measured_field(const case_file::Case& c, const std::filesystem::path& csv,
                                  base::Executor& executor = base::local_executor());
/// The shards' logs of one sweep joined into the field a single run gives; shards of another
/// case, model version or grid are refused naming both files.
FieldResult merge_field(const case_file::Case& c, const std::string& source, const std::vector<std::filesystem::path>& logs);

}  // namespace pdamp::tasks
