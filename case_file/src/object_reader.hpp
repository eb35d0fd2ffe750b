// The case reader's object: base::StrictObject (unknown keys, pointers) plus
// the case's conventions: a default per key, a range per number, and every value read
// recorded in the resolved case. Private to case_file.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case_error.hpp"
#include "pdamp/case_file/ranges.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/strict_object.hpp"

namespace pdamp::case_file::detail {

using nlohmann::json;

/// Significant digits of numbers in messages: enough to tell 0.1000001 from 0.1.
inline constexpr int kMessageDigits = 10;

inline std::string json_type_name(const json& value) { return value.type_name(); }

/// Stands in for an omitted section, so that its defaults are read and recorded.
inline const json& empty_object() {
  static const json kEmpty = json::object();
  return kEmpty;
}

/// Reads one JSON object: every read key is recorded with its resolved value, and
/// finish() rejects the keys nobody read, naming the allowed ones. Numbers are checked
/// against a Range; where an option struct owns the range, read them with Range{}
/// (finite) and map its validate() lines instead.
class ObjectReader {
 public:
  /// CaseError "must be a JSON object, got <type>" when `object` is no object; the
  /// root's type is checked by its caller (its errors carry no pointer).
  ObjectReader(const std::string& file, const json& object, std::string pointer, json& resolved)
      : strict_(object, pointer, file), file_(file), object_(object), pointer_(std::move(pointer)), resolved_(resolved) {
    resolved_ = json::object();
  }

  /// `key` may be a path below this object ("lattice/0").
  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw CaseError(file_, pointer_ + (key.empty() ? "" : "/" + key), what);
  }
  bool has(const std::string& key) const { return object_.contains(key); }
  bool is_string(const std::string& key) const { return has(key) && object_.at(key).is_string(); }
  bool is_number(const std::string& key) const { return has(key) && object_.at(key).is_number(); }
  /// An array of min_size..max_size numbers in `range`.
  std::vector<double> number_array(const std::string& key, Range range, const std::string& unit, std::size_t min_size,
                                   std::size_t max_size = std::numeric_limits<std::size_t>::max()) {
    strict_.optional(key);
    if (!has(key) || !object_.at(key).is_array()) fail(key, "required (an array of numbers" + unit + ")");
    if (object_.at(key).size() < min_size)
      fail(key, "has " + std::to_string(object_.at(key).size()) + " entries: needs at least " + std::to_string(min_size));
    if (object_.at(key).size() > max_size)
      fail(key, "has " + std::to_string(object_.at(key).size()) + " entries: at most " + std::to_string(max_size));
    std::vector<double> values;
    for (std::size_t i = 0; i < object_.at(key).size(); ++i) {
      const json& item = object_.at(key)[i];
      if (!item.is_number() || !range.contains(item.get<double>()))
        fail(key + "/" + std::to_string(i), range.text() + unit);
      values.push_back(item.get<double>());
    }
    resolved_[key] = values;
    return values;
  }
  /// An array of at least min_size strings.
  std::vector<std::string> text_array(const std::string& key, std::size_t min_size) {
    strict_.optional(key);
    if (!has(key) || !object_.at(key).is_array()) fail(key, "required (an array of strings)");
    if (object_.at(key).size() < min_size)
      fail(key, "has " + std::to_string(object_.at(key).size()) + " entries: needs at least " + std::to_string(min_size));
    std::vector<std::string> values;
    for (std::size_t i = 0; i < object_.at(key).size(); ++i) {
      const json& item = object_.at(key)[i];
      if (!item.is_string()) fail(key + "/" + std::to_string(i), "must be a string, got " + json_type_name(item));
      values.push_back(item.get<std::string>());
    }
    resolved_[key] = values;
    return values;
  }
  /// An array of at most `max_size` objects (refused before any is read: what a model can
  /// use, so that a hostile length costs nothing); the callback reads each with its own reader.
  template <typename Fn>
  void array(const std::string& key, Fn&& read, std::size_t max_size = std::numeric_limits<std::size_t>::max()) {
    strict_.optional(key);
    if (!has(key)) {
      resolved_[key] = json::array();
      return;
    }
    const json& items = object_.at(key);
    if (!items.is_array()) fail(key, "must be an array of objects, got " + json_type_name(items));
    if (items.size() > max_size)
      fail(key, "has " + std::to_string(items.size()) + " entries: at most " + std::to_string(max_size));
    resolved_[key] = json::array();
    for (std::size_t i = 0; i < items.size(); ++i) {
      resolved_[key].push_back(json::object());
      ObjectReader child(file_, items[i], pointer_ + "/" + key + "/" + std::to_string(i), resolved_[key][i]);
      read(child);
      child.finish();
    }
  }

