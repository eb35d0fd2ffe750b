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
  base::Executor& executor;  ///< where independent jobs run (this process, or MPI ranks)
  /// This process writes and prints the results (under mpirun: rank 0; the other ranks only
  /// compute the jobs they are sent).
  bool primary = true;
  bool report = false;        ///< pdamp run: also DIR/report.html
  std::string command;        ///< the command's name ("run", "field merge"), for the output folder's owner
};

struct Command {
  CommandSpec spec;
  std::function<int(const ParsedArgs&, CommandContext&)> run;
  /// Under mpirun (docs/distributed.md): the command runs on every rank, its jobs spread
  /// over them by the executor; otherwise it runs on rank 0 while the others wait.
  bool every_rank = false;
};

/// Every subcommand, in the order `pdamp --help` lists them.
const std::vector<Command>& commands();

}  // namespace pdamp::cli
