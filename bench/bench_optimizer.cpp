// Optimiser benchmarks: the analytic cliff problem and the robust clearance sizing, per back
// end; the filling ratios of the shipped 3-layer case and the clearance on the beam (issue 12 §6).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numbers>
#include <string>

#include "../tests/optimizer/cliff_problem.hpp"  // the tests' problem, not a copy
#include "pdamp/case_file/case.hpp"
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
/// builds them (cli/optimize_command.cpp, make_problem: the first damper's layers as
/// candidates, released from rest, step_log_change 0.2).
struct FillingProblem {
  pdamp::structure::ModalModel modal;
  opt::FillingRatioOptions options;
  opt::Options solver;
};

FillingProblem manipulator_link_problem() {
  namespace cf = pdamp::case_file;
  const cf::Case c = cf::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_optimize.json");
  const cf::FillingRatiosTask& task = *c.task.filling_ratios;
  const cf::StructureSetup setup = cf::structure_setup(c, cf::LossMethod::kFormulas);
  const cf::DamperSpec& spec = c.dampers.front();
  FillingProblem p;
  p.modal = setup.modal;
  p.options.damper = setup.dampers.front();
  p.options.fixed_dampers.assign(setup.dampers.begin() + 1, setup.dampers.end());
  p.options.model = spec.model;
  p.options.model_options = spec.model_options;
  p.options.mass_budget_kg = task.mass_budget_kg;
  for (std::size_t k = 0; k < spec.layers.size(); ++k) {
    const cf::LayerSpec& layer = spec.layers[k];
    const double r = layer.particle_radius_m;
    opt::LayerCandidate l;
    l.name = layer.name;
    l.inner_length_m = layer.container.inner_length(spec.drive_axis);
    l.slab_length_m = 2.0 * r;
    l.spheres_per_slab = task.spheres_per_slab.at(k);
    l.sphere_mass_kg = layer.bed_mass_kg / layer.particle_count;
    l.sphere_volume_m3 = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    l.initial_slabs = std::min(layer.particle_count / l.spheres_per_slab, l.max_slabs());
    p.options.layers.push_back(l);
  }
  p.options.decay.initial_modal_amplitudes = cf::initial_modal_amplitudes(c, setup, task.decay).cwiseAbs();
  p.options.decay.duration_s = task.decay.duration_s;
  p.options.decay.threshold_fraction = task.decay.settling_threshold;
  p.options.decay.step_log_change = 0.2;
  p.solver.global_evaluations = task.global_evaluations;
  p.solver.max_evaluations = task.max_evaluations;
  return p;
}

/// The whole 3-layer optimisation of the shipped case on the closed forms (relaxed solve,
/// rounded neighbours, single-layer baseline; no DEM verification), as `pdamp optimize
/// cases/manipulator_link_optimize.json --no-verify`. Target (issue 12 §6): < 2 s.
void BM_FillingRatios(benchmark::State& state, opt::Backend backend) {
  FillingProblem p = manipulator_link_problem();
  p.solver.backend = backend;
  int evaluations = 0;
  double settling = 0.0;
  for (auto _ : state) {
    const opt::FillingRatioResult r = opt::optimize_filling_ratios(p.modal, p.options, p.solver);
    evaluations = r.decay_evaluations;
    settling = r.chosen.settling_time_s;
    benchmark::DoNotOptimize(r.chosen.objective);  // the const overload: "+m,r" on a double miscompiles here
  }
  state.counters["evaluations"] = evaluations;
  state.counters["chosen_settling_s"] = benchmark::Counter(settling);
}
BENCHMARK_CAPTURE(BM_FillingRatios, nlopt, opt::Backend::kNlopt)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_CAPTURE(BM_FillingRatios, ipopt, opt::Backend::kIpopt)->Unit(benchmark::kMillisecond)->Iterations(3);

/// The base-excited beam of cases/beam_base_excited.json (as tests/optimizer/
/// test_clearance_on_structure.cpp builds it): 3 modes, the damper's weight on the
/// geometric stiffness, rolling, 0.148 kg bed, 0.3 kg container, U = 1.33 mm, 1.2-2.4 Hz.
void BM_ClearanceOnStructure(benchmark::State& state, opt::ClearanceObjective objective) {
  namespace st = pdamp::structure;
  st::BeamModel beam;
  st::BeamSegment segment;
  segment.length_m = 0.6;
  segment.section.shape = st::SectionShape::kSolidRectangle;
  segment.section.width_m = 0.03;
  segment.section.depth_m = 0.002;
  segment.material = {206e9, 7850.0};
  segment.elements = 24;
  beam.segments.push_back(segment);
  beam.supports.push_back({st::Support::Kind::kClamped, 0.0, 0.0, 0.0, 0.0});
  beam.points.push_back({"tip", 0.6});
  beam.points.push_back({"middle", 0.3});
  beam.carried_weights.push_back({0.6, 0.3 + 0.148});
  beam.axial_gravity_m_s2 = -9.80665;
  beam.geometric_stiffness = true;
  st::ModalDamping damping;
  damping.ratios = {0.002};
  const st::ModalModel model = st::beam_modal_model(beam, 3, damping).modal;
  opt::ClearanceOnStructureOptions o;
  o.site = "tip";
  o.drive_direction = {0.0, 1.0};
  o.base_direction = {0.0, 1.0};
  o.container_mass_kg = 0.3;
  o.bed_mass_kg = 0.148;
  o.model = pdamp::formulas::DamperModel::kRolling;
  o.base_amplitude_m = 1.33e-3;
  o.frequency_min_hz = 1.2;
  o.frequency_max_hz = 2.4;
  o.frequency_points = 200;
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
