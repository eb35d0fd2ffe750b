// Tests of the LossModel implementations: closed forms, and fields filled from them or given.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "pdamp/surrogate/loss_model.hpp"
#include "pdamp/surrogate/sweep.hpp"

namespace {

using namespace pdamp::surrogate;
namespace fm = pdamp::formulas;

constexpr double kPi = 3.14159265358979323846;
constexpr double kClearance = 0.1;  // m
constexpr double kBedMass = 0.74;   // kg: 36 steel spheres of 5 mm radius

SweepOptions formula_options() {
  SweepOptions options;
  options.source = FieldSource::kFormulas;
  options.case_hash = "case";
  options.model_version = 1;
  options.clearance_m = kClearance;
  options.bed_mass_kg = kBedMass;
  options.threads = 1;
  return options;
}

}  // namespace

TEST_CASE("a formula field holds the closed-form values at its grid points", "[surrogate]") {
  // Strokes from the scattered state through the onset and the peak to X = h, at low and
  // high intensity, on a (Γ, X/h) grid and on a (f, X) grid.
  const Grid grids[] = {Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 8.0, 5, AxisSpacing::kLog},
                                          {0.01, 0.1, 10, AxisSpacing::kLinear}),
                        Grid::from_ranges(GridAxes::kIntensityStrokeOverClearance, {0.2, 5.0, 4, AxisSpacing::kLog},
                                          {0.1, 1.0, 10, AxisSpacing::kLinear})};
  for (const auto model : {fm::DamperModel::kRolling, fm::DamperModel::kBouncing, fm::DamperModel::kAuto}) {
    const ClosedFormLossModel closed_form(model, kClearance);
    for (const Grid& grid : grids) {
      const SweepResult result = run_sweep(grid, formula_evaluator(model, kClearance, kBedMass), formula_options());
      REQUIRE(result.field.validate().empty());
      for (std::size_t k = 0; k < grid.size(); ++k) {
        const DrivePoint drive = drive_point(grid, k, kClearance);
        // Reference: the LossModel of the closed forms at the same drive, and the
        // definition E_diss = η*·½ m_bed (XΩ)² (docs/theory.md §1).
        const DamperResponse expected = closed_form.evaluate(drive.frequency_hz, drive.amplitude_m);
        const FieldPoint& p = result.field.points[k];
        CHECK(p.eta_star == expected.eta_star);
        CHECK(p.motion_mode == expected.regime);
        CHECK(p.eta_star_stderr == 0.0);
        CHECK(std::isnan(p.apparent_mass_kg));
        const double v = 2 * kPi * drive.frequency_hz * drive.amplitude_m;
        CHECK(p.e_diss_j == Approx(p.eta_star * 0.5 * kBedMass * v * v).epsilon(1e-14));
      }
    }
  }
}

TEST_CASE("a field loss model returns node values at nodes and the nearest node's mode", "[surrogate]") {
  const Grid grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 4.0, 4, AxisSpacing::kLinear},
                                      {0.02, 0.08, 4, AxisSpacing::kLinear});
  SweepResult result =
      run_sweep(grid, formula_evaluator(fm::DamperModel::kBouncing, kClearance, kBedMass), formula_options());
  const EffectiveFieldLossModel formula_model(result.field);
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const auto response = formula_model.evaluate(grid.coordinate0(k), grid.coordinate1(k));
    CHECK(response.eta_star == Approx(result.field.points[k].eta_star).margin(1e-14));
    CHECK(response.regime == result.field.points[k].motion_mode);
    CHECK(std::isnan(response.apparent_mass_fraction));  // the closed forms do not give it
  }
  // With the apparent mass given everywhere it is interpolated like η*: a fraction
  // linear in X is reproduced exactly between nodes.
  for (std::size_t k = 0; k < grid.size(); ++k)
    result.field.points[k].apparent_mass_fraction = 10.0 * grid.coordinate1(k);
  const EffectiveFieldLossModel with_mass(result.field);
  CHECK(with_mass.evaluate(2.5, 0.05).apparent_mass_fraction == Approx(0.5).epsilon(1e-14));
  // Through the LossModel interface, as a structure model would use it.
  const LossModel& model = with_mass;
  CHECK(model.evaluate(1.0, 0.02).eta_star == Approx(result.field.points[0].eta_star).margin(1e-14));
  CHECK(with_mass.lookup().evaluate(9.0, 0.05).warnings == kClampedAxis0);
}

