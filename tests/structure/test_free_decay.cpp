// Tests of the slowly-varying-amplitude free decay: closed-form envelopes and a direct
// time integration of a 1-DOF with an equivalent nonlinear viscous damper.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "pdamp/structure/free_decay.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace {

using namespace pdamp::structure;
namespace sg = pdamp::surrogate;
constexpr double kPi = 3.14159265358979323846;

/// η* = K·X^p, no apparent mass (p = 0: constant η*).
class PowerLoss final : public sg::LossModel {
 public:
  PowerLoss(double k, double p) : k_(k), p_(p) {}
  sg::DamperResponse evaluate(double, double x) const override {
    sg::DamperResponse r;
    r.eta_star = k_ * std::pow(x, p_);
    r.d_eta_star_d_stroke_1_m = p_ * r.eta_star / x;
    r.apparent_mass_fraction = 0.0;
    return r;
  }
  sg::StrokeRange stroke_range_m(double) const override { return {1e-9, 1.0}; }

 private:
  double k_, p_;
};

ModalModel one_dof(double f_hz, double zeta) {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, f_hz);
  m.damping_ratios = Eigen::VectorXd::Constant(1, zeta);
  m.modal_masses_kg = Eigen::VectorXd::Ones(1);
  Eigen::MatrixXd shape(2, 1);
  shape << 1.0, 0.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(1)}};
  return m;
}

Damper damper_with(std::shared_ptr<const sg::LossModel> loss, double bed_kg) {
  Damper d;
  d.name = "tip";
  d.point = "tip";
  d.layers = {{"bed", bed_kg, std::move(loss)}};
  return d;
}

}  // namespace

TEST_CASE("a constant loss factor decays exponentially at the structural plus added damping", "[structure]") {
  // a(t) = a0 exp(−(ζ_s + ½η*μ)ω t) (1-DOF, φ = 1, m = 1 kg). RK4 on ln a with a constant
  // rate is exact up to round-off: 1e-10.
  const double f = 5.0, zeta = 0.002, eta = 1.2, bed = 0.02;
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, 0.01);
  options.duration_s = 15.0;
  options.sample_times_s = {0.0, 1.0, 2.5, 7.0, 15.0};
  const FreeDecay decay = free_decay(one_dof(f, zeta), {damper_with(std::make_shared<PowerLoss>(eta, 0.0), bed)}, options);
  const double rate = (zeta + 0.5 * eta * bed) * 2 * kPi * f;
  REQUIRE(decay.samples.size() == 5);
  for (const auto& s : decay.samples)
    CHECK(s.modal_amplitudes[0] == Approx(0.01 * std::exp(-rate * s.time_s)).epsilon(1e-10));
  // Settling to 1%: t_s = ln(100)/rate; the linear decay's equivalent ζ is its own.
  REQUIRE(decay.outcome == FreeDecay::Outcome::kSettled);
  CHECK(decay.settling_time_s == Approx(std::log(100.0) / rate).epsilon(1e-9));
  CHECK(decay.equivalent_damping_ratio == Approx(zeta + 0.5 * eta * bed).epsilon(1e-9));
  // Energy balance: dissipated (layer + structure) + remaining = initial. The dissipated
  // energies are RK4 quadratures of e^{−2λt} with 2λ dt = 0.1 per step: local relative error
  // 0.1⁵/120 ≈ 8e-8, and the sum over the decay stays below that: 2e-7.
  const auto& last = decay.samples.back();
  const double e0 = 0.5 * std::pow(2 * kPi * f, 2) * 1e-4;
  CHECK(last.layer_dissipated_energy_j[0] + last.structural_dissipated_energy_j + last.mechanical_energy_j ==
        Approx(e0).epsilon(2e-7));
  CHECK(last.layer_dissipated_energy_j[0] / last.structural_dissipated_energy_j == Approx(0.5 * eta * bed / zeta).epsilon(1e-12));
}

TEST_CASE("a power-law loss factor follows the Bernoulli envelope", "[structure]") {
  // ȧ = −αa − βa^{1+p}, α = ζ_sω, β = ½K m_bed ω (b = 1): a^{−p} = (a0^{−p} + β/α)e^{pαt} − β/α.
  // RK4 steps of 0.05 in ln a: local error ≲ 0.05⁵/120 ≈ 3e-9, global ≲ 1e-7 over the decay; 1e-6.
  const double f = 8.0, zeta = 0.001, k = 40.0, p = 0.7, bed = 0.01;
  const double w = 2 * kPi * f, alpha = zeta * w, beta = 0.5 * k * bed * w, a0 = 0.02;
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, a0);
  options.duration_s = 20.0;
  options.sample_times_s = {0.5, 2.0, 5.0, 12.0, 20.0};
  const FreeDecay decay = free_decay(one_dof(f, zeta), {damper_with(std::make_shared<PowerLoss>(k, p), bed)}, options);
  for (const auto& s : decay.samples) {
    const double inv = (std::pow(a0, -p) + beta / alpha) * std::exp(p * alpha * s.time_s) - beta / alpha;
    CHECK(s.modal_amplitudes[0] == Approx(std::pow(inv, -1.0 / p)).epsilon(1e-6));
  }
}

