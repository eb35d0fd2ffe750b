// What the subcommands print and write: the report module's writers, and readable tables.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pdamp/report/external_program.hpp"
#include "pdamp/report/html_report.hpp"
#include "pdamp/report/output_dir.hpp"
#include "pdamp/report/plots.hpp"
#include "pdamp/report/structure_plots.hpp"

namespace pdamp::cli {

using namespace report;

/// Two-column "name  value" table for the readable (non --json) output.
std::string key_value_table(const std::vector<std::pair<std::string, std::string>>& rows);

}  // namespace pdamp::cli
