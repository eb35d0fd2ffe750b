// Checks of numeric arguments: the tests (positive and finite, ...) and one message form,
// "<name> = <value>: must be <rule>", thrown as std::invalid_argument or listed by a
// validate(). The value is printed with kCheckDigits significant digits, so that an input
// that is just outside a bound stays distinguishable from the bound.
#pragma once

#include <cmath>
#include <string>
#include <string_view>

namespace pdamp::base {

/// Significant digits of the value in a check's message.
inline constexpr int kCheckDigits = 12;

inline bool positive_finite(double value) { return value > 0.0 && std::isfinite(value); }
inline bool non_negative_finite(double value) { return value >= 0.0 && std::isfinite(value); }

/// "<name> = <value>: must be <rule>".
std::string violation(std::string_view name, double value, std::string_view rule);

/// Throws std::invalid_argument("<context>: <name> = <value>: must be <rule>") unless `ok`
/// (without "<context>: " when `context` is empty).
void require(bool ok, std::string_view name, double value, std::string_view rule, std::string_view context = {});
/// require(value > 0 and finite, ..., "> 0 and finite").
void require_positive(std::string_view name, double value, std::string_view context = {});
/// require(value >= 0 and finite, ..., ">= 0 and finite").
void require_non_negative(std::string_view name, double value, std::string_view context = {});
/// require(lo <= value <= hi, ..., "in [lo, hi]"); NaN fails.
void require_in(std::string_view name, double value, double lo, double hi, std::string_view context = {});

}  // namespace pdamp::base
