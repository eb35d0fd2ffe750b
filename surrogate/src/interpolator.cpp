// Bilinear interpolation over a Grid: cell location, weights, derivatives, range policy.
#include "pdamp/surrogate/interpolator.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;

namespace {

/// Points this close outside an axis (relative to its span in t) count as inside:
/// conversions such as Γ = XΩ²/g round by a few ulp at the grid edge.
constexpr double kEdgeTolerance = 1e-9;
/// Axes whose nodes sit this close to equal steps in t (relative to the span) are
/// indexed directly instead of by binary search.
constexpr double kUniformTolerance = 1e-10;

}  // namespace

std::string_view to_string(OutOfRangePolicy policy) { return policy == OutOfRangePolicy::kError ? "error" : "clamp"; }

std::optional<OutOfRangePolicy> out_of_range_policy_from_string(std::string_view name) {
  if (name == "clamp") return OutOfRangePolicy::kClamp;
  if (name == "error") return OutOfRangePolicy::kError;
  return std::nullopt;
}

BilinearInterpolator::BilinearInterpolator(const Grid& grid, std::vector<double> values, OutOfRangePolicy policy)
    : grid_(grid), values_(std::move(values)), policy_(policy) {
  detail::throw_if_any(grid_.validate(), "interpolator grid");
  if (values_.size() != grid_.size()) {
    throw std::invalid_argument("interpolator values: " + std::to_string(values_.size()) + " values for a grid of " +
                                std::to_string(grid_.size()) + " nodes");
  }
  axis0_ = make_axis(grid_.axis0);
  axis1_ = make_axis(grid_.axis1);
  // Stepping along axis 0 moves a whole row in storage.
  axis0_.next *= grid_.axis1.size();
}

BilinearInterpolator::AxisLookup BilinearInterpolator::make_axis(const Axis& axis) {
  AxisLookup a;
  a.quantity = axis.quantity;
  a.log = axis.spacing == AxisSpacing::kLog;
  for (double x : axis.values) a.t.push_back(a.log ? std::log(x) : x);
  const std::size_t n = a.t.size();
  a.t_min = a.t.front();
  a.t_max = a.t.back();
  if (n == 1) {
    a.inv_width = {0.0};
    a.last_cell = 0;
    a.next = 0;
    // A single node: accept a relative 1e-9 neighbourhood of x (absolute in ln x).
    const double tolerance = a.log ? kEdgeTolerance : kEdgeTolerance * std::abs(a.t_min);
    a.t_low = a.t_min - tolerance;
    a.t_high = a.t_max + tolerance;
    return a;
  }
  const double span = a.t_max - a.t_min;
  for (std::size_t i = 0; i + 1 < n; ++i) a.inv_width.push_back(1.0 / (a.t[i + 1] - a.t[i]));
  a.last_cell = n - 2;
  a.t_low = a.t_min - kEdgeTolerance * span;
  a.t_high = a.t_max + kEdgeTolerance * span;
  const double step = span / static_cast<double>(n - 1);
  a.uniform = true;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::abs(a.t[i] - (a.t_min + static_cast<double>(i) * step)) > kUniformTolerance * span) a.uniform = false;
  }
  a.inv_step = 1.0 / step;
  return a;
}

std::size_t BilinearInterpolator::cell_of(const AxisLookup& axis, double t) {
  if (axis.uniform) {
    // t >= t_min here, so the cast is of a non-negative number.
    return std::min(static_cast<std::size_t>((t - axis.t_min) * axis.inv_step), axis.last_cell);
  }
  // First node above t among t[1..last_cell]; the cell starts one node below it.
  const auto first = axis.t.begin() + 1;
  const auto last = axis.t.begin() + static_cast<std::ptrdiff_t>(axis.last_cell) + 1;
  return static_cast<std::size_t>(std::upper_bound(first, last, t) - axis.t.begin()) - 1;
}

double BilinearInterpolator::outside(const AxisLookup& axis, double x, double t) const {
  const std::string name(to_string(axis.quantity));
  if (std::isnan(x)) throw std::invalid_argument(name + " = nan: must be a number");
  if (policy_ == OutOfRangePolicy::kError) {
    throw std::invalid_argument(name + " = " + format_number(x, 12) + ": outside the field's axis [" +
                                format_number(axis.log ? std::exp(axis.t_min) : axis.t_min, 12) + ", " +
                                format_number(axis.log ? std::exp(axis.t_max) : axis.t_max, 12) +
                                "] (out-of-range policy \"error\")");
  }
  // Below the axis includes x <= 0 on a log axis, where ln x is NaN or −inf.
  return (t > axis.t_max) ? axis.t_max : axis.t_min;
}

BilinearInterpolator::Located BilinearInterpolator::locate(const AxisLookup& axis, double x) const {
  double t = axis.log ? std::log(x) : x;
  const bool clamped = !(t >= axis.t_low && t <= axis.t_high);  // also true for NaN
  if (clamped) [[unlikely]] {
    t = outside(axis, x, t);
  }
  t = std::clamp(t, axis.t_min, axis.t_max);  // the tolerance band sits on the edge node
  const std::size_t cell = cell_of(axis, t);
  const double inv_width = axis.inv_width[cell];
  const double w = (t - axis.t[cell]) * inv_width;
  const double dw_dx = clamped ? 0.0 : (axis.log ? inv_width / x : inv_width);
  return {cell, w, dw_dx, clamped};
}

BilinearInterpolator::Result BilinearInterpolator::evaluate(double x0, double x1) const {
  const Located a = locate(axis0_, x0);
  const Located b = locate(axis1_, x1);
  // axis0_.next is n1 (or 0 on a single-node axis, where a.cell is 0): the cell's first node.
  const double* v = values_.data() + a.cell * axis0_.next + b.cell;
  const double v00 = v[0];
  const double v01 = v[axis1_.next];
  const double v10 = v[axis0_.next];
  const double v11 = v[axis0_.next + axis1_.next];
  const double low = v00 + b.w * (v01 - v00);   // along axis 1 at the cell's lower axis-0 node
  const double high = v10 + b.w * (v11 - v10);  // ... at its upper axis-0 node
  Result r;
  r.value = low + a.w * (high - low);
  r.d_dx0 = (high - low) * a.dw_dx;
  r.d_dx1 = ((v01 - v00) + a.w * ((v11 - v10) - (v01 - v00))) * b.dw_dx;
  r.clamped0 = a.clamped;
  r.clamped1 = b.clamped;
  return r;
}

std::size_t BilinearInterpolator::nearest_node(double x0, double x1) const {
  auto nearest = [](const AxisLookup& axis, double x) {
    if (std::isnan(x)) throw std::invalid_argument(std::string(to_string(axis.quantity)) + " = nan: must be a number");
    double t = axis.log ? (x > 0.0 ? std::log(x) : axis.t_min) : x;
    t = std::clamp(t, axis.t_min, axis.t_max);
    const std::size_t cell = cell_of(axis, t);
    const bool upper = axis.next != 0 && (t - axis.t[cell]) * axis.inv_width[cell] > 0.5;
    return cell + (upper ? 1 : 0);
  };
  return grid_.index(nearest(axis0_, x0), nearest(axis1_, x1));
}

}  // namespace pdamp::surrogate
