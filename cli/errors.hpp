// The command line's exit codes and the error classes they stand for (docs/interface.md):
// the classes are the libraries' own (strict_json: InputError, NumericalError, Interrupted).
#pragma once

#include "pdamp/strict_json/input_error.hpp"
#include "pdamp/strict_json/run_errors.hpp"

namespace pdamp::cli {

using strict_json::InputError;
using strict_json::Interrupted;
using strict_json::NumericalError;

inline constexpr int kExitOk = 0;
inline constexpr int kExitOther = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNumerical = 3;

}  // namespace pdamp::cli
