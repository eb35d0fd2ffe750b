// Structure-coupling benchmarks on one core: an FRF with every root and its stability, a
// backbone and a free decay, each on a 3-mode model with one closed-form damper.
#include <benchmark/benchmark.h>

#include <memory>

#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/harmonic_balance.hpp"

namespace {

namespace st = pdamp::structure;
namespace sg = pdamp::surrogate;
namespace fm = pdamp::formulas;

/// Mass-normalised 3-mode model (8, 23, 51 Hz) with a tip point and base participation.
st::ModalModel three_modes() {
  st::ModalModel m;
  m.natural_frequencies_hz = Eigen::Vector3d(8.0, 23.0, 51.0);
  m.damping_ratios = Eigen::Vector3d(0.005, 0.008, 0.01);
  m.modal_masses_kg = Eigen::Vector3d::Ones();
  Eigen::MatrixXd tip(2, 3);
  tip << 1.2, -0.8, 0.5, 0.1, 0.05, -0.2;
  m.points = {{"tip", tip, Eigen::RowVectorXd::Zero(3)}};
  m.base_participation = Eigen::MatrixXd(3, 2);
  m.base_participation << 1.3, 0.0, -0.5, 0.0, 0.3, 0.0;
  return m;
}

/// Bouncing block, h = 20 mm, no gravity across the drive, a fitted (non-provisional)
/// scattered law: the closed form answers without warnings, hence without allocating.
std::vector<st::Damper> one_damper() {
  fm::ModelOptions options;
  options.gravity_across_drive = false;
  options.scattered.provisional = false;
  st::Damper d;
  d.name = "tip";
  d.point = "tip";
  d.container_mass_kg = 0.01;
  d.layers = {{"bed", 0.02, std::make_shared<sg::ClosedFormLossModel>(fm::DamperModel::kBouncing, 0.02, options)}};
  return {d};
}

void BM_FrequencyResponse2000(benchmark::State& state) {
  const st::ModalModel model = three_modes();
  const auto dampers = one_damper();
  st::Excitation excitation;
  excitation.amplitude = 3e-3;  // base, 3 mm along x: the tip crosses the onset near both lower modes
  st::HarmonicBalanceOptions options;
  for (int k = 0; k < 2000; ++k) options.frequencies_hz.push_back(4.0 + 56.0 * k / 1999.0);
  std::size_t roots = 0, ends = 0, unstable = 0;
  for (auto _ : state) {
    const auto frf = st::harmonic_balance(model, dampers, excitation, options);
    roots = unstable = 0;
    for (const auto& p : frf.points)
      for (const auto& r : p.roots) {
        ++roots;
        unstable += r.stability == st::Stability::kUnstable;
      }
    ends = frf.branch_ends.size();
    benchmark::DoNotOptimize(roots);
  }
  state.counters["roots"] = static_cast<double>(roots);
  state.counters["unstable"] = static_cast<double>(unstable);
  state.counters["branch_ends"] = static_cast<double>(ends);
}
BENCHMARK(BM_FrequencyResponse2000)->Unit(benchmark::kMillisecond);

void BM_Backbone1000(benchmark::State& state) {
  const st::ModalModel model = three_modes();
  const auto dampers = one_damper();
  st::BackboneOptions options;
  for (int k = 0; k < 1000; ++k) options.damper_amplitudes_m.push_back(1e-4 * std::pow(1e3, k / 999.0));
  for (auto _ : state) benchmark::DoNotOptimize(st::backbone(model, dampers, options));
}
BENCHMARK(BM_Backbone1000)->Unit(benchmark::kMillisecond);

void BM_FreeDecay60s(benchmark::State& state) {
  const st::ModalModel model = three_modes();
  const auto dampers = one_damper();
  st::FreeDecayOptions options;
  options.initial_modal_amplitudes = Eigen::Vector3d(0.02, 0.002, 0.0005);
  options.duration_s = 60.0;
  for (int k = 0; k <= 60; ++k) options.sample_times_s.push_back(k);
  std::size_t steps = 0;
  for (auto _ : state) {
    const auto decay = st::free_decay(model, dampers, options);
    steps = decay.steps;
    benchmark::DoNotOptimize(decay);
  }
  state.counters["rk4_steps"] = static_cast<double>(steps);
}
BENCHMARK(BM_FreeDecay60s)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
