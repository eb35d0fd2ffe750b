// base's number text (format_number) and argument checks (checks.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <locale>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

using pdamp::base::format_number;

namespace {

/// What std::ostream prints in the classic locale: format_number's specification.
std::string classic_stream(double value, int digits) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out.precision(digits);
  out << value;
  return out.str();
}

/// A locale that groups thousands with '.' and writes ',' as the decimal mark (as de_DE
/// does), built in so that the test needs no installed locale.
struct GermanPunctuation : std::numpunct<char> {
  char do_decimal_point() const override { return ','; }
  char do_thousands_sep() const override { return '.'; }
  std::string do_grouping() const override { return "\3"; }
};

/// The message of the std::invalid_argument that `check` throws ("" if none).
template <class Check>
std::string message_of(Check&& check) {
  try {
    check();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("format_number prints the given significant digits in the shorter of fixed and scientific") {
  CHECK(format_number(1.0 / 3.0, 6) == "0.333333");
  CHECK(format_number(1.0 / 3.0) == "0.333333");  // 6 by default
  CHECK(format_number(3.141592653589793, 12) == "3.14159265359");
  CHECK(format_number(0.1, 17) == "0.10000000000000001");  // 17: every double back to the last bit
  CHECK(format_number(1e-7, 6) == "1e-07");
  CHECK(format_number(123456789.0, 4) == "1.235e+08");
  CHECK(format_number(2.5, 3) == "2.5");  // no trailing zeros
  CHECK(format_number(0.0, 10) == "0");
  CHECK(format_number(-0.0, 10) == "-0");
}

TEST_CASE("format_number prints NaN as nan and infinities as inf") {
  CHECK(format_number(std::numeric_limits<double>::quiet_NaN(), 6) == "nan");
  CHECK(format_number(std::numeric_limits<double>::quiet_NaN(), 12) == "nan");
  CHECK(format_number(std::numeric_limits<double>::infinity(), 12) == "inf");
  CHECK(format_number(-std::numeric_limits<double>::infinity(), 3) == "-inf");
}

TEST_CASE("format_number prints as std::ostream in the classic locale for every digit count") {
  const double values[] = {
      0.0,     1.0,           -1.5,   0.1,      1.0 / 3.0, 2.0 / 3.0, 123456.789,
      1e-300,  1e300,         5e-324, 9.999995, 0.000123,  99999.5,   1234567.0,
      -2.5e-5, 6.02214076e23, 1e15,   1e16,     1e-5,      1e-4,      std::numeric_limits<double>::max()};
  for (const double value : values)
    for (int digits = 0; digits <= 20; ++digits) {
      INFO(value << " with " << digits << " digits");
      CHECK(format_number(value, digits) == classic_stream(value, digits));
    }
  // 60 digits: 1e-300 takes 66 characters (the stream path, past to_chars' buffer); 0.1's
  // exact decimal expansion has 55 digits.
  CHECK(format_number(1e-300, 60) == classic_stream(1e-300, 60));
  CHECK(format_number(1e-300, 60).size() == 66);
  CHECK(format_number(0.1, 60) == classic_stream(0.1, 60));
  CHECK(format_number(0.1, 60) == "0.1000000000000000055511151231257827021181583404541015625");
}

TEST_CASE("format_number ignores the global locale's decimal mark and digit grouping") {
  const std::locale previous = std::locale::global(std::locale(std::locale::classic(), new GermanPunctuation));
  std::ostringstream plain;  // a stream in the global locale, as the module-private formatters had
  plain.precision(10);
  plain << 1234567.5;
  const std::string formatted = format_number(1234567.5, 10);
  std::locale::global(previous);
  CHECK(plain.str() == "1.234.567,5");  // the global locale is in force: the check below can fail
  CHECK(formatted == "1234567.5");
}

TEST_CASE("checks throw std::invalid_argument as \"<name> = <value>: must be <rule>\"") {
  using namespace pdamp::base;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();

  CHECK(message_of([] { require_positive("clearance_m", 0.0); }) == "clearance_m = 0: must be > 0 and finite");
  CHECK(message_of([&] { require_positive("clearance_m", nan); }) == "clearance_m = nan: must be > 0 and finite");
  CHECK(message_of([&] { require_positive("clearance_m", inf); }) == "clearance_m = inf: must be > 0 and finite");
  CHECK(message_of([] { require_positive("clearance_m", 1e-300); }).empty());

  CHECK(message_of([] { require_non_negative("intensity", -1e-9); }) == "intensity = -1e-09: must be >= 0 and finite");
  CHECK(message_of([&] { require_non_negative("intensity", nan); }) == "intensity = nan: must be >= 0 and finite");
  CHECK(message_of([] { require_non_negative("intensity", 0.0); }).empty());

  CHECK(message_of([] { require_in("inertia_factor", 1.5, 0.0, 1.0); }) == "inertia_factor = 1.5: must be in [0, 1]");
  CHECK(message_of([&] { require_in("inertia_factor", nan, 0.0, 1.0); }) == "inertia_factor = nan: must be in [0, 1]");
  CHECK(message_of([] { require_in("inertia_factor", 0.0, 0.0, 1.0); }).empty());
  CHECK(message_of([] { require_in("inertia_factor", 1.0, 0.0, 1.0); }).empty());
  CHECK(message_of([] { require_in("bed_restitution", 0.95, 0.0, 0.9); }) ==
        "bed_restitution = 0.95: must be in [0, 0.9]");

  CHECK(message_of([] { require(false, "restitution", 0.0, "in (0, 1]"); }) == "restitution = 0: must be in (0, 1]");
  CHECK(message_of([] { require(true, "restitution", 0.0, "in (0, 1]"); }).empty());
  // A context (the function) goes first.
  CHECK(message_of([] { require_positive("radius_m", -1.0, "hertz_contact"); }) ==
        "hertz_contact: radius_m = -1: must be > 0 and finite");
  CHECK(violation("x", 2.0, "<= 1") == "x = 2: must be <= 1");
}

TEST_CASE("a check's value keeps 12 significant digits: just outside a bound is not the bound") {
  using namespace pdamp::base;
  CHECK(message_of([] { require_in("s", 1.00000000001, 0.0, 1.0); }) == "s = 1.00000000001: must be in [0, 1]");
  CHECK(message_of([] { require_positive("x", -1.0 / 3.0); }) == "x = -0.333333333333: must be > 0 and finite");
}
