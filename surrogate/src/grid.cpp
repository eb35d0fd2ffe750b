// Axes and grids of effective fields: names, units, node generation and validation.
#include "pdamp/surrogate/grid.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <cmath>
#include <stdexcept>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;

namespace {

constexpr int kMaxAxisCount = 100000;

/// "n0 x n1 = N nodes: must be <= kMaxGridNodes" if the grid is too large, "" otherwise.
std::string size_problem(std::size_t n0, std::size_t n1) {
  if (n0 * n1 <= kMaxGridNodes) return {};
  return std::to_string(n0) + " x " + std::to_string(n1) + " = " + std::to_string(n0 * n1) +
         " nodes: must be <= " + std::to_string(kMaxGridNodes) + " (1000 x 1000)";
}

}  // namespace

std::string_view to_string(AxisQuantity quantity) {
  switch (quantity) {
    case AxisQuantity::kFrequencyHz: return "frequency_hz";
    case AxisQuantity::kAmplitudeM: return "amplitude_m";
    case AxisQuantity::kIntensity: return "intensity";
    case AxisQuantity::kStrokeOverClearance: return "stroke_over_clearance";
  }
  return "unknown";
}

std::string_view unit_of(AxisQuantity quantity) {
  switch (quantity) {
    case AxisQuantity::kFrequencyHz: return "Hz";
    case AxisQuantity::kAmplitudeM: return "m";
    case AxisQuantity::kIntensity:
    case AxisQuantity::kStrokeOverClearance: return "1";
  }
  return "unknown";
}

std::optional<AxisQuantity> axis_quantity_from_string(std::string_view name) {
  for (auto q : {AxisQuantity::kFrequencyHz, AxisQuantity::kAmplitudeM, AxisQuantity::kIntensity,
                 AxisQuantity::kStrokeOverClearance}) {
    if (to_string(q) == name) return q;
  }
  return std::nullopt;
}

std::string_view to_string(AxisSpacing spacing) { return spacing == AxisSpacing::kLog ? "log" : "linear"; }

std::optional<AxisSpacing> axis_spacing_from_string(std::string_view name) {
  if (name == "linear") return AxisSpacing::kLinear;
  if (name == "log") return AxisSpacing::kLog;
  return std::nullopt;
}

std::string_view to_string(GridAxes axes) {
  return axes == GridAxes::kFrequencyAmplitude ? "frequency_amplitude" : "intensity_stroke_over_clearance";
}

std::vector<std::string> AxisRange::validate(const std::string& prefix) const {
  std::vector<std::string> problems;
  if (!positive_finite(min))
    problems.push_back(prefix + ".min = " + format_number(min, 12) + ": must be > 0 and finite");
  if (!std::isfinite(max) || max < min) {
    problems.push_back(prefix + ".max = " + format_number(max, 12) +
                       ": must be finite and >= min = " + format_number(min, 12));
  }
  if (count < 1 || count > kMaxAxisCount) {
    problems.push_back(prefix + ".count = " + std::to_string(count) + ": must be in [1, " +
                       std::to_string(kMaxAxisCount) + "]");
  } else if (count == 1 && max != min) {
    problems.push_back(prefix + ".count = 1: needs max == min (got min = " + format_number(min, 12) +
                       ", max = " + format_number(max, 12) + ")");
  } else if (count > 1 && !(max > min)) {
    problems.push_back(prefix + ".max = " + format_number(max, 12) + ": must be > min = " + format_number(min, 12) +
                       " when count > 1");
  }
  return problems;
}

Axis Axis::from_range(AxisQuantity quantity, const AxisRange& range) {
  const std::string name(to_string(quantity));
  detail::throw_if_any(range.validate(name), "axis " + name);
  Axis axis{quantity, range.spacing, std::vector<double>(static_cast<std::size_t>(range.count))};
  const int last = range.count - 1;
  for (int k = 0; k <= last; ++k) {
    const double fraction = last == 0 ? 0.0 : static_cast<double>(k) / last;
    axis.values[k] = range.spacing == AxisSpacing::kLog
                         ? std::exp(std::log(range.min) + fraction * (std::log(range.max) - std::log(range.min)))
                         : range.min + fraction * (range.max - range.min);
  }
  // The end nodes are exactly the user's numbers (exp(log x) may differ from x by an ulp).
  axis.values.front() = range.min;
  axis.values.back() = range.max;
  return axis;
}

