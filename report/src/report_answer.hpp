// The answer paragraph of report.html (report_answer.cpp): what the case asked, answered
// in the units a damper is built with, and the verdict of the check that backs it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pdamp/report/html_report.hpp"

namespace pdamp::report {

struct Answer {
  std::vector<std::string> paragraphs;  ///< plain text (escaped by the page)
  std::string verdict;                  ///< the DEM check's or the margin's, empty if none
  std::optional<bool> passed;           ///< colours the verdict; none: neutral
};

/// From the task's typed result and its case; empty paragraphs for a task without a
/// written answer.
Answer report_answer(const TaskResult& result, const case_file::Case& c);

/// Numbers as the page prints them: three significant digits ("–" where not finite);
/// lengths in mm, masses in g.
std::string three_digits(double value);
std::string in_mm(double metres);
std::string in_g(double kilograms);

}  // namespace pdamp::report
