// What the subcommands print and write: the output folder, the end every command shares
// (result JSON, resolved case, report, commit, warnings, the result on stdout), tables.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/report/html_report.hpp"
#include "pdamp/report/output_dir.hpp"
#include "pdamp/tasks/output_folder.hpp"

namespace pdamp::cli {

using Rows = std::vector<std::pair<std::string, std::string>>;
using report::format_number;

/// Two-column "name  value" table for the readable (non --json) output.
std::string key_value_table(const Rows& rows);
/// One line each on stderr, "pdamp: warning: ...", made printable.
void print_warnings(const std::vector<std::string>& warnings);

/// Whether this process writes the results: the executor's primary process (under mpirun
/// rank 0; the other ranks only compute the jobs they are sent). The one place cli/ asks.
bool writes_results(const CommandContext& context);
/// The -o folder, checked before any work (report::OutputDir), or none: without -o, and on
/// a process that writes nothing (writes_results).
std::unique_ptr<report::OutputDir> output_dir(const ParsedArgs& args, const CommandContext& context);
/// A study's folder `dir` (field, sensitivity: always one), with `in_place` (a results log
/// the study writes into it as it goes) when not empty; none on a process that writes nothing.
std::unique_ptr<report::OutputDir> study_dir(const std::string& dir, const CommandContext& context,
                                             const std::string& in_place = "");
/// Where a task's result JSON says its files are.
tasks::OutputFolder output_folder(const report::OutputDir* files);

/// The end of a checkpointed DEM run (dem, decay --method dem, the verification of
/// optimize and run), whose signals are deferred from its start to its commit (the
/// command holds a report::DeferredSignals that long): the run is complete, so a signal
/// from now on waits until its results are committed instead of abandoning them
/// (report::OutputDir::finish_despite_signals); a test may pause here ("run-ended"). Without
/// files (a process that writes nothing) there is nothing to commit.
void dem_results_ready(report::OutputDir* files);
/// After the commit into `files`: the run's checkpoints go, its results being kept. Without
/// files nothing was committed (no -o, or a process that writes nothing): they stay.
void remove_checkpoints(const report::OutputDir* files, const std::vector<std::filesystem::path>& checkpoints);

/// How a command ends.
struct ResultFiles {
  std::string json_name;                      ///< the result JSON's file name ("decay.json"); empty: none
  const case_file::Case* resolved = nullptr;  ///< also case_resolved.json
  bool report = false;                        ///< also report.html (of this case)
  const char* paths_key = "outputs";          ///< the key of the written paths ("files" for loss, dem, field)
  bool paths_without_folder = true;           ///< the key, empty, also without -o
  bool refuse_non_finite = false;             ///< a closed form's result: a number that is not finite is exit 3
};

/// The end of a command: with `files`, result["warnings"], the result JSON, the resolved
/// case and the report (answering from `typed`) staged and all committed; the warnings on
/// stderr; the result on stdout with --json, else `rows` and a "wrote" row per file.
/// Returns the exit code.
int finish(const ParsedArgs& args, report::OutputDir* files, nlohmann::json& result,
           const std::vector<std::string>& warnings, Rows rows, const ResultFiles& how,
           const report::TaskResult& typed = {});

}  // namespace pdamp::cli
