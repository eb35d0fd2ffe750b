// Strict reading of one JSON object (strict_object.hpp).
#include "pdamp/base/strict_object.hpp"

#include <cmath>

namespace pdamp::base {

void fail_at(const std::string& file, const std::string& pointer, const std::string& rule) {
  throw InputError(file, pointer.empty() ? "/" : pointer, rule);
}

StrictObject::StrictObject(const nlohmann::json& object, std::string pointer, const std::string& file)
    : object_(object), pointer_(std::move(pointer)), file_(file) {
  if (!object_.is_object()) fail("", std::string("must be a JSON object, got ") + object_.type_name());
}

void StrictObject::fail(std::string_view key, const std::string& rule) const {
  fail_at(file_, key.empty() ? pointer_ : pointer(key), rule);
}

const nlohmann::json& StrictObject::required(std::string_view key) {
  allowed_.emplace(key);
  const auto it = object_.find(std::string(key));
  if (it == object_.end()) fail_at(file_, pointer(key), "missing (required key)");
  return *it;
}

const nlohmann::json* StrictObject::optional(std::string_view key) {
  allowed_.emplace(key);
  const auto it = object_.find(std::string(key));
  return it == object_.end() ? nullptr : &*it;
}

std::string StrictObject::string(std::string_view key) {
  const auto& value = required(key);
  if (!value.is_string()) fail(key, std::string("must be a string, got ") + value.type_name());
  return value.get<std::string>();
}

void StrictObject::expect_string(std::string_view key, std::string_view expected) {
  const std::string value = string(key);
  if (value != expected) fail(key, "is \"" + value + "\", must be \"" + std::string(expected) + "\"");
}

double StrictObject::number(std::string_view key, bool positive, std::string_view unit) {
  return number_value(required(key), pointer(key), positive, unit);
}

double StrictObject::number_value(const nlohmann::json& value, const std::string& at, bool positive,
                                  std::string_view unit) const {
  const std::string in_unit = unit.empty() || unit == "1" ? "" : " (in " + std::string(unit) + ")";
  if (!value.is_number()) fail_at(file_, at, std::string("must be a finite number") + in_unit + ", got " + value.type_name());
  const double x = value.get<double>();
  if (!std::isfinite(x)) fail_at(file_, at, "must be a finite number" + in_unit);
  if (positive && !(x > 0.0)) fail_at(file_, at, "must be > 0" + in_unit);
  return x;
}

long long StrictObject::integer(std::string_view key, long long min, long long max) {
  const auto& value = required(key);
  if (!value.is_number_integer()) fail(key, std::string("must be an integer, got ") + value.type_name());
  const long long x = value.get<long long>();
  if (x < min || x > max) fail(key, std::to_string(x) + " must be in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
  return x;
}

const nlohmann::json& StrictObject::array(std::string_view key) {
  const auto& value = required(key);
  if (!value.is_array()) fail(key, std::string("must be a JSON array, got ") + value.type_name());
  return value;
}

void StrictObject::finish() const {
  for (const auto& [key, value] : object_.items()) {
    (void)value;
    if (allowed_.count(key) == 0) {
      std::string names;
      for (const auto& name : allowed_) names += (names.empty() ? "" : ", ") + name;
      fail_at(file_, pointer(key), "unknown key (allowed here: " + names + ")");
    }
  }
}

}  // namespace pdamp::base
