// Checkpoints of the DEM world (docs/dem.md "Checkpoints"): a world restored from a saved state continues
// bit for bit as the saved one (the reference is the uninterrupted run itself), states of
// other worlds and damaged states are refused with the world unchanged, and checkpoint files
// carry their header and refuse damage.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/base/input_error.hpp"

namespace {

namespace dr = pdamp::dem_reference;

/// A colliding, rotating, shaken bed: random placement, random velocities, rolling
/// resistance (the rolling-torque pool), a box shaken harmonically along x and y, so
/// that contacts start and end, lists are rebuilt and (a mixed bed) renumbered.
dr::WorldOptions shaken_gas(int threads, int particles, double radius_m, const dr::Vec3& box_m) {
  dr::WorldOptions o;
  auto& c = o.compartments.front();
  c.container.box_inner_size_m = box_m;
  c.particles = {dr::ParticleGroupOptions{particles, radius_m, 0.2, 0}};
  c.placement = dr::InitialPlacement::kRandom;
  o.default_pair.rolling_friction = 0.01;
  o.seed = 7;
  o.threads = threads;
  return o;
}

dr::World started(const dr::WorldOptions& o) {
  dr::World world(o);
  std::mt19937_64 rng(5);
  const auto u = [&]() { return static_cast<double>(rng() >> 11) * 0x1.0p-52 - 1.0; };
  for (int i = 0; i < world.particle_count(); ++i) world.set_particle_state(i, world.position(i), {u(), u(), u()}, {u(), 0.0, 0.0});
  return world;
}

/// The container: a stroke of 2 mm at 30 Hz along x and a turn about z (rotation path).
dr::ContainerState shaker(double t) {
  dr::ContainerState s;
  const double w = 2.0 * dem_test::kPi * 30.0;
  s.position_m = {0.002 * std::sin(w * t), 0.0, 0.0};
  s.velocity_m_s = {0.002 * w * std::cos(w * t), 0.0, 0.0};
  const double a = 0.05 * std::sin(w * t), rate = 0.05 * w * std::cos(w * t);
  s.orientation = {std::cos(a), -std::sin(a), 0.0, std::sin(a), std::cos(a), 0.0, 0.0, 0.0, 1.0};
  s.angular_velocity_rad_s = {0.0, 0.0, rate};
  return s;
}

void run(dr::World& world, int steps) {
  for (int k = 0; k < steps; ++k) world.step(shaker(world.time_s() + world.time_step_s()));
}

std::string saved(const dr::World& world) {
  dr::StateWriter out;
  world.save_state(out);
  return out.take();
}

void restore(dr::World& world, const std::string& bytes) {
  dr::StateReader in(bytes, "state");
  world.restore_state(in);
  in.finish();
}

/// Everything a caller can read of a world, for "bit for bit" comparisons.
void require_same(const dr::World& a, const dr::World& b) {
  CHECK(a.state_hash() == b.state_hash());
  CHECK(a.step_count() == b.step_count());
  CHECK(a.time_s() == b.time_s());
  CHECK(a.neighbour_rebuilds() == b.neighbour_rebuilds());
  CHECK(a.contact_count() == b.contact_count());
  const auto ea = a.energy(), eb = b.energy();
  CHECK(ea.container_work_j == eb.container_work_j);
  CHECK(ea.normal_damping_j == eb.normal_damping_j);
  CHECK(ea.friction_j == eb.friction_j);
  CHECK(ea.rolling_j == eb.rolling_j);
  CHECK(ea.elastic_j == eb.elastic_j);
  for (int k = 0; k < 3; ++k) {
    CHECK(a.load().force_n[k] == b.load().force_n[k]);
    CHECK(a.load().moment_nm[k] == b.load().moment_nm[k]);
  }
  CHECK(saved(a) == saved(b));
}

}  // namespace

