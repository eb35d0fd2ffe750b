// Private pieces of the field file format shared with the sweep results file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "pdamp/surrogate/grid.hpp"

namespace pdamp::surrogate::detail {

/// {"name", "unit", "spacing", "values"} of one axis, as written in field and results files.
nlohmann::ordered_json axis_json(const Axis& axis);
/// Strict reading of axis `index` (0 or 1) at `pointer` in `file`: known name allowed for
/// that axis, its unit, spacing, values > 0 and strictly increasing; std::invalid_argument
/// "<file>: <pointer>: <rule>" otherwise.
Axis read_axis(const nlohmann::json& value, const std::string& pointer, const std::string& file, int index);

}  // namespace pdamp::surrogate::detail
