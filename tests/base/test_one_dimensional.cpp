// base's one-dimensional searches (one_dimensional.hpp): the Illinois root and the golden
// section.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "pdamp/base/one_dimensional.hpp"

using namespace pdamp::base;

TEST_CASE("the Illinois bracket replaces the end of the new value's sign and halves the other when kept twice") {
  IllinoisBracket b{0.0, -1.0, 1.0, 1.0};
  CHECK(b.secant() == 0.5);
  b.update(0.5, -0.5);  // lo replaced once: f_hi unchanged
  CHECK(b.lo == 0.5);
  CHECK(b.f_lo == -0.5);
  CHECK(b.f_hi == 1.0);
  b.update(0.7, -0.2);  // lo replaced again: f_hi halved
  CHECK(b.lo == 0.7);
  CHECK(b.f_hi == 0.5);
  b.update(0.9, 0.1);  // hi replaced: f_lo kept
  CHECK(b.hi == 0.9);
  CHECK(b.f_hi == 0.1);
  CHECK(b.f_lo == -0.2);
}

TEST_CASE("illinois_root finds the cube root of 2") {
  int evaluations = 0;
  const auto f = [&](double x) {
    ++evaluations;
    return x * x * x - 2.0;
  };
  const double root = illinois_root(f, 1.0, f(1.0), 2.0, f(2.0), 1e-14, 0.0, 100);
  // |f| < 1e-14 at the returned x, and f' = 3x² ≈ 4.8 there: |x − ∛2| < 1e-14/4.8 ≈ 2e-15,
  // plus the rounding of f itself (a few ulp of 2 ≈ 1e-15 over f'): 1e-14 holds with room.
  CHECK(std::abs(root - std::cbrt(2.0)) < 1e-14);
  // Superlinear: 8 steps; regula falsi without the Illinois rule takes 37 here.
  CHECK(evaluations <= 2 + 10);
}

TEST_CASE("illinois_root stops at a bracket narrower than the x tolerance") {
  const auto f = [](double x) { return std::atan(x - 0.25); };
  const double root = illinois_root(f, -1.0, f(-1.0), 3.0, f(3.0), 0.0, 1e-6, 200);
  // The bracket holds the root and is narrower than 1e-6 when the search stops, and the
  // last secant root lies inside it.
  CHECK(std::abs(root - 0.25) < 1e-6);
}

TEST_CASE("golden_section finds the maximum of sin on [0, 3] at pi/2") {
  GoldenSectionOptions o;
  o.maximum = true;
  o.max_iterations = 100;
  const GoldenSection s = golden_section([](double x) { return std::sin(x); }, 0.0, 3.0, o);
  // Near a smooth maximum sin x = 1 − (x − π/2)²/2 differs from 1 by less than its rounding
  // (1.1e-16) for |x − π/2| < 1.5e-8, so no comparison can place the maximum closer than a
  // few times that: 1e-7.
  CHECK(std::abs(s.middle() - std::numbers::pi / 2) < 1e-7);
  CHECK(std::max(s.f1, s.f2) > 1.0 - 1e-15);
  CHECK(s.evaluations == 102);  // two to start, one a step
  CHECK(s.lo <= s.x1);
  CHECK(s.x1 <= s.x2);
  CHECK(s.x2 <= s.hi);
}

TEST_CASE("golden_section narrows a kinked minimum to its bracket, 0.618 a step") {
  GoldenSectionOptions o;
  o.max_iterations = 60;
  const GoldenSection s = golden_section([](double x) { return std::abs(x - 0.3); }, 0.0, 1.0, o);
  // A kink is located to the bracket, 0.618⁶⁰ ≈ 2.9e-13 wide. Each new inner point is
  // rounded (by up to 1.1e-16 below 1) and carried on as a bracket end, so the last width
  // is off by a few 1.1e-16 / 2.9e-13 ≈ 4e-4 of itself: 2e-3.
  const double width = std::pow(kInverseGoldenRatio, 60);
  CHECK(s.hi - s.lo == Approx(width).epsilon(2e-3));
  CHECK(s.lo <= 0.3);
  CHECK(s.hi >= 0.3);
}

