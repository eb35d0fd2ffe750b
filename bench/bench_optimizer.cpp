// Optimiser benchmarks: the analytic cliff problem and the robust clearance sizing, per back
// end; the filling ratios of the shipped 3-layer case and the clearance on the beam.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numbers>
#include <string>

#include "../tests/optimizer/beam_problem.hpp"   // the tests' problems, not copies
#include "../tests/optimizer/cliff_problem.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/filling_ratio_problem.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/optimizer/filling_ratios.hpp"
#include "pdamp/optimizer/robust_sizing.hpp"
#include "pdamp/optimizer/solve.hpp"
#include "pdamp/structure/beam.hpp"

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

/// The optimiser's inputs for cases/manipulator_link_optimize.json as `pdamp optimize`
/// builds them (case_file::filling_ratio_problem), with the task's evaluation budgets.
struct FillingProblem {
  pdamp::case_file::FillingRatioProblem problem;
  opt::Options solver;
};

FillingProblem manipulator_link_problem() {
  namespace cf = pdamp::case_file;
  const cf::Case c = cf::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_optimize.json");
  FillingProblem p{cf::filling_ratio_problem(c), {}};
  p.solver.global_evaluations = c.task.filling_ratios->global_evaluations;
  p.solver.max_evaluations = c.task.filling_ratios->max_evaluations;
  return p;
}

/// The whole 3-layer optimisation of the shipped case on the closed forms (relaxed solve,
/// rounded neighbours, single-layer baseline; no DEM verification), as `pdamp optimize
/// cases/manipulator_link_optimize.json --method formulas --no-verify`. Target: < 2 s.
void BM_FillingRatios(benchmark::State& state, opt::Backend backend) {
  FillingProblem p = manipulator_link_problem();
  p.solver.backend = backend;
  int evaluations = 0;
  double settling = 0.0;
  for (auto _ : state) {
    const opt::FillingRatioResult r = opt::optimize_filling_ratios(p.problem.modal, p.problem.options, p.solver);
    evaluations = r.decay_evaluations;
    settling = r.chosen.settling_time_s;
    benchmark::DoNotOptimize(r.chosen.objective);  // the const overload: "+m,r" on a double miscompiles here
  }
  state.counters["evaluations"] = evaluations;
  state.counters["chosen_settling_s"] = benchmark::Counter(settling);
}
BENCHMARK_CAPTURE(BM_FillingRatios, nlopt, opt::Backend::kNlopt)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_FillingRatios, ipopt, opt::Backend::kIpopt)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The shipped optimisation with its DEM verification (tasks::run_filling_ratios, as `pdamp
/// optimize cases/manipulator_link_optimize.json` without files): the two DEM-in-the-loop
/// decays of the chosen and baseline designs on two threads, `verify_duration_s` simulated
/// each at the case's softening. Counters: the two decays' steps per wall second.
void BM_FillingRatiosVerified(benchmark::State& state, double verify_duration_s) {
  namespace cf = pdamp::case_file;
  const cf::Case shipped = cf::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_optimize.json");
  nlohmann::json document = shipped.document;
  document["task"]["verify"]["duration_s"] = verify_duration_s;
  const cf::Case c = cf::load_case_document(document, shipped.path);
  double steps = 0.0, dem_wall_s = 0.0;
  pdamp::tasks::FillingRatiosOptions options;
  options.calibrated = false;  // the verification's DEM alone, on the closed forms' designs
  for (auto _ : state) {
    const auto r =
        pdamp::tasks::run_filling_ratios(c, options, pdamp::base::silent_hooks(), pdamp::base::local_executor());
    for (const auto& d : r.verification->designs) {
      steps += static_cast<double>(d.dem.steps);
      dem_wall_s += d.dem.wall_time_s;
    }
    benchmark::DoNotOptimize(r.verification->passed);
  }
  state.counters["dem_steps_per_s"] = benchmark::Counter(steps / dem_wall_s);
}
BENCHMARK_CAPTURE(BM_FillingRatiosVerified, two_s, 2.0)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(BM_FillingRatiosVerified, shipped_20_s, 20.0)->Unit(benchmark::kMillisecond)->Iterations(1);

/// The base-excited beam of cases/beam_base_excited.json (tests/optimizer/beam_problem.hpp):
/// 3 modes, the damper's weight on the
/// geometric stiffness, rolling, 0.148 kg bed, 0.3 kg container, U = 1.33 mm, 1.2-2.4 Hz.
void BM_ClearanceOnStructure(benchmark::State& state, opt::ClearanceObjective objective) {
  const pdamp::structure::ModalModel model = pdamp::test::beam_model();
  opt::ClearanceOnStructureOptions o = pdamp::test::beam_options();
  o.objective = objective;
  int evaluations = 0;
  for (auto _ : state) {
    const opt::ClearanceOnStructureResult r = opt::size_clearance_on_structure(model, o);
    evaluations = r.summary.evaluations;
    benchmark::DoNotOptimize(r.summary.x.data());
  }
  state.counters["evaluations"] = evaluations;
}
BENCHMARK_CAPTURE(BM_ClearanceOnStructure, beam_design_stroke, opt::ClearanceObjective::kDesignStrokeAtResonance)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ClearanceOnStructure, beam_lowest_peak, opt::ClearanceObjective::kLowestPeak)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
