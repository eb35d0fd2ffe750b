// Small helpers shared by structure's sources (private to the library).
#pragma once

#include <sstream>
#include <string>

namespace pdamp::structure::detail {

inline constexpr double kTwoPi = 6.28318530717958647692;

/// A number for messages, 12 significant digits (inputs stay distinguishable).
inline std::string number(double value) {
  std::ostringstream out;
  out.precision(12);
  out << value;
  return out.str();
}

}  // namespace pdamp::structure::detail
