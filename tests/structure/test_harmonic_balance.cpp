// Tests of the harmonic-balance FRF: linear dampers against closed-form FRFs, and a
// constructed amplitude-dependent damper with a fold against its analytic fold and a
// time integration of its slow flow.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>

#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/harmonic_balance.hpp"

namespace {

using namespace pdamp::structure;
namespace sg = pdamp::surrogate;
using Complex = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

/// η* = c/(m_bed Ω): a viscous damper of coefficient c (N s/m); no apparent mass.
class ViscousLoss final : public sg::LossModel {
 public:
  ViscousLoss(double c, double m) : c_(c), m_(m) {}
  sg::DamperResponse evaluate(double f, double) const override {
    sg::DamperResponse r;
    r.eta_star = c_ / (m_ * 2 * kPi * f);
    r.apparent_mass_fraction = 0.0;
    return r;
  }
  sg::StrokeRange stroke_range_m(double) const override { return {1e-7, 1.0}; }

 private:
  double c_, m_;
};

/// Constant η*, apparent mass α·X/X_ref (a mass that grows with amplitude: a softening fold).
class GrowingMassLoss final : public sg::LossModel {
 public:
  GrowingMassLoss(double eta, double alpha_per_m) : eta_(eta), alpha_(alpha_per_m) {}
  sg::DamperResponse evaluate(double, double x) const override {
    sg::DamperResponse r;
    r.eta_star = eta_;
    r.apparent_mass_fraction = alpha_ * x;
    r.d_apparent_mass_fraction_d_stroke_1_m = alpha_;
    return r;
  }
  sg::StrokeRange stroke_range_m(double) const override { return {1e-7, 1.0}; }

 private:
  double eta_, alpha_;
};

/// A modal model of `modes` modes, mass-normalised, with points "site" and "force".
ModalModel model_of(const Eigen::VectorXd& f_hz, const Eigen::VectorXd& zeta, const Eigen::MatrixXd& site,
                    const Eigen::MatrixXd& force, const Eigen::MatrixXd& gamma) {
  ModalModel m;
  m.natural_frequencies_hz = f_hz;
  m.damping_ratios = zeta;
  m.modal_masses_kg = Eigen::VectorXd::Ones(f_hz.size());
  m.points = {{"site", site, Eigen::RowVectorXd::Zero(f_hz.size())},
              {"force", force, Eigen::RowVectorXd::Zero(f_hz.size())}};
  m.base_participation = gamma;
  return m;
}

/// 1-DOF: mass M on a spring to the base, f_n, ζ; mass-normalised φ = 1/√M, Γ = √M along x.
ModalModel one_dof(double mass, double f_hz, double zeta) {
  Eigen::MatrixXd shape(2, 1);
  shape << 1.0 / std::sqrt(mass), 0.0;
  Eigen::MatrixXd gamma(1, 2);
  gamma << std::sqrt(mass), 0.0;
  return model_of(Eigen::VectorXd::Constant(1, f_hz), Eigen::VectorXd::Constant(1, zeta), shape, shape, gamma);
}

ModalModel three_modes() {
  Eigen::VectorXd f(3), zeta(3);
  f << 8.0, 23.0, 51.0;
  zeta << 0.01, 0.015, 0.02;
  Eigen::MatrixXd site(2, 3), force(2, 3), gamma(3, 2);
  site << 0.9, -0.6, 0.35, 0.2, 0.1, -0.3;
  force << 0.4, 0.7, -0.5, 0.0, 0.3, 0.2;
  gamma << 1.1, 0.1, -0.4, 0.2, 0.25, -0.1;
  return model_of(f, zeta, site, force, gamma);
}

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) v[static_cast<std::size_t>(k)] = a + (b - a) * k / (n - 1);
  return v;
}

Damper damper_with(std::shared_ptr<const sg::LossModel> loss, double bed_kg, double container_kg,
                   Eigen::Vector2d drive = {1.0, 0.0}) {
  Damper d;
  d.name = "tip";
  d.point = "site";
  d.drive_direction = drive;
  d.container_mass_kg = container_kg;
  d.layers = {{"bed", bed_kg, std::move(loss)}};
  return d;
}

