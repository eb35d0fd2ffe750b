// The run errors of run_errors.hpp.
#include "pdamp/base/run_errors.hpp"

#include "pdamp/base/input_file.hpp"

namespace pdamp::base {

NumericalError::NumericalError(const std::string& what_failed, std::string advice)
    : std::runtime_error(printable(advice.empty() ? what_failed : what_failed + " (" + advice + ")")),
      advice_(std::move(advice)) {}

Interrupted::Interrupted(int signal_number, const std::string& what_happened)
    : std::runtime_error("interrupted by signal " + std::to_string(signal_number) + "; " + what_happened),
      signal_number_(signal_number) {}

}  // namespace pdamp::base
