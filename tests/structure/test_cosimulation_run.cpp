// Tests of the co-simulation as an object (structure::Cosimulation): a free decay advanced in
// uneven segments with a checkpoint between them, and a harmonic run advanced in segments,
// equal one cosimulate() call bit for bit; the stage times; refusals of what does not fit.
#include <catch2/catch.hpp>

#include <cmath>
#include <csignal>
#include <limits>
#include <stdexcept>

#include "pdamp/base/run_errors.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "structure/cosimulation_support.hpp"

namespace {

using namespace pdamp::structure;
using pdamp::test::bed;
using pdamp::test::tip_damper;
namespace dem = pdamp::dem_reference;

/// Two modes (10 and 27 Hz) that both move the tip along the drive y, so that the modal
/// products of the step are true matrix products.
ModalModel two_modes() {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::Vector2d(10.0, 27.0);
  m.damping_ratios = Eigen::Vector2d(0.01, 0.02);
  m.modal_masses_kg = Eigen::Vector2d(0.1, 0.05);
  Eigen::MatrixXd shape(2, 2);
  shape << 0.0, 0.0, 1.0, 0.6;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(2)}};
  return m;
}

/// One mode with base participation (the ledger test's forced case).
ModalModel one_mode_on_a_base() {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 10.0);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.01);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, 0.1);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(1)}};
  m.base_participation = Eigen::MatrixXd(1, 2);
  m.base_participation << 0.0, 0.08;
  return m;
}

/// Four spheres impacting in a box at the tip.
std::vector<CosimulationDamper> impacting_bed() {
  return {tip_damper(bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                         dem::InitialPlacement::kCollectedLattice),
                     0.02)};
}

DecayRun decay(double duration_s) {
  DecayRun o;
  o.initial_modal_displacements = Eigen::Vector2d(0.01, 0.003);
  o.duration_s = duration_s;
  o.sample_interval_s = 0.002;
  return o;
}

void check_same_energy(const CosimulationEnergy& a, const CosimulationEnergy& b) {
  CHECK(a.excitation_work_j == b.excitation_work_j);
  CHECK(a.structural_damping_j == b.structural_damping_j);
  CHECK(a.delta_structure_kinetic_j == b.delta_structure_kinetic_j);
  CHECK(a.delta_structure_potential_j == b.delta_structure_potential_j);
  CHECK(a.dem_normal_damping_j == b.dem_normal_damping_j);
  CHECK(a.dem_friction_j == b.dem_friction_j);
  CHECK(a.dem_rolling_j == b.dem_rolling_j);
  CHECK(a.delta_bed_kinetic_j == b.delta_bed_kinetic_j);
  CHECK(a.delta_bed_potential_j == b.delta_bed_potential_j);
  CHECK(a.delta_bed_elastic_j == b.delta_bed_elastic_j);
  CHECK(a.container_work_j == b.container_work_j);
  CHECK(a.relative_error == b.relative_error);
}

void check_same_history(const CosimulationHistory& a, const CosimulationHistory& b) {
  REQUIRE(a.time_s.size() == b.time_s.size());
  CHECK(a.time_s == b.time_s);
  CHECK(a.modal_displacements == b.modal_displacements);
  CHECK(a.site_displacement_m == b.site_displacement_m);
  CHECK(a.site_rotation_rad == b.site_rotation_rad);
  CHECK(a.container_load_n == b.container_load_n);
  CHECK(a.container_moment_nm == b.container_moment_nm);
}

}  // namespace

