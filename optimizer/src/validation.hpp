// Private: the formatting and throwing shared by the validate() functions.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace pdamp::optimizer::detail {

/// Shortest round-trip-ish text of a number for messages ("0.05", "nan", "inf").
inline std::string format_number(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

/// Throws std::invalid_argument listing every violation, one a line, after
/// "invalid <what>:"; does nothing when violations is empty.
inline void throw_if_invalid(const std::vector<std::string>& violations, const std::string& what) {
  if (violations.empty()) return;
  std::string message = "invalid " + what + ":";
  for (const std::string& line : violations) message += "\n  " + line;
  throw std::invalid_argument(message);
}

}  // namespace pdamp::optimizer::detail
