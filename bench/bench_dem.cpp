// DEM benchmark: particle-steps per second of the reference DEM (1 and 2 threads) for
// 36, 1,000, 10,000 and 100,000 steel spheres in a vibrating box (the 100,000 also with
// the particles numbered in random order, as a bed that has been fluidised for a while
// leaves them), a whole harmonic run of the 36-sphere case, and the memory per
// particle; the 6 × 6 single layer of the shipped low-intensity box with the perfect
// lattice and with the ball-lot tolerance (the perfect lattice's lanes move as clones and
// keep zero-overlap contacts).
// Prints a table (the targets: bench/results/README.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using Clock = std::chrono::steady_clock;

/// The low-intensity case of docs/theory.md §8: 36 steel spheres (r = 5 mm) in one layer,
/// collected against −x in a 160 × 61 × 40 mm box driven along x at 2 Hz, X = 40 mm.
dr::DamperSimulationOptions low_intensity_case() {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.container.box_inner_size_m = {0.160, 0.061, 0.040};
  c.particles = {dr::ParticleGroupOptions{36, 0.005, 0.0, 0}};
  c.lattice_counts = {6, 6, 1};
  o.world.default_pair.restitution.constant = 0.8;
  o.world.default_pair.friction = 0.3;
  o.frequency_hz = 2.0;
  o.amplitude_m = 0.04;
  return o;
}

/// n ≈ count steel spheres of radius 1 mm in a collected cubic lattice (n_x × n_y × n_z)
/// with a clearance of 40% of the bed extent along the drive x; driven at 40 Hz, Γ = 3,
/// gravity −z. At this intensity the bed is fluidised: a demanding, realistic load.
dr::DamperSimulationOptions vibrated_box(int count) {
  dr::DamperSimulationOptions o = low_intensity_case();
  const double r = 0.001;
  int nyz = 1;
  while ((nyz + 1) * (nyz + 1) * (nyz + 1) <= count) ++nyz;
  const int nx = (count + nyz * nyz - 1) / (nyz * nyz);
  auto& c = o.world.compartments.front();
  c.particles = {dr::ParticleGroupOptions{count, r, 0.0, 0}};
  c.lattice_counts = {nx, nyz, nyz};
  c.container.box_inner_size_m = {1.4 * nx * 2.0 * r, nyz * 2.0 * r + 1e-4, (nyz + 2) * 2.0 * r};
  o.frequency_hz = 40.0;
  const double omega = 2.0 * 3.14159265358979 * o.frequency_hz;
  o.amplitude_m = 3.0 * 9.80665 / (omega * omega);
  return o;
}

/// The 6 × 6 single layer: r = 5 mm, ε = 0.7, μ = 0.15, μ_r = 0.005, steel, 2 Hz,
/// X = 0.3 h = 30 mm (below the jump) in the shipped 160 × 61 × 40 mm box; `perfect`:
/// identical spheres (lot_diameter_variation_m = 0), else the default G100 tolerance.
dr::DamperSimulationOptions layer_6x6_case(bool perfect) {
  dr::DamperSimulationOptions o = low_intensity_case();
  auto& c = o.world.compartments.front();
  if (perfect) c.particles.front().lot_diameter_variation_m = 0.0;
  o.world.default_pair.restitution.constant = 0.7;
  o.world.default_pair.friction = 0.15;
  o.world.default_pair.rolling_friction = 0.005;
  o.amplitude_m = 0.030;
  return o;
}

struct StepRate {
  double particle_steps_per_s = 0.0;
  double bytes_per_particle = 0.0;
  double step_s = 0.0;
  int particles = 0;
};

/// Deals the particles' states out again in a seeded random order: particle i takes
/// the position and velocity particle perm[i] had. The bed is the same; only the
/// numbering no longer follows the lattice (as after some periods of fluidisation,
/// which a benchmark cannot afford to simulate at 100,000 spheres).
void shuffle_numbering(dr::World& world) {
  const int n = world.particle_count();
  std::vector<dr::Vec3> position, velocity, spin;
  for (int i = 0; i < n; ++i) {
    position.push_back(world.position(i));
    velocity.push_back(world.velocity(i));
    spin.push_back(world.angular_velocity(i));
  }
  std::vector<int> perm(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) perm[static_cast<std::size_t>(i)] = i;
  std::mt19937_64 rng(7);
  for (int i = n - 1; i > 0; --i) {
    std::swap(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(rng() % static_cast<unsigned>(i + 1))]);
  }
  for (int i = 0; i < n; ++i) {
    const auto from = static_cast<std::size_t>(perm[static_cast<std::size_t>(i)]);
    world.set_particle_state(i, position[from], velocity[from], spin[from]);
  }
}

/// Steps a world under the harmonic drive: warm-up steps (bed in motion), then timed ones.
StepRate step_rate(const dr::DamperSimulationOptions& sim, int threads, double time_step_s, long warmup, long timed,
                   bool shuffled = false) {
  dr::WorldOptions o = sim.world;
  o.threads = threads;
  o.integration.time_step_s = time_step_s;
  const dr::HarmonicMotion motion(sim.drive_axis, sim.amplitude_m, sim.frequency_hz);
  dr::World world(o, dr::ContainerState{});
  if (shuffled) shuffle_numbering(world);
  for (long k = 0; k < warmup; ++k) world.step(motion);
  const auto start = Clock::now();
  for (long k = 0; k < timed; ++k) world.step(motion);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  StepRate r;
  r.particles = world.particle_count();
  r.particle_steps_per_s = static_cast<double>(timed) * r.particles / seconds;
  // All arrays the world holds (capacities: particles, neighbour lists, contact
  // histories, cells, thread buffers), after the timed steps.
  r.bytes_per_particle = static_cast<double>(world.memory_bytes()) / r.particles;
  r.step_s = world.time_step_s();
  if (world.status().outcome != dr::Outcome::kCompleted) {
    std::fprintf(stderr, "bench_dem: %s\n", world.status().message.c_str());
  }
  return r;
}