// Reference: one cosimulate() call of a 0.3 s decay with real impacts, on two modes. The run
// advanced in segments of 1, 777 and 4321 steps (none a whole number of sample intervals)
// and one ended by a stop request after 48,
// saved, the object destroyed, restored from the bytes into new worlds and advanced by 0, 3,
// 10007 steps and then beyond its end must give the same bits: history, final modes and
// particles, the energy ledger of the result and of the state, the counters. A segment
// shares every running sum with the next; the restore recomputes the opening acceleration
// with the closing kick's own products.
TEST_CASE("a free decay advanced in uneven segments with a checkpoint between them equals one cosimulate call",
          "[cosimulation]") {
  const ModalModel model = two_modes();
  const auto dampers = impacting_bed();
  DecayRun options = decay(0.6);
  options.snapshots = 40;  // the beds for ParaView, some before the checkpoint and some after
  CosimulationState whole_state;
  const CosimulationResult whole = cosimulate(model, dampers, options, whole_state);
  REQUIRE(whole.outcome == dem::Outcome::kCompleted);
  CHECK(whole.energy.dem_dissipated_j() > 0.1 * whole.energy.structural_damping_j);  // real impacts

  std::string bytes;
  std::int64_t done = 0;
  {
    // Stops at its third poll once armed (an interrupt).
    struct Stopper : pdamp::base::RunHooks {
      bool armed = false;
      int polls = 0;
      int stop_requested() override { return armed && ++polls == 3 ? SIGINT : 0; }
    } stopper;
    Cosimulation run(model, dampers, options, stopper);
    CHECK(run.time_step_s() == whole.time_step_s);
    CHECK(run.total_steps() == whole.steps);
    CHECK(run.steps_done() == 0);
    for (const std::int64_t steps : {1, 777, 4321}) {
      CHECK(run.advance(steps) == steps);
      done += steps;
    }
    // A stop request ends a long segment at the next poll, a step boundary like any other.
    stopper.armed = true;
    CHECK(run.advance(1000000) == 3 * Cosimulation::kStopPollSteps);
    CHECK(run.stop_signal() == SIGINT);
    done += 3 * Cosimulation::kStopPollSteps;
    CHECK(run.steps_done() == done);
    CHECK(!run.finished());
    CHECK(run.result().steps == done);
    CHECK(!run.result().bed_snapshots.empty());
    CHECK(run.result().bed_snapshots.size() < 40);
    dem::StateWriter out;
    run.save(out);
    bytes = out.take();
  }
  dem::StateReader in(bytes, "checkpoint");
  Cosimulation run = Cosimulation::restore(model, dampers, options, in);
  in.finish();
  CHECK(run.steps_done() == done);
  CHECK(run.total_steps() == whole.steps);
  CHECK(run.advance(0) == 0);
  CHECK(run.advance(-3) == 0);
  CHECK(run.advance(3) == 3);
  CHECK(run.advance(10007) == 10007);
  const std::int64_t left = run.total_steps() - run.steps_done();
  CHECK(run.advance(left + 100) == left);
  CHECK(run.finished());
  CHECK(run.advance(1) == 0);

  const CosimulationResult r = run.result();
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  CHECK(r.steps == whole.steps);
  CHECK(r.simulated_time_s == whole.simulated_time_s);
  CHECK(r.start_time_s == whole.start_time_s);
  CHECK(r.settling_steps == whole.settling_steps);
  CHECK(!r.continued);
  CHECK(r.warnings == whole.warnings);
  check_same_history(r.history, whole.history);
  CHECK(r.final_modal_displacements == whole.final_modal_displacements);
  CHECK(r.final_modal_velocities == whole.final_modal_velocities);
  check_same_energy(r.energy, whole.energy);
  // The snapshots: evenly spaced, the last at the end, those taken before the checkpoint
  // restored with it: the bits of the whole run's.
  REQUIRE(r.bed_snapshots.size() == 40);
  REQUIRE(whole.bed_snapshots.size() == 40);
  CHECK(whole.bed_snapshots.back().front().particles.time_s == whole.start_time_s + whole.simulated_time_s);
  for (std::size_t k = 0; k < 40; ++k) {
    const auto& a = r.bed_snapshots[k].front();
    const auto& b = whole.bed_snapshots[k].front();
    CHECK(a.particles.time_s == b.particles.time_s);
    CHECK(a.particles.positions_m == b.particles.positions_m);
    CHECK(a.particles.velocities_m_s == b.particles.velocities_m_s);
    CHECK(a.particles.radii_m == b.particles.radii_m);
    CHECK(a.container_position_m == b.container_position_m);
  }
  const CosimulationState& state = run.state();
  CHECK(state.worlds[0].state_hash() == whole_state.worlds[0].state_hash());
  CHECK(state.steps == whole_state.steps);
  CHECK(state.time_s == whole_state.time_s);
  check_same_energy(state.energy_since_start, whole_state.energy_since_start);

  // The stage times: a fresh run's settling and every stage took time; a restored run's are
  // its own process's (no settling).
  const auto& t = whole.stage_times;
  CHECK(t.settling_s > 0.0);
  for (const double s : {t.modal_kick_drift_s, t.bed_steps_s, t.closing_kick_s, t.ledger_s, t.measures_s})
    CHECK(s > 0.0);
  CHECK(r.stage_times.settling_s == 0.0);
  CHECK(r.stage_times.bed_steps_s > 0.0);
}