/// Independent reference: the full modal system D(Ω) q = r solved directly (no receptance
/// reduction): diag(ω²−Ω²+2iζωΩ) − Ω² m_c ΦᵀΦ + Z b bᵀ, with Z of a linear layer.
Complex direct_output(const ModalModel& m, const Damper& d, Complex z, const Excitation& e, double f,
                      const Eigen::Vector2d& out_dir) {
  const double w = 2 * kPi * f;
  const Eigen::Index n = m.mode_count();
  const Eigen::MatrixXd& phi = m.points[0].translation;
  const Eigen::VectorXd b = phi.transpose() * d.drive_direction;
  Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double wj = 2 * kPi * m.natural_frequencies_hz[j];
    a(j, j) = Complex(wj * wj - w * w, 2 * m.damping_ratios[j] * wj * w);
  }
  a -= (w * w * d.container_mass_kg * phi.transpose() * phi).cast<Complex>();
  a += z * (b * b.transpose()).cast<Complex>();
  Eigen::VectorXcd r(n);
  Complex base_site = 0.0, base_out = 0.0;
  if (e.kind == Excitation::Kind::kBaseTranslation) {
    // Absolute site motion x = Φq + u: the layer force −Z nᵀ(Φq + u) and the container's
    // inertia −m_c(−Ω²)(Φq + u) both see the base.
    base_site = d.drive_direction.dot(e.direction) * e.amplitude;
    base_out = out_dir.dot(e.direction) * e.amplitude;
    r = (w * w * e.amplitude * (m.base_participation + d.container_mass_kg * phi.transpose()) * e.direction)
            .cast<Complex>() -
        z * base_site * b.cast<Complex>();
  } else {
    r = (m.points[1].translation.transpose() * e.direction * e.amplitude).cast<Complex>();
  }
  const Eigen::VectorXcd q = a.partialPivLu().solve(r);
  return ((out_dir.transpose() * phi).cast<Complex>() * q)(0) + base_out;
}

}  // namespace

TEST_CASE("a viscous damper on a 1-DOF reproduces the closed-form receptance and transmissibility", "[structure]") {
  // Reference: m' = M + m_c, X/F = 1/(k − Ω²m' + iΩ(c_s + c)) for the force, and for base
  // motion the absolute transmissibility (k + iΩc_s)/(k − Ω²m' + iΩ(c_s + c)) (the layer acts
  // on absolute velocity). The root is refined to 1e-13 in ln X, so 1e-6 is loose on purpose:
  // it leaves room for the reduction's round-off near resonance (condition ~1/ζ).
  const double mass = 2.0, fn = 10.0, zeta = 0.01, c = 3.0, container = 0.2, bed = 0.3;
  const ModalModel model = one_dof(mass, fn, zeta);
  const Damper damper = damper_with(std::make_shared<ViscousLoss>(c, bed), bed, container);
  const double k = mass * std::pow(2 * kPi * fn, 2), cs = 2 * zeta * 2 * kPi * fn * mass;
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(5.0, 15.0, 201);
  for (const auto kind : {Excitation::Kind::kPointForce, Excitation::Kind::kBaseTranslation}) {
    Excitation e;
    e.kind = kind;
    e.point = "force";
    e.amplitude = kind == Excitation::Kind::kPointForce ? 2.0 : 1e-3;
    const FrequencyResponse frf = harmonic_balance(model, {damper}, e, options);
    REQUIRE(frf.outcome == FrequencyResponse::Outcome::kConverged);
    for (const auto& p : frf.points) {
      const double w = 2 * kPi * p.frequency_hz;
      const Complex den(k - w * w * (mass + container), w * (cs + c));
      const Complex expected = kind == Excitation::Kind::kPointForce ? 1.0 / den : Complex(k, w * cs) / den;
      REQUIRE(p.roots.size() == 1);
      CHECK(std::abs(p.roots[0].outputs[0] - expected) <= 1e-6 * std::abs(expected));
      CHECK(p.roots[0].stability == Stability::kStable);
      // Without the bed: the same with c = 0 (containers attached).
      const Complex den0(k - w * w * (mass + container), w * cs);
      const Complex linear = kind == Excitation::Kind::kPointForce ? 1.0 / den0 : Complex(k, w * cs) / den0;
      CHECK(std::abs(p.linear_outputs[0] - linear) <= 1e-9 * std::abs(linear));
    }
  }
}

