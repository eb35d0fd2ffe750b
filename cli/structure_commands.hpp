// The Level III subcommands (pdamp modes, frf, decay, optimize) and the structure tasks of
// pdamp run: flags to a task's options, the task, its files, the printout.
#pragma once

#include <vector>

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::cli {

/// pdamp modes, frf, decay and optimize, in the order `pdamp --help` lists them.
std::vector<Command> structure_commands();

/// The case's task of kind modes, frf or decay, exactly as the command of that name (pdamp run).
int run_structure_case(const ParsedArgs& args, CommandContext& context, const case_file::Case& c);
/// The case's task of kind filling_ratios, placement or clearance, exactly as pdamp optimize (pdamp run).
int run_optimize_case(const ParsedArgs& args, CommandContext& context, const case_file::Case& c);
/// pdamp optimize.
Command optimize_command();

}  // namespace pdamp::cli