TEST_CASE("the formula evaluator rejects a bad damper at once", "[surrogate]") {
  CHECK_THROWS_WITH(formula_evaluator(fm::DamperModel::kRolling, -0.1, kBedMass),
                    Catch::Contains("clearance_m = -0.1: must be > 0 and finite"));
  CHECK_THROWS_WITH(formula_evaluator(fm::DamperModel::kRolling, 0.1, 0.0),
                    Catch::Contains("bed_mass_kg = 0: must be > 0 and finite"));
}

namespace {

/// Independent reference for the closed forms' first harmonics: an event-driven (fixed
/// small step) simulation of the ideal block in the container, X = 1, Ω = 1 (so V = 1),
/// clearance r = h_eff/X... in units of X. In flight the bed accelerates with κ/(1+κ) of the
/// container (rolling without slip; 0 for a free block); at a wall it rides while the wall
/// pushes; impacts are plastic. Returns the bed velocity's first harmonic v̂ over the last
/// of `cycles` cycles: η* = −Im v̂, m_app/m_bed = Re v̂.
std::complex<double> simulated_first_harmonic(double kappa, double clearance_over_stroke, int cycles) {
  const int steps = 200000;
  const double dphi = 2 * kPi / steps;
  // The rolling bed's relative motion is 1/(1+κ) of the free block's, so the block's
  // effective clearance r = h_eff/X means a real travel r/(1+κ).
  const double travel = clearance_over_stroke / (1.0 + kappa);
  double x_rel = 0.0, v_bed = 0.0;
  int wall = 0;  // 0: riding on the wall at x_rel = 0, 1: at x_rel = travel, -1: flying
  std::complex<double> harmonic = 0.0;
  for (int k = 0; k < cycles * steps; ++k) {
    const double phi = -0.5 * kPi + k * dphi;  // riding on wall 0 (a_c = −sin φ > 0) until φ = 0
    const double a_c = -std::sin(phi);
    // A wall pushes only: leave it when the container starts to pull away.
    if ((wall == 0 && a_c < 0.0) || (wall == 1 && a_c > 0.0)) {
      wall = -1;
      v_bed = std::cos(phi);
    }
    double v_mid;
    if (wall >= 0) {
      v_mid = std::cos(phi + 0.5 * dphi);
    } else {
      const double v_start = v_bed;
      v_bed += kappa / (1.0 + kappa) * (std::cos(phi + dphi) - std::cos(phi));  // a_s = κ/(1+κ)·a_c
      v_mid = 0.5 * (v_start + v_bed);
      x_rel += v_mid * dphi - (std::sin(phi + dphi) - std::sin(phi));
      if (x_rel >= travel || x_rel <= 0.0) {  // plastic impact: the bed takes the wall's velocity
        wall = x_rel >= travel ? 1 : 0;
        x_rel = wall == 1 ? travel : 0.0;
        v_bed = std::cos(phi + dphi);
      }
    }
    if (k >= (cycles - 1) * steps) harmonic += v_mid * std::exp(std::complex<double>(0.0, -(phi + 0.5 * dphi))) * dphi / kPi;
  }
  return harmonic;
}

}  // namespace