// Reference: the uninterrupted run. A second world built from the same options, given the
// first one's state after 700 steps (250), must reach the same bits after 1500 more (500) (every
// particle, the contact histories, the energy account, the load), serial and with two
// threads (partitions and halo sums, > 1500 particles), and the saved state of the two
// must be identical bytes.
TEST_CASE("a restored world continues bit for bit as the saved one", "[dem_reference]") {
  for (const int threads : {1, 2}) {
    INFO("threads " << threads);
    const dr::WorldOptions o = threads == 1 ? shaken_gas(1, 80, 0.003, {0.04, 0.04, 0.04})
                                            : shaken_gas(2, 1600, 0.0015, {0.05, 0.05, 0.06});
    // Fewer steps for the large world: it stays a fast test under the sanitizers too.
    const int before = threads == 1 ? 700 : 250, after = threads == 1 ? 1500 : 500;
    dr::World reference = started(o);
    run(reference, before);
    const std::string saved_state = saved(reference);
    run(reference, after);
    CHECK(reference.energy().dissipated_j() > 0.0);
    CHECK(reference.neighbour_rebuilds() > 2);

    dr::World resumed(o);  // a fresh world: its own bed, lists and numbering until restored
    restore(resumed, saved_state);
    CHECK(resumed.step_count() == before);
    run(resumed, after);
    require_same(reference, resumed);
  }
}

// Reference: the world before the failed restore (its saved bytes).
TEST_CASE("a state of another world or a damaged state is refused and leaves the world unchanged", "[dem_reference]") {
  const dr::WorldOptions o = shaken_gas(1, 80, 0.003, {0.04, 0.04, 0.04});
  dr::World source = started(o);
  run(source, 300);
  const std::string good = saved(source);

  dr::World target = started(o);
  run(target, 10);
  const std::string before = saved(target);
  const auto refused = [&](const std::string& bytes, const std::string& words) {
    CHECK_THROWS_WITH(restore(target, bytes), Catch::Contains(words));
    CHECK(saved(target) == before);
  };

  SECTION("another particle count") {
    const dr::World other = started(shaken_gas(1, 81, 0.003, {0.04, 0.04, 0.04}));
    refused(saved(other), "particles: = 81 in the state, 80 in this world");
  }
  SECTION("another time step") {
    dr::WorldOptions softer = o;
    softer.materials.front().material.youngs_modulus_pa *= 0.01;
    const dr::World other(softer);
    refused(saved(other), "time_step_s");
  }
  SECTION("every truncation") {
    for (std::size_t length : {std::size_t{0}, std::size_t{5}, good.size() / 3, good.size() / 2, good.size() - 1})
      refused(good.substr(0, length), "state");
  }
  SECTION("bytes after the world's own are its caller's to refuse") {
    const std::string longer = good + "x";  // the reader views the bytes: they must outlive it
    dr::StateReader in(longer, "state");
    target.restore_state(in);
    CHECK_THROWS_WITH(in.finish(), Catch::Contains("1 bytes are left over"));
  }
  SECTION("a numbering that is no permutation") {
    // The order array follows the "particles" tag: its count (8 bytes), then 80 ints.
    std::string bad = good;
    const auto at = bad.find("particles") + std::string("particles").size() + 8;
    bad[at] = bad[at + 4];
    bad[at + 1] = bad[at + 5];
    bad[at + 2] = bad[at + 6];
    bad[at + 3] = bad[at + 7];
    refused(bad, "order");
  }
  SECTION("a hostile count") {
    std::string bad = good;
    const auto at = bad.find("particles") + std::string("particles").size();
    for (int b = 0; b < 8; ++b) bad[at + static_cast<std::size_t>(b)] = static_cast<char>(0x7f);
    refused(bad, "order");
  }
  SECTION("a non-finite position") {
    std::string bad = good;
    // x[0]: after the order (8 + 4·80 bytes) and its own count (8 bytes).
    const auto at = bad.find("particles") + std::string("particles").size() + 8 + 4 * 80 + 8;
    const double nan = std::nan("");
    std::memcpy(&bad[at], &nan, sizeof nan);
    refused(bad, "particles: is not finite");
  }
}