TEST_CASE("golden_section stops once the bracket is no wider than min_width") {
  GoldenSectionOptions o;
  o.max_iterations = 1000;
  o.min_width = 1e-6;
  const GoldenSection s = golden_section([](double x) { return (x - 0.3) * (x - 0.3); }, 0.0, 1.0, o);
  // 0.618^28 = 1.4e-6 > 1e-6 >= 0.618^29 = 8.8e-7: 29 steps, the last one needed.
  CHECK(s.hi - s.lo <= 1e-6);
  CHECK(s.hi - s.lo > kInverseGoldenRatio * 1e-6);
  CHECK(s.evaluations == 2 + 29);
}

TEST_CASE("golden_section evaluates the inner points in order: x1, x2, then one new point a step") {
  std::vector<double> points;
  GoldenSectionOptions o;
  o.max_iterations = 3;
  const GoldenSection s = golden_section(
      [&](double x) {
        points.push_back(x);
        return (x - 0.9) * (x - 0.9);
      },
      0.0, 1.0, o);
  REQUIRE(points.size() == 5);
  CHECK(points[0] == 1.0 - kInverseGoldenRatio * 1.0);
  CHECK(points[1] == 0.0 + kInverseGoldenRatio * 1.0);
  // The minimum at 0.9 lies above x2: every step keeps the upper part and adds a new x2.
  CHECK(points[2] > points[1]);
  CHECK(points[3] > points[2]);
  CHECK(s.x2 == points[4]);
}

TEST_CASE("golden_section without reuse evaluates both inner points at every step") {
  std::vector<double> points;
  GoldenSectionOptions o;
  o.max_iterations = 20;
  o.reuse_inner_point = false;
  const GoldenSection s = golden_section(
      [&](double x) {
        points.push_back(x);
        return (x - 0.3) * (x - 0.3);
      },
      0.0, 1.0, o);
  CHECK(points.size() == 40);
  CHECK(s.evaluations == 40);
  // Each pair is the step's x1 then x2, computed from that step's bracket.
  for (std::size_t k = 0; k + 1 < points.size(); k += 2) CHECK(points[k] < points[k + 1]);
  // The minimum stays inside: 20 steps leave 0.618²⁰ ≈ 6.6e-5 of the bracket.
  CHECK(std::abs(s.middle() - 0.3) < 1e-4);
}

TEST_CASE("golden_section's ties keep the side the options name") {
  const auto flat = [](double) { return 1.0; };
  GoldenSectionOptions o;
  o.max_iterations = 50;
  o.ties_keep_lower = true;
  CHECK(golden_section(flat, 0.0, 1.0, o).hi < 1e-9);  // 0.618⁵⁰ ≈ 3.5e-11
  o.ties_keep_lower = false;
  CHECK(golden_section(flat, 0.0, 1.0, o).lo > 1.0 - 1e-9);
  o.maximum = true;
  CHECK(golden_section(flat, 0.0, 1.0, o).lo > 1.0 - 1e-9);
}

TEST_CASE("golden_section reproduces the textbook loop bit for bit") {
  // The loop the structure solver's scan had before it used golden_section: maximum,
  // fixed step count, ties to the upper part.
  const auto f = [](double u) { return -std::cosh(u - 0.37) + 0.1 * std::sin(7.0 * u); };
  double a = -2.0, b = 1.5;
  const double g = 0.61803398874989485;
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < 60; ++i) {
    if (fc > fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  GoldenSectionOptions o;
  o.maximum = true;
  o.max_iterations = 60;
  const GoldenSection s = golden_section(f, -2.0, 1.5, o);
  CHECK(s.lo == a);
  CHECK(s.hi == b);
  CHECK(s.x1 == c);
  CHECK(s.f1 == fc);
  CHECK(s.x2 == d);
  CHECK(s.f2 == fd);
}