TEST_CASE("a hysteretic damper on a 3-mode model reproduces the direct modal solve", "[structure]") {
  // Reference: direct_output, the full 3 x 3 complex system with Z = iΩ² m_bed η (constant
  // η*) written out; the code goes through the damper-site receptance instead.
  const ModalModel model = three_modes();
  const double eta = 0.8, bed = 0.05, container = 0.03;
  class Hysteretic final : public sg::LossModel {
   public:
    sg::DamperResponse evaluate(double, double) const override {
      sg::DamperResponse r;
      r.eta_star = 0.8;
      r.apparent_mass_fraction = 0.0;
      return r;
    }
    sg::StrokeRange stroke_range_m(double) const override { return {1e-9, 1.0}; }
  };
  const Eigen::Vector2d drive = Eigen::Vector2d(0.8, 0.6);
  const Damper damper = damper_with(std::make_shared<Hysteretic>(), bed, container, drive);
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(2.0, 70.0, 300);
  options.outputs = {{"site-x", "site", {1.0, 0.0}}, {"force-y", "force", {0.0, 1.0}}};
  for (const auto kind : {Excitation::Kind::kPointForce, Excitation::Kind::kBaseTranslation}) {
    Excitation e;
    e.kind = kind;
    e.point = "force";
    e.direction = Eigen::Vector2d(0.6, 0.8);
    e.amplitude = kind == Excitation::Kind::kPointForce ? 1.0 : 1e-3;
    const FrequencyResponse frf = harmonic_balance(model, {damper}, e, options);
    for (const auto& p : frf.points) {
      const double w = 2 * kPi * p.frequency_hz;
      const Complex z(0.0, w * w * bed * eta);
      REQUIRE(p.roots.size() == 1);
      const Complex site = direct_output(model, damper, z, e, p.frequency_hz, Eigen::Vector2d(1.0, 0.0));
      CHECK(std::abs(p.roots[0].outputs[0] - site / e.amplitude) <= 1e-6 * std::abs(site / e.amplitude));
      // The root is the site's amplitude along the drive.
      const Complex along = direct_output(model, damper, z, e, p.frequency_hz, drive);
      CHECK(p.roots[0].damper_amplitudes_m[0] == Approx(std::abs(along)).epsilon(1e-9));
    }
  }
}

TEST_CASE("the half-power damping ratio of a viscous damper's peak matches the added damping", "[structure]") {
  // 1-DOF receptance with ζ_total = (c_s + c)/(2√(k m')) = 0.02: half-power gives
  // ζ(1 + O(ζ²)) for the displacement FRF, and the linear interpolation between 4000 grid
  // frequencies (step 2.5e-3 f_n, ~0.06 of the bandwidth) adds ~1e-4: 1e-3 relative.
  const double mass = 1.0, fn = 10.0, zeta = 0.005;
  const double k = mass * std::pow(2 * kPi * fn, 2), cs = 2 * zeta * 2 * kPi * fn * mass;
  const double c = 2 * 0.015 * std::sqrt(k * mass);  // adds ζ = 0.015
  const ModalModel model = one_dof(mass, fn, zeta);
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(5.0, 15.0, 4001);
  Excitation e;
  e.kind = Excitation::Kind::kPointForce;
  e.point = "force";
  e.amplitude = 1.0;
  const auto frf = harmonic_balance(model, {damper_with(std::make_shared<ViscousLoss>(c, 0.1), 0.1, 0.0)}, e, options);
  REQUIRE(frf.peaks.size() == 1);
  const double zeta_total = (cs + c) / (2 * std::sqrt(k * mass));
  CHECK(frf.peaks[0].damping_ratio == Approx(zeta_total).epsilon(1e-3));
  CHECK(frf.peaks[0].frequency_hz == Approx(fn * std::sqrt(1 - 2 * zeta_total * zeta_total)).epsilon(1e-5));
  REQUIRE(frf.linear_peaks.size() == 1);
  CHECK(frf.linear_peaks[0].damping_ratio == Approx(zeta).epsilon(2e-3));  // bandwidth ~2 grid steps: coarser
}

