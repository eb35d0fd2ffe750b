// Tests of a stepped sine's settling (dem_frequency_response.hpp): the convergence window of
// the per-period amplitude, a point right after a jump whose slow transient still drifts,
// the least transient a point runs, and the steps per period that tell coinciding points.
#include <catch2/catch.hpp>

#include <cmath>
#include <complex>
#include <random>

#include "pdamp/structure/dem_frequency_response.hpp"
#include "structure/cosimulation_support.hpp"

namespace {

using namespace pdamp::structure;
using pdamp::test::tip_damper;
namespace dem = pdamp::dem_reference;
using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

/// One lightly damped mode on a moving base: f = 10 Hz bare, ζ = 0.01, m = 1 kg, base
/// participation Γ = 0.8 kg, point "tip" with unit shape; a 0.25 kg container (the mode with
/// it: 10/√1.25 = 8.944 Hz).
constexpr double kF = 10.0, kZeta = 0.01, kM = 1.0, kGamma = 0.8, kMc = 0.25, kU = 1e-4;

ModalModel lightly_damped_mode() { return pdamp::test::one_mode_on_base(kF, kZeta, kM, kGamma); }

/// The exact steady transmissibility |U + q̂|/U of that mode with the container at f_hz.
double exact_transmissibility(double f_hz) {
  const double W = 2 * kPi * f_hz, k = kM * std::pow(2 * kPi * kF, 2), c = 2 * kZeta * 2 * kPi * kF * kM;
  const cd D = k - W * W * (kM + kMc) + cd(0, 1) * W * c;
  return std::abs(kU + W * W * (kGamma + kMc) * kU / D) / kU;
}

/// A lone sphere in a 0.12 m box without gravity never touches a wall (the site moves at most
/// 2·|U + q̂| ≈ 6 mm here, the sphere has 5.5 cm to either wall): the system is linear.
std::vector<CosimulationDamper> container_only() {
  return {tip_damper(pdamp::test::lone_sphere(0.12), kMc)};
}

SteadyStateRun base_drive() {
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = kU;
  o.analysed_periods = 4;
  return o;
}

/// Up from 7 Hz, far below the mode, to 8.8 Hz, near it: the jump starts a free vibration at
/// 8.944 Hz beating against the drive (0.144 Hz apart: one beat every 61 periods) and decaying
/// as e^{−ζωt}, 0.07 of the amplitude per period: the per-period amplitude drifts for tens of
/// periods after the jump.
SteppedSineBranch jump_branch(const SteadyStateSettling& settling) {
  const ModalModel model = lightly_damped_mode();
  const auto dampers = container_only();
  const std::vector<double> f = {7.0, 8.8};
  const SteadyStateRun o = stepped_sine_options(base_drive(), settling);
  const double dt = stepped_sine_time_step(model, dampers, o, f);
  return stepped_sine_branch(model, dampers, o, f, SweepDirection::kUp, dt, pdamp::base::silent_hooks());
}

}  // namespace

