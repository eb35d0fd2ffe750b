// Numbers in messages and tables: the one formatter of pdamp's texts.
#pragma once

#include <string>

namespace pdamp::base {

/// `value` with `significant` significant digits in the shortest of fixed and scientific
/// notation, as std::ostream prints it by default (printf's %g) in the classic locale:
/// "0.1", "1e-07", "inf", "-inf", "nan" (whatever the global locale's digit grouping or
/// decimal mark).
std::string format_number(double value, int significant = 6);

}  // namespace pdamp::base