// Reference: one cosimulate() call of a base-driven run that settles early (its transient
// ends after fewer than the 100 periods allowed) with impacting spheres. Segments of 9973
// steps (not a period) give the same steady state and ledger to the bit, the planned end
// moves to the settled one, and the state continues as cosimulate's. A harmonic run has no
// checkpoint (its measures' sums are not in it).
TEST_CASE("a harmonic run advanced in segments equals one call, and its end moves once it has settled",
          "[cosimulation]") {
  const ModalModel model = one_mode_on_a_base();
  const auto dampers = impacting_bed();
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = 1e-3;
  o.excitation.frequency_hz = 9.0;
  o.transient_periods = 100;
  o.analysed_periods = 2;
  o.settle_until_stable = true;
  o.stable_tolerance = 0.05;
  CosimulationState whole_state;
  const CosimulationResult whole = cosimulate(model, dampers, o, whole_state);
  REQUIRE(whole.outcome == dem::Outcome::kCompleted);
  REQUIRE(whole.steady_state.stable);

  Cosimulation run(model, dampers, o);
  CHECK(run.total_steps() == 102 * whole.steps_per_period);
  while (!run.finished()) CHECK(run.advance(9973) > 0);
  CHECK(run.total_steps() == whole.steps);
  CHECK(run.total_steps() < 102 * whole.steps_per_period);
  const CosimulationResult r = run.result();
  CHECK(r.steps == whole.steps);
  CHECK(r.steady_state.transient_periods == whole.steady_state.transient_periods);
  CHECK(r.steady_state.analysed_periods == 2);
  CHECK(r.steady_state.period_site_amplitudes_m == whole.steady_state.period_site_amplitudes_m);
  CHECK(r.steady_state.site_amplitudes_m == whole.steady_state.site_amplitudes_m);
  CHECK(r.steady_state.bed_force_amplitudes_n == whole.steady_state.bed_force_amplitudes_n);
  CHECK(r.steady_state.modal_amplitudes == whole.steady_state.modal_amplitudes);
  check_same_history(r.history, whole.history);
  check_same_energy(r.energy, whole.energy);
  dem::StateWriter out;
  CHECK_THROWS_AS(run.save(out), std::logic_error);
  const CosimulationState state = std::move(run).take_state();
  CHECK(state.worlds[0].state_hash() == whole_state.worlds[0].state_hash());
  CHECK(state.excitation_phase_rad == whole_state.excitation_phase_rad);
  CHECK_THROWS_AS(run.advance(1), std::logic_error);
}

