// The end every command shares, and readable tables (output.hpp).
#include "output.hpp"

#include <iostream>
#include <sstream>

#include "pdamp/report/external_program.hpp"
#include "pdamp/report/html_report.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/tasks/closed_forms.hpp"
#include "version.hpp"

namespace pdamp::cli {

std::string key_value_table(const Rows& rows) {
  std::size_t width = 0;
  for (const auto& row : rows) width = std::max(width, row.first.size());
  std::ostringstream out;
  // A value may quote a user's text (a case's name): made printable, so that a newline or a
  // terminal escape in it cannot forge lines or drive the terminal.
  for (const auto& [key, value] : rows)
    out << key << std::string(width + 2 - key.size(), ' ') << base::printable(value) << "\n";
  return out.str();
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << "pdamp: warning: " << base::printable(w) << "\n";
}

bool writes_results(const CommandContext& context) { return context.executor.primary(); }

std::unique_ptr<report::OutputDir> output_dir(const ParsedArgs& args, const CommandContext& context) {
  if (!writes_results(context)) return nullptr;
  const auto dir = args.optional_text("-o");
  if (!dir) return nullptr;
  // Results name their files in JSON, which holds UTF-8 only: refused now, not after the work.
  if (!base::valid_utf8(*dir))
    throw base::InputError("-o", "", "'" + base::printable(*dir) +
                                   "' is not valid UTF-8: the results record their paths in JSON; rename the folder");
  // The owner of the folder's outputs: the command and the file it ran on (its first
  // argument, made absolute, so that another spelling of the same path is the same case).
  report::OutputOwner owner;
  owner.command = context.command;
  if (!args.positional().empty()) {
    std::error_code error;
    const auto absolute = std::filesystem::weakly_canonical(args.positional().front(), error);
    owner.input = error ? args.positional().front() : absolute.string();
  }
  return std::make_unique<report::OutputDir>(*dir, "-o", owner, args.has("--overwrite"));
}

std::unique_ptr<report::OutputDir> study_dir(const std::string& dir, const CommandContext& context,
                                             const std::string& in_place) {
  if (!writes_results(context)) return nullptr;
  auto files = std::make_unique<report::OutputDir>(dir);
  if (!in_place.empty()) files->in_place(in_place);
  return files;
}

tasks::OutputFolder output_folder(const report::OutputDir* files) {
  return files ? tasks::OutputFolder{files->dir()} : tasks::OutputFolder{};
}

void dem_results_ready(report::OutputDir* files) {
  if (!files) return;  // nothing to commit here
  files->finish_despite_signals();
  report::test_pause_point("run-ended");
}

void remove_checkpoints(const report::OutputDir* files, const std::vector<std::filesystem::path>& checkpoints) {
  if (!files) return;
  std::error_code ignored;
  for (const auto& checkpoint : checkpoints)
    if (!checkpoint.empty()) std::filesystem::remove(checkpoint, ignored);
}

int finish(const ParsedArgs& args, report::OutputDir* files, nlohmann::json& result,
           const std::vector<std::string>& warnings, Rows rows, const ResultFiles& how, const report::TaskResult& typed) {
  if (how.refuse_non_finite) tasks::require_finite(result);
  nlohmann::json paths = nlohmann::json::array();
  if (files) {
    result["warnings"] = warnings;
    if (how.resolved) files->add_json("case_resolved.json", how.resolved->resolved);
    if (!how.json_name.empty()) files->add_json(how.json_name, result);
    if (how.report && how.resolved) report::stage_report(*files, *how.resolved, typed, result, warnings, provenance_line());
    paths = files->commit();
  }
  result["warnings"] = warnings;
  if (files || how.paths_without_folder) result[how.paths_key] = paths;
  print_warnings(warnings);
  if (args.has("--json")) {
    std::cout << result.dump(2) << "\n";
  } else {
    for (const auto& path : paths) rows.push_back({"wrote", path.get<std::string>()});
    std::cout << key_value_table(rows);
  }
  return 0;
}

}  // namespace pdamp::cli