/// Largest step <= 1 µs the automatic bound allows for these options.
double step_at_most_1us(dr::WorldOptions o) {
  o.integration.time_step_s = 0.0;
  return std::min(1e-6, dr::time_step_bound(o).max_time_step_s);
}

}  // namespace

int main(int argc, char** argv) {
  // Optional arguments: a scale factor for the timed step counts (default 1), and a
  // particle count to run only the vibrated-box rows of that size (quick comparisons;
  // 36: only the 6 × 6 layer rows).
  const double scale = argc > 1 ? std::atof(argv[1]) : 1.0;
  const int only_count = argc > 2 ? std::atoi(argv[2]) : 0;
  std::printf("# bench_dem: reference DEM, steel spheres (E = 210 GPa), particle-steps per second\n");
  std::printf("%-34s %9s %8s %10s %14s %12s\n", "case", "particles", "threads", "dt_s", "Mparticle-steps/s",
              "bytes/particle");

  // 36 spheres at steel stiffness and a 1 µs step (40 steps per contact at 0.3 m/s
  // impacts, the drive's velocity amplitude 0.5 m/s being shared by the rolling bed).
  if (only_count == 0) {
    auto sim = low_intensity_case();
    sim.world.integration.steps_per_contact = 40;
    sim.world.integration.max_impact_speed_m_s = 0.3;
    const double dt = step_at_most_1us(sim.world);
    const long steps = static_cast<long>(2'000'000 * scale);
    for (const int threads : {1, 2}) {
      const auto r = step_rate(sim, threads, dt, 500'000, steps);
      std::printf("%-34s %9d %8d %10.3g %14.2f %12.0f\n", "low-intensity 2 Hz step", r.particles, threads, r.step_s,
                  r.particle_steps_per_s / 1e6, r.bytes_per_particle);
    }
  }
  // The same case as a whole run_harmonic (settling, 1 + 1 periods, recording on) at its
  // automatic step.
  if (only_count == 0) {
    auto sim = low_intensity_case();
    sim.transient_periods = 1;
    sim.analysed_periods = 1;
    const auto result = dr::run_harmonic(sim);
    std::printf("%-34s %9d %8d %10.3g %14.2f %12s\n", "low-intensity 2 Hz whole run", result.summary.particles, 1,
                result.time_step_s, result.particle_steps_per_s / 1e6, "-");
  }
  // The 6 × 6 layer, 1 thread, from the collected lattice: one period of warm-up (the
  // tolerant bed's lanes drift apart), one timed; at run_harmonic's automatic step and at 1 µs.
  if (only_count == 0 || only_count == 36) {
    for (const bool perfect : {true, false}) {
      auto sim = layer_6x6_case(perfect);
      const double auto_dt = dr::estimate_run(sim).time_step_s;
      for (const double dt : {auto_dt, 1e-6}) {
        // A World refuses a step above its own bound: the automatic step is its own
        // (automatic steps per contact); for exactly 1 µs it is told of 0.2 m/s impacts
        // at 40 steps per contact (run_harmonic accepts 1 µs with a warning: 28 steps per
        // contact at the drive's 1.52 m/s).
        sim.world.integration.steps_per_contact = dt == auto_dt ? 0 : 40;
        sim.world.integration.max_impact_speed_m_s = dt == auto_dt ? 1.0 : 0.2;
        const long period = static_cast<long>(1.0 / (sim.frequency_hz * dt));
        const auto r = step_rate(sim, 1, dt, period, static_cast<long>(scale * period));
        std::printf("%-34s %9d %8d %10.3g %14.2f %12.0f\n",
                    perfect ? "6x6 layer 2 Hz, perfect lattice" : "6x6 layer 2 Hz, G100 tolerance", r.particles, 1,
                    r.step_s, r.particle_steps_per_s / 1e6, r.bytes_per_particle);
      }
    }
  }
  for (const int count : {1000, 10000, 100000}) {
    if (only_count != 0 && count != only_count) continue;
    const auto sim = vibrated_box(count);
    const double dt = step_at_most_1us(sim.world);
    const long timed = static_cast<long>(scale * 2e8 / count) + 10;
    for (const bool shuffled : {false, true}) {
      if (shuffled && count < 100000) continue;
      for (const int threads : {1, 2}) {
        const auto r = step_rate(sim, threads, dt, 2000, timed, shuffled);
        std::printf("%-34s %9d %8d %10.3g %14.2f %12.0f\n",
                    shuffled ? "vibrated box, shuffled numbering" : "vibrated box 40 Hz, Gamma 3", r.particles, threads,
                    r.step_s, r.particle_steps_per_s / 1e6, r.bytes_per_particle);
      }
    }
  }
  return 0;
}