TEST_CASE("a restore refuses a checkpoint of other settings, and a continuation that does not fit keeps the state",
          "[cosimulation]") {
  const ModalModel model = two_modes();
  const auto dampers = impacting_bed();
  Cosimulation run(model, dampers, decay(0.01));
  run.advance(100);
  dem::StateWriter out;
  run.save(out);
  const std::string bytes = out.take();
  SECTION("another step") {
    DecayRun other = decay(0.01);
    other.time_step_s = 0.5 * run.time_step_s();
    dem::StateReader in(bytes, "checkpoint");
    CHECK_THROWS_WITH(Cosimulation::restore(model, dampers, other, in),
                      Catch::Contains("cosimulation checkpoint: time_step_s = ") &&
                          Catch::Contains("a checkpoint of other settings"));
  }
  SECTION("a continuation with initial values") {
    CosimulationState state = std::move(run).take_state();
    const auto hash = state.worlds[0].state_hash();
    CHECK_THROWS_WITH(Cosimulation(model, dampers, decay(0.01), std::move(state)),
                      Catch::Contains("must be empty when continuing"));
    REQUIRE(state.started());
    CHECK(state.worlds[0].state_hash() == hash);
  }
}

// Reference: the definition of the sampled bed force (CosimulationHistory::container_load_n):
// the mean over the steps since the previous sample. The same decay sampled at every step
// gives each step's force; a sample every k steps must be the mean of the k step values
// before it, to round-off. An impacting bed makes the difference to a value read at the
// sample alone large.
TEST_CASE("the sampled bed force is the mean over its sample interval, so impacts are not aliased", "[cosimulation]") {
  const ModalModel model = two_modes();
  const auto dampers = impacting_bed();
  DecayRun fine = decay(0.1);
  CosimulationState fine_state;
  const CosimulationResult first = cosimulate(model, dampers, fine, fine_state);
  fine.sample_interval_s = first.time_step_s;
  CosimulationState every_state;
  const CosimulationResult every = cosimulate(model, dampers, fine, every_state);
  DecayRun coarse = fine;
  const int k = 40;
  coarse.sample_interval_s = k * first.time_step_s;
  CosimulationState coarse_state;
  const CosimulationResult sampled = cosimulate(model, dampers, coarse, coarse_state);
  REQUIRE(every.history.time_s.size() > static_cast<std::size_t>(10 * k));
  double largest_difference = 0.0;  // between the mean and the value at the sample
  for (std::size_t s = 1; s < sampled.history.time_s.size(); ++s) {
    double mean = 0.0;
    for (std::size_t j = (s - 1) * k + 1; j <= s * k; ++j) mean += every.history.container_load_n(static_cast<Eigen::Index>(j), 0);
    mean /= k;
    const double at_sample = every.history.container_load_n(static_cast<Eigen::Index>(s * k), 0);
    CHECK(sampled.history.container_load_n(static_cast<Eigen::Index>(s), 0) == Approx(mean).margin(1e-9));
    largest_difference = std::max(largest_difference, std::abs(mean - at_sample));
  }
  CHECK(largest_difference > 1e-3);
}

// The beds settle before any checkpoint can hold them; a big bed settles for hours. The
// hooks hear from the settling about every progress_interval_s and are asked every
// kStopPollSteps steps whether to stop: a stop ends the construction there, keeping nothing
// (base::Interrupted); here at the poll after the second report.
TEST_CASE("the settling reports its progress, and a stop request ends it at once", "[cosimulation]") {
  DecayRun options = decay(0.3);
  options.progress_interval_s = 1e-9;  // every poll
  struct StopAfterTwoReports : pdamp::base::RunHooks {
    int settling_reports = 0;
    void progress(const pdamp::base::Progress& p) override {
      if (p.stage == "settling") ++settling_reports;
    }
    int stop_requested() override { return settling_reports >= 2 ? SIGTERM : 0; }
  } hooks;
  try {
    Cosimulation(two_modes(), impacting_bed(), options, hooks);
    FAIL("the settling did not stop");
  } catch (const pdamp::base::Interrupted& e) {
    CHECK(e.signal_number() == SIGTERM);
  }
  CHECK(hooks.settling_reports == 2);
}
