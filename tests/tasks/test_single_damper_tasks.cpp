// The single-damper studies as library calls, without the binary: the closed forms, the
// damper design, a formulas field and sensitivity study, and a DEM run stopped through
// its hooks and resumed.
#include <catch2/catch.hpp>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli/cli_support.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/tasks/closed_forms.hpp"
#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"
#include "pdamp/tasks/sensitivity.hpp"
#include "support/temp_dir.hpp"
#include "tasks/executor_support.hpp"

using namespace pdamp;
using test::case_path;

namespace {

const case_file::Case& low_intensity() {
  static const case_file::Case c = case_file::load_case(case_path("low_intensity_36_spheres.json"));
  return c;
}

}  // namespace

// Reference: the definitions of docs/theory.md §1, E_diss = η*·½ m_bed (XΩ)², the energy
// per cycle 2π E_diss and c_eq = η* m_bed Ω, evaluated here from η* (rounding only: 1e-12).
TEST_CASE("a loss point's energies follow from eta* by the complex-power definitions", "[tasks]") {
  tasks::LossOptions o;
  o.model = formulas::DamperModel::kAuto;
  o.clearance_m = 0.1;
  o.amplitude_m = 0.04;
  o.frequency_hz = 2.0;
  o.bed_mass_kg = 0.148;
  o.with_curve = true;
  const auto study = tasks::run_loss(o);
  const double omega = 2.0 * M_PI * o.frequency_hz, v = o.amplitude_m * omega;
  const double eta = study.point.loss.eta_star;
  CHECK(study.point.e_diss_j == Approx(eta * 0.5 * 0.148 * v * v).epsilon(1e-12));
  CHECK(study.point.energy_per_cycle_j == Approx(2.0 * M_PI * study.point.e_diss_j).epsilon(1e-12));
  CHECK(study.point.equivalent_damping_n_s_m == Approx(eta * 0.148 * omega).epsilon(1e-12));
  REQUIRE(study.curve.size() == 301);
  CHECK(study.curve.front().stroke_m == Approx(0.02 * o.clearance_m));
  CHECK(study.curve.back().stroke_m == Approx(1.5 * o.clearance_m));
  o.bed_mass_kg.reset();
  CHECK_THAT(tasks::run_loss(o).warnings.back(), Catch::Contains("1 kg bed"));
}

// Reference: size_for_stroke inverts optimum_stroke (the design stroke of the clearance it
// returns is the target); 1e-9 is the root finder's tolerance.
TEST_CASE("the clearance for a stroke has that stroke as its design stroke", "[tasks]") {
  for (const auto model : {formulas::DamperModel::kRolling, formulas::DamperModel::kBouncing}) {
    const auto sizing = tasks::size_for_stroke(model, 0.003, {});
    CHECK(formulas::optimum_stroke(model, sizing.clearance_m, {}).x_opt_m == Approx(0.003).epsilon(1e-9));
    CHECK(sizing.at.x_onset_m < sizing.stroke_m);
  }
}

// Reference: the rolling design stroke is 0.4 h_roll (docs/theory.md §3, the design value
// of the source study's experiments); the curve spans the case's design sweep.
TEST_CASE("the damper design of the shipped low-intensity case is the rolling design stroke", "[tasks]") {
  const auto& c = low_intensity();
  const auto d = tasks::run_damper_design(c);
  CHECK(d.family == formulas::DamperModel::kRolling);
  CHECK(d.optimum.x_opt_m == Approx(0.4 * d.clearance_m).epsilon(1e-4));
  REQUIRE(d.curve.size() == static_cast<std::size_t>(c.design.sweep_points));
  CHECK(d.curve.front().stroke_m == Approx(c.design.sweep_min_over_clearance * d.clearance_m));
  const auto j = tasks::to_json(d);
  CHECK(j["optimum"]["x_opt_m"] == d.optimum.x_opt_m);
  CHECK(j["task"] == "damper_design");
}

TEST_CASE("a study of one damper refuses a case of several layers, naming /dampers", "[tasks]") {
  const auto c = case_file::load_case(case_path("manipulator_link_decay.json"));
  try {
    (void)tasks::run_damper_design(c);
    FAIL("no error");
  } catch (const base::InputError& e) {
    CHECK(e.pointer() == "/dampers");
    CHECK_THAT(e.rule(), Catch::Contains("one damper of one layer"));
  }
}

