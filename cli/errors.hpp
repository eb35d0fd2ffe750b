// The CLI's error types and their exit codes (INTERFACE.md).
#pragma once

#include <stdexcept>
#include <string>

#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::cli {

/// Bad input: exit code 2, one line `pdamp: error: <where>: <key>: <what>`. A case
/// file's errors (case_file::CaseError) exit 2 the same way.
class InputError : public std::runtime_error {
 public:
  /// where: a file name or a flag; key: a JSON pointer or key (may be empty).
  /// The message is made printable here (strict_json::printable): a NUL in a user's key
  /// would cut what() short, a newline would break the one line.
  InputError(const std::string& where, const std::string& key, const std::string& what)
      : std::runtime_error(strict_json::printable(where + (key.empty() ? "" : ": " + key) + ": " + what)) {}
  /// A message that already reads "<where>: <key>: <what>" (a library's error).
  explicit InputError(const std::string& formatted) : std::runtime_error(strict_json::printable(formatted)) {}
};

/// A numerical failure detected at run time (e.g. DEM instability): exit code 3.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A signal (SIGINT, SIGTERM, SIGHUP) arrived while results were being written: the
/// staged files are removed and pdamp ends by the signal (its default action).
class Interrupted : public std::runtime_error {
 public:
  /// `what_happened`: what was kept (a checkpoint and how to resume), else "no result was written".
  explicit Interrupted(int signal_number, const std::string& what_happened = "no result was written")
      : std::runtime_error("interrupted by signal " + std::to_string(signal_number) + "; " + what_happened),
        signal_number_(signal_number) {}
  int signal_number() const { return signal_number_; }

 private:
  int signal_number_;
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitOther = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitNumerical = 3;

}  // namespace pdamp::cli