namespace {

/// The constructed softening damper on a 1-DOF under a force F: D(X, Ω) X = F with
/// D = k − Ω²(M + m_b α X) + i(Ω c_s + Ω² m_b η).
struct SofteningCase {
  double mass = 1.0, fn = 10.0, zeta = 0.005, bed = 0.1, eta = 0.05, alpha = 100.0, force = 1.0;
  double k() const { return mass * std::pow(2 * kPi * fn, 2); }
  double cs() const { return 2 * zeta * 2 * kPi * fn * mass; }
  Complex d(double x, double w) const {
    return Complex(k() - w * w * (mass + bed * alpha * x), w * cs() + w * w * bed * eta);
  }
  /// Slow flow of the same 1-DOF (modal mass 1 after the φ = 1 normalisation, M = 1):
  /// (2iΩM + c_s) ȧ = F − D(|a|) a, written here from scratch.
  Complex slow_rate(Complex a, double w) const { return (force - d(std::abs(a), w) * a) / Complex(cs(), 2 * w * mass); }
};

}  // namespace

TEST_CASE("a softening damper's fold is found where the analytic fold conditions put it", "[structure]") {
  const SofteningCase c;
  const ModalModel model = one_dof(c.mass, c.fn, c.zeta);
  const Damper damper = damper_with(std::make_shared<GrowingMassLoss>(c.eta, c.alpha), c.bed, 0.0);
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(8.0, 11.0, 301);
  Excitation e;
  e.kind = Excitation::Kind::kPointForce;
  e.point = "force";
  e.amplitude = c.force;
  const FrequencyResponse frf = harmonic_balance(model, {damper}, e, options);
  // Every root: compare the count with a dense independent scan of S(X) = X²|D|² − F².
  for (std::size_t k = 0; k < frf.points.size(); k += 10) {
    const double w = 2 * kPi * frf.points[k].frequency_hz;
    int sign_changes = 0;
    double prev = std::norm(c.d(1e-7, w)) * 1e-14 - c.force * c.force;
    for (int i = 1; i <= 20000; ++i) {
      const double x = 1e-7 * std::pow(1e7, i / 20000.0);
      const double s = x * x * std::norm(c.d(x, w)) - c.force * c.force;
      sign_changes += (s > 0) != (prev > 0);
      prev = s;
    }
    CHECK(frf.points[k].roots.size() == static_cast<std::size_t>(sign_changes));
    for (const auto& r : frf.points[k].roots) {
      const double x = r.damper_amplitudes_m[0];
      CHECK(x * std::abs(c.d(x, w)) == Approx(c.force).epsilon(1e-10));
    }
  }
  // Folds: S = 0 and ∂S/∂X = 0, with ∂S/∂X = 2X|D|² − 2X²Ω² m_b α Re D, solved by Newton in
  // (ln X, Ω) from each reported fold (finite-difference Jacobian, step 1e-7: the residuals
  // are smooth polynomials). Tolerances: the fold frequency is bisected to 2⁻⁶⁰ of a grid
  // step (1e-12 relative is safe); the fold amplitude comes from a golden-section search
  // of a quadratic extremum, accurate to ~√ε ≈ 1e-8 in ln X: 1e-6.
  std::size_t folds = 0;
  for (const auto& end : frf.branch_ends) {
    if (end.kind != BranchEnd::Kind::kFold) continue;
    ++folds;
    auto residual = [&](double u, double w) {
      const double x = std::exp(u);
      const Complex dd = c.d(x, w);
      return Eigen::Vector2d(x * x * std::norm(dd) / (c.force * c.force) - 1.0,
                             (2 * x * std::norm(dd) - 2 * x * x * w * w * c.bed * c.alpha * dd.real()) * x /
                                 (c.force * c.force));
    };
    double u = std::log(end.damper_amplitude_m), w = 2 * kPi * end.frequency_hz;
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector2d r = residual(u, w);
      Eigen::Matrix2d j;
      j.col(0) = (residual(u + 1e-7, w) - r) / 1e-7;
      j.col(1) = (residual(u, w * (1 + 1e-7)) - r) / (w * 1e-7);
      const Eigen::Vector2d step = j.fullPivLu().solve(-r);
      u += step[0];
      w += step[1];
    }
    CHECK(residual(u, w).norm() < 1e-10);
    CHECK(end.frequency_hz == Approx(w / (2 * kPi)).epsilon(1e-9));
    CHECK(end.damper_amplitude_m == Approx(std::exp(u)).epsilon(1e-6));
  }
  CHECK(folds == 2);  // the bent peak: one fold where the upper branch ends, one where it begins

  // Stability: integrate the slow flow (RK4, dt = 1e-3 s against rates <= ~10 rad/s) from each
  // root perturbed by 1% along (1 + i)/√2 for 20 s (≥ 6 slow time constants 1/(ζ_tot Ω)):
  // a stable root pulls back within 1e-3 of its amplitude, an unstable one leaves by > 10%.
  std::size_t checked_stable = 0, checked_unstable = 0;
  for (const auto& p : frf.points) {
    if (p.roots.size() < 3) continue;
    const double w = 2 * kPi * p.frequency_hz;
    for (const auto& r : p.roots) {
      // The root's modal amplitude: a = F/D (site = modal coordinate since φ = 1).
      const double x = r.damper_amplitudes_m[0];
      const Complex root = c.force / c.d(x, w);
      Complex a = root * (1.0 + 0.01 * Complex(1.0, 1.0) / std::sqrt(2.0));
      const double dt = 1e-3;
      double max_departure = 0.0;
      for (int step = 0; step < 20000; ++step) {
        const Complex k1 = c.slow_rate(a, w), k2 = c.slow_rate(a + 0.5 * dt * k1, w);
        const Complex k3 = c.slow_rate(a + 0.5 * dt * k2, w), k4 = c.slow_rate(a + dt * k3, w);
        a += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        max_departure = std::max(max_departure, std::abs(a - root) / std::abs(root));
      }
      if (r.stability == Stability::kStable) {
        CHECK(std::abs(a - root) / std::abs(root) < 1e-3);
        ++checked_stable;
      } else {
        CHECK(max_departure > 0.1);
        ++checked_unstable;
      }
    }
    if (checked_unstable >= 3) break;
  }
  CHECK(checked_stable >= 6);
  CHECK(checked_unstable >= 3);
}