std::vector<std::string> Axis::validate(const std::string& prefix) const {
  std::vector<std::string> problems;
  if (values.empty()) problems.push_back(prefix + ".values: must hold at least one node");
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::string at = prefix + ".values[" + std::to_string(k) + "] = " + format_number(values[k], 12);
    if (!positive_finite(values[k])) {
      problems.push_back(at + ": must be > 0 and finite");
    } else if (k > 0 && !(values[k] > values[k - 1])) {
      problems.push_back(at + ": must be > values[" + std::to_string(k - 1) +
                         "] = " + format_number(values[k - 1], 12) + " (strictly increasing)");
    }
  }
  return problems;
}

Grid Grid::from_ranges(GridAxes axes, const AxisRange& range0, const AxisRange& range1) {
  const bool fa = axes == GridAxes::kFrequencyAmplitude;
  // Checked before the axes are built: each count alone is in range, their product may not be.
  if (range0.count > 0 && range1.count > 0) {
    const std::string problem =
        size_problem(static_cast<std::size_t>(range0.count), static_cast<std::size_t>(range1.count));
    if (!problem.empty()) throw std::invalid_argument("grid: " + problem);
  }
  return {Axis::from_range(fa ? AxisQuantity::kFrequencyHz : AxisQuantity::kIntensity, range0),
          Axis::from_range(fa ? AxisQuantity::kAmplitudeM : AxisQuantity::kStrokeOverClearance, range1)};
}

GridAxes Grid::axes() const {
  if (axis0.quantity == AxisQuantity::kFrequencyHz && axis1.quantity == AxisQuantity::kAmplitudeM) {
    return GridAxes::kFrequencyAmplitude;
  }
  if (axis0.quantity == AxisQuantity::kIntensity && axis1.quantity == AxisQuantity::kStrokeOverClearance) {
    return GridAxes::kIntensityStrokeOverClearance;
  }
  throw std::invalid_argument("grid axes (" + std::string(to_string(axis0.quantity)) + ", " +
                              std::string(to_string(axis1.quantity)) +
                              "): must be (frequency_hz, amplitude_m) or (intensity, stroke_over_clearance)");
}

std::vector<std::string> Grid::validate() const {
  std::vector<std::string> problems = axis0.validate("axis 0 (" + std::string(to_string(axis0.quantity)) + ")");
  for (auto& line : axis1.validate("axis 1 (" + std::string(to_string(axis1.quantity)) + ")")) {
    problems.push_back(std::move(line));
  }
  try {
    (void)axes();
  } catch (const std::invalid_argument& e) {
    problems.emplace_back(e.what());
  }
  if (const std::string problem = size_problem(axis0.size(), axis1.size()); !problem.empty()) {
    problems.push_back("grid: " + problem);
  }
  return problems;
}

DrivePoint drive_point(const Grid& grid, std::size_t k, double clearance_m) {
  const double c0 = grid.coordinate0(k);
  const double c1 = grid.coordinate1(k);
  if (grid.axes() == GridAxes::kFrequencyAmplitude) return {c0, c1};
  if (!positive_finite(clearance_m)) {
    throw std::invalid_argument("clearance_m = " + format_number(clearance_m, 12) +
                                ": must be > 0 and finite to turn (intensity, stroke_over_clearance) into a drive");
  }
  // Γ = XΩ²/g  =>  Ω = √(Γg/X).
  const double amplitude_m = c1 * clearance_m;
  const double omega = std::sqrt(c0 * formulas::kStandardGravity / amplitude_m);
  return {omega / (2.0 * formulas::kPi), amplitude_m};
}

}  // namespace pdamp::surrogate
