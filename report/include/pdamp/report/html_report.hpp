// The one-page HTML report of `pdamp run -o DIR` (DIR/report.html), written for the
// engineer who asked: first the answer (the design in g and mm, what it gains over no
// particles and over the best single layer, the verdict of the DEM's check), then the
// evidence (the plots, embedded as data URIs so the page reads offline; the verification;
// the warnings), then the details (the solver, every number, provenance). Every text from
// the case is escaped.
#pragma once

#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/report/output_dir.hpp"
#include "pdamp/tasks/clearance.hpp"
#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/frf.hpp"
#include "pdamp/tasks/modes.hpp"
#include "pdamp/tasks/placement.hpp"

namespace pdamp::report {

/// The typed result whose question the report answers (none: a task whose report shows
/// its numbers only).
using TaskResult = std::variant<std::monostate, const tasks::FillingRatiosResult*, const tasks::DamperDesignResult*,
                                const tasks::DecayResult*, const tasks::FrfResult*, const tasks::PlacementStudy*,
                                const tasks::ModesResult*, const tasks::ClearanceStudy*>;

/// Stages report.html built from the typed result (the answer and its evidence), the result
/// JSON (every number, in the details), the warnings and the pictures already staged in
/// `files` (PNG, else SVG, as produced by gnuplot): call it just before files.commit().
/// `provenance`: the program's version and commit, printed at the end.
void stage_report(OutputDir& files, const case_file::Case& c, const TaskResult& typed, const nlohmann::json& result,
                  const std::vector<std::string>& warnings, const std::string& provenance);

/// A picture for the report: its file name (caption key) and its bytes.
struct ReportPicture {
  std::string file_name;  ///< "eta_curve.png"; .png or .svg
  std::string bytes;
};

/// Everything the page shows; the texts are raw (report_html escapes them).
struct ReportInput {
  std::string case_name;
  std::string case_description;
  std::string case_file;
  const case_file::Case* case_read = nullptr;  ///< what the answer reads of the case (none: nothing)
  std::string provenance;             ///< "pdamp 0.1.0, commit ..."
  TaskResult typed;                   ///< what the answer and the evidence read
  nlohmann::json result;              ///< the task's result JSON: every number, in the details
  std::vector<std::string> warnings;
  std::vector<ReportPicture> pictures;
  bool gnuplot_found = true;          ///< false: a note instead of the plots
};

/// The self-contained page: no script, no external resource (a Content-Security-Policy
/// allows only inline style and data: images), so nothing in it can run.
std::string report_html(const ReportInput& input);

/// `text` with & < > " ' as character references: inert inside elements and quoted attributes.
std::string html_escape(std::string_view text);

/// Standard base64 (RFC 4648 §4, padded), for data URIs.
std::string base64(std::string_view bytes);

}  // namespace pdamp::report