  double number(const std::string& key, std::optional<double> fallback, Range range, const std::string& unit = "") {
    strict_.optional(key);
    double value = 0.0;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (" + range.text() + unit + ")");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_number()) fail(key, "must be a number" + unit + ", got " + json_type_name(item));
      value = item.get<double>();
    }
    if (!range.contains(value)) {
      fail(key, "= " + base::format_number(value, kMessageDigits) + ": " + range.text() + unit);
    }
    resolved_[key] = value;
    return value;
  }
  /// Absent: nothing. null is not "absent" (it would hide a half-edited value): a
  /// number must be given or the key omitted.
  std::optional<double> optional_number(const std::string& key, Range range, const std::string& unit = "") {
    if (!object_.contains(key)) {
      strict_.optional(key);
      return std::nullopt;
    }
    if (object_.at(key).is_null()) fail(key, "must be a number" + unit + " (omit the key for the default), got null");
    return number(key, std::nullopt, range, unit);
  }
  int integer(const std::string& key, std::optional<int> fallback, int min, int max) {
    strict_.optional(key);
    int value = 0;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "])");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      // A whole number written 36.0 or 1e3 is an integer too (as lattice counts and
      // --periods take it); the comparison is done in double, so 2^64 - 1 (an unsigned
      // JSON integer) is not read as -1.
      const bool whole = item.is_number_integer() ||
                         (item.is_number_float() && std::isfinite(item.get<double>()) &&
                          item.get<double>() == std::floor(item.get<double>()));
      if (!whole)
        fail(key,
             "must be a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "], got " +
                 (item.is_number() ? base::format_number(item.get<double>(), kMessageDigits) : json_type_name(item)));
      const double wide = item.is_number_unsigned() ? static_cast<double>(item.get<unsigned long long>())
                                                    : item.get<double>();
      if (wide < min || wide > max)
        fail(key, "= " + base::format_number(wide, kMessageDigits) + ": must be in [" + std::to_string(min) + ", " +
                      std::to_string(max) + "]");
      value = static_cast<int>(wide);
    }
    resolved_[key] = value;
    return value;
  }
  std::string text(const std::string& key, std::optional<std::string> fallback,
                   const std::vector<std::string>& allowed = {}) {
    strict_.optional(key);
    std::string value;
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required" + allowed_text(allowed));
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_string()) fail(key, "must be a string, got " + json_type_name(item));
      value = item.get<std::string>();
    }
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), value) == allowed.end())
      fail(key, "'" + value + "' is not allowed" + allowed_text(allowed));
    resolved_[key] = value;
    return value;
  }
  bool boolean(const std::string& key, bool fallback) {
    strict_.optional(key);
    bool value = fallback;
    if (object_.contains(key)) {
      const json& item = object_.at(key);
      if (!item.is_boolean()) fail(key, "must be true or false, got " + json_type_name(item));
      value = item.get<bool>();
    }
    resolved_[key] = value;
    return value;
  }
  std::array<double, 3> vector3(const std::string& key, std::optional<std::array<double, 3>> fallback, Range range,
                                const std::string& unit) {
    strict_.optional(key);
    std::array<double, 3> value{};
    if (!object_.contains(key)) {
      if (!fallback) fail(key, "required (3 numbers" + unit + ")");
      value = *fallback;
    } else {
      const json& item = object_.at(key);
      if (!item.is_array() || item.size() != 3) fail(key, "must be an array of 3 numbers" + unit);
      for (std::size_t i = 0; i < 3; ++i) {
        if (!item[i].is_number()) fail(key + "/" + std::to_string(i), "must be a number" + unit);
        value[i] = item[i].get<double>();
        if (!range.contains(value[i])) {
          fail(key + "/" + std::to_string(i),
               "= " + base::format_number(value[i], kMessageDigits) + ": " + range.text() + unit);
        }
      }
    }
    resolved_[key] = value;
    return value;
  }
  /// A nested object; the callback reads it with its own reader.
  template <typename Fn>
  void object(const std::string& key, bool required, Fn&& read) {
    strict_.optional(key);
    if (!object_.contains(key)) {
      if (required) fail(key, "required (a JSON object)");
      return;
    }
    ObjectReader child(file_, object_.at(key), pointer_ + "/" + key, resolved_[key]);
    read(child);
    child.finish();
  }
  /// Rejects the keys nobody read, naming the allowed ones.
  void finish() const { strict_.finish(); }
  json& resolved() { return resolved_; }
  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }

 private:
  static std::string allowed_text(const std::vector<std::string>& allowed) {
    if (allowed.empty()) return "";
    std::string out = " (one of:";
    for (const auto& a : allowed) out += " " + a;
    return out + ")";
  }

  base::StrictObject strict_;  ///< records the keys read
  const std::string& file_;
  const json& object_;
  std::string pointer_;
  json& resolved_;
};

int axis_index(const std::string& name);

}  // namespace pdamp::case_file::detail
