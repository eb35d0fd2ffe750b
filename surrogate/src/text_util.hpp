// Private text helpers of the surrogate module: labels and rule lists in messages (numbers
// are base::format_number's, with 12 significant digits to tell close values apart).
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pdamp::surrogate::detail {

/// True if `text` holds a control byte (below 0x20, or DEL): a label (motion mode, fit
/// source) is printed in tables and one-line messages, where such a byte breaks the
/// line or, for NUL, cuts the text.
inline bool has_control_byte(std::string_view text) {
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7F) return true;
  }
  return false;
}

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