TEST_CASE("the closed forms' apparent mass and loss factor are the first harmonic of the ideal orbit", "[surrogate]") {
  // Reference: simulated_first_harmonic, a time-stepped ideal block (2e5 steps per cycle,
  // 40 cycles to settle the sub-peak orbit, whose multiplier (π/2)tan ψ is <= 0.45 here).
  // Event times are resolved to one step (3e-5 rad), which moves the harmonics by O(1e-5):
  // margin 3e-4. Checked on both branches, bouncing (κ = 0) and rolling (κ = 2/5).
  struct Case {
    fm::DamperModel model;
    double kappa;
  };
  for (const Case c : {Case{fm::DamperModel::kBouncing, 0.0}, Case{fm::DamperModel::kRolling, 0.4}}) {
    const double h = 0.05;
    const ClosedFormLossModel loss(c.model, h);
    for (const double stroke_over_effective_clearance : {0.28, 0.3, 1.2 / kPi, 0.5, 1.0, 2.0}) {
      const double x = stroke_over_effective_clearance * (1.0 + c.kappa) * h;
      const DamperResponse r = loss.evaluate(2.0, x);  // Γ = 0.08-0.9: rolls without slip at μ = 0.3
      const auto v = simulated_first_harmonic(c.kappa, 1.0 / stroke_over_effective_clearance, 40);
      CHECK(r.eta_star == Approx(-v.imag()).margin(3e-4));
      CHECK(r.apparent_mass_fraction == Approx(v.real()).margin(3e-4));
    }
  }
  // Landmarks of the derivation: 0 at the bouncing peak, −8/(π²+4) at the onset, → 1 at large X.
  const ClosedFormLossModel bouncing(fm::DamperModel::kBouncing, 0.1);
  CHECK(bouncing.evaluate(20.0, 0.1 / kPi).apparent_mass_fraction == Approx(0.0).margin(1e-12));
  const double onset = bouncing.discontinuities_stroke_m(20.0).at(0);
  CHECK(onset == Approx(0.1 / std::sqrt(kPi * kPi + 4)).epsilon(1e-15));
  CHECK(bouncing.evaluate(20.0, onset).apparent_mass_fraction == Approx(-8.0 / (kPi * kPi + 4)).epsilon(1e-6));
  CHECK(bouncing.evaluate(20.0, 50.0).apparent_mass_fraction == Approx(1.0).margin(0.02));
}

TEST_CASE("the closed forms' stroke derivatives match central differences on every smooth piece", "[surrogate]") {
  // Central difference with step δ = 1e-6 X: truncation ~δ²·|f'''|/6 and round-off ~ε/δ
  // (1e-10 relative) balance near 1e-6 relative; tolerance 1e-5 relative of the slope scale
  // η*/X. Auto at 60 Hz slides (Γ >> Γ_slip), so dκ_eff/dX enters the chain rule.
  fm::ModelOptions sliding;  // defaults: gravity across the drive, μ = 0.3
  struct Case {
    fm::DamperModel model;
    double frequency_hz;
  };
  const double h = 0.02;
  for (const Case c : {Case{fm::DamperModel::kBouncing, 30.0}, Case{fm::DamperModel::kRolling, 2.0},
                       Case{fm::DamperModel::kAuto, 60.0}, Case{fm::DamperModel::kAuto, 2.0},
                       Case{fm::DamperModel::kScattered, 60.0}}) {
    const ClosedFormLossModel loss(c.model, h, sliding);
    const auto jumps = loss.discontinuities_stroke_m(c.frequency_hz);
    for (const double x_over_h : {0.05, 0.2, 0.27, 0.3, 0.33, 0.4, 0.45, 0.6, 1.0, 3.0}) {
      const double x = x_over_h * h, step = 1e-6 * x;
      bool straddles = false;
      for (double j : jumps) straddles = straddles || std::abs(x - j) < 2 * step;
      if (straddles) continue;
      const DamperResponse r = loss.evaluate(c.frequency_hz, x);
      const DamperResponse up = loss.evaluate(c.frequency_hz, x + step);
      const DamperResponse down = loss.evaluate(c.frequency_hz, x - step);
      if (up.regime != down.regime) continue;  // the peak X_opt: continuous and flat on both sides
      const double scale = 1.0 / x;
      CHECK(r.d_eta_star_d_stroke_1_m == Approx((up.eta_star - down.eta_star) / (2 * step)).margin(1e-5 * scale));
      CHECK(r.d_apparent_mass_fraction_d_stroke_1_m ==
            Approx((up.apparent_mass_fraction - down.apparent_mass_fraction) / (2 * step)).margin(1e-5 * scale));
    }
  }
}