// Reference: series constructed here whose answers are known by construction.
TEST_CASE("amplitude_window and amplitudes_converged: a window of period-to-period changes, not one pair",
          "[structure][cosimulation]") {
  const std::size_t w = kConvergenceWindowPeriods;
  // Constant: no change, no spread.
  const AmplitudeWindow flat = amplitude_window(std::vector<double>(w + 3, 2.0));
  CHECK(flat.periods == static_cast<int>(w));
  CHECK(flat.max_relative_change == 0.0);
  CHECK(flat.relative_drift == 0.0);
  CHECK(flat.relative_spread == 0.0);
  CHECK(amplitudes_converged(flat, 1e-3));
  // Too few periods: never converged, the measures over what there is.
  const AmplitudeWindow short_window = amplitude_window(std::vector<double>(w - 1, 2.0));
  CHECK(short_window.periods == static_cast<int>(w - 1));
  CHECK_FALSE(amplitudes_converged(short_window, 0.5));
  CHECK(amplitude_window({1.0}).periods == 0);
  CHECK(std::isnan(amplitude_window({1.0}).max_relative_change));
  // One pair of equal periods at the end does not make a window: a beat (±30%) whose last two
  // periods happen to agree is refused by the earlier changes in the window.
  std::vector<double> beat;
  for (std::size_t k = 0; k < w; ++k) beat.push_back(1.0 + 0.3 * std::sin(0.8 * static_cast<double>(k)));
  beat.push_back(beat.back());
  const AmplitudeWindow b = amplitude_window(beat);
  CHECK(b.periods == static_cast<int>(w));
  CHECK(b.max_relative_change > 0.2);
  CHECK_FALSE(amplitudes_converged(b, 0.05));
  // A smooth drift of 1% per period: every change 1% (below 5%), but 7% across the window.
  std::vector<double> drift;
  for (std::size_t k = 0; k < w; ++k) drift.push_back(1.0 + 0.01 * static_cast<double>(k));
  const AmplitudeWindow d = amplitude_window(drift);
  CHECK(d.max_relative_change == Approx(0.01 / 1.035).epsilon(1e-12));
  CHECK(d.relative_drift == Approx(0.07 / 1.035).epsilon(1e-12));
  CHECK_FALSE(amplitudes_converged(d, 0.05));
  CHECK(amplitudes_converged(d, 0.07));
  // Stationary scatter of 1% (a settled bed): the default 5% accepts it nearly always (the
  // largest of 7 changes, each of standard deviation 1.4%, exceeds 5% in about 0.3% of draws).
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  int accepted = 0;
  const int trials = 2000;
  for (int t = 0; t < trials; ++t) {
    std::vector<double> a;
    for (std::size_t k = 0; k < w; ++k) a.push_back(1.0 + noise(rng));
    accepted += amplitudes_converged(amplitude_window(a), SteadyStateSettling{}.stable_tolerance) ? 1 : 0;
  }
  CHECK(accepted > 0.97 * trials);
}

// Reference: the exact steady transmissibility of the linear 1-DOF (the lone sphere never
// touches), which is what a run of any length converges to. A point right after the jump
// drifts for tens of periods; with a cap of 16 periods it is reported unconverged, allowed
// enough it converges with its window's changes below the tolerance.
//
// Tolerance of the converged amplitude. After the jump the per-period amplitude is
// A∞|1 + r_k e^{iφ_k}|, r_k = r₀e^{−σk} (σ = 2πζ f_n/f = 0.071 per period) and φ advancing by
// β = 2π·0.144/8.8 = 0.103 rad per period. Each period-to-period change is r_k·Re[(e^{−σ+iβ} − 1)
// e^{iφ_k}] to first order, |e^{−σ+iβ} − 1| = 0.12; over the window's 7 changes the phase turns
// by 0.72 rad, so the largest of them is at least sin(0.36)·0.12·r = 0.043·r: a window whose
// changes are all below the tolerance τ has r < τ/0.043 = 23τ. With τ = 1e-3 the transient left
// is below 2.3% at the window's end and decays further (e^{−8σ} = 0.57) over the analysed
// periods, whose first harmonic takes it in at most in full: an error below 2.3% of A∞, plus
// the scheme's O((ωdt)²) ≈ 1e-5 amplified by Q = 50 (see test_cosimulation.cpp).
TEST_CASE("a stepped-sine point right after a jump is not converged while its amplitude drifts",
          "[structure][cosimulation]") {
  SteadyStateSettling capped;
  capped.max_transient_periods = 16;
  const SteppedSineBranch short_run = jump_branch(capped);
  REQUIRE(short_run.outcome == dem::Outcome::kCompleted);
  REQUIRE(short_run.points.size() == 2);
  const SteppedSinePoint& p = short_run.points[1];
  INFO("window: change " << p.window_max_relative_change << ", drift " << p.window_relative_drift << ", spread "
                         << p.window_relative_spread);
  CHECK_FALSE(p.converged);
  CHECK_FALSE(p.stable);
  CHECK(p.transient_periods == 16);
  CHECK(p.periods() == 16 + 4);
  CHECK(p.window_periods == static_cast<int>(kConvergenceWindowPeriods));
  CHECK(p.window_max_relative_change > capped.stable_tolerance);
  CHECK(p.period_magnitudes.size() == 20);

  SteadyStateSettling enough;
  enough.max_transient_periods = 1000;
  enough.stable_tolerance = 1e-3;
  const SteppedSineBranch long_run = jump_branch(enough);
  REQUIRE(long_run.outcome == dem::Outcome::kCompleted);
  for (const SteppedSinePoint& q : long_run.points) {
    const double exact = exact_transmissibility(q.frequency_hz);
    INFO(q.frequency_hz << " Hz: " << q.transient_periods << " transient periods, change "
                        << q.window_max_relative_change << ", drift " << q.window_relative_drift << ", |X/U| "
                        << q.magnitude[0] << " against " << exact);
    CHECK(q.converged);
    CHECK(q.window_max_relative_change <= enough.stable_tolerance);
    CHECK(q.window_relative_drift <= enough.stable_tolerance);
    CHECK(q.window_relative_spread <= enough.stable_tolerance);
    CHECK(q.magnitude[0] == Approx(exact).epsilon(0.023));
  }
  // The point after the jump needs far more than the capped 16 periods.
  CHECK(long_run.points[1].transient_periods > 16);
  // Against the capped run's (unconverged) amplitude, which still carries the transient.
  INFO("capped " << p.magnitude[0] << ", converged " << long_run.points[1].magnitude[0] << ", exact "
                 << exact_transmissibility(p.frequency_hz));
  CHECK(std::abs(p.magnitude[0] / exact_transmissibility(p.frequency_hz) - 1.0) >
        std::abs(long_run.points[1].magnitude[0] / exact_transmissibility(p.frequency_hz) - 1.0));
}

