// Private: the throwing shared by the validate() functions (their numbers are
// base::format_number's, with 10 significant digits).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace pdamp::optimizer::detail {

/// Throws std::invalid_argument listing every violation, one a line, after
/// "invalid <what>:"; does nothing when violations is empty.
inline void throw_if_invalid(const std::vector<std::string>& violations, const std::string& what) {
  if (violations.empty()) return;
  std::string message = "invalid " + what + ":";
  for (const std::string& line : violations) message += "\n  " + line;
  throw std::invalid_argument(message);
}

}  // namespace pdamp::optimizer::detail