TEST_CASE("the onset is listed as a jump and the response changes regime across it", "[surrogate]") {
  // The onset stroke of each model (fixed point of X = (1+κ_eff(Γ(X)))h/√(π²+4) for auto):
  // one part in 1e-9 above it the orbit answers, one part below the scattered fit.
  const double h = 0.03;
  for (const auto model : {fm::DamperModel::kBouncing, fm::DamperModel::kRolling, fm::DamperModel::kAuto}) {
    for (const double f : {2.0, 40.0}) {
      const ClosedFormLossModel loss(model, h);
      const auto jumps = loss.discontinuities_stroke_m(f);
      REQUIRE(jumps.size() == 1);
      CHECK(loss.evaluate(f, jumps[0] * (1 + 1e-9)).regime != "scattered");
      CHECK(loss.evaluate(f, jumps[0] * (1 - 1e-9)).regime == "scattered");
      CHECK(loss.evaluate(f, jumps[0] * (1 - 1e-9)).eta_star < loss.evaluate(f, jumps[0] * (1 + 1e-9)).eta_star);
    }
  }
  CHECK(ClosedFormLossModel(fm::DamperModel::kScattered, h).discontinuities_stroke_m(2.0).empty());
}

TEST_CASE("closed-form warning bits follow the formulas' warnings", "[surrogate]") {
  fm::ModelOptions quiet;
  quiet.gravity_across_drive = false;
  quiet.scattered.provisional = false;
  const ClosedFormLossModel clean(fm::DamperModel::kBouncing, 0.02, quiet);
  CHECK(clean.evaluate(30.0, 0.01).warnings == 0);
  CHECK(clean.warning_messages(30.0, 0.01).empty());
  // Below the onset: scattered fit and assumed apparent mass, no validity breach.
  const DamperResponse below = clean.evaluate(30.0, 0.002);
  CHECK(below.warnings == (kLossScatteredState | kLossApparentMassAssumed));
  CHECK(below.apparent_mass_fraction == 0.0);  // no-impact limit of a free block
  // The default bouncing model with gravity across the drive warns (decoupled state, X < h).
  const ClosedFormLossModel on_base(fm::DamperModel::kBouncing, 0.02);
  CHECK((on_base.evaluate(30.0, 0.01).warnings & kLossOutsideClosedForm) != 0);
  CHECK_THAT(on_base.warning_messages(30.0, 0.01).at(0), Catch::Contains("decoupled"));
  // Rolling spheres below their onset: the no-impact limit transmits κ/(1+κ) = 2/7.
  CHECK(ClosedFormLossModel(fm::DamperModel::kRolling, 0.1).evaluate(2.0, 0.01).apparent_mass_fraction ==
        Approx(2.0 / 7.0).epsilon(1e-15));
  CHECK_THROWS_WITH(ClosedFormLossModel(fm::DamperModel::kRolling, 0.0), Catch::Contains("clearance_m = 0"));
}

TEST_CASE("a field loss model gives the lookup's slope, its warning bits and the missing apparent mass", "[surrogate]") {
  // Bilinear in (f, X): inside a cell the slope in X is exact for the interpolant, so a
  // central difference inside the cell agrees to round-off (1e-8 of η*/X).
  const Grid grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 4.0, 4, AxisSpacing::kLinear},
                                      {0.02, 0.08, 4, AxisSpacing::kLinear});
  const SweepResult result =
      run_sweep(grid, formula_evaluator(fm::DamperModel::kBouncing, kClearance, kBedMass), formula_options());
  const EffectiveFieldLossModel model(result.field);
  const DamperResponse r = model.evaluate(2.5, 0.05);
  const double step = 1e-6;
  const double fd = (model.evaluate(2.5, 0.05 + step).eta_star - model.evaluate(2.5, 0.05 - step).eta_star) / (2 * step);
  CHECK(r.d_eta_star_d_stroke_1_m == Approx(fd).margin(1e-8 * r.eta_star / 0.05));
  CHECK(r.d_eta_star_d_stroke_1_m == model.lookup().evaluate(2.5, 0.05).d_value_d_amplitude);
  CHECK(r.warnings == kLossApparentMassMissing);
  CHECK(std::isnan(r.d_apparent_mass_fraction_d_stroke_1_m));
  const DamperResponse outside = model.evaluate(2.5, 0.2);
  CHECK((outside.warnings & kLossOutsideFieldGrid) != 0);
  CHECK(outside.d_eta_star_d_stroke_1_m == 0.0);
  CHECK(model.stroke_range_m(2.5).min_m == Approx(0.02));
  CHECK(model.stroke_range_m(2.5).max_m == Approx(0.08));
  CHECK(model.discontinuities_stroke_m(2.5).empty());
  CHECK_FALSE(model.warning_messages(2.5, 0.2).empty());
}