TEST_CASE("the onset cliff of a closed-form damper ends branches as a jump, not as a root", "[structure]") {
  // Bouncing block, h = 20 mm, gravity off: η* jumps at X_onset = h/√(π²+4). Near resonance
  // the response passes the onset: the residual changes sign across the jump there. No root
  // may sit at the jump, and the branch ends are reported as kDiscontinuity.
  pdamp::formulas::ModelOptions mo;
  mo.gravity_across_drive = false;
  mo.scattered.provisional = false;
  const double h = 0.02;
  auto loss = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kBouncing, h, mo);
  const double onset = loss->discontinuities_stroke_m(10.0).at(0);
  const ModalModel model = one_dof(1.0, 10.0, 0.01);
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(8.0, 12.0, 400);
  Excitation e;
  e.kind = Excitation::Kind::kBaseTranslation;
  e.amplitude = 4e-4;
  const auto frf = harmonic_balance(model, {damper_with(loss, 0.05, 0.02)}, e, options);
  std::size_t cliffs = 0;
  for (const auto& end : frf.branch_ends) {
    if (end.kind != BranchEnd::Kind::kDiscontinuity) continue;
    ++cliffs;
    CHECK(end.damper_amplitude_m == Approx(onset).epsilon(1e-9));
  }
  CHECK(cliffs >= 1);
  std::size_t pinned = 0;
  for (const auto& p : frf.points) {
    for (const auto& r : p.roots) CHECK(std::abs(r.damper_amplitudes_m[0] / onset - 1.0) > 1e-10);
    // A frequency without any root has its response held at the cliff from both sides.
    if (p.roots.empty()) CHECK(p.held_at_jump.size() == 1);
    for (const auto& held : p.held_at_jump) {
      CHECK(held.damper_amplitude_m == Approx(onset).epsilon(1e-12));
      CHECK(held.upper_state_fraction > 0.0);
      CHECK(held.upper_state_fraction < 1.0);
      // The held state closes the amplitude equation: |output| = |site|/U = X_onset/U.
      CHECK(std::abs(held.outputs[0]) == Approx(onset / 4e-4).epsilon(1e-9));
      ++pinned;
    }
  }
  // Reference for the pinned state: just below the onset the linear-in-X drive pushes the
  // amplitude up (|y| > X), just above the orbit's η* ≈ 0.9 pulls it down (|y| < X).
  for (const auto& p : frf.points)
    if (!p.held_at_jump.empty()) {
      const double w = 2 * kPi * p.frequency_hz, k = std::pow(2 * kPi * 10.0, 2), cs = 2 * 0.01 * 2 * kPi * 10.0;
      auto site = [&](double x) {
        const auto r = loss->evaluate(p.frequency_hz, x);
        const Complex z = 0.05 * w * w * Complex(-r.apparent_mass_fraction, r.eta_star);
        // 1-DOF base motion, absolute site: (k + iΩc_s)U / (k − Ω²(1 + m_c) + iΩc_s + Z).
        return std::abs(Complex(k, w * cs) * 4e-4 / (Complex(k - w * w * 1.02, w * cs) + z));
      };
      CHECK(site(onset * (1 - 1e-9)) > onset * (1 - 1e-9));
      CHECK(site(onset) < onset);
    }
  INFO("frequencies pinned at the onset: " << pinned);
  CHECK(pinned >= 1);
}

