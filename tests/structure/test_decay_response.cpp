// The bed's response period by period along a sampled decay (structure::
// bed_response_per_period), against a linear bed whose η* and apparent mass are known in
// closed form: F = m_a ẍ + c ẋ on the container's motion gives, at Ω,
//   η* = c/(m_bed Ω),   m_app/m_bed = m_a/m_bed   (docs/theory.md §1).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include "pdamp/structure/sampled_decay.hpp"

namespace st = pdamp::structure;

namespace {

struct LinearBedDecay {
  std::vector<double> t;
  Eigen::VectorXd y, force;
};

/// y = y_s + X e^{−λt} sin(Ωt) sampled `per_period` times a period over `periods`; the force
/// the container applies to a linear bed F = m_a ÿ + c ẏ as the co-simulation's history holds
/// it, the exact mean over the interval ending at each sample: (m_a Δẏ + c Δy)/Δt (the first
/// sample its own value).
LinearBedDecay linear_bed_decay(double omega, double lambda, double m_a, double c, double offset, int per_period,
                                int periods) {
  const double amplitude = 0.01, dt = 2.0 * std::numbers::pi / omega / per_period;
  const int n = per_period * periods + 1;
  LinearBedDecay d;
  d.y.resize(n);
  d.force.resize(n);
  std::vector<double> v(n);
  for (int k = 0; k < n; ++k) {
    const double t = k * dt, e = amplitude * std::exp(-lambda * t), s = std::sin(omega * t), co = std::cos(omega * t);
    v[k] = e * (omega * co - lambda * s);
    d.t.push_back(t);
    d.y(k) = offset + e * s;
    const double a = e * ((lambda * lambda - omega * omega) * s - 2.0 * lambda * omega * co);
    d.force(k) = k == 0 ? m_a * a + c * v[0] : (m_a * (v[k] - v[k - 1]) + c * (d.y(k) - d.y(k - 1))) / dt;
  }
  return d;
}

}  // namespace

TEST_CASE("bed_response_per_period: a linear bed's eta* and apparent mass, period by period",
          "[structure][sampled_decay]") {
  const double omega = 2.0 * std::numbers::pi * 3.5, m_bed = 0.05, m_a = 0.02, c = 0.3, offset = -1e-3;
  const double eta = c / (m_bed * omega), mass_fraction = m_a / m_bed;
  SECTION("steady amplitude: exact to the trapezoid's error") {
    // 200 samples a period: the trapezoid's, the linear interpolation's and the centring's
    // errors are O((Ωdt)²/12) = 8e-5.
    const auto d = linear_bed_decay(omega, 0.0, m_a, c, offset, 200, 12);
    const auto periods = st::bed_response_per_period(d.t, d.y, offset, d.force, m_bed);
    REQUIRE(periods.size() >= 10);
    for (const auto& p : periods) {
      CHECK(p.frequency_hz == Approx(3.5).epsilon(1e-6));
      CHECK(p.stroke_m == Approx(0.01).epsilon(1e-4));
      CHECK(p.eta_star == Approx(eta).epsilon(1e-3));
      CHECK(p.apparent_mass_fraction == Approx(mass_fraction).epsilon(1e-3));
    }
  }
  SECTION("a decay faster than the damped link's: the envelope taken out") {
    // λ/Ω = 0.02 (ζ of 2 %; the shipped link with beds decays at ζ 0.2-1 %): the amplitude
    // falls by 12 % over a period. Taken as a pure sine, η* would be low by 2(λ/Ω)m_a/m_bed
    // = 1.6e-2 (6 %); with the envelope taken out the linear bed's values come back to the
    // trapezoid's error at 60 samples a period, (Ωdt)²/12 = 1e-3: 0.5 % holds them.
    const double lambda = 0.02 * omega;
    const auto d = linear_bed_decay(omega, lambda, m_a, c, offset, 60, 12);
    const auto periods = st::bed_response_per_period(d.t, d.y, offset, d.force, m_bed);
    REQUIRE(periods.size() >= 10);
    for (const auto& p : periods) {
      CHECK(p.eta_star == Approx(eta).epsilon(0.005));
      CHECK(p.apparent_mass_fraction == Approx(mass_fraction).epsilon(0.005));
      CHECK(p.stroke_m == Approx(0.01 * std::exp(-lambda * p.time_s)).epsilon(0.005));
    }
  }
  SECTION("no whole period: nothing") {
    const auto d = linear_bed_decay(omega, 0.0, m_a, c, offset, 50, 1);
    CHECK(st::bed_response_per_period(d.t, d.y, offset, d.force, m_bed).size() <= 1);
  }
}
