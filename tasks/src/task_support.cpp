// Private helpers shared by the tasks' sources (task_support.hpp).
#include "task_support.hpp"

#include "pdamp/base/input_error.hpp"

namespace pdamp::tasks::detail {

SingleDamper single_damper(const case_file::Case& c, const std::string& study) {
  if (c.dampers.size() != 1 || c.dampers.front().layers.size() != 1)
    throw base::InputError(c.path, "/dampers",
                                  study + " takes one damper of one layer (the case has " +
                                      std::to_string(c.dampers.size()) + " dampers, the first with " +
                                      std::to_string(c.dampers.front().layers.size()) + " layers)");
  return {c.dampers.front(), c.dampers.front().layers.front()};
}

std::vector<double> spaced(double lo, double hi, int n, bool log) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
    v[static_cast<std::size_t>(i)] = log ? std::exp(std::log(lo) + s * (std::log(hi) - std::log(lo))) : lo + s * (hi - lo);
  }
  v.back() = hi;
  return v;
}

std::optional<std::string> non_finite_number(const nlohmann::json& value, const std::string& at) {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) return at.empty() ? "/" : at;
  if (value.is_object() || value.is_array()) {
    std::size_t i = 0;
    for (auto it = value.begin(); it != value.end(); ++it, ++i)
      if (auto bad = non_finite_number(*it, at + "/" + (value.is_object() ? it.key() : std::to_string(i)))) return bad;
  }
  return std::nullopt;
}

}  // namespace pdamp::tasks::detail
