// Private text helpers of the surrogate module: numbers and rule lists in messages.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pdamp::surrogate::detail {

/// A double as text with enough digits to tell close values apart.
inline std::string number(double value, int digits = 12) {
  std::ostringstream out;
  out.precision(digits);
  out << value;
  return out.str();
}

inline bool positive_finite(double value) { return value > 0.0 && std::isfinite(value); }

/// The lines joined by "; " (one exception message from a validate() list).
inline std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += (text.empty() ? "" : "; ") + line;
  return text;
}

/// Throws std::invalid_argument("<context>: <rule>; <rule>...") if `problems` is not empty.
inline void throw_if_any(const std::vector<std::string>& problems, const std::string& context) {
  if (!problems.empty()) throw std::invalid_argument(context + ": " + joined(problems));
}

}  // namespace pdamp::surrogate::detail
