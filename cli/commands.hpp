// The subcommands of pdamp: each parses its flags, calls a task of the tasks library,
// writes its files through the report module and prints.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "args.hpp"
#include "pdamp/base/executor.hpp"

namespace pdamp::cli {

/// What a command runs with besides its flags (main sets it up).
struct CommandContext {
  /// Where a task's independent jobs run (this process, or MPI ranks); its primary() process
  /// writes and prints the results (output.hpp), the others only compute what they are sent.
  base::Executor& executor;
  bool report = false;        ///< pdamp run: also DIR/report.html
  std::string command;        ///< the command's name ("run", "field merge"), for the output folder's owner
};

struct Command {
  CommandSpec spec;
  std::function<int(const ParsedArgs&, CommandContext&)> run;
  /// The command runs a study of the tasks library, which decides whether it is distributed
  /// (docs/distributed.md): under mpirun the command starts on every rank. A command that runs
  /// none (closed forms, validate, merges, export and import) runs on rank 0 alone.
  bool runs_task = false;
};

/// Every subcommand, in the order `pdamp --help` lists them.
const std::vector<Command>& commands();

}  // namespace pdamp::cli