TEST_CASE("the bed models' responses: rebounding orbit, impact map and Coulomb block, with their stroke derivatives",
          "[surrogate]") {
  // Same central differences as above (δ = 1e-6 X, tolerance 1e-5 η*/X), on the rebounding
  // bed (e_b = 0.2: orbit below the peak, tail above), below the onset with the impact map
  // (piecewise linear in ξ, nodes 0.0014 apart in ξ: none of these strokes lies within 2δ of
  // one), and the nested bed's Coulomb block under auto (Γ = 0.02-0.4 at 10 Hz: held, then
  // sliding past μ = 0.3). η* is the formulas' to the bit, m_app that of the orbit or block.
  const double h = 0.02;
  fm::ModelOptions rebounding;
  rebounding.bed_restitution = 0.2;
  fm::ModelOptions map;
  map.below_onset = fm::BelowOnsetModel::kImpactMap;
  fm::ModelOptions nested;
  nested.nested_bed = true;
  struct Case {
    fm::DamperModel model;
    double frequency_hz;
    fm::ModelOptions options;
  };
  for (const Case& c : {Case{fm::DamperModel::kRolling, 2.0, rebounding}, Case{fm::DamperModel::kAuto, 60.0, rebounding},
                       Case{fm::DamperModel::kRolling, 2.0, map}, Case{fm::DamperModel::kAuto, 10.0, nested}}) {
    const ClosedFormLossModel loss(c.model, h, c.options);
    const auto jumps = loss.discontinuities_stroke_m(c.frequency_hz);
    for (const double x_over_h : {0.05, 0.2, 0.27, 0.28, 0.29, 0.33, 0.4, 0.6, 1.0}) {
      const double x = x_over_h * h, step = 1e-6 * x;
      bool straddles = false;
      for (double j : jumps) straddles = straddles || std::abs(x - j) < 2 * step;
      if (straddles) continue;
      const DamperResponse r = loss.evaluate(c.frequency_hz, x);
      const DamperResponse up = loss.evaluate(c.frequency_hz, x + step);
      const DamperResponse down = loss.evaluate(c.frequency_hz, x - step);
      if (up.regime != down.regime) continue;
      const auto formula = fm::reduced_loss_factor(c.model, h, x, c.frequency_hz, c.options);
      CAPTURE(static_cast<int>(c.model), c.frequency_hz, x_over_h, r.regime);
      CHECK(r.eta_star == formula.eta_star);
      const double scale = 1.0 / x;
      CHECK(r.d_eta_star_d_stroke_1_m == Approx((up.eta_star - down.eta_star) / (2 * step)).margin(1e-5 * scale));
      CHECK(r.d_apparent_mass_fraction_d_stroke_1_m ==
            Approx((up.apparent_mass_fraction - down.apparent_mass_fraction) / (2 * step)).margin(1e-5 * scale));
      if (c.options.bed_restitution > 0.0 && r.regime == "sub_peak") {
        const auto orbit = fm::rebounding_orbit(formula.inertia_factor, 0.2, h, x);
        CHECK(r.apparent_mass_fraction == Approx(orbit.apparent_mass_fraction).margin(1e-12));
      }
      if (c.options.nested_bed) {
        const auto block = fm::coulomb_block(0.3, formula.intensity, h / x);
        CHECK(r.apparent_mass_fraction == block.apparent_mass_fraction);
      }
    }
  }
  // Below the onset with the map: m_app = κ/(1+κ); the nested bed has no jump.
  CHECK(ClosedFormLossModel(fm::DamperModel::kRolling, h, map).evaluate(2.0, 0.2 * h).apparent_mass_fraction ==
        Approx(0.4 / 1.4).epsilon(1e-15));
  CHECK(ClosedFormLossModel(fm::DamperModel::kAuto, h, nested).discontinuities_stroke_m(10.0).empty());
  CHECK(ClosedFormLossModel(fm::DamperModel::kRolling, h, rebounding).discontinuities_stroke_m(2.0).at(0) ==
        fm::onset_stroke_m(0.4, h, 0.2));
}