// Reference: formulas::reduced_loss_factor at each node's drive (the field is the closed
// form sampled, nothing else); exact. The same sweep with every point computed through its
// bytes ("another process") gives the same field.
TEST_CASE("a formulas field is the closed form at every node, here or spread over processes", "[tasks]") {
  const auto& c = low_intensity();
  tasks::FieldOptions options;
  const auto plan = tasks::plan_field(c, options, base::local_executor());
  const auto here = tasks::run_field(c, plan, base::silent_hooks(), base::local_executor());
  const auto& damper = c.dampers.front();
  const double h = damper.layers.front().clearance_m;
  REQUIRE(here.field.points.size() == plan.grid.size());
  for (std::size_t k = 0; k < plan.grid.size(); ++k) {
    const auto drive = surrogate::drive_point(plan.grid, k, h);
    const auto loss = formulas::reduced_loss_factor(damper.model, h, drive.amplitude_m, drive.frequency_hz, damper.model_options);
    CHECK(here.field.points[k].eta_star == loss.eta_star);
  }
  test::BytesExecutor elsewhere;
  const auto spread = tasks::run_field(c, plan, base::silent_hooks(), elsewhere);
  CHECK(elsewhere.jobs_elsewhere == static_cast<int>(plan.grid.size()));
  CHECK(spread.field.points == here.field.points);
  CHECK_FALSE(here.scattered_fit.has_value());  // a formulas field has no scattered state to fit
}

// The descending branch's sweep: its approach stroke X_a may be a node of the grid (that
// node and those above start from rest, as the evaluator runs them), and the sweep carries
// X_a into the field's provenance. Planning only (no DEM run).
TEST_CASE("a DEM field approached from above accepts X_a on its grid and records it", "[tasks]") {
  const test::TempDir dir("field_approach");
  nlohmann::json j = nlohmann::json::parse(std::ifstream(case_path("fields/link_narrow_dem/case.json")));
  const double top = j["field"]["axis1"]["max"].get<double>();
  j["dem"]["approach"] = {{"amplitude_m", top}};
  const auto path = dir.path / "narrow_from_above.json";
  std::ofstream(path) << j.dump();
  const auto c = case_file::load_case(path.string());
  tasks::FieldOptions options;
  options.source = "dem";
  const auto plan = tasks::plan_field(c, options, base::local_executor());
  CHECK(plan.sweep.approach_amplitude_m == top);
  const auto at_top = surrogate::dem_point_options(c.dem.simulation, 3.6, top);
  CHECK(at_top.approach_amplitude_m == 0.0);  // from rest at X_a itself
  CHECK(surrogate::dem_point_options(c.dem.simulation, 3.6, 0.5 * top).approach_amplitude_m == top);
}

// Reference: the baseline variant is the case itself, so its eta* is the case's closed form
// at the study's drive and its change 0; each variant's closed form is computed from its own
// case (independently of the sweep).
TEST_CASE("a formulas sensitivity study's baseline row is the case's closed form", "[tasks]") {
  const auto& c = low_intensity();
  tasks::SensitivityOptions options;
  options.source = "formulas";
  const auto plan = tasks::plan_sensitivity(c, options, base::local_executor());
  const auto r = tasks::run_sensitivity(c, plan, base::silent_hooks(), base::local_executor());
  REQUIRE(r.rows.size() == plan.study.variants.size());
  CHECK(r.rows.front().parameter == "baseline");
  CHECK(r.rows.front().eta_star == r.rows.front().closed_form_eta_star);
  CHECK(r.rows.front().delta_eta_star == 0.0);
  for (const auto& row : r.rows) CHECK(row.eta_star == row.closed_form_eta_star);
}

namespace {

/// Hooks that ask the run to stop at its first chance (as SIGINT would).
struct StopAtOnce : base::RunHooks {
  int stop_requested() override { return SIGINT; }
};
/// Hooks that ask the run to stop once its first checkpoint is due (a signal in the transient).
struct StopAtFirstCheckpoint : base::RunHooks {
  bool asked = false;
  bool checkpoint_due(double) override { return asked = true; }
  int stop_requested() override { return asked ? SIGINT : 0; }
};
/// Hooks that save a checkpoint at every chance and never stop.
struct SaveAlways : base::RunHooks {
  bool checkpoint_due(double) override { return true; }
};

}  // namespace

