// Checkpoints of the DEM in the loop (docs/cosimulation.md §6b): a free decay run in segments, its state
// and result written to bytes and read back into new worlds after every segment, equals the
// uninterrupted run; states and results of another shape are refused naming the field.
#include <catch2/catch.hpp>

#include <cmath>

#include "pdamp/structure/cosimulation.hpp"
#include "structure/cosimulation_support.hpp"

namespace {

using namespace pdamp::structure;
using pdamp::test::bed;
using pdamp::test::tip_damper;
namespace dem = pdamp::dem_reference;

ModalModel one_dof() {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 10.0);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.01);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, 0.1);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Constant(1, 0.0)}};
  return m;
}

/// Four spheres impacting in a box at the tip (the ledger test's bed).
std::vector<CosimulationDamper> impacting_bed() {
  return {tip_damper(bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                         dem::InitialPlacement::kCollectedLattice),
                     0.02)};
}

DecayRun decay(double duration_s) {
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, 0.01);
  o.duration_s = duration_s;
  o.sample_interval_s = 0.002;
  return o;
}

}  // namespace

// Reference: the uninterrupted 0.5 s decay. Segments of whole sample intervals, each
// continuing a state read back from bytes into new worlds (as a resumed process does),
// must give the same samples to the bit (times, modes, site, load), the same final particles
// and the same energy ledger (CosimulationState::energy_since_start continues the sums).
TEST_CASE("a free decay continued from a checkpoint after every segment equals the uninterrupted run",
          "[cosimulation]") {
  const ModalModel model = one_dof();
  const auto dampers = impacting_bed();
  const double duration = 0.5;
  CosimulationState whole_state;
  const CosimulationResult whole = cosimulate(model, dampers, decay(duration), whole_state);
  REQUIRE(whole.outcome == dem::Outcome::kCompleted);

  const double dt = cosimulation_time_step(model, dampers, decay(duration)).time_step_s;
  REQUIRE(dt == whole.time_step_s);
  const auto sample_every = static_cast<std::int64_t>(std::llround(0.002 / dt));
  const std::int64_t total = std::llround(duration / dt);
  const std::int64_t segment = 37 * sample_every;  // not a divisor of the run: a short last segment
  CosimulationResult sum;
  std::string bytes;
  for (std::int64_t done = 0; done < total;) {
    const std::int64_t steps = std::min(segment, total - done);
    DecayRun o = decay(static_cast<double>(steps) * dt);
    CosimulationState state;
    if (done > 0) {
      // A new process: the state and the result so far from the checkpoint's bytes.
      dem::StateReader in(bytes, "checkpoint");
      state = restore_cosimulation_state(model, dampers, in);
      sum = restore_cosimulation_result(in, 1, 1);
      in.finish();
      o.initial_modal_displacements.resize(0);
    }
    const CosimulationResult part = cosimulate(model, dampers, o, state);
    REQUIRE(part.outcome == dem::Outcome::kCompleted);
    REQUIRE(part.steps == steps);
    if (done == 0) {
      sum = part;
    } else {
      append_continuation(sum, part, state);
    }
    done += steps;
    dem::StateWriter out;
    save_cosimulation_state(state, out);
    save_cosimulation_result(sum, out);
    bytes = out.take();
    if (done == total) CHECK(state.worlds[0].state_hash() == whole_state.worlds[0].state_hash());
  }
  CHECK(sum.steps == whole.steps);
  REQUIRE(sum.history.time_s.size() == whole.history.time_s.size());
  CHECK(sum.history.time_s == whole.history.time_s);
  CHECK(sum.history.modal_displacements == whole.history.modal_displacements);
  CHECK(sum.history.site_displacement_m == whole.history.site_displacement_m);
  CHECK(sum.history.container_load_n == whole.history.container_load_n);
  CHECK(sum.final_modal_displacements == whole.final_modal_displacements);
  // The ledger since the first start: the same sums in the same order as the one run's.
  const auto& a = sum.energy;
  const auto& b = whole.energy;
  CHECK(b.dem_dissipated_j() > 0.1 * b.structural_damping_j);  // real impacts
  CHECK(a.structural_damping_j == b.structural_damping_j);
  CHECK(a.dem_dissipated_j() == b.dem_dissipated_j());
  CHECK(a.delta_structure_potential_j == b.delta_structure_potential_j);
  CHECK(a.delta_bed_kinetic_j == b.delta_bed_kinetic_j);
  CHECK(a.relative_error == b.relative_error);
  CHECK(whole_state.energy_since_start.relative_error == b.relative_error);
}

TEST_CASE("a co-simulation checkpoint of another shape is refused naming the field", "[cosimulation]") {
  const ModalModel model = one_dof();
  const auto dampers = impacting_bed();
  CosimulationState state;
  const CosimulationResult r = cosimulate(model, dampers, decay(0.02), state);
  dem::StateWriter out;
  save_cosimulation_state(state, out);
  save_cosimulation_result(r, out);
  const std::string bytes = out.take();

  SECTION("two dampers expected") {
    dem::StateReader in(bytes, "checkpoint");
    auto two = dampers;
    two.push_back(dampers.front());
    CHECK_THROWS_WITH(restore_cosimulation_state(model, two, in), Catch::Contains("worlds: 1 in the state for 2 damper(s)"));
  }
  SECTION("another bed") {
    dem::StateReader in(bytes, "checkpoint");
    auto other = impacting_bed();
    other[0].world.compartments[0].lattice_counts = {1, 1, 2};
    other[0].world.compartments[0].particles[0].count = 2;
    CHECK_THROWS_WITH(restore_cosimulation_state(model, other, in), Catch::Contains("particles: = 4 in the state, 2"));
  }
  SECTION("a result of two modes expected") {
    dem::StateReader in(bytes, "checkpoint");
    (void)restore_cosimulation_state(model, dampers, in);
    CHECK_THROWS_WITH(restore_cosimulation_result(in, 2, 1), Catch::Contains("frequencies_with_containers_hz"));
  }
  SECTION("truncated") {
    dem::StateReader in(std::string_view(bytes).substr(0, bytes.size() - 9), "checkpoint");
    (void)restore_cosimulation_state(model, dampers, in);
    CHECK_THROWS_WITH(restore_cosimulation_result(in, 1, 1), Catch::Contains("damaged or of another layout"));
  }
}
