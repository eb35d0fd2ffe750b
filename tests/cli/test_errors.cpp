// The one table of error classes and exit codes (cli/errors.cpp): each class of error
// ends a command with its documented exit code (docs/command_line.md).
#include <catch2/catch.hpp>

#include <csignal>
#include <new>
#include <stdexcept>

#include "errors.hpp"
#include "pdamp/base/executor.hpp"

using namespace pdamp;

namespace {

template <class E>
cli::ErrorOutcome outcome_of(const E& error) {
  return cli::classify_error(std::make_exception_ptr(error), "decay");
}

}  // namespace

TEST_CASE("each class of error ends a command with its exit code", "[cli]") {
  const auto bad = outcome_of(base::InputError("case.json", "/dem/time_step_s", "must be > 0"));
  CHECK(bad.exit_code == 2);
  CHECK(bad.message == "case.json: /dem/time_step_s: must be > 0");
  const auto refused = outcome_of(std::invalid_argument("clearance_m = -1: must be > 0"));
  CHECK(refused.exit_code == 2);
  CHECK(refused.message == "pdamp decay: clearance_m = -1: must be > 0");
  const auto numerical = outcome_of(base::NumericalError("beam model: the generalized eigenproblem failed", "check the masses"));
  CHECK(numerical.exit_code == 3);
  CHECK(numerical.message == "beam model: the generalized eigenproblem failed (check the masses)");
  const auto stopped = outcome_of(base::Interrupted(SIGTERM, "wrote the checkpoint"));
  CHECK(stopped.end_by_signal == SIGTERM);
  CHECK_THAT(stopped.message, Catch::Contains("wrote the checkpoint"));
  const auto served = outcome_of(base::JobsServedElsewhere());
  CHECK(served.exit_code == 0);
  CHECK(served.message.empty());
  CHECK(outcome_of(std::bad_alloc()).exit_code == 1);
  CHECK(outcome_of(std::runtime_error("disk full")).exit_code == 1);
}
