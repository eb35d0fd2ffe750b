// The resonance measures of a sampled response (structure/sampled_response.hpp), against
// curves whose answers are known in closed form (the stepped sine's steady-state test:
// test_stepped_sine.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/sampled_response.hpp"

namespace st = pdamp::structure;

namespace {

/// |H| of a base-excited SDOF, absolute transmissibility: √(1 + (2ζr)²)/√((1 − r²)² + (2ζr)²).
double transmissibility(double f, double fn, double zeta) {
  const double r = f / fn, a = 2.0 * zeta * r;
  return std::sqrt(1.0 + a * a) / std::sqrt((1.0 - r * r) * (1.0 - r * r) + a * a);
}

}  // namespace

TEST_CASE("sampled_peak: a parabola's vertex and a tent's 0.9 band are exact", "[structure][sampled_response]") {
  // c = 10 − (f − 1.73)² on a coarse non-uniform grid: the parabola through any three
  // samples is the curve itself, so the vertex is 1.73.
  const std::vector<double> f = {0.73, 1.1, 1.6, 1.9, 2.3, 2.73};
  std::vector<double> parabola, tent;
  for (double x : f) parabola.push_back(10.0 - (x - 1.73) * (x - 1.73));
  const auto peak = st::sampled_peak(f, parabola);
  CHECK(peak.index == 2);
  CHECK(peak.frequency_hz == Approx(1.73).epsilon(1e-12));
  // Without standard errors the argmax is the peak sample.
  CHECK(peak.indistinguishable_low_hz == 1.6);
  CHECK(peak.indistinguishable_high_hz == 1.6);
  // The curve's maximum (1.73, not a sample) lies between the peak sample's neighbours.
  CHECK(peak.maximum_low_hz == 1.1);
  CHECK(peak.maximum_high_hz == 1.9);
  CHECK((peak.maximum_low_hz < 1.73 && 1.73 < peak.maximum_high_hz));
  // A curve rising to its last sample: the bracket stops at the end.
  const auto rising = st::sampled_peak({1.0, 1.1, 1.2}, {1.0, 2.0, 3.0});
  CHECK(rising.maximum_low_hz == 1.1);
  CHECK(rising.maximum_high_hz == 1.2);
  // c = 10 − 2|f − 1.73| is linear on each flank, so is the interpolation: the level 0.9
  // of the largest sample (9.74 at 1.6) is crossed at 1.73 ± (10 − 0.9·9.74)/2 exactly
  // (the samples there bracket it on one flank each).
  for (double x : f) tent.push_back(10.0 - 2.0 * std::abs(x - 1.73));
  const auto band = st::sampled_peak(f, tent);
  const double half_width = (10.0 - 0.9 * 9.74) / 2.0;
  CHECK(band.band.low_hz == Approx(1.73 - half_width).epsilon(1e-12));
  CHECK(band.band.high_hz == Approx(1.73 + half_width).epsilon(1e-12));
  CHECK(band.band_centre_hz == Approx(1.73).epsilon(1e-12));
}

TEST_CASE("sampled_peak: the argmax of a linear mode, and a held plateau's band centre", "[structure][sampled_response]") {
  // A damped transmissibility (ζ = 0.25, fn = 1.8 Hz) sampled every 0.05 Hz: the parabola
  // finds the linear SDOF's transmissibility peak r = √(√(1 + 8ζ²) − 1)/(2ζ) within 1%.
  const double fn = 1.8;
  std::vector<double> f;
  for (double x = 1.0; x <= 2.6 + 1e-9; x += 0.05) f.push_back(x);
  const auto sampled = [&](auto&& curve) {
    std::vector<double> c;
    for (double x : f) c.push_back(curve(x));
    return c;
  };
  const double zeta = 0.25;
  const double r_peak = std::sqrt(std::sqrt(1.0 + 8.0 * zeta * zeta) - 1.0) / (2.0 * zeta);
  CHECK(st::sampled_peak(f, sampled([&](double x) { return transmissibility(x, fn, zeta); })).frequency_hz ==
        Approx(r_peak * fn).epsilon(0.01));
  // A damper that holds its stroke (the amplitude-limited plateau of a tuned particle
  // damper): a lightly damped mode capped at 3.4, the cap tilted by ±1.5% across the band
  // (a DEM bed's scatter, a slightly different loss model). The argmax jumps from one end
  // of the plateau to the other; the band's centre, set by the steep flanks, stays put.
  const auto capped = [&](double tilt) {
    return sampled([&](double x) { return std::min(transmissibility(x, fn, 0.01), 3.4 * (1.0 + tilt * (x - fn))); });
  };
  const auto up = st::sampled_peak(f, capped(0.03));
  const auto down = st::sampled_peak(f, capped(-0.03));
  const double argmax_shift = std::abs(up.frequency_hz - down.frequency_hz);
  const double centre_shift = std::abs(up.band_centre_hz - down.band_centre_hz);
  CHECK(argmax_shift > 0.2);         // of the plateau's width (T > 3.4 for 1.3 < f < 2.1 Hz about)
  CHECK(centre_shift < 0.1 * argmax_shift);
}

