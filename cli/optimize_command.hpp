// pdamp optimize: the optimisation tasks of a case (task kind filling_ratios: the whole
// slabs of each layer of a multi-layer damper for the fastest free decay).
#pragma once

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::cli {

/// `pdamp optimize CASE.json [--backend nlopt|ipopt] [--verify|--no-verify] [-o DIR] [--json]`.
Command optimize_command();

/// `--no-verify`: skip the task's DEM verification (pdamp optimize, and pdamp run lists it).
extern const FlagSpec kNoVerifyFlag;

/// Runs the case's filling_ratios task exactly as pdamp optimize (pdamp run); the back
/// end is the task's unless args has --backend; the DEM verification runs when the task
/// has a verify block or args has --verify, unless args has --no-verify.
int run_optimize_task(const ParsedArgs& args, const case_file::Case& c);

}  // namespace pdamp::cli