// Reference: the uninterrupted run of the same plan. A run asked to stop in its transient saves
// its state and throws Interrupted; resumed from that state it gives the uninterrupted result to the bit
// (the DEM is deterministic for a thread count).
TEST_CASE("a DEM run stopped by its hooks and resumed equals the uninterrupted run", "[tasks]") {
  const auto& c = low_intensity();
  tasks::DemRunOptions options;
  options.analysed_periods = 2;
  options.threads = 1;
  const auto plan = tasks::plan_dem(c, options);
  const auto reference = tasks::run_dem(c, plan, {}, base::silent_hooks());
  const test::TempDir dir("tasks_dem_checkpoint");
  const tasks::CheckpointFile file{dir.path / "dem.checkpoint", false};
  // Asked to stop while the bed settles: it stops at once, with no checkpoint to resume.
  StopAtOnce at_once;
  CHECK_THROWS_WITH(tasks::run_dem(c, plan, file, at_once), Catch::Contains("before its first checkpoint"));
  CHECK_FALSE(std::filesystem::exists(file.path));
  StopAtFirstCheckpoint stop;
  CHECK_THROWS_AS(tasks::run_dem(c, plan, file, stop), base::Interrupted);
  REQUIRE(std::filesystem::exists(file.path));
  SaveAlways save;
  const auto resumed = tasks::run_dem(c, plan, {file.path, true}, save);
  CHECK(resumed.dem.eta_star == reference.dem.eta_star);
  CHECK(resumed.dem.apparent_mass_kg == reference.dem.apparent_mass_kg);
  CHECK(resumed.dem.series.force_n == reference.dem.series.force_n);
  // A checkpoint of another run (here: other periods) is refused naming the file.
  options.analysed_periods = 3;
  CHECK_THROWS_AS(tasks::run_dem(c, tasks::plan_dem(c, options), {file.path, true}, save), base::InputError);
}

// Reference: the collect-and-collide orbit of a collected bed exists down to its saddle-node
// onset, for a free plastic block X_on = h/√(π² + 4) = 0.269 h (docs/theory.md), below the
// stroke at which a bed started from rest jumps onto it (0.27-0.30 h for this layer, from the
// DEM field of cases/fields/link_narrow_dem). Between the two the state depends on history:
// the narrow link layer (2 × 4 spheres of r = 5 mm, h = 8 mm, 3.6 Hz) at X = 2.1 mm = 0.26 h
// keeps collecting and colliding (η* = 1.43 ± 0.04 at contacts softened 1e-2, 10 periods)
// when the drive comes down from 5 mm, and scatters (η* = 0.21 ± 0.02) when started from
// rest. Both above the tolerance by a factor of 3 either way: η* > 0.8 and < 0.5.
TEST_CASE("a DEM run approached from above keeps the collect-and-collide orbit that one from rest misses", "[tasks]") {
  std::ifstream in(case_path("fields/link_narrow_dem/case.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document.erase("field");
  document["dem"] = {{"stiffness_softening", 0.01}, {"transient_periods", 5}, {"analysed_periods", 6}};
  tasks::DemRunOptions options;
  options.amplitude_m = 0.0021;
  options.frequency_hz = 3.6;
  const auto from_rest_case = case_file::load_case_document(document, "narrow_from_rest.json");
  document["dem"]["approach"] = {{"amplitude_m", 0.005}};
  const auto from_above_case = case_file::load_case_document(document, "narrow_from_above.json");
  const auto from_rest = tasks::run_dem(from_rest_case, tasks::plan_dem(from_rest_case, options), {}, base::silent_hooks());
  const auto plan = tasks::plan_dem(from_above_case, options);
  const auto from_above = tasks::run_dem(from_above_case, plan, {}, base::silent_hooks());
  CHECK(from_rest.dem.eta_star < 0.5);
  CHECK(from_above.dem.eta_star > 0.8);
  CHECK(from_above.dem.motion_mode == dem_reference::MotionMode::kRollingCollectAndCollide);
  // The approach's 5 + 10 periods are steps of the run, planned and done; the ledger of the
  // analysed periods still closes (the drive is continuous where the ramp ends).
  CHECK(plan.estimate.approach_steps == 15 * plan.estimate.steps_per_period);
  CHECK(from_above.dem.summary.steps == plan.estimate.total_steps);
  CHECK(from_above.dem.energy_balance_error < 0.01);
  // The step is bounded at the larger stroke's impact speed (at least 2X_aΩ).
  CHECK(plan.estimate.impact_speed_m_s >= 2.0 * 0.005 * 2.0 * M_PI * 3.6);
  const auto j = tasks::to_json(from_above);
  CHECK(j["approach"]["from_amplitude_m"] == 0.005);
  CHECK_FALSE(tasks::to_json(from_rest).contains("approach"));
  // An approach from below the stroke is refused naming its key.
  document["dem"]["approach"] = {{"amplitude_m", 0.001}};
  try {
    (void)tasks::plan_dem(case_file::load_case_document(document, "narrow_from_below.json"), options);
    FAIL("an approach from below the stroke was accepted");
  } catch (const base::InputError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("/dem/approach/amplitude_m"));
    CHECK_THAT(std::string(e.what()), Catch::Contains("> amplitude_m"));
  }
}
