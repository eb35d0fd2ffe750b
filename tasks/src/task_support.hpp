// Private helpers shared by the tasks' sources: the single damper of the Level II tasks,
// warnings kept once each, spaced values, JSON numbers that may be undefined.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"

namespace pdamp::tasks::detail {

/// The one damper of one layer that the closed-form and DEM studies of Level II take (a
/// format-1 case, or a format-2 case with one damper of one layer).
struct SingleDamper {
  const case_file::DamperSpec& damper;
  const case_file::LayerSpec& layer;
};
/// InputError naming /dampers when the case has more than one damper or layer; `study`
/// names what needs the single damper ("pdamp dem", "the damper_design task").
SingleDamper single_damper(const case_file::Case& c, const std::string& study);

/// Warnings collected once each, in order.
class Warnings {
 public:
  void add(const std::string& w) {
    if (seen_.insert(w).second) list_.push_back(w);
  }
  void add(const std::vector<std::string>& ws, const std::string& prefix = "") {
    for (const auto& w : ws) add(prefix + w);
  }
  const std::vector<std::string>& list() const { return list_; }

 private:
  std::vector<std::string> list_;
  std::set<std::string> seen_;
};

/// n values from lo to hi (both included), evenly spaced, or evenly in log when `log`.
std::vector<double> spaced(double lo, double hi, int n, bool log);

/// The JSON pointer of the first number in `value` that is not finite, if any.
std::optional<std::string> non_finite_number(const nlohmann::json& value, const std::string& at = "");

}  // namespace pdamp::tasks::detail
