// Tests of the LossModel implementations: closed forms, and fields filled from them or given.
#include <catch2/catch.hpp>
#include <cmath>
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
        // definition E_diss = η*·½ m_bed (XΩ)² (PHYSICS.md §1).
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
