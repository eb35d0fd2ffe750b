// The errors of a run that are not bad input (input_error.hpp): a numerical failure found
// while computing, and a stop asked for by a signal. With InputError they are pdamp's whole
// error model; the command line maps each class to its exit code in one table
// (docs/command_line.md: 2 bad input, 3 numerical failure, the signal's own end).
#pragma once

#include <stdexcept>
#include <string>

namespace pdamp::base {

/// A numerical failure detected at run time: a DEM that goes unstable, an eigenproblem or a
/// solver that fails, a result that is not finite. Exit code 3. what() is "<what failed>"
/// or "<what failed> (<advice>)"; advice() says what the user can change.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& what_failed, std::string advice = "");
  const std::string& advice() const { return advice_; }

 private:
  std::string advice_;
};

/// A signal (SIGINT, SIGTERM, SIGHUP) asked a run to stop, and it stopped at a consistent
/// point: what it kept (a checkpoint and how to resume it) is in what(). The command line
/// then ends by the signal's default action.
class Interrupted : public std::runtime_error {
 public:
  /// `what_happened`: what was kept (a checkpoint and how to resume), else "no result was written".
  explicit Interrupted(int signal_number, const std::string& what_happened = "no result was written");
  int signal_number() const { return signal_number_; }

 private:
  int signal_number_;
};

}  // namespace pdamp::base