TEST_CASE("come down from above, a rolling bed below the onset answers with the rolling tail", "[surrogate]") {
  // evaluate (from rest) keeps the scattered fit; evaluate_from_above takes the rolling tail:
  // no loss and m_app/m_bed = κ/(1+κ) without rolling resistance, the block of friction μ_r
  // with it (formulas::rolling_tail, tested against a stepped sphere), and the same response
  // as evaluate above the onset.
  const double h = 0.01, f = 3.0;
  const double onset = fm::onset_stroke_m(0.4, h);
  const ClosedFormLossModel model(fm::DamperModel::kRolling, h);
  const auto rest = model.evaluate(f, 0.5 * onset);
  const auto above = model.evaluate_from_above(f, 0.5 * onset);
  CHECK(rest.regime == "scattered");
  CHECK(rest.eta_star > 0.0);
  CHECK(above.regime == "rolling_tail");
  CHECK(above.eta_star == 0.0);
  CHECK(above.apparent_mass_fraction == Approx(2.0 / 7.0).epsilon(1e-15));
  CHECK(above.d_eta_star_d_stroke_1_m == 0.0);
  CHECK(above.warnings == 0u);
  for (const double x : {onset, 2.0 * onset}) {
    CHECK(model.evaluate_from_above(f, x).eta_star == model.evaluate(f, x).eta_star);
    CHECK(model.evaluate_from_above(f, x).apparent_mass_fraction == model.evaluate(f, x).apparent_mass_fraction);
  }
  // With rolling resistance: η* > 0 and its slope is the difference quotient's (the central
  // difference inside the model against one over 1e-4 X here: 1e-5 relative).
  fm::ModelOptions resisted;
  resisted.rolling_resistance = 0.02;
  const ClosedFormLossModel rolling(fm::DamperModel::kRolling, h, resisted);
  const double x = 0.5 * onset, dx = 1e-4 * x;
  const auto r = rolling.evaluate_from_above(f, x);
  const double gamma = x * std::pow(2.0 * fm::kPi * f, 2) / fm::kStandardGravity;
  // (Γ computed here in another order: round-off only.)
  CHECK(r.eta_star == Approx(fm::rolling_tail(0.4, 0.02, gamma).eta_star).epsilon(1e-12));
  CHECK(r.apparent_mass_fraction == Approx(fm::rolling_tail(0.4, 0.02, gamma).apparent_mass_fraction).epsilon(1e-12));
  const double slope = (rolling.evaluate_from_above(f, x + dx).eta_star - rolling.evaluate_from_above(f, x - dx).eta_star) / (2.0 * dx);
  CHECK(r.d_eta_star_d_stroke_1_m == Approx(slope).epsilon(1e-5));
  // The option below_onset_from_above = scattered_fit restores the law from rest.
  fm::ModelOptions as_rest;
  as_rest.below_onset_from_above = fm::BelowOnsetModel::kScatteredFit;
  const ClosedFormLossModel old(fm::DamperModel::kRolling, h, as_rest);
  CHECK(old.evaluate_from_above(f, 0.5 * onset).eta_star == rest.eta_star);
}
