// Tests of grid axes: node generation, validation and the (Γ, X/h) to drive conversion.
#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pdamp/surrogate/grid.hpp"

namespace {

using namespace pdamp::surrogate;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;  // standard gravity, m/s^2

bool contains(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST_CASE("linear and log axes hit their end points exactly and step evenly", "[surrogate]") {
  const Axis linear = Axis::from_range(AxisQuantity::kFrequencyHz, {1.0, 5.0, 5, AxisSpacing::kLinear});
  REQUIRE(linear.values == std::vector<double>{1.0, 2.0, 3.0, 4.0, 5.0});
  const Axis log = Axis::from_range(AxisQuantity::kAmplitudeM, {0.001, 0.1, 3, AxisSpacing::kLog});
  REQUIRE(log.values.front() == 0.001);
  REQUIRE(log.values.back() == 0.1);
  // Geometric mean of the ends; a few ulp from exp/log.
  CHECK(log.values[1] == Approx(0.01).epsilon(1e-14));
  const Axis single = Axis::from_range(AxisQuantity::kIntensity, {0.5, 0.5, 1, AxisSpacing::kLinear});
  CHECK(single.values == std::vector<double>{0.5});
}

TEST_CASE("axis ranges and axes report every violated rule", "[surrogate]") {
  const auto problems = AxisRange{-1.0, -2.0, 0, AxisSpacing::kLinear}.validate("frequency_hz");
  CHECK(contains(problems, "frequency_hz.min = -1: must be > 0"));
  CHECK(contains(problems, "frequency_hz.max = -2"));
  CHECK(contains(problems, "frequency_hz.count = 0: must be in [1, 100000]"));
  CHECK(contains(AxisRange{1.0, 2.0, 1, AxisSpacing::kLinear}.validate("a"), "a.count = 1: needs max == min"));
  CHECK_THROWS_WITH(Axis::from_range(AxisQuantity::kAmplitudeM, {1.0, 1.0, 3, AxisSpacing::kLog}),
                    Catch::Contains("amplitude_m.max = 1: must be > min = 1 when count > 1"));

  const Axis bad{AxisQuantity::kAmplitudeM, AxisSpacing::kLinear, {0.1, 0.1, std::nan("")}};
  const auto axis_problems = bad.validate("axis 1");
  CHECK(contains(axis_problems, "axis 1.values[1] = 0.1: must be > values[0] = 0.1 (strictly increasing)"));
  CHECK(contains(axis_problems, "axis 1.values[2] = nan: must be > 0 and finite"));
}

TEST_CASE("a grid pairs frequency with amplitude or intensity with stroke over clearance", "[surrogate]") {
  const Grid fa = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 2.0, 2, AxisSpacing::kLinear},
                                    {0.01, 0.03, 3, AxisSpacing::kLinear});
  CHECK(fa.axes() == GridAxes::kFrequencyAmplitude);
  CHECK(fa.size() == 6);
  CHECK(fa.index(1, 2) == 5);
  CHECK(fa.coordinate0(4) == 2.0);
  CHECK(fa.coordinate1(4) == Approx(0.02));
  CHECK(fa.validate().empty());

  Grid mixed = fa;
  mixed.axis1.quantity = AxisQuantity::kStrokeOverClearance;
  CHECK_THROWS_AS(mixed.axes(), std::invalid_argument);
  CHECK(contains(mixed.validate(), "must be (frequency_hz, amplitude_m) or (intensity, stroke_over_clearance)"));
}

TEST_CASE("drive points of an intensity grid reproduce the node's intensity and stroke", "[surrogate]") {
  const double clearance = 0.05;
  const Grid grid = Grid::from_ranges(GridAxes::kIntensityStrokeOverClearance, {0.2, 2.0, 4, AxisSpacing::kLog},
                                      {0.1, 1.0, 3, AxisSpacing::kLinear});
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const DrivePoint d = drive_point(grid, k, clearance);
    // Reference: the definitions Γ = X(2πf)²/g and s = X/h (docs/theory.md §1), to rounding.
    const double omega = 2.0 * kPi * d.frequency_hz;
    CHECK(d.amplitude_m * omega * omega / kG == Approx(grid.coordinate0(k)).epsilon(1e-14));
    CHECK(d.amplitude_m / clearance == Approx(grid.coordinate1(k)).epsilon(1e-15));
  }
  CHECK_THROWS_WITH(drive_point(grid, 0, 0.0), Catch::Contains("clearance_m = 0: must be > 0"));
  const Grid fa = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {3.0, 3.0, 1, AxisSpacing::kLinear},
                                    {0.02, 0.02, 1, AxisSpacing::kLinear});
  CHECK(drive_point(fa, 0, 0.0).frequency_hz == 3.0);  // a drive grid needs no clearance
}

TEST_CASE("a grid of more than a million nodes is refused, each axis alone may be long", "[surrogate]") {
  // Each count is within AxisRange's [1, 100000]; 2000 x 2000 DEM points would run for years.
  CHECK_THROWS_WITH(Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 100.0, 2000, AxisSpacing::kLinear},
                                      {0.001, 0.1, 2000, AxisSpacing::kLog}),
                    Catch::Equals("grid: 2000 x 2000 = 4000000 nodes: must be <= 1000000 (1000 x 1000)"));
  const Grid line = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 1.0, 1, AxisSpacing::kLinear},
                                      {0.001, 0.1, 100000, AxisSpacing::kLog});
  CHECK(line.size() == 100000);
  CHECK(line.validate().empty());
  const Grid largest = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 100.0, 1000, AxisSpacing::kLinear},
                                         {0.001, 0.1, 1000, AxisSpacing::kLog});
  CHECK(largest.size() == kMaxGridNodes);
  Grid too_large = largest;
  too_large.axis0.values.push_back(200.0);
  CHECK(contains(too_large.validate(), "grid: 1001 x 1000 = 1001000 nodes: must be <= 1000000"));
}