TEST_CASE("the envelope's settling time matches a direct time integration within 2%", "[structure]") {
  // Reference: ẍ + 2ζωẋ + ω²x + c(X)ẋ/m = 0 integrated with RK4 (200 steps per period), the
  // equivalent viscous coefficient c(X) = η*(X) m_bed ω at the amplitude from the energy,
  // X = √(x² + (ẋ/ω)²); settled when X drops below 1% of X0. Averaging neglects the
  // within-cycle variation of X, O(ζ) ≈ 1% here: 2%.
  const double f = 4.0, zeta = 0.002, k = 2.0, p = 0.5, bed = 0.05, x0 = 0.03;
  const double w = 2 * kPi * f;
  const auto loss = std::make_shared<PowerLoss>(k, p);
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, x0);
  options.duration_s = 60.0;
  const FreeDecay decay = free_decay(one_dof(f, zeta), {damper_with(loss, bed)}, options);
  REQUIRE(decay.outcome == FreeDecay::Outcome::kSettled);
  double x = x0, v = 0.0, t = 0.0;
  const double dt = 1.0 / (200 * f);
  auto accel = [&](double xx, double vv) {
    const double amplitude = std::sqrt(xx * xx + vv * vv / (w * w));
    const double c = loss->evaluate(f, amplitude).eta_star * bed * w;
    return -2 * zeta * w * vv - w * w * xx - c * vv;
  };
  while (std::sqrt(x * x + v * v / (w * w)) > 0.01 * x0 && t < 120.0) {
    const double k1x = v, k1v = accel(x, v);
    const double k2x = v + 0.5 * dt * k1v, k2v = accel(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v, k3v = accel(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = accel(x + dt * k3x, v + dt * k3v);
    x += dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
    v += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    t += dt;
  }
  CHECK(decay.settling_time_s == Approx(t).epsilon(0.02));
}

TEST_CASE("two layers of different clearance take over one after the other", "[structure]") {
  // Closed-form bouncing layers with h = 40 mm and 8 mm: the wide one works at large
  // amplitude, the narrow one late in the decay (docs/theory.md §7.7). The wide layer's power
  // dominates at the start (η* 0.9 against 0.12 at X = 0.03 m), the narrow one's later.
  pdamp::formulas::ModelOptions mo;
  mo.gravity_across_drive = false;
  mo.scattered.provisional = false;
  auto wide = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kBouncing, 0.04, mo);
  auto narrow = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kBouncing, 0.008, mo);
  Damper d;
  d.name = "tip";
  d.point = "tip";
  d.layers = {{"wide", 0.01, wide}, {"narrow", 0.01, narrow}};
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, 0.03);
  options.duration_s = 30.0;
  for (int k = 0; k <= 300; ++k) options.sample_times_s.push_back(0.1 * k);
  options.threshold_fraction = 0.05;
  const FreeDecay decay = free_decay(one_dof(6.0, 0.001), {d}, options);
  REQUIRE(decay.layer_names == std::vector<std::string>{"tip/wide", "tip/narrow"});
  CHECK(decay.samples.front().layer_power_w[0] > 5 * decay.samples.front().layer_power_w[1]);
  bool narrow_leads_later = false;
  for (const auto& s : decay.samples)
    narrow_leads_later = narrow_leads_later || (s.time_s > 1.0 && s.layer_power_w[1] > 5 * s.layer_power_w[0]);
  CHECK(narrow_leads_later);
  CHECK(decay.outcome == FreeDecay::Outcome::kSettled);
  CHECK(decay.samples.back().layer_dissipated_energy_j[1] > 0.0);
}

TEST_CASE("a free decay warns when a second mode carries more than 10% of the damper amplitude", "[structure]") {
  ModalModel m = one_dof(5.0, 0.01);
  m.natural_frequencies_hz = Eigen::Vector2d(5.0, 17.0);
  m.damping_ratios = Eigen::Vector2d(0.01, 0.01);
  m.modal_masses_kg = Eigen::Vector2d::Ones();
  m.points[0].translation = Eigen::MatrixXd(2, 2);
  m.points[0].translation << 1.0, 0.5, 0.0, 0.0;
  m.points[0].rotation = Eigen::RowVectorXd::Zero(2);
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::Vector2d(0.01, 0.004);  // mode 2: 0.002 of 0.012 = 17%
  options.duration_s = 1.0;
  const FreeDecay decay = free_decay(m, {damper_with(std::make_shared<PowerLoss>(1.0, 0.0), 0.01)}, options);
  REQUIRE(decay.warnings.size() == 1);
  CHECK_THAT(decay.warnings[0], Catch::Contains("single-mode averaging"));
  options.initial_modal_amplitudes = Eigen::Vector2d(0.01, 0.001);  // 5%
  CHECK(free_decay(m, {damper_with(std::make_shared<PowerLoss>(1.0, 0.0), 0.01)}, options).warnings.empty());
}

