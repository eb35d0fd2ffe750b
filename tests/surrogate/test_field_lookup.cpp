// Tests of physical field lookup: (Γ, X/h) fields, normalised rescaling, derivatives, missing points.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>

#include "pdamp/surrogate/field_lookup.hpp"

namespace {

using namespace pdamp::surrogate;

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.80665;  // standard gravity, m/s^2

double intensity(double f, double x) { return x * (2 * kPi * f) * (2 * kPi * f) / kG; }

/// A field whose η* is the given function of its axis values, every point ok.
EffectiveField field_of(const Grid& grid, double clearance_m, const std::function<double(double, double)>& eta) {
  EffectiveField field;
  field.grid = grid;
  field.clearance_m = clearance_m;
  field.bed_mass_kg = 0.5;
  field.provenance = make_provenance(FieldSource::kFormulas, "test", 1);
  for (std::size_t k = 0; k < grid.size(); ++k) {
    FieldPoint p;
    p.eta_star = eta(grid.coordinate0(k), grid.coordinate1(k));
    p.e_diss_j = 1.0;
    p.status = PointStatus::kOk;
    p.motion_mode = "mode" + std::to_string(k);
    field.points.push_back(p);
  }
  return field;
}

/// Bilinear in (Γ, s): interpolation of it on linear (Γ, s) axes is exact.
double bilinear_gs(double gamma, double s) { return 0.2 + 0.1 * gamma + 0.8 * s - 0.3 * gamma * s; }

Grid gs_grid() {
  return Grid::from_ranges(GridAxes::kIntensityStrokeOverClearance, {0.1, 3.0, 8, AxisSpacing::kLinear},
                           {0.05, 1.2, 12, AxisSpacing::kLinear});
}

}  // namespace

TEST_CASE("an intensity-stroke field is looked up through gamma = X Omega^2/g and s = X/h", "[surrogate]") {
  const double h = 0.04;
  const FieldLookup lookup(field_of(gs_grid(), h, bilinear_gs));
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> log_f(std::log(1.0), std::log(4.0)), s(0.1, 1.1);
  int inside = 0;
  for (int k = 0; k < 500; ++k) {
    const double f = std::exp(log_f(random));
    const double x = s(random) * h;
    const double gamma = intensity(f, x);
    if (gamma < 0.1 || gamma > 3.0) continue;
    ++inside;
    const auto r = lookup.evaluate(f, x);
    // Reference: the bilinear function at (Γ, X/h) computed here from the definitions.
    CHECK(r.value == Approx(bilinear_gs(gamma, x / h)).margin(1e-13));
    CHECK(r.warnings == 0);
    // Chain rule by hand: ∂Γ/∂f = 2Γ/f, ∂Γ/∂X = Γ/X, ∂s/∂X = 1/h.
    const double dv_dgamma = 0.1 - 0.3 * (x / h), dv_ds = 0.8 - 0.3 * gamma;
    CHECK(r.d_value_d_frequency == Approx(dv_dgamma * 2 * gamma / f).epsilon(1e-10));
    CHECK(r.d_value_d_amplitude == Approx(dv_dgamma * gamma / x + dv_ds / h).epsilon(1e-10));
  }
  CHECK(inside > 100);
}

TEST_CASE("lookup derivatives in frequency and amplitude match finite differences", "[surrogate]") {
  // Reference: central differences of the lookup; the mapped point stays inside one
  // cell, where the patch is smooth. Tolerance: O(h²) truncation and 1e-16/h rounding.
  const auto smooth = [](double x0, double x1) { return std::sin(2 * x0) * std::cos(3 * x1); };
  for (const auto& [grid, h] :
       {std::pair{gs_grid(), 0.04},
        std::pair{Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 10.0, 9, AxisSpacing::kLog},
                                    {0.002, 0.05, 11, AxisSpacing::kLinear}),
                  0.02}}) {
    const FieldLookup lookup(field_of(grid, h, smooth));
    for (const auto& [f, x] : {std::pair{2.1, 0.0213}, std::pair{3.3, 0.0371}, std::pair{1.7, 0.0052}}) {
      const auto r = lookup.evaluate(f, x);
      if (r.warnings != 0) continue;  // clamped directions have derivative 0 by design
      const double df = 1e-6 * f, dx = 1e-6 * x;
      const double fd_f = (lookup.evaluate(f + df, x).value - lookup.evaluate(f - df, x).value) / (2 * df);
      const double fd_x = (lookup.evaluate(f, x + dx).value - lookup.evaluate(f, x - dx).value) / (2 * dx);
      CHECK(r.d_value_d_frequency == Approx(fd_f).epsilon(1e-5).margin(1e-7));
      CHECK(r.d_value_d_amplitude == Approx(fd_x).epsilon(1e-5).margin(1e-5));
    }
  }
}

