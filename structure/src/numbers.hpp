// Constants shared by structure's sources (private to the library); numbers in messages
// are base::format_number's, with 12 significant digits (inputs stay distinguishable).
#pragma once

namespace pdamp::structure::detail {

inline constexpr double kTwoPi = 6.28318530717958647692;

}  // namespace pdamp::structure::detail
