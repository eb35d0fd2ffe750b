// A bed's field along a decay (surrogate::decay_field): the binning rules, against periods
// whose bins and means are worked out by hand.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "pdamp/surrogate/decay_field.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace sg = pdamp::surrogate;

TEST_CASE("decay_field: one node per stroke bin, the mean of its periods, empty bins interpolated",
          "[surrogate][decay_field]") {
  // 4 bins a decade: bin b holds strokes in [10^(b/4), 10^((b+1)/4)), node at 10^((b+0.5)/4).
  // Strokes 1e-2 (bin −8), 1.1e-3 and 1.2e-3 (bin −12), none in −11..−9, the release first.
  std::vector<sg::DecayPeriodResponse> periods = {
      {0.1, 3.0, 0.02, 9.0, 9.0},       // the release: left out
      {0.4, 3.0, 1e-2, 0.6, 1.0},       // bin −8
      {0.7, 3.5, 1.1e-3, 0.02, 0.3},    // bin −12
      {1.0, 3.5, 1.2e-3, -0.01, 0.26},  // bin −12: mean η* 0.005, m_app 0.28
  };
  const auto field = sg::decay_field(periods, 0.01, 0.05, sg::make_provenance(sg::FieldSource::kDem, "test", 1), 4);
  REQUIRE(field.grid.axis1.values.size() == 5);
  CHECK(field.grid.axis1.values.front() == Approx(std::pow(10.0, -11.5 / 4.0)).epsilon(1e-12));
  CHECK(field.grid.axis1.values.back() == Approx(std::pow(10.0, -7.5 / 4.0)).epsilon(1e-12));
  // Two frequency nodes around the mean frequency of the periods used, (3 + 3.5 + 3.5)/3.
  const double f = 10.0 / 3.0;
  REQUIRE(field.grid.axis0.values.size() == 2);
  CHECK(field.grid.axis0.values[0] == Approx(0.8 * f));
  CHECK(field.grid.axis0.values[1] == Approx(1.25 * f));
  REQUIRE(field.points.size() == 10);
  for (std::size_t i0 = 0; i0 < 2; ++i0) {
    const auto& low = field.points[field.grid.index(i0, 0)];
    CHECK(low.eta_star == Approx(0.005));
    CHECK(low.apparent_mass_fraction == Approx(0.28));
    CHECK(low.motion_mode == "decay");
    const auto& high = field.points[field.grid.index(i0, 4)];
    CHECK(high.eta_star == Approx(0.6));
    CHECK(high.motion_mode == "decay");
    // Bin −10, half way between the ends by index: the mean of their values.
    const auto& middle = field.points[field.grid.index(i0, 2)];
    CHECK(middle.eta_star == Approx(0.3025));
    CHECK(middle.apparent_mass_fraction == Approx(0.64));
    CHECK(middle.motion_mode == "decay_interpolated");
  }
  // As a loss model: at a node the value of its bin.
  const sg::EffectiveFieldLossModel model(field);
  CHECK(model.evaluate(f, field.grid.axis1.values[4]).eta_star == Approx(0.6));
}

TEST_CASE("decay_field: a bin averaging below zero is a bed that dissipates nothing", "[surrogate][decay_field]") {
  std::vector<sg::DecayPeriodResponse> periods = {
      {0.1, 3.0, 0.02, 1.0, 1.0}, {0.4, 3.0, 1e-3, -0.02, 0.28}, {0.7, 3.0, 1e-3, 0.01, 0.28}, {1.0, 3.0, 1e-2, 0.5, 0.9}};
  const auto field = sg::decay_field(periods, 0.01, 0.05, sg::make_provenance(sg::FieldSource::kDem, "test", 1), 4);
  CHECK(field.points.front().eta_star == 0.0);
}

TEST_CASE("decay_field: refuses too few periods and values that are not finite", "[surrogate][decay_field]") {
  const auto provenance = sg::make_provenance(sg::FieldSource::kDem, "test", 1);
  std::vector<sg::DecayPeriodResponse> two = {{0.1, 3.0, 0.02, 1.0, 1.0}, {0.4, 3.0, 1e-3, 0.1, 0.3}};
  CHECK_THROWS_WITH(sg::decay_field(two, 0.01, 0.05, provenance), Catch::Contains("at least two after the release"));
  std::vector<sg::DecayPeriodResponse> bad = {
      {0.1, 3.0, 0.02, 1.0, 1.0}, {0.4, 3.0, 1e-3, NAN, 0.3}, {0.7, 3.0, 1e-3, 0.1, 0.3}};
  CHECK_THROWS_WITH(sg::decay_field(bad, 0.01, 0.05, provenance), Catch::Contains("t = 0.4"));
}