// Reference: the rule itself: a transient at least min_transient_periods long, whatever the
// convergence test says; the cap raised to it; more than the cap refused by validate().
TEST_CASE("a stepped sine runs at least the least transient periods at every point", "[structure][cosimulation]") {
  SteadyStateSettling free_settling;
  free_settling.stable_tolerance = 0.05;
  const SteppedSineBranch quick = jump_branch(free_settling);
  REQUIRE(quick.outcome == dem::Outcome::kCompleted);
  REQUIRE(quick.points[0].converged);
  const int least = quick.points[0].transient_periods + 10;
  SteadyStateSettling held = free_settling;
  held.min_transient_periods = least;
  held.max_transient_periods = 0;  // raised to the least
  CHECK(stepped_sine_options(base_drive(), held).transient_periods == least);
  const SteppedSineBranch slow = jump_branch(held);
  REQUIRE(slow.outcome == dem::Outcome::kCompleted);
  for (const SteppedSinePoint& p : slow.points) CHECK(p.transient_periods >= least);
  // At the cap (= the least) the test is made once, at its end.
  CHECK(slow.points[0].transient_periods == least);
  CHECK(slow.points[0].converged);

  SteadyStateRun o = base_drive();
  o.excitation.frequency_hz = 8.0;
  o.transient_periods = 5;
  o.min_transient_periods = 6;
  const auto problems = validate(o, lightly_damped_mode());
  REQUIRE(problems.size() == 1);
  CHECK(problems.front().find("min_transient_periods = 6") != std::string::npos);
}

TEST_CASE("stepped_sine_steps_per_period: frequencies closer than a step per period coincide", "[structure]") {
  const double dt = 1e-4;
  const auto n = stepped_sine_steps_per_period({10.0, 10.0001, 10.01}, dt);
  REQUIRE(n.size() == 3);
  CHECK(n[0] == 1000);
  CHECK(n[1] == 1000);  // 999.99: the same whole steps, the same frequency run
  CHECK(n[2] == 999);
}
