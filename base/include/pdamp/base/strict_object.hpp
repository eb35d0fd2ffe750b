// One JSON object read strictly: every key read is recorded, finish() rejects the rest;
// every error names file, JSON pointer and rule (InputError).
#pragma once

#include <functional>
#include <set>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "pdamp/base/input_error.hpp"

namespace pdamp::base {

/// Throws InputError(file, pointer, rule); the pointer of the root is "/".
[[noreturn]] void fail_at(const std::string& file, const std::string& pointer, const std::string& rule);

/// A JSON object whose keys are read through it: required and optional keys are marked
/// as read, and finish() rejects any key nobody asked for, listing the allowed ones.
/// The object and the file name must outlive the reader.
class StrictObject {
 public:
  /// InputError "must be a JSON object, got <type>" when `object` is no object.
  StrictObject(const nlohmann::json& object, std::string pointer, const std::string& file);

  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }
  std::string pointer(std::string_view key) const { return pointer_ + "/" + pointer_token(key); }
  /// Whether the object has `key` (the key is not marked as read).
  bool contains(std::string_view key) const { return object_.contains(key); }
  const nlohmann::json& object() const { return object_; }

  [[noreturn]] void fail(std::string_view key, const std::string& rule) const;

  /// The value of `key`, marked as read; InputError "missing (required key)" if absent.
  const nlohmann::json& required(std::string_view key);
  /// The value of `key` or nullptr, marked as read (allowed) either way.
  const nlohmann::json* optional(std::string_view key);

  std::string string(std::string_view key);
  /// A string that must equal `expected` (format tags, units).
  void expect_string(std::string_view key, std::string_view expected);
  /// A finite number, > 0 when `positive` (the rule text names the unit if given).
  double number(std::string_view key, bool positive, std::string_view unit = "");
  double number_value(const nlohmann::json& value, const std::string& at, bool positive,
                      std::string_view unit = "") const;
  /// An integer in [min, max].
  long long integer(std::string_view key, long long min, long long max);
  const nlohmann::json& array(std::string_view key);

  /// Rejects keys that were never asked for: "unknown key (allowed here: a, b)".
  void finish() const;

 private:
  const nlohmann::json& object_;
  std::string pointer_;
  const std::string& file_;
  std::set<std::string, std::less<>> allowed_;
};

}  // namespace pdamp::base