TEST_CASE("a checkpoint file carries its header and refuses damage", "[dem_reference]") {
  dr::CheckpointHeader h;
  h.kind = "decay_dem";
  h.case_hash = "abc123";
  h.physics_model_version = dr::kPhysicsModelVersion;
  h.settings = "duration_s=2";
  h.simulated_time_s = 0.5;
  h.end_time_s = 2.0;
  const std::string payload("\x00\x01\x02 state bytes \xff", 18);
  const std::string file = dr::encode_checkpoint(h, payload);
  const auto decoded = dr::decode_checkpoint(file, "run.checkpoint");
  CHECK(decoded.payload == payload);
  CHECK(decoded.header.kind == "decay_dem");
  CHECK(decoded.header.case_hash == "abc123");
  CHECK(decoded.header.settings == "duration_s=2");
  CHECK(decoded.header.simulated_time_s == 0.5);

  using pdamp::base::InputError;
  CHECK_THROWS_WITH(dr::decode_checkpoint("{}", "f"), Catch::Contains("f: not a pdamp checkpoint"));
  CHECK_THROWS_WITH(dr::decode_checkpoint(file.substr(0, file.size() - 1), "f"),
                    Catch::Contains("f: /payload_bytes") && Catch::Contains("truncated"));
  std::string flipped = file;
  flipped.back() = 'x';
  CHECK_THROWS_WITH(dr::decode_checkpoint(flipped, "f"), Catch::Contains("/payload_fnv1a64") && Catch::Contains("damaged"));
  std::string extra_key = file;
  extra_key.insert(extra_key.find("\"kind\""), "\"spare\":1,");
  CHECK_THROWS_AS(dr::decode_checkpoint(extra_key, "f"), InputError);
  CHECK_THROWS_WITH(dr::decode_checkpoint("PDAMP-CHECKPOINT 1\n{\"kind\":", "f"), Catch::Contains("f: "));
}

