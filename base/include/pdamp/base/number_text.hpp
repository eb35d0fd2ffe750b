// Numbers in messages and tables: the one formatter of pdamp's texts.
#pragma once

#include <string>

namespace pdamp::base {

/// `value` with `significant` significant digits in the shortest of fixed and scientific
/// notation (std::ostream's default floatfield), "n/a" for NaN.
std::string format_number(double value, int significant = 6);

}  // namespace pdamp::base
