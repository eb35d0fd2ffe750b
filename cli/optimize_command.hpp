// pdamp optimize: the optimisation tasks of a case (task kind filling_ratios: the whole
// slabs of each layer of a multi-layer damper for the fastest free decay).
#pragma once

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::cli {

/// `pdamp optimize CASE.json [--backend nlopt|ipopt] [-o DIR] [--json]`.
Command optimize_command();

/// Runs the case's filling_ratios task exactly as pdamp optimize (pdamp run); the back
/// end is the task's unless args has --backend.
int run_optimize_task(const ParsedArgs& args, const case_file::Case& c);

}  // namespace pdamp::cli
