// Tests of bilinear interpolation: exactness on bilinear data, derivatives, range policy.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "pdamp/surrogate/interpolator.hpp"

namespace {

using namespace pdamp::surrogate;

using Function = std::function<double(double, double)>;

std::vector<double> sample(const Grid& grid, const Function& f) {
  std::vector<double> values;
  for (std::size_t k = 0; k < grid.size(); ++k) values.push_back(f(grid.coordinate0(k), grid.coordinate1(k)));
  return values;
}

/// A deliberately non-uniform linear axis (binary-search path) and a uniform one.
Grid linear_grid() {
  return {Axis{AxisQuantity::kFrequencyHz, AxisSpacing::kLinear, {1.0, 2.0, 3.0, 4.0, 5.0}},
          Axis{AxisQuantity::kAmplitudeM, AxisSpacing::kLinear, {0.01, 0.015, 0.03, 0.06, 0.1}}};
}

Grid log_grid() {
  return Grid::from_ranges(GridAxes::kFrequencyAmplitude, {0.5, 50.0, 7, AxisSpacing::kLog},
                           {1e-4, 1e-1, 10, AxisSpacing::kLog});
}

constexpr double a = 0.7, b = -0.3, c = 12.0, d = 2.5;  // coefficients of the bilinear test data

}  // namespace

TEST_CASE("interpolation is exact on data bilinear in the axis coordinates", "[surrogate]") {
  std::mt19937_64 random(42);
  SECTION("linear axes, uniform and non-uniform") {
    const Grid grid = linear_grid();
    // Reference: f(x, y) = a + bx + cy + dxy, which bilinear interpolation reproduces
    // exactly; tolerance is rounding of O(10) values.
    const Function f = [](double x, double y) { return a + b * x + c * y + d * x * y; };
    const BilinearInterpolator interpolator(grid, sample(grid, f));
    std::uniform_real_distribution<double> x(1.0, 5.0), y(0.01, 0.1);
    for (int k = 0; k < 1000; ++k) {
      const double x0 = x(random), x1 = y(random);
      const auto r = interpolator.evaluate(x0, x1);
      CHECK(r.value == Approx(f(x0, x1)).margin(1e-13));
      CHECK(r.d_dx0 == Approx(b + d * x1).margin(1e-12));
      CHECK(r.d_dx1 == Approx(c + d * x0).margin(1e-11));
      CHECK_FALSE(r.clamped0);
      CHECK_FALSE(r.clamped1);
    }
    // At the nodes themselves (both ends included).
    for (std::size_t k = 0; k < grid.size(); ++k) {
      CHECK(interpolator.evaluate(grid.coordinate0(k), grid.coordinate1(k)).value ==
            Approx(f(grid.coordinate0(k), grid.coordinate1(k))).margin(1e-14));
    }
  }
  SECTION("log axes, for data bilinear in ln x and ln y") {
    const Grid grid = log_grid();
    const Function f = [](double x, double y) {
      return a + b * std::log(x) + c * std::log(y) + d * std::log(x) * std::log(y);
    };
    const BilinearInterpolator interpolator(grid, sample(grid, f));
    std::uniform_real_distribution<double> u(std::log(0.5), std::log(50.0)), v(std::log(1e-4), std::log(1e-1));
    for (int k = 0; k < 1000; ++k) {
      const double x0 = std::exp(u(random)), x1 = std::exp(v(random));
      const auto r = interpolator.evaluate(x0, x1);
      // Values reach ~100 (d·ln x·ln y): rounding of a few ulp of that.
      CHECK(r.value == Approx(f(x0, x1)).margin(1e-11));
      CHECK(r.d_dx0 == Approx((b + d * std::log(x1)) / x0).epsilon(1e-10));
      CHECK(r.d_dx1 == Approx((c + d * std::log(x0)) / x1).epsilon(1e-10));
    }
  }
}

TEST_CASE("derivatives match central finite differences inside the cells", "[surrogate]") {
  // Reference: central differences of the interpolant itself, with steps far inside a
  // cell; the patch is linear in t along each axis, so on linear axes the difference is
  // exact to rounding and on log axes its error is O(h²) ~ 1e-12 relative.
  for (const Grid& grid : {linear_grid(), log_grid()}) {
    const Function f = [](double x, double y) { return std::sin(x) * std::exp(-30.0 * y) + x * y; };
    const BilinearInterpolator interpolator(grid, sample(grid, f));
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(0.1, 0.9);
    for (int k = 0; k < 200; ++k) {
      const std::size_t i0 = random() % (grid.axis0.size() - 1), i1 = random() % (grid.axis1.size() - 1);
      const double x0 = grid.axis0.values[i0] + unit(random) * (grid.axis0.values[i0 + 1] - grid.axis0.values[i0]);
      const double x1 = grid.axis1.values[i1] + unit(random) * (grid.axis1.values[i1 + 1] - grid.axis1.values[i1]);
      const double h0 = 1e-6 * x0, h1 = 1e-6 * x1;
      const auto r = interpolator.evaluate(x0, x1);
      const double fd0 =
          (interpolator.evaluate(x0 + h0, x1).value - interpolator.evaluate(x0 - h0, x1).value) / (2 * h0);
      const double fd1 =
          (interpolator.evaluate(x0, x1 + h1).value - interpolator.evaluate(x0, x1 - h1).value) / (2 * h1);
      // Rounding of the difference quotient: ~1e-16·|v|/h ~ 1e-9 relative at worst.
      CHECK(r.d_dx0 == Approx(fd0).epsilon(1e-6).margin(1e-8));
      CHECK(r.d_dx1 == Approx(fd1).epsilon(1e-6).margin(1e-6));
    }
  }
}

