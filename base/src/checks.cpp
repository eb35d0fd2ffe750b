// The checks of checks.hpp.
#include "pdamp/base/checks.hpp"

#include <stdexcept>

#include "pdamp/base/number_text.hpp"

namespace pdamp::base {

std::string violation(std::string_view name, double value, std::string_view rule) {
  std::string text(name);
  text += " = ";
  text += format_number(value, kCheckDigits);
  text += ": must be ";
  text += rule;
  return text;
}

void require(bool ok, std::string_view name, double value, std::string_view rule, std::string_view context) {
  if (ok) return;
  std::string message;
  if (!context.empty()) {
    message = context;
    message += ": ";
  }
  message += violation(name, value, rule);
  throw std::invalid_argument(message);
}

void require_positive(std::string_view name, double value, std::string_view context) {
  require(positive_finite(value), name, value, "> 0 and finite", context);
}

void require_non_negative(std::string_view name, double value, std::string_view context) {
  require(non_negative_finite(value), name, value, ">= 0 and finite", context);
}

void require_in(std::string_view name, double value, double lo, double hi, std::string_view context) {
  if (lo <= value && value <= hi) return;
  require(false, name, value, "in [" + format_number(lo, kCheckDigits) + ", " + format_number(hi, kCheckDigits) + "]",
          context);
}

}  // namespace pdamp::base
