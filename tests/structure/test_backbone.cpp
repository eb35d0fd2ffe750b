// Tests of the single-mode backbones against the small-mass-ratio formula ζ_add = ½η*μ
// (docs/theory.md §7.3) and the apparent-mass frequency shift.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>

#include "pdamp/structure/backbone.hpp"

namespace {

using namespace pdamp::structure;
namespace sg = pdamp::surrogate;
constexpr double kPi = 3.14159265358979323846;

/// Constant η* and a constant apparent-mass fraction.
class ConstantLoss final : public sg::LossModel {
 public:
  ConstantLoss(double eta, double mass_fraction) : eta_(eta), mass_fraction_(mass_fraction) {}
  sg::DamperResponse evaluate(double, double) const override {
    sg::DamperResponse r;
    r.eta_star = eta_;
    r.apparent_mass_fraction = mass_fraction_;
    return r;
  }
  sg::StrokeRange stroke_range_m(double) const override { return {1e-9, 1.0}; }

 private:
  double eta_, mass_fraction_;
};

ModalModel three_modes() {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::Vector3d(8.0, 23.0, 51.0);
  m.damping_ratios = Eigen::Vector3d(0.01, 0.015, 0.02);
  m.modal_masses_kg = Eigen::Vector3d::Ones();
  Eigen::MatrixXd site(2, 3);
  site << 0.9, -0.6, 0.35, 0.2, 0.1, -0.3;
  m.points = {{"site", site, Eigen::RowVectorXd::Zero(3)}};
  return m;
}

Damper damper_with(std::shared_ptr<const sg::LossModel> loss, double bed_kg, double container_kg) {
  Damper d;
  d.name = "tip";
  d.point = "site";
  d.container_mass_kg = container_kg;
  d.layers = {{"bed", bed_kg, std::move(loss)}};
  return d;
}

}  // namespace

TEST_CASE("the added damping ratio is half the loss factor times the modal mass ratio", "[structure]") {
  // Mass-normalised shapes, no container, no apparent mass: ζ_add = b²η*m_bed/(2 m_j) =
  // ½η*μ exactly; with an apparent mass the effective mass grows by μ·m_app/m_bed, the
  // frequency falls by 1/√(1 + μ m_app/m_bed) and ζ_add by the same mass factor.
  const ModalModel model = three_modes();
  const double bed = 1e-3, eta = 4.0 / kPi;
  for (int mode = 0; mode < 3; ++mode) {
    const double b = model.points[0].translation(0, mode);
    const double mu = b * b * bed;
    BackboneOptions options;
    options.mode = mode;
    options.damper_amplitudes_m = {1e-4, 1e-3, 1e-2};
    const Backbone plain = backbone(model, {damper_with(std::make_shared<ConstantLoss>(eta, 0.0), bed, 0.0)}, options);
    CHECK(plain.modal_mass_ratio == Approx(mu).epsilon(1e-14));
    for (const auto& p : plain.points) {
      CHECK(p.added_damping_ratio == Approx(0.5 * eta * mu).epsilon(1e-12));
      CHECK(p.natural_frequency_hz == Approx(model.natural_frequencies_hz[mode]).epsilon(1e-14));
      CHECK(p.modal_amplitude == Approx(p.damper_amplitude_m / std::abs(b)).epsilon(1e-14));
    }
    const Backbone heavy = backbone(model, {damper_with(std::make_shared<ConstantLoss>(eta, 0.6), bed, 0.0)}, options);
    for (const auto& p : heavy.points) {
      CHECK(p.natural_frequency_hz == Approx(model.natural_frequencies_hz[mode] / std::sqrt(1 + 0.6 * mu)).epsilon(1e-12));
      CHECK(p.added_damping_ratio == Approx(0.5 * eta * mu / (1 + 0.6 * mu)).epsilon(1e-12));
    }
  }
}

TEST_CASE("a bouncing damper at its peak adds 0.64 of the mass ratio as damping", "[structure]") {
  // At X_opt = h/π the ideal orbit gives η* = 4/π and m_app = 0 (docs/structure_coupling.md §2;
  // collect_and_collide.md §2): ζ_add = ½(4/π)μ = 0.637μ with no frequency shift (docs/theory.md §7.3). A container adds
  // its mass to the mode: m_eff = 1 + m_c|φ|².
  pdamp::formulas::ModelOptions mo;
  mo.gravity_across_drive = false;
  const double h = 0.02;
  auto loss = std::make_shared<sg::ClosedFormLossModel>(pdamp::formulas::DamperModel::kBouncing, h, mo);
  const ModalModel model = three_modes();
  const double bed = 2e-3, container = 1e-3;
  BackboneOptions options;
  options.mode = 0;
  options.damper_amplitudes_m = {h / kPi};
  const Backbone bb = backbone(model, {damper_with(loss, bed, container)}, options);
  const Eigen::Vector2d phi = model.points[0].translation.col(0);
  const double m_eff = 1.0 + container * phi.squaredNorm();
  const double mu = phi.x() * phi.x() * bed;
  CHECK(bb.points[0].added_damping_ratio == Approx(0.5 * (4 / kPi) * mu / m_eff).epsilon(1e-9));
  CHECK(bb.points[0].natural_frequency_hz == Approx(8.0 / std::sqrt(m_eff)).epsilon(1e-9));
  // Above the peak the bed rides part of the cycle: the apparent mass is positive and
  // lowers the frequency; η* falls.
  options.damper_amplitudes_m = {h};
  const Backbone above = backbone(model, {damper_with(loss, bed, container)}, options);
  CHECK(above.points[0].natural_frequency_hz < bb.points[0].natural_frequency_hz);
  CHECK(above.points[0].added_damping_ratio < bb.points[0].added_damping_ratio);
}

TEST_CASE("a backbone rejects a mode index out of range and a damper at a node", "[structure]") {
  const ModalModel model = three_modes();
  BackboneOptions options;
  options.mode = 3;
  options.damper_amplitudes_m = {1e-3};
  const Damper d = damper_with(std::make_shared<ConstantLoss>(1.0, 0.0), 1e-3, 0.0);
  CHECK_THROWS_WITH(backbone(model, {d}, options), Catch::Contains("mode = 3: must be < 3"));
  options.mode = 0;
  options.damper_amplitudes_m = {-1.0};
  CHECK_THROWS_WITH(backbone(model, {d}, options), Catch::Contains("damper_amplitudes_m[0] = -1: must be > 0"));
}
