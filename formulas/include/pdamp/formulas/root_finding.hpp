// Root finding shared by the closed forms and the structure solvers: regula falsi with the
// Illinois update (Dowell & Jarratt 1971), superlinear where plain regula falsi stalls.
#pragma once

#include <cmath>

namespace pdamp::formulas {

/// The bracket [lo, hi] of a continuous residual with f(lo) and f(hi) of opposite signs,
/// and the Illinois rule: the secant's root replaces the end of its own sign, and when the
/// same end is kept twice the other end's value is halved.
struct IllinoisBracket {
  double lo = 0.0, f_lo = 0.0, hi = 0.0, f_hi = 0.0;
  int side = 0;  ///< which end the last step kept (-1 lo replaced, 1 hi replaced, 0 none yet)

  /// The root of the secant through the two ends.
  double secant() const { return (lo * f_hi - hi * f_lo) / (f_hi - f_lo); }
  /// x with residual f replaces the end of f's sign.
  void update(double x, double f) {
    if ((f > 0.0) == (f_lo > 0.0)) {
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
};

/// Root of a continuous `residual` bracketed by lo and hi (f_lo, f_hi of opposite signs).
/// Stops at |f| < f_tolerance or a bracket narrower than x_tolerance, returning the last
/// secant root.
template <class Residual>
double illinois_root(const Residual& residual, double lo, double f_lo, double hi, double f_hi, double f_tolerance,
                     double x_tolerance, int max_iterations) {
  IllinoisBracket bracket{lo, f_lo, hi, f_hi};
  double x = hi;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    x = bracket.secant();
    const double f = residual(x);
    if (std::abs(f) < f_tolerance || bracket.hi - bracket.lo < x_tolerance) break;
    bracket.update(x, f);
  }
  return x;
}

}  // namespace pdamp::formulas
