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
};

/// Every subcommand, in the order `pdamp --help` lists them.
const std::vector<Command>& commands();

}  // namespace pdamp::cli
