// The number formatter of number_text.hpp.
#include "pdamp/base/number_text.hpp"

#include <cmath>
#include <sstream>

namespace pdamp::base {

std::string format_number(double value, int significant) {
  if (std::isnan(value)) return "n/a";
  std::ostringstream out;
  out.precision(significant);
  out << value;
  return out.str();
}

}  // namespace pdamp::base