TEST_CASE("a decay through a closed-form damper's onset cliff matches the envelope quadrature", "[structure]") {
  // Reference: t(a) = ∫ d ln a/((ζ_s + ½η*(a)μ)ω) from a to a0 (1-DOF, φ = 1, m_app shifts Ω:
  // rate = (c_s + η* m_bed Ω)/(2 m_eff) with m_eff = 1 + m_bed·m_app/m_bed and Ω = ω/√m_eff),
  // by Simpson's rule on each smooth piece, split at the onset (2e5 intervals per piece:
  // error ≪ 1e-9). The solver cuts its step at the cliff: 1e-6 relative.
  pdamp::formulas::ModelOptions mo;
  mo.gravity_across_drive = false;
  mo.scattered.provisional = false;
  const double h = 0.01, f = 6.0, zeta = 0.002, bed = 0.01, a0 = 0.02;
  auto loss = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kBouncing, h, mo);
  FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, a0);
  options.duration_s = 120.0;
  options.threshold_m = 1e-3;  // below the onset 2.685 mm: the decay passes the cliff
  const FreeDecay decay = free_decay(one_dof(f, zeta), {damper_with(loss, bed)}, options);
  REQUIRE(decay.outcome == FreeDecay::Outcome::kSettled);
  const double w = 2 * kPi * f;
  auto inverse_rate = [&](double u) {
    const double a = std::exp(u);
    const auto r = loss->evaluate(f, a);  // Ω shifts by ≤ 0.5%: η* of the bouncing block does not depend on f
    const double m_eff = 1.0 + bed * r.apparent_mass_fraction;
    const double omega = w / std::sqrt(m_eff);
    return 1.0 / ((2 * zeta * w + r.eta_star * bed * omega) / (2 * m_eff));
  };
  auto simpson = [&](double lo, double hi) {
    const int n = 200000;
    const double du = (hi - lo) / n;
    double sum = inverse_rate(lo) + inverse_rate(hi);
    for (int k = 1; k < n; ++k) sum += (k % 2 ? 4.0 : 2.0) * inverse_rate(lo + k * du);
    return sum * du / 3.0;
  };
  const double onset = loss->discontinuities_stroke_m(f).at(0);
  const double expected = simpson(std::log(onset), std::log(a0)) + simpson(std::log(1e-3), std::log(onset) - 1e-12);
  CHECK(decay.settling_time_s == Approx(expected).epsilon(1e-6));
}

TEST_CASE("a bed released above its onset decays into the rolling tail; one released below starts as from rest",
          "[structure]") {
  // One mode, a rolling closed-form bed (h = 10 mm, onset 3.76 mm): released at 3 onsets it
  // collects and collides down to the onset, then rolls without impacts (no rolling
  // resistance): the layer's dissipated energy stops growing there (energy conservation of
  // the envelope equations: only the structure dissipates). Released at 0.8 onsets it is a
  // bed from rest below the onset: the scattered fit dissipates from the start.
  const double f = 3.0, zeta = 0.003, bed = 0.03, h = 0.01;
  const auto loss = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kRolling, h);
  const double onset = loss->discontinuities_stroke_m(f).front();
  const auto decay = [&](double release_m) {
    FreeDecayOptions options;
    options.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, release_m);
    options.duration_s = 40.0;
    options.sample_times_s = uniform_sample_times(options.duration_s, 401);
    options.threshold_fraction = 0.001;
    return free_decay(one_dof(f, zeta), {damper_with(loss, bed)}, options);
  };
  const FreeDecay from_above = decay(3.0 * onset);
  std::size_t below = 0;
  while (below < from_above.samples.size() && from_above.samples[below].damper_amplitudes_m[0] >= onset) ++below;
  REQUIRE(below + 10 < from_above.samples.size());
  const double at_onset = from_above.samples[below].layer_dissipated_energy_j[0];
  CHECK(at_onset > 0.0);
  CHECK(from_above.samples.back().layer_dissipated_energy_j[0] == at_onset);
  CHECK(from_above.samples.back().layer_power_w[0] == 0.0);
  // Below the onset the envelope decays at the structure's rate alone, c_j/(2 m), m the modal
  // mass with the rolling bed's apparent mass 2/7 m_bed (single-mode backbone; RK4 is exact
  // for a constant rate: 1e-6 leaves room for the frequency iteration's tolerance).
  const auto& s0 = from_above.samples[below + 2];
  const auto& s1 = from_above.samples.back();
  const double rate = zeta * 2.0 * kPi * f / (1.0 + 2.0 / 7.0 * bed);  // c_j/(2(m_j + 2/7 m_bed)), m_j = 1 kg
  CHECK(std::log(s0.modal_amplitudes[0] / s1.modal_amplitudes[0]) / (s1.time_s - s0.time_s) ==
        Approx(rate).epsilon(1e-6));

  const FreeDecay from_rest = decay(0.8 * onset);
  CHECK(from_rest.samples[1].layer_dissipated_energy_j[0] > 0.0);
  CHECK(from_rest.samples[1].layer_power_w[0] > 0.0);
}