TEST_CASE("sampled_peak: standard errors widen the argmax's range to the points it cannot be told from",
          "[structure][sampled_response]") {
  const std::vector<double> f = {1.0, 1.1, 1.2, 1.3, 1.4};
  const std::vector<double> c = {2.0, 3.1, 3.3, 3.15, 2.0};
  // se 0.05: 3.3 − 0.1 = 3.2; 3.1 + 0.1 = 3.2 (in), 3.15 + 0.1 (in), 2 + 0.1 (out).
  const auto peak = st::sampled_peak(f, c, {0.05, 0.05, 0.05, 0.05, 0.05});
  CHECK(peak.indistinguishable_low_hz == 1.1);
  CHECK(peak.indistinguishable_high_hz == 1.3);
  CHECK(peak.maximum_low_hz == 1.0);  // the points either side of those
  CHECK(peak.maximum_high_hz == 1.4);
  CHECK(std::isnan(st::sampled_peak({1.0, 2.0}, {1.0, 2.0}).band.high_hz));  // no fall on the right
  // A dip inside the band (a DEM point's scatter) does not cut it: the outermost crossings.
  const auto dipped = st::sampled_peak({1.0, 1.1, 1.2, 1.3, 1.4, 1.5}, {1.0, 3.0, 3.3, 2.9, 3.1, 1.0});
  CHECK(dipped.band.low_hz == Approx(1.0 + 0.1 * (2.97 - 1.0) / 2.0));
  CHECK(dipped.band.high_hz == Approx(1.4 + 0.1 * (3.1 - 2.97) / 2.1));
  CHECK_THROWS_AS(st::sampled_peak({1.0, 1.0}, {1.0, 2.0}), std::invalid_argument);
  CHECK_THROWS_AS(st::sampled_peak({1.0, 2.0}, {1.0}), std::invalid_argument);
  CHECK_THROWS_AS(st::sampled_peak({1.0, 2.0}, {1.0, 2.0}, {0.1, -0.1}), std::invalid_argument);
}

// Reference: the half-power width of a lightly damped SDOF, (f₂ − f₁)/(2f_peak) = ζ + O(ζ²)
// (for the transmissibility the O(ζ²) term is below 1% of ζ at ζ = 0.02), sampled every
// 0.5% of f_n: the linear interpolation between samples of the steep flanks errs by < 0.2%
// of the width, so 2% bounds both. A curve that never falls to 1/√2 on one side has none.
TEST_CASE("sampled_peak: the half-power damping ratio of a sampled mode", "[structure][sampled_response]") {
  const double fn = 10.0, zeta = 0.02;
  std::vector<double> f, c;
  for (double x = 8.0; x <= 12.0 + 1e-9; x += 0.05) f.push_back(x), c.push_back(transmissibility(x, fn, zeta));
  CHECK(st::sampled_peak(f, c).damping_ratio == Approx(zeta).epsilon(0.02));
  std::vector<double> f_high(f.begin() + 38, f.end()), c_high(c.begin() + 38, c.end());  // from 9.9 Hz: no low flank
  CHECK(std::isnan(st::sampled_peak(f_high, c_high).damping_ratio));
}
