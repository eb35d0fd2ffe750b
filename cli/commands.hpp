// The subcommands of pdamp: each parses its flags, calls the libraries and prints.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "args.hpp"

namespace pdamp::cli {

struct Command {
  CommandSpec spec;
  std::function<int(const ParsedArgs&)> run;
  /// Under mpirun (docs/distributed.md): the command runs on every rank, its DEM tasks
  /// spread over them by a distributed::TaskFarm; otherwise it runs on rank 0 while the
  /// others wait.
  bool every_rank = false;
};

/// Every subcommand, in the order `pdamp --help` lists them.
const std::vector<Command>& commands();

}  // namespace pdamp::cli