TEST_CASE("outside the grid clamp takes the edge and flags it, error throws", "[surrogate]") {
  const Grid grid = linear_grid();
  const Function f = [](double x, double y) { return a + b * x + c * y + d * x * y; };
  const BilinearInterpolator clamp(grid, sample(grid, f));
  CHECK(clamp.policy() == OutOfRangePolicy::kClamp);  // the documented default

  const auto above = clamp.evaluate(7.0, 0.05);
  CHECK(above.value == Approx(f(5.0, 0.05)).margin(1e-13));
  CHECK(above.clamped0);
  CHECK_FALSE(above.clamped1);
  CHECK(above.d_dx0 == 0.0);  // constant beyond the edge
  CHECK(above.d_dx1 == Approx(c + d * 5.0));

  const auto below = clamp.evaluate(2.0, 1e-5);
  CHECK(below.value == Approx(f(2.0, 0.01)).margin(1e-13));
  CHECK(below.clamped1);
  CHECK(below.d_dx1 == 0.0);

  // Rounding just past the edge is not "outside" (1e-9 of the span).
  CHECK_FALSE(clamp.evaluate(5.0 * (1 + 1e-12), 0.1 * (1 + 1e-12)).clamped0);

  const BilinearInterpolator error(grid, sample(grid, f), OutOfRangePolicy::kError);
  CHECK_THROWS_WITH(error.evaluate(7.0, 0.05), Catch::Contains("frequency_hz = 7: outside the field's axis [1, 5]") &&
                                                   Catch::Contains("\"error\""));
  CHECK_THROWS_WITH(error.evaluate(2.0, 0.2),
                    Catch::Contains("amplitude_m = 0.2: outside the field's axis [0.01, 0.1]"));
  CHECK_NOTHROW(error.evaluate(5.0, 0.01));

  for (const auto* interpolator : {&clamp, &error}) {
    CHECK_THROWS_WITH(interpolator->evaluate(std::nan(""), 0.05), Catch::Contains("frequency_hz = nan"));
  }
  CHECK(out_of_range_policy_from_string("error") == OutOfRangePolicy::kError);
  CHECK_FALSE(out_of_range_policy_from_string("wrap").has_value());
}

TEST_CASE("a log axis clamps zero and negative values to its lower edge", "[surrogate]") {
  const Grid grid = log_grid();
  const BilinearInterpolator interpolator(grid, sample(grid, [](double x, double y) { return x + y; }));
  const auto r = interpolator.evaluate(2.0, -1.0);
  CHECK(r.clamped1);
  CHECK(r.value == Approx(interpolator.evaluate(2.0, 1e-4).value));
}

TEST_CASE("a single-node axis gives a constant along it and flags any other value", "[surrogate]") {
  const Grid grid{Axis{AxisQuantity::kFrequencyHz, AxisSpacing::kLinear, {2.0}},
                  Axis{AxisQuantity::kAmplitudeM, AxisSpacing::kLinear, {0.01, 0.02, 0.04}}};
  const BilinearInterpolator interpolator(grid, {1.0, 3.0, 4.0});
  const auto on = interpolator.evaluate(2.0, 0.015);
  CHECK(on.value == Approx(2.0));  // halfway between 1 and 3
  CHECK_FALSE(on.clamped0);
  CHECK(on.d_dx0 == 0.0);
  CHECK(on.d_dx1 == Approx(200.0));  // (3 − 1)/0.01
  const auto off = interpolator.evaluate(2.5, 0.03);
  CHECK(off.clamped0);
  CHECK(off.value == Approx(3.5));
  CHECK(interpolator.nearest_node(9.0, 0.035) == 2);
}

TEST_CASE("a missing node poisons exactly the cells around it", "[surrogate]") {
  const Grid grid = linear_grid();  // 5 x 5
  std::vector<double> values(grid.size(), 1.0);
  values[grid.index(2, 2)] = std::numeric_limits<double>::quiet_NaN();  // node (3 Hz, 0.03 m)
  const BilinearInterpolator interpolator(grid, values);
  CHECK(std::isnan(interpolator.evaluate(2.5, 0.02).value));
  CHECK(std::isnan(interpolator.evaluate(3.5, 0.05).value));
  CHECK(interpolator.evaluate(1.5, 0.012).value == 1.0);
  CHECK(interpolator.evaluate(4.5, 0.08).value == 1.0);
}

TEST_CASE("the interpolator rejects a grid and values that do not fit", "[surrogate]") {
  const Grid grid = linear_grid();
  CHECK_THROWS_WITH(BilinearInterpolator(grid, std::vector<double>(3, 0.0)),
                    Catch::Contains("3 values for a grid of 25 nodes"));
  Grid bad = grid;
  bad.axis0.values[1] = 0.5;
  CHECK_THROWS_WITH(BilinearInterpolator(bad, std::vector<double>(25, 0.0)), Catch::Contains("strictly increasing"));
}

TEST_CASE("nearest node is found in interpolation coordinates", "[surrogate]") {
  const Grid grid = log_grid();  // axis 1: 1e-4 ... 1e-1, 10 nodes, ratio 10^(1/3)
  const BilinearInterpolator interpolator(grid, std::vector<double>(grid.size(), 0.0));
  // Between 1e-4 and 2.154e-4 the log midpoint is 1.468e-4 (the linear one would be 1.58e-4).
  CHECK(interpolator.nearest_node(0.5, 1.45e-4) == grid.index(0, 0));
  CHECK(interpolator.nearest_node(0.5, 1.49e-4) == grid.index(0, 1));
  CHECK(interpolator.nearest_node(1e3, 1.0) == grid.size() - 1);
}