// Reference: the uninterrupted harmonic run of the same options. Stopped at a checkpoint in
// its transient and again in its analysis, each time resumed from the bytes written (as a
// new process would), the run's measures, series, snapshots and counters are the same bits.
TEST_CASE("a harmonic run stopped at checkpoints and resumed equals the uninterrupted run", "[dem_reference]") {
  dr::DamperSimulationOptions o = dem_test::shipped_layer(0.5, 0.8, 0.3, 0.0, 1000.0);
  o.transient_periods = 2;
  o.analysed_periods = 3;
  o.samples_per_period = 64;
  o.snapshots = 4;
  const dr::DamperResult whole = dr::run_harmonic(o);
  REQUIRE(whole.summary.outcome == dr::Outcome::kCompleted);

  // The test's hooks and sink: checkpoint_due() and stop_requested() say what the test sets.
  struct Hooks : pdamp::base::RunHooks {
    std::function<bool()> due;
    std::function<bool()> stop;
    bool checkpoint_due(double seconds_since_checkpoint) override {
      CHECK(seconds_since_checkpoint >= 0.0);
      return due();
    }
    int stop_requested() override { return stop() ? 15 : 0; }
  } hooks;
  struct Sink : dr::CheckpointSink {
    std::string state;
    double written_at = 0.0;
    int checkpoints = 0;
    void store(const std::string& bytes, double t) override {
      state = bytes;
      written_at = t;
      ++checkpoints;
    }
  } sink;
  dr::CheckpointStorage storage;
  storage.sink = &sink;
  const std::string& state = sink.state;
  const double& written_at = sink.written_at;
  const int& checkpoints = sink.checkpoints;
  hooks.due = [] { return true; };  // every period end
  // stop_requested() is a state (a signal arrived), polled every kStopPollSteps steps, at
  // period ends and after each write. The first run stops at its first checkpoint (the
  // transient's first period end). The second, with no periodic checkpoint due, is asked to
  // stop at its poll that falls 2.5 periods on (a period is 64 blocks, a multiple of
  // kStopPollSteps steps: its ends are polls): it writes its state there, mid-period in the
  // analysis (the drive bins and a block in progress). The third runs to the end (one
  // checkpoint at the period end after 3.5 periods, none at the run's end).
  hooks.stop = [&] { return checkpoints == 1; };
  const dr::DamperResult first = dr::run_harmonic(o, hooks, storage);
  CHECK(first.stopped);
  CHECK(written_at == Approx(1.0 / o.frequency_hz).epsilon(1e-9));
  storage.resume_state = state;
  hooks.due = [] { return false; };
  const std::int64_t period = whole.steps_per_period;
  REQUIRE(period % dr::kStopPollSteps == 0);
  const std::int64_t stop_poll = (5 * period / 2) / dr::kStopPollSteps;
  std::int64_t polls = 0;
  hooks.stop = [&] { return ++polls == stop_poll; };
  const dr::DamperResult second = dr::run_harmonic(o, hooks, storage);
  CHECK(second.stopped);
  CHECK(checkpoints == 2);
  const double periods_at_stop = written_at * o.frequency_hz;
  CHECK(periods_at_stop > 3.0);  // in the analysis
  CHECK(periods_at_stop < 4.0);
  CHECK(std::abs(periods_at_stop - std::round(periods_at_stop)) > 1e-3);  // not at a period end
  storage.resume_state = state;
  hooks.due = [] { return true; };
  hooks.stop = [] { return false; };
  const dr::DamperResult last = dr::run_harmonic(o, hooks, storage);
  REQUIRE_FALSE(last.stopped);
  REQUIRE(last.summary.outcome == dr::Outcome::kCompleted);
  CHECK(last.eta_star == whole.eta_star);
  CHECK(last.eta_star_stderr == whole.eta_star_stderr);
  CHECK(last.e_diss_j == whole.e_diss_j);
  CHECK(last.apparent_mass_kg == whole.apparent_mass_kg);
  CHECK(last.energy_balance_error == whole.energy_balance_error);
  CHECK(last.motion_mode == whole.motion_mode);
  CHECK(last.eta_star_per_period == whole.eta_star_per_period);
  CHECK(last.series.force_n == whole.series.force_n);
  CHECK(last.series.bed_relative_position_m == whole.series.bed_relative_position_m);
  CHECK(last.summary.steps == whole.summary.steps);
  REQUIRE(last.snapshots.size() == whole.snapshots.size());
  CHECK(last.snapshots.back().positions_m == whole.snapshots.back().positions_m);
  CHECK(checkpoints == 3);

  // Asked to stop while the bed settles: the run ends at once, without a checkpoint.
  storage.resume_state.clear();
  hooks.stop = [] { return true; };
  const dr::DamperResult settling = dr::run_harmonic(o, hooks, storage);
  CHECK(settling.stopped);
  CHECK(checkpoints == 3);
  CHECK(settling.summary.steps == dr::kStopPollSteps);  // at the first poll
  CHECK_THAT(settling.summary.message, Catch::Contains("no checkpoint"));

  // Without a sink a stop still ends the run, and nothing is stored.
  polls = 0;
  hooks.stop = [&] { return ++polls == stop_poll; };
  const dr::DamperResult unsaved = dr::run_harmonic(o, hooks, dr::CheckpointStorage{});
  CHECK(unsaved.stopped);
  CHECK(checkpoints == 3);

  // A state of other options is refused naming the field.
  dr::DamperSimulationOptions other = o;
  other.analysed_periods = 1;
  storage.resume_state = state;
  CHECK_THROWS_WITH(dr::run_harmonic(other, hooks, storage), Catch::Contains("step"));
}