TEST_CASE("a frequency-amplitude field serves another clearance at equal intensity and X/h", "[surrogate]") {
  // Field for h1 whose values depend on (Γ, X/h1) only, sampled at its (f, X) nodes.
  const double h1 = 0.04, h2 = 0.09;
  const auto law = [](double gamma, double s) { return std::exp(-gamma) * s; };
  const Grid grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 4.0, 4, AxisSpacing::kLinear},
                                      {0.01, 0.04, 4, AxisSpacing::kLinear});
  const EffectiveField field = field_of(grid, h1, [&](double f, double x) { return law(intensity(f, x), x / h1); });
  LookupOptions options;
  options.clearance_m = h2;
  const FieldLookup lookup(field, FieldColumn::kEtaStar, options);
  // The query at h2 with the same Γ and X/h as node (f1, X1) at h1: X2 = X1·h2/h1, and
  // Γ equal gives f2 = f1·√(X1/X2). Reference: the law itself at that (Γ, X/h).
  for (std::size_t k = 0; k < grid.size(); ++k) {
    const double f1 = grid.coordinate0(k), x1 = grid.coordinate1(k);
    const double x2 = x1 * h2 / h1, f2 = f1 * std::sqrt(x1 / x2);
    const auto r = lookup.evaluate(f2, x2);
    CHECK(r.value == Approx(law(intensity(f2, x2), x2 / h2)).epsilon(1e-12));
    CHECK(r.warnings == kRescaledClearance);
  }
  const auto lines = lookup.describe(kRescaledClearance);
  REQUIRE(lines.size() == 1);
  CHECK_THAT(lines[0], Catch::Contains("clearance 0.04 m used for clearance 0.09 m"));
  // The same clearance given explicitly is no rescaling.
  options.clearance_m = h1;
  CHECK(FieldLookup(field, FieldColumn::kEtaStar, options).evaluate(2.0, 0.02).warnings == 0);
}

TEST_CASE("an intensity-stroke field serves another clearance through X/h", "[surrogate]") {
  LookupOptions options;
  options.clearance_m = 0.08;
  const FieldLookup lookup(field_of(gs_grid(), 0.04, bilinear_gs), FieldColumn::kEtaStar, options);
  const double f = 1.5, x = 0.05;
  const auto r = lookup.evaluate(f, x);
  CHECK(r.value == Approx(bilinear_gs(intensity(f, x), x / 0.08)).margin(1e-13));
  CHECK(r.warnings == kRescaledClearance);
  CHECK(lookup.clearance_m() == 0.08);
}

TEST_CASE("clamped lookups say which axis and range, error lookups throw with the query", "[surrogate]") {
  const EffectiveField field = field_of(gs_grid(), 0.04, bilinear_gs);
  const FieldLookup clamp(field);
  const auto r = clamp.evaluate(20.0, 0.02);  // Γ = 32 > 3
  CHECK(r.warnings == kClampedAxis0);
  CHECK(r.d_value_d_frequency == 0.0);
  CHECK(r.value == Approx(bilinear_gs(3.0, 0.5)).margin(1e-13));
  const auto lines = clamp.describe(r.warnings);
  REQUIRE(lines.size() == 1);
  CHECK_THAT(lines[0], Catch::Contains("intensity range [0.1, 3]"));

  LookupOptions options;
  options.out_of_range = OutOfRangePolicy::kError;
  const FieldLookup error(field, FieldColumn::kEtaStar, options);
  CHECK_THROWS_WITH(error.evaluate(20.0, 0.02),
                    Catch::Contains("field lookup at frequency_hz = 20, amplitude_m = 0.02") &&
                        Catch::Contains("intensity = ") && Catch::Contains("outside the field's axis [0.1, 3]"));
  CHECK_THROWS_WITH(clamp.evaluate(0.0, 0.02),
                    Catch::Contains("frequency_hz = 0, amplitude_m = 0.02: both must be > 0"));
  CHECK_THROWS_WITH(clamp.evaluate(2.0, std::nan("")), Catch::Contains("both must be > 0 and finite"));
  options.clearance_m = -1.0;
  CHECK_THROWS_WITH(FieldLookup(field, FieldColumn::kEtaStar, options),
                    Catch::Contains("clearance_m = -1: must be >= 0 and finite"));
}

TEST_CASE("a lookup next to a missing or failed point is an error naming that point", "[surrogate]") {
  const Grid grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 3.0, 3, AxisSpacing::kLinear},
                                      {0.01, 0.03, 3, AxisSpacing::kLinear});
  EffectiveField field = field_of(grid, 0.05, [](double f, double x) { return f * x; });
  field.points[grid.index(2, 2)] = FieldPoint{};  // (3 Hz, 0.03 m) missing
  field.points[grid.index(2, 2)].status = PointStatus::kMissing;
  const FieldLookup lookup(field);
  CHECK_THROWS_WITH(lookup.evaluate(2.9, 0.029),
                    Catch::Contains("nearest node frequency_hz = 3, amplitude_m = 0.03, status missing"));
  CHECK(lookup.evaluate(1.5, 0.015).value == Approx(1.5 * 0.015));

  // A column the source does not give (apparent mass of a formula field) is an error too.
  const FieldLookup mass(field, FieldColumn::kApparentMass);
  CHECK_THROWS_WITH(mass.evaluate(1.5, 0.015), Catch::Contains("column not given"));
}

TEST_CASE("column values follow the point status", "[surrogate]") {
  const Grid grid = Grid::from_ranges(GridAxes::kFrequencyAmplitude, {1.0, 2.0, 2, AxisSpacing::kLinear},
                                      {0.01, 0.01, 1, AxisSpacing::kLinear});
  EffectiveField field = field_of(grid, 0.05, [](double f, double) { return f; });
  field.points[1].status = PointStatus::kFailed;
  field.points[1].eta_star = FieldPoint::kUnknown;
  const auto eta = column_values(field, FieldColumn::kEtaStar);
  CHECK(eta[0] == 1.0);
  CHECK(std::isnan(eta[1]));
  CHECK(column_values(field, FieldColumn::kEDiss)[0] == 1.0);
}