TEST_CASE("two viscous dampers on a 3-mode model reproduce the direct modal solve by vector Newton", "[structure]") {
  // Reference: the 3 x 3 system with both layers' Z = iΩc_d b_d b_dᵀ written out. Newton
  // stops at |ln|y| − ln X| < 1e-13, so the outputs agree to ~1e-12; 1e-6 as for one damper.
  const ModalModel model = three_modes();
  Damper a = damper_with(std::make_shared<ViscousLoss>(2.0, 0.05), 0.05, 0.02);
  Damper b = damper_with(std::make_shared<ViscousLoss>(1.0, 0.03), 0.03, 0.0, Eigen::Vector2d(0.0, 1.0));
  b.name = "mid";
  b.point = "force";
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(3.0, 60.0, 120);
  Excitation e;
  e.kind = Excitation::Kind::kPointForce;
  e.point = "force";
  e.amplitude = 1.0;
  const FrequencyResponse frf = harmonic_balance(model, {a, b}, e, options);
  CHECK(frf.outcome == FrequencyResponse::Outcome::kConverged);
  for (const auto& p : frf.points) {
    const double w = 2 * kPi * p.frequency_hz;
    const Eigen::VectorXd ba = model.points[0].translation.transpose() * a.drive_direction;
    const Eigen::VectorXd bb = model.points[1].translation.transpose() * b.drive_direction;
    Eigen::MatrixXcd d = Eigen::MatrixXcd::Zero(3, 3);
    for (int j = 0; j < 3; ++j) {
      const double wj = 2 * kPi * model.natural_frequencies_hz[j];
      d(j, j) = Complex(wj * wj - w * w, 2 * model.damping_ratios[j] * wj * w);
    }
    const Eigen::MatrixXd phi = model.points[0].translation;
    d -= (w * w * 0.02 * phi.transpose() * phi).cast<Complex>();
    d += Complex(0.0, w * 2.0) * (ba * ba.transpose()).cast<Complex>() +
         Complex(0.0, w * 1.0) * (bb * bb.transpose()).cast<Complex>();
    const Eigen::VectorXcd q =
        d.partialPivLu().solve((model.points[1].translation.transpose() * e.direction).cast<Complex>());
    REQUIRE(p.roots.size() == 1);
    const Complex site_a = ba.cast<Complex>().dot(q), site_b = bb.cast<Complex>().dot(q);
    CHECK(std::abs(p.roots[0].outputs[0] - site_a) <= 1e-6 * std::abs(site_a));
    CHECK(std::abs(p.roots[0].outputs[1] - site_b) <= 1e-6 * std::abs(site_b));
    CHECK(p.roots[0].stability == Stability::kStable);
  }
}

