// Searches along one variable, shared by the closed forms, the structure solvers and the
// optimiser: a root by regula falsi with the Illinois update (Dowell & Jarratt 1971),
// superlinear where plain regula falsi stalls, and an extremum by golden-section search.
#pragma once

#include <cmath>

namespace pdamp::base {

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

/// (√5 − 1)/2: each golden-section step keeps this fraction of the bracket.
inline constexpr double kInverseGoldenRatio = 0.61803398874989485;

/// How golden_section searches.
struct GoldenSectionOptions {
  bool maximum = false;      ///< the maximum of f (else its minimum)
  int max_iterations = 100;  ///< steps (a step shrinks the bracket by kInverseGoldenRatio)
  /// Stops before a step once hi − lo <= min_width; 0: every one of max_iterations steps.
  double min_width = 0.0;
  /// Equal values at the inner points keep the lower part [lo, x2] (else the upper [x1, hi]).
  bool ties_keep_lower = false;
  /// A step evaluates f once, at its new inner point, and keeps the other one (the golden
  /// section proper); false: a step recomputes both inner points from its bracket and
  /// evaluates f at both (twice the evaluations, for callers whose results were set so).
  bool reuse_inner_point = true;
};

/// The end of a golden-section search: its last bracket and its last inner points
/// x1 = hi − g (hi − lo) <= x2 = lo + g (hi − lo) with their values f1, f2.
struct GoldenSection {
  double lo = 0.0, hi = 0.0;
  double x1 = 0.0, f1 = 0.0, x2 = 0.0, f2 = 0.0;
  int evaluations = 0;

  /// The middle of the last bracket: the extremum's abscissa.
  double middle() const { return 0.5 * (lo + hi); }
};

/// Golden-section search for an extremum of a unimodal f on [lo, hi]: the inner points
/// x1 = hi − g (hi − lo) and x2 = lo + g (hi − lo) (g = kInverseGoldenRatio), evaluated x1
/// first; a step keeps [lo, x2] where f(x1) is the better (options.maximum: the larger) and
/// [x1, hi] otherwise, also when a value is NaN (ties: options.ties_keep_lower). The
/// arithmetic is fixed, so a search gives the same points bit for bit on every run.
template <class F>
GoldenSection golden_section(F&& f, double lo, double hi, const GoldenSectionOptions& options) {
  const double g = kInverseGoldenRatio;
  GoldenSection s;
  s.lo = lo;
  s.hi = hi;
  const auto keep_lower = [&](double f1, double f2) {
    if (options.maximum) return options.ties_keep_lower ? f1 >= f2 : f1 > f2;
    return options.ties_keep_lower ? f1 <= f2 : f1 < f2;
  };
  const auto go_on = [&] { return !(options.min_width > 0.0) || s.hi - s.lo > options.min_width; };
  if (!options.reuse_inner_point) {
    for (int iteration = 0; iteration < options.max_iterations && go_on(); ++iteration) {
      s.x1 = s.hi - g * (s.hi - s.lo);
      s.x2 = s.lo + g * (s.hi - s.lo);
      s.f1 = f(s.x1);
      s.f2 = f(s.x2);
      s.evaluations += 2;
      if (keep_lower(s.f1, s.f2)) {
        s.hi = s.x2;
      } else {
        s.lo = s.x1;
      }
    }
    return s;
  }
  s.x1 = s.hi - g * (s.hi - s.lo);
  s.x2 = s.lo + g * (s.hi - s.lo);
  s.f1 = f(s.x1);
  s.f2 = f(s.x2);
  s.evaluations = 2;
  for (int iteration = 0; iteration < options.max_iterations && go_on(); ++iteration) {
    if (keep_lower(s.f1, s.f2)) {
      s.hi = s.x2;
      s.x2 = s.x1;
      s.f2 = s.f1;
      s.x1 = s.hi - g * (s.hi - s.lo);
      s.f1 = f(s.x1);
    } else {
      s.lo = s.x1;
      s.x1 = s.x2;
      s.f1 = s.f2;
      s.x2 = s.lo + g * (s.hi - s.lo);
      s.f2 = f(s.x2);
    }
    ++s.evaluations;
  }
  return s;
}

}  // namespace pdamp::base
