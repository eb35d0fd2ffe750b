// Effective-field lookup benchmarks: lookups per second on one core (target >= 1e7/s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "pdamp/surrogate/field_lookup.hpp"
#include "pdamp/surrogate/interpolator.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace {

namespace sg = pdamp::surrogate;

constexpr double kClearance = 0.04;     // m
constexpr std::size_t kQueries = 4096;  // cycled; fits in L1 with the grid, as an optimiser's working set does

/// A field of `n` x `n` nodes with smooth η* and every point ok.
sg::EffectiveField make_field(sg::GridAxes axes, sg::AxisSpacing spacing, int n, bool uneven) {
  sg::EffectiveField field;
  const bool fa = axes == sg::GridAxes::kFrequencyAmplitude;
  field.grid = sg::Grid::from_ranges(axes, {fa ? 1.0 : 0.1, fa ? 20.0 : 5.0, n, spacing},
                                     {fa ? 0.001 : 0.05, fa ? 0.05 : 1.5, n, spacing});
  if (uneven) {
    // Squeeze the nodes towards the low end so that the binary-search path is taken.
    for (auto* axis : {&field.grid.axis0, &field.grid.axis1}) {
      const double lo = axis->values.front(), hi = axis->values.back();
      for (auto& x : axis->values) x = lo + (hi - lo) * std::pow((x - lo) / (hi - lo), 1.5);
    }
  }
  field.clearance_m = kClearance;
  field.bed_mass_kg = 0.74;
  field.provenance = sg::make_provenance(sg::FieldSource::kFormulas, "bench", 1);
  for (std::size_t k = 0; k < field.grid.size(); ++k) {
    sg::FieldPoint p;
    p.eta_star = 0.5 + 0.4 * std::sin(field.grid.coordinate0(k)) * std::cos(30.0 * field.grid.coordinate1(k));
    p.e_diss_j = 1.0;
    p.apparent_mass_fraction = 0.3;
    p.motion_mode = "collect_and_collide";
    p.status = sg::PointStatus::kOk;
    field.points.push_back(p);
  }
  return field;
}

/// Random drives inside the frequency-amplitude box (for (Γ, X/h) fields most map inside too).
std::vector<std::pair<double, double>> queries() {
  std::mt19937_64 random(1);
  std::uniform_real_distribution<double> f(1.0, 20.0), x(0.001, 0.05);
  std::vector<std::pair<double, double>> q(kQueries);
  for (auto& [fq, xq] : q) {
    fq = f(random);
    xq = x(random);
  }
  return q;
}

/// FieldLookup::evaluate (η* and both derivatives) on a 50 x 50 field, one lookup per iteration.
void BM_FieldLookup(benchmark::State& state, sg::GridAxes axes, sg::AxisSpacing spacing, bool uneven,
                    double clearance_m) {
  const sg::EffectiveField field = make_field(axes, spacing, 50, uneven);
  sg::LookupOptions options;
  options.clearance_m = clearance_m;
  const sg::FieldLookup lookup(field, sg::FieldColumn::kEtaStar, options);
  const auto q = queries();
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& [f, x] = q[i++ & (kQueries - 1)];
    benchmark::DoNotOptimize(lookup.evaluate(f, x));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_FieldLookup, freq_amp_linear, sg::GridAxes::kFrequencyAmplitude, sg::AxisSpacing::kLinear, false,
                  0.0);
BENCHMARK_CAPTURE(BM_FieldLookup, freq_amp_log, sg::GridAxes::kFrequencyAmplitude, sg::AxisSpacing::kLog, false, 0.0);
BENCHMARK_CAPTURE(BM_FieldLookup, freq_amp_uneven_binary_search, sg::GridAxes::kFrequencyAmplitude,
                  sg::AxisSpacing::kLinear, true, 0.0);
BENCHMARK_CAPTURE(BM_FieldLookup, freq_amp_rescaled_clearance, sg::GridAxes::kFrequencyAmplitude,
                  sg::AxisSpacing::kLinear, false, 0.05);
BENCHMARK_CAPTURE(BM_FieldLookup, intensity_stroke_linear, sg::GridAxes::kIntensityStrokeOverClearance,
                  sg::AxisSpacing::kLinear, false, 0.0);
BENCHMARK_CAPTURE(BM_FieldLookup, intensity_stroke_log, sg::GridAxes::kIntensityStrokeOverClearance,
                  sg::AxisSpacing::kLog, false, 0.0);

/// The grid-level interpolator alone, in its own axis units.
void BM_BilinearInterpolator(benchmark::State& state) {
  const sg::EffectiveField field = make_field(sg::GridAxes::kFrequencyAmplitude, sg::AxisSpacing::kLinear, 50, false);
  const sg::BilinearInterpolator interpolator(field.grid, sg::column_values(field, sg::FieldColumn::kEtaStar));
  const auto q = queries();
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& [f, x] = q[i++ & (kQueries - 1)];
    benchmark::DoNotOptimize(interpolator.evaluate(f, x));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_BilinearInterpolator);

/// EffectiveFieldLossModel::evaluate: η*, apparent-mass fraction and the regime label
/// (a std::string copy) through the virtual LossModel interface the structures use.
void BM_EffectiveFieldLossModel(benchmark::State& state) {
  const sg::EffectiveField field = make_field(sg::GridAxes::kFrequencyAmplitude, sg::AxisSpacing::kLinear, 50, false);
  const sg::EffectiveFieldLossModel model(field);
  const sg::LossModel& loss = model;
  const auto q = queries();
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& [f, x] = q[i++ & (kQueries - 1)];
    benchmark::DoNotOptimize(loss.evaluate(f, x));
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EffectiveFieldLossModel);

}  // namespace

BENCHMARK_MAIN();
