// Formula benchmarks: complex power of long records and the closed-form loss factor and Hertz impact.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/complex_power.hpp"
#include "pdamp/formulas/hertz_impact.hpp"

namespace {

namespace fm = pdamp::formulas;

/// complex_power of N samples: 10 Hz drive sampled 1000 times per period (dt = 0.1 ms),
/// force and velocity of a damper-like signal with harmonics. The FFTW plan (per T/dt)
/// is made by a first call outside the timed loop, as the DEM's repeated calls see it.
void BM_ComplexPower(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  constexpr double kFrequency = 10.0;
  constexpr int kSamplesPerPeriod = 1000;
  const double dt = 1.0 / (kFrequency * kSamplesPerPeriod);
  const double omega = 2.0 * fm::kPi * kFrequency;
  std::vector<double> force(static_cast<std::size_t>(n));
  std::vector<double> velocity(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double phase = omega * dt * i;
    velocity[i] = 0.3 * std::cos(phase);
    force[i] = 2.0 * std::cos(phase - 0.7) + 0.4 * std::cos(3.0 * phase) + 0.1;
  }
  benchmark::DoNotOptimize(fm::complex_power(force, velocity, dt, kFrequency));
  for (auto _ : state) {
    benchmark::DoNotOptimize(fm::complex_power(force, velocity, dt, kFrequency));
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_ComplexPower)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMicrosecond);

/// One closed-form η* evaluation (the work behind `pdamp loss`) at a stroke X = h·ratio.
void BM_ReducedLossFactor(benchmark::State& state, fm::DamperModel model, double stroke_over_clearance,
                          double frequency_hz) {
  double clearance_m = 0.04;
  double stroke_m = clearance_m * stroke_over_clearance;
  for (auto _ : state) {
    benchmark::DoNotOptimize(clearance_m);
    benchmark::DoNotOptimize(stroke_m);
    benchmark::DoNotOptimize(fm::reduced_loss_factor(model, clearance_m, stroke_m, frequency_hz));
  }
}
// Collect-and-collide above the peak (impact phase from φ − sin φ = h/X), the
// sub-peak orbit (ψ from π cos ψ + 2 sin ψ = h/X), the scattered fit, and kAuto at
// low intensity (rolling family).
BENCHMARK_CAPTURE(BM_ReducedLossFactor, bouncing_above_peak, fm::DamperModel::kBouncing, 0.5, 60.0);
BENCHMARK_CAPTURE(BM_ReducedLossFactor, bouncing_sub_peak, fm::DamperModel::kBouncing, 0.3, 60.0);
BENCHMARK_CAPTURE(BM_ReducedLossFactor, bouncing_scattered, fm::DamperModel::kAuto, 0.2, 60.0);
BENCHMARK_CAPTURE(BM_ReducedLossFactor, auto_rolling_2hz, fm::DamperModel::kAuto, 0.4, 2.0);

/// δ_max and t_c of one steel sphere on a polymer layer (closed forms).
void BM_HertzImpact(benchmark::State& state) {
  const fm::Material steel;
  const fm::Material polymer{1200.0, 200e6, 0.45};
  const fm::HertzContact contact = fm::sphere_wall_contact(0.005, 4.1e-3, steel, polymer);
  double speed = 0.5;
  for (auto _ : state) {
    benchmark::DoNotOptimize(speed);
    benchmark::DoNotOptimize(fm::max_penetration(contact, speed));
    benchmark::DoNotOptimize(fm::contact_time(contact, speed));
  }
}
BENCHMARK(BM_HertzImpact);

}  // namespace

BENCHMARK_MAIN();
