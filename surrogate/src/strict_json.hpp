// Private strict JSON reading for surrogate files: every error names file, pointer and rule.
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>

#include "pdamp/formulas/input_file.hpp"

namespace pdamp::surrogate::detail {

/// JSON pointer reference token for `key` (RFC 6901: "~" -> "~0", "/" -> "~1").
inline std::string pointer_token(std::string_view key) {
  std::string token;
  for (char c : key) {
    if (c == '~') {
      token += "~0";
    } else if (c == '/') {
      token += "~1";
    } else {
      token += c;
    }
  }
  return token;
}

/// Throws std::invalid_argument("<file>: <pointer>: <rule>"); the pointer of the root is "/".
/// The message goes through formulas::printable: keys and strings quoted from a user's
/// file may hold newlines or NUL ("\u0000"), which would break or cut a one-line message.
[[noreturn]] inline void fail_at(const std::string& file, const std::string& pointer, const std::string& rule) {
  throw std::invalid_argument(formulas::printable(file + ": " + (pointer.empty() ? "/" : pointer) + ": " + rule));
}

/// One JSON object read strictly: required and optional keys are marked as read, and
/// finish() rejects any key nobody asked for, listing the allowed ones.
class StrictObject {
 public:
  StrictObject(const nlohmann::json& object, std::string pointer, const std::string& file)
      : object_(object), pointer_(std::move(pointer)), file_(file) {
    if (!object_.is_object()) fail("", std::string("must be a JSON object, got ") + object_.type_name());
  }

  const std::string& pointer() const { return pointer_; }
  std::string pointer(std::string_view key) const { return pointer_ + "/" + pointer_token(key); }

  [[noreturn]] void fail(std::string_view key, const std::string& rule) const {
    fail_at(file_, key.empty() ? pointer_ : pointer(key), rule);
  }

  const nlohmann::json& required(std::string_view key) {
    allowed_.emplace(key);
    const auto it = object_.find(std::string(key));
    if (it == object_.end()) fail_at(file_, pointer(key), "missing (required key)");
    return *it;
  }
  const nlohmann::json* optional(std::string_view key) {
    allowed_.emplace(key);
    const auto it = object_.find(std::string(key));
    return it == object_.end() ? nullptr : &*it;
  }

  std::string string(std::string_view key) {
    const auto& value = required(key);
    if (!value.is_string()) fail(key, std::string("must be a string, got ") + value.type_name());
    return value.get<std::string>();
  }
  /// A string that must equal `expected` (format tags, units).
  void expect_string(std::string_view key, std::string_view expected) {
    const std::string value = string(key);
    if (value != expected) {
      fail(key, "is \"" + value + "\", must be \"" + std::string(expected) + "\"");
    }
  }
  /// A finite number, > 0 when `positive` (the rule text names the unit if given).
  double number(std::string_view key, bool positive, std::string_view unit = "") {
    return number_value(required(key), pointer(key), positive, unit);
  }
  double number_value(const nlohmann::json& value, const std::string& at, bool positive,
                      std::string_view unit = "") const {
    const std::string in_unit = unit.empty() || unit == "1" ? "" : " (in " + std::string(unit) + ")";
    if (!value.is_number()) {
      fail_at(file_, at, std::string("must be a finite number") + in_unit + ", got " + value.type_name());
    }
    const double x = value.get<double>();
    if (!std::isfinite(x)) fail_at(file_, at, "must be a finite number" + in_unit);
    if (positive && !(x > 0.0)) fail_at(file_, at, "must be > 0" + in_unit);
    return x;
  }
  /// An integer in [min, max].
  long long integer(std::string_view key, long long min, long long max) {
    const auto& value = required(key);
    if (!value.is_number_integer()) fail(key, std::string("must be an integer, got ") + value.type_name());
    const long long x = value.get<long long>();
    if (x < min || x > max) {
      fail(key, std::to_string(x) + " must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    return x;
  }
  const nlohmann::json& array(std::string_view key) {
    const auto& value = required(key);
    if (!value.is_array()) fail(key, std::string("must be a JSON array, got ") + value.type_name());
    return value;
  }

  /// Rejects keys that were never asked for.
  void finish() const {
    for (const auto& [key, value] : object_.items()) {
      if (allowed_.count(key) == 0) {
        std::string names;
        for (const auto& name : allowed_) names += (names.empty() ? "" : ", ") + name;
        fail_at(file_, pointer(key), "unknown key (allowed here: " + names + ")");
      }
    }
  }

 private:
  const nlohmann::json& object_;
  std::string pointer_;
  const std::string& file_;
  std::set<std::string, std::less<>> allowed_;
};

}  // namespace pdamp::surrogate::detail
