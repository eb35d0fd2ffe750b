// The Level III subcommands (pdamp modes, frf, decay) and the structure tasks of pdamp run:
// a format-2 case through case_file::structure_setup and the structure solvers.
#pragma once

#include <vector>

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"

namespace pdamp::cli {

/// `--method formulas|field|dem` (default formulas), shared with pdamp run.
extern const FlagSpec kMethodFlag;
/// The stepped sine's flags of pdamp frf --method dem (--dem-points, --dem-min-frequency,
/// --dem-max-frequency, --dem-sweep); pdamp run lists them among its flags to accept them
/// on an frf task (without them, run uses the defaults).
extern const std::vector<FlagSpec> kDemSweepFlags;

/// pdamp modes, frf and decay, in the order `pdamp --help` lists them.
std::vector<Command> structure_commands();

/// Runs the case's task of kind modes, frf or decay exactly as the command of that name
/// (pdamp run). Other kinds are not structure tasks: std::logic_error.
int run_structure_task(const ParsedArgs& args, const case_file::Case& c);

}  // namespace pdamp::cli
