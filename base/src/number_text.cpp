// The number formatter of number_text.hpp.
#include "pdamp/base/number_text.hpp"

#include <charconv>
#include <locale>
#include <sstream>
#include <system_error>

namespace pdamp::base {

std::string format_number(double value, int significant) {
  // std::to_chars in general format with a precision prints as printf's "%.*g" in the C
  // locale, which is what std::ostream's default floatfield prints in the classic locale;
  // it is cheaper (no stream), so the warning paths that format many numbers stay cheap.
  char buffer[64];
  const auto [end, error] =
      std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, significant);
  if (error == std::errc()) return std::string(buffer, end);
  // More digits than the buffer holds: the stream itself.
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(significant);
  out << value;
  return out.str();
}

}  // namespace pdamp::base