TEST_CASE("a loss model without apparent mass is coupled with the documented fraction and a warning", "[structure]") {
  class NoMass final : public sg::LossModel {
   public:
    sg::DamperResponse evaluate(double, double) const override {
      sg::DamperResponse r;
      r.eta_star = 0.5;
      r.apparent_mass_fraction = std::numeric_limits<double>::quiet_NaN();
      r.warnings = sg::kLossApparentMassMissing;
      return r;
    }
    sg::StrokeRange stroke_range_m(double) const override { return {1e-9, 1.0}; }
  };
  // Reference: the same damper with the bed rigidly attached (fraction 1, the default), a
  // linear layer Z = Ω² m_bed(−1 + 0.5i): 1-DOF receptance 1/(k − Ω²(M + m_bed) + i(Ωc_s + 0.5Ω²m_bed)).
  const ModalModel model = one_dof(1.0, 10.0, 0.01);
  HarmonicBalanceOptions options;
  options.frequencies_hz = {9.0, 10.0, 11.0};
  Excitation e;
  e.kind = Excitation::Kind::kPointForce;
  e.point = "force";
  e.amplitude = 1.0;
  const auto frf = harmonic_balance(model, {damper_with(std::make_shared<NoMass>(), 0.1, 0.0)}, e, options);
  CHECK((frf.loss_warnings & sg::kLossApparentMassMissing) != 0);
  CHECK_FALSE(frf.warnings.empty());
  for (const auto& p : frf.points) {
    const double w = 2 * kPi * p.frequency_hz, k = std::pow(2 * kPi * 10.0, 2);
    const Complex expected = 1.0 / Complex(k - w * w * 1.1, w * 2 * 0.01 * 2 * kPi * 10.0 + 0.5 * w * w * 0.1);
    CHECK(std::abs(p.roots.at(0).outputs[0] - expected) <= 1e-9 * std::abs(expected));
  }
}

TEST_CASE("harmonic balance rejects bad inputs naming the field", "[structure]") {
  const ModalModel model = one_dof(1.0, 10.0, 0.01);
  HarmonicBalanceOptions options;
  options.frequencies_hz = {10.0, 9.0};
  Excitation e;
  e.amplitude = -1.0;
  const Damper d = damper_with(std::make_shared<ViscousLoss>(1.0, 0.1), 0.1, 0.0);
  CHECK_THROWS_WITH(harmonic_balance(model, {d}, e, options), Catch::Contains("frequencies_hz[1] = 9: must be >"));
  CHECK_THROWS_WITH(harmonic_balance(model, {d}, e, options), Catch::Contains("excitation.amplitude = -1"));
  options.frequencies_hz = {10.0};
  e.amplitude = 1.0;
  Damper bad = d;
  bad.point = "nowhere";
  bad.layers[0].bed_mass_kg = 0.0;
  CHECK_THROWS_WITH(harmonic_balance(model, {bad}, e, options), Catch::Contains("dampers[0].point = \"nowhere\""));
  CHECK_THROWS_WITH(harmonic_balance(model, {bad}, e, options), Catch::Contains("dampers[0].layers[0].bed_mass_kg = 0"));
}

// Reference: the closed-form rolling damper on a 1-DOF held at its onset over a band of
// frequencies (the damper amplitude pinned at the onset stroke, X = (1+κ)h/√(π²+4) with
// κ = 2/5: docs/theory.md §3): the response is flat there, and the flat top is one peak (at
// its middle), not one peak per sample that round-off makes a local maximum.
TEST_CASE("a response held at the onset over a band of frequencies is one peak", "[structure]") {
  const double h = 0.03;
  const auto loss = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kRolling, h);
  const ModalModel m = one_dof(0.6, 2.0, 0.002);
  Excitation e;
  e.direction = {1.0, 0.0};
  e.amplitude = 0.00133;
  HarmonicBalanceOptions o;
  o.frequencies_hz = linspace(1.5, 2.5, 401);
  const auto r = harmonic_balance(m, {damper_with(loss, 0.148, 0.3)}, e, o);
  std::size_t held = 0;
  for (const auto& p : r.points) held += p.held_at_jump.size();
  REQUIRE(held > 3);  // the case must exercise the plateau
  REQUIRE(r.peaks.size() == 1);
  const double onset = loss->discontinuities_stroke_m(2.0).front();
  CHECK(onset == Approx(1.4 * h / std::sqrt(kPi * kPi + 4.0)).epsilon(1e-12));
  // The plateau's height is the onset stroke over U (absolute amplitude of the site); the
  // roots beside it, on the collect-and-collide piece, sit just above the onset (0.14%
  // here), so the peak is within 1% above onset/U.
  CHECK(r.peaks.front().magnitude >= onset / e.amplitude * (1.0 - 1e-9));
  CHECK(r.peaks.front().magnitude <= 1.01 * onset / e.amplitude);
}

