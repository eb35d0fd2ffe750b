// Private root finding of the formulas module.
#pragma once

#include <cmath>

namespace pdamp::formulas::detail {

/// Root of a continuous decreasing-through-zero `residual` bracketed by lo (f_lo > 0)
/// and hi (f_hi <= 0): regula falsi with the Illinois update (the retained end's value
/// halved when the same end is kept twice), superlinear where plain regula falsi
/// stalls. Stops at |f| < f_tolerance or a bracket narrower than x_tolerance.
template <class Residual>
double illinois_root(const Residual& residual, double lo, double f_lo, double hi, double f_hi, double f_tolerance,
                     double x_tolerance, int max_iterations) {
  int side = 0;
  double x = hi;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
    const double f = residual(x);
    if (std::abs(f) < f_tolerance || hi - lo < x_tolerance) break;
    if (f > 0.0) {
      lo = x;
      f_lo = f;
      if (side == -1) f_hi *= 0.5;
      side = -1;
    } else {
      hi = x;
      f_hi = f;
      if (side == 1) f_lo *= 0.5;
      side = 1;
    }
  }
  return x;
}

}  // namespace pdamp::formulas::detail
