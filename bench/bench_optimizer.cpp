// Optimiser benchmarks: the analytic cliff problem and the robust clearance sizing, per back end.
#include <benchmark/benchmark.h>

#include "../tests/optimizer/cliff_problem.hpp"  // the tests' problem, not a copy
#include "pdamp/optimizer/robust_sizing.hpp"
#include "pdamp/optimizer/solve.hpp"

namespace {

namespace opt = pdamp::optimizer;

/// One solve of the cliff problem (global ISRES stage of 2000 evaluations, then the
/// back end's local stage), with analytic or forward-difference gradients.
void BM_SolveCliffProblem(benchmark::State& state, opt::Backend backend, bool with_gradients) {
  const opt::Problem problem = opt::test::cliff_problem(with_gradients);
  opt::Options options;
  options.backend = backend;
  int evaluations = 0;
  for (auto _ : state) {
    const opt::Summary summary = opt::solve(problem, options);
    evaluations = summary.evaluations;
    benchmark::DoNotOptimize(summary.x.data());
  }
  state.counters["evaluations"] = evaluations;
}
BENCHMARK_CAPTURE(BM_SolveCliffProblem, nlopt_analytic, opt::Backend::kNlopt, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SolveCliffProblem, nlopt_differences, opt::Backend::kNlopt, false)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SolveCliffProblem, ipopt_analytic, opt::Backend::kIpopt, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SolveCliffProblem, ipopt_differences, opt::Backend::kIpopt, false)
    ->Unit(benchmark::kMillisecond);

/// Worst-case rolling sizing over strokes 8-20 mm at 12 Hz (9 samples: 9 η* per point).
void BM_RobustSizing(benchmark::State& state, opt::Backend backend) {
  opt::RobustSizingOptions options;
  options.stroke_min_m = 0.008;
  options.stroke_max_m = 0.02;
  options.frequency_min_hz = options.frequency_max_hz = 12.0;
  opt::Options solver;
  solver.backend = backend;
  int evaluations = 0;
  for (auto _ : state) {
    const opt::RobustSizing sizing = opt::size_clearance_robustly(options, solver);
    evaluations = sizing.summary.evaluations;
    benchmark::DoNotOptimize(sizing.clearance_m);
  }
  state.counters["evaluations"] = evaluations;
}
BENCHMARK_CAPTURE(BM_RobustSizing, nlopt, opt::Backend::kNlopt)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RobustSizing, ipopt, opt::Backend::kIpopt)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
