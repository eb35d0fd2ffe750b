// The command line's exit codes and the one table that maps pdamp's error classes to them
// (docs/command_line.md): the classes are the libraries' own (base: InputError,
// NumericalError, Interrupted; tasks: JobsServedElsewhere).
#pragma once

#include <exception>
#include <string>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/run_errors.hpp"

namespace pdamp::cli {

using base::InputError;
using base::Interrupted;
using base::NumericalError;

inline constexpr int kExitOk = 0;
inline constexpr int kExitOther = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNumerical = 3;

/// What an error that ended a command means for the process.
struct ErrorOutcome {
  int exit_code = kExitOther;
  std::string message;    ///< the one line after "pdamp: error: "; empty: say nothing
  int end_by_signal = 0;  ///< nonzero: end by this signal's default action after the line
};

/// The table: base::InputError (a file, flag or key breaks a rule) and a library's
/// std::invalid_argument (it refuses a value it was given) exit 2; NumericalError exits 3;
/// Interrupted ends by its signal; JobsServedElsewhere (an MPI worker) exits 0 silently;
/// std::bad_alloc and anything else exit 1. `command` names the subcommand for a bare
/// std::invalid_argument.
ErrorOutcome classify_error(const std::exception_ptr& error, const std::string& command);

}  // namespace pdamp::cli