// Reference: the geometry of a rotating site. A container of length L centred at a site
// that rotates by θ per unit q while translating by b along the drive has its ends moving
// by θL/2 beyond b: 0.2/1 = 20% with θ = 2, L = 0.2 m (warned at the 10% default), 5% with
// L = 0.05 m (not warned); an unknown length (0) is never warned about.
TEST_CASE("a damper at a rotating site is warned about with the end motion it sees", "[structure]") {
  ModalModel m = one_dof(1.0, 5.0, 0.01);
  m.points[0].rotation = Eigen::RowVectorXd::Constant(1, 2.0);
  Damper d = damper_with(std::make_shared<ViscousLoss>(1.0, 0.1), 0.1, 0.2);
  d.length_along_drive_m = 0.2;
  const auto warned = rotation_warnings(m, {d});
  REQUIRE(warned.size() == 1);
  CHECK_THAT(warned.front(), Catch::Contains("mode 1") && Catch::Contains("20%"));
  d.length_along_drive_m = 0.05;
  CHECK(rotation_warnings(m, {d}).empty());
  d.length_along_drive_m = 0.0;
  CHECK(rotation_warnings(m, {d}).empty());
}

// Reference: direct_output, the full modal system solved directly, on the modes of a
// finite-element cantilever (4 modes of a 0.6 m spring-steel strip) with a viscous damper
// at its tip: the harmonic balance on an FE model (not only hand-made modal data)
// reproduces the linear FRF to 1e-6 (as above), for a force at mid-span and base motion.
TEST_CASE("a viscous damper on a beam model reproduces the direct modal solve", "[structure]") {
  BeamModel beam;
  BeamSegment segment;
  segment.length_m = 0.6;
  segment.section.width_m = 0.03;
  segment.section.depth_m = 0.002;
  segment.elements = 20;
  beam.segments = {segment};
  Support clamp;
  clamp.kind = Support::Kind::kClamped;
  beam.supports = {clamp};
  beam.points = {{"site", 0.6}, {"force", 0.3}};
  ModalDamping damping;
  damping.ratios = {0.005};
  const ModalModel model = beam_modal_model(beam, 4, damping).modal;
  REQUIRE(model.points[0].name == "site");
  const double c = 0.8, bed = 0.15;
  const Damper damper = damper_with(std::make_shared<ViscousLoss>(c, bed), bed, 0.3, {0.0, 1.0});
  HarmonicBalanceOptions options;
  options.frequencies_hz = linspace(0.5, 60.0, 400);
  options.outputs = {{"site-y", "site", {0.0, 1.0}}};
  for (const auto kind : {Excitation::Kind::kPointForce, Excitation::Kind::kBaseTranslation}) {
    Excitation e;
    e.kind = kind;
    e.point = "force";
    e.direction = {0.0, 1.0};
    e.amplitude = kind == Excitation::Kind::kPointForce ? 1.0 : 1e-3;
    const FrequencyResponse frf = harmonic_balance(model, {damper}, e, options);
    for (const auto& p : frf.points) {
      const Complex z(0.0, 2 * kPi * p.frequency_hz * c);
      REQUIRE(p.roots.size() == 1);
      const Complex site = direct_output(model, damper, z, e, p.frequency_hz, Eigen::Vector2d(0.0, 1.0));
      CHECK(std::abs(p.roots[0].outputs[0] - site / e.amplitude) <= 1e-6 * std::abs(site / e.amplitude));
    }
  }
}
