// Co-simulation benchmark (docs/cosimulation.md): particle-steps per second of the DEM bed in the
// loop (structure::cosimulate, one mode, base excitation) against the bare DEM stepping the
// same bed through the coupled run's own container motion (replayed step by step), one
// thread, best of N. Also the bare DEM under a harmonic drive (another motion, other
// contacts). Prints a table; the target is a ratio of at least 0.9.
// Beds: `single` (the shipped low-intensity layer, 36 spheres) or `layered` (the shipped
// three-layer link damper's chosen design: 96 spheres of 2.5 mm in three compartments of
// one world, as the optimiser's DEM verification steps them).
// Usage: bench_cosimulation [periods = 1] [repeats = 3] [single|layered]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <Eigen/Dense>

#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/structure/cosimulation.hpp"

namespace {

namespace dr = pdamp::dem_reference;
namespace st = pdamp::structure;
using Clock = std::chrono::steady_clock;

constexpr double kFrequency = 2.0;    // Hz: drive and natural frequency (low intensity)

/// The shipped low-intensity bed: 36 steel spheres (r = 5 mm), 6 × 6 × 1 in a
/// 160 × 61 × 40 mm box, gravity across the drive x, ε = 0.8, μ = 0.3, one thread.
dr::WorldOptions single_bed() {
  dr::WorldOptions o;
  auto& c = o.compartments.front();
  c.container.box_inner_size_m = {0.160, 0.061, 0.040};
  c.particles = {dr::ParticleGroupOptions{36, 0.005, 0.0, 0}};
  c.lattice_counts = {6, 6, 1};
  o.default_pair.restitution.constant = 0.8;
  o.default_pair.friction = 0.3;
  o.integration.steps_per_contact = 40;
  o.integration.max_impact_speed_m_s = 0.3;
  o.threads = 1;
  return o;
}

/// The shipped link damper's chosen design (cases/manipulator_link_optimize.json): steel
/// spheres of 2.5 mm, 1, 3 and 2 slabs of 16 in boxes 70, 40 and 28 mm long (41 × 12 mm
/// across), stacked 15 mm apart across gravity, driven along x; default contact law.
dr::WorldOptions layered_bed() {
  dr::WorldOptions o;
  o.compartments.clear();
  const double lengths[3] = {0.070, 0.040, 0.028};
  const int slabs[3] = {1, 3, 2};
  for (int k = 0; k < 3; ++k) {
    dr::CompartmentOptions c;
    c.container.box_inner_size_m = {lengths[k], 0.041, 0.012};
    c.offset_m = {0.0, 0.0, 0.015 * (k - 1)};
    c.particles = {dr::ParticleGroupOptions{16 * slabs[k], 0.0025, 0.0, 0}};
    o.compartments.push_back(c);
  }
  o.integration.steps_per_contact = 40;
  o.integration.max_impact_speed_m_s = 0.3;
  o.threads = 1;
  return o;
}

/// One mode at kFrequency, modal mass 1 kg, the site moving 1 m per unit q along y.
st::ModalModel one_mode() {
  st::ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, kFrequency);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.01);
  m.modal_masses_kg = Eigen::VectorXd::Ones(1);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(1)}};
  m.base_participation = Eigen::MatrixXd(1, 2);
  m.base_participation << 0.0, 1.0;
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const int periods = argc > 1 ? std::atoi(argv[1]) : 1;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const bool layered = argc > 3 && std::string(argv[3]) == "layered";
  const auto bed = [layered]() { return layered ? layered_bed() : single_bed(); };
  // The automatic bound of the bed (40 steps per contact at 0.3 m/s, as bench_dem), so
  // both runs take the same step.
  const double kStep = dr::time_step_bound(bed()).max_time_step_s;
  const long steps = static_cast<long>(periods / (kFrequency * kStep));
  st::CosimulationDamper damper;
  damper.name = "tip";
  damper.point = "tip";
  damper.drive_direction = {0.0, 1.0};
  damper.container_mass_kg = 0.3;
  damper.world = bed();
  damper.world.integration.time_step_s = kStep;
  damper.rotation = false;
  st::SteadyStateRun options;
  options.excitation.kind = st::CosimulationExcitationKind::kBaseTranslation;
  options.excitation.direction = {0.0, 1.0};
  options.excitation.amplitude = 0.00133;
  options.excitation.frequency_hz = kFrequency;
  options.transient_periods = 0;
  options.analysed_periods = periods;
  options.bed_settling_time_s = 0.0;
  options.time_step_s = kStep;
  options.progress_interval_s = 1e9;

  // The coupled run's container trajectory, every step (an untimed run: the timed ones keep
  // the default sampling). The runs are deterministic, so each timed run moves the bed the same.
  st::SteadyStateRun traced = options;
  traced.sample_interval_s = kStep;
  const auto trace = st::cosimulate(one_mode(), {damper}, traced);
  if (trace.outcome != dr::Outcome::kCompleted) {
    std::fprintf(stderr, "bench_cosimulation: %s\n", trace.message.c_str());
    return 3;
  }
  const Eigen::VectorXd y = trace.history.site_displacement_m.col(0);
  const double site_amplitude = std::abs(trace.steady_state.site_amplitudes_m.front());

  // Best of `repeats` for each run (the machine's other load only ever slows a run down).
  double coupled_s = 1e300, replay_s = 1e300, harmonic_s = 1e300, energy_error = 0.0;
  long coupled_steps = 0;
  int particles = 0;
  for (int k = 0; k < repeats; ++k) {
    const auto result = st::cosimulate(one_mode(), {damper}, options);
    coupled_s = std::min(coupled_s, result.wall_time_s);
    coupled_steps = result.steps;
    energy_error = result.energy.relative_error;

    // The bare DEM replaying the coupled run's own site motion through the same World::step
    // (position along the drive axis x, velocity the step's difference, as the loop passes
    // them): the same contacts, so the ratio is the coupling's own cost.
    dr::WorldOptions bare = bed();
    bare.integration.time_step_s = kStep;
    dr::ContainerState state;
    state.position_m[0] = y[0];
    dr::World replay(bare, state);
    auto start = Clock::now();
    for (Eigen::Index i = 1; i < y.size(); ++i) {
      state.velocity_m_s[0] = (y[i] - y[i - 1]) / kStep;
      state.position_m[0] = y[i];
      replay.step(state);
    }
    replay_s = std::min(replay_s, std::chrono::duration<double>(Clock::now() - start).count());
    particles = replay.particle_count();

    // The bare DEM under a prescribed harmonic drive at the site's steady amplitude (a
    // different motion: for reference).
    const dr::HarmonicMotion motion(dr::Vec3{1.0, 0.0, 0.0}, site_amplitude, kFrequency);
    dr::World world(bare, dr::ContainerState{});
    start = Clock::now();
    for (long i = 0; i < steps; ++i) world.step(motion);
    harmonic_s = std::min(harmonic_s, std::chrono::duration<double>(Clock::now() - start).count());
  }
  const double n = particles;
  const double coupled_rate = static_cast<double>(coupled_steps) * n / coupled_s;
  const double replay_rate = static_cast<double>(y.size() - 1) * n / replay_s;
  const double harmonic_rate = static_cast<double>(steps) * n / harmonic_s;
  std::printf("# bench_cosimulation: %d spheres, step %.3g s, %ld steps (%d period(s) at %.3g Hz), 1 thread, best of %d\n",
              particles, kStep, coupled_steps, periods, kFrequency, repeats);
  std::printf("%-44s %16s\n", "run", "Mparticle-steps/s");
  std::printf("%-44s %16.2f\n", "bare DEM, the coupled run's motion replayed", replay_rate / 1e6);
  std::printf("%-44s %16.2f\n", "bare DEM, harmonic drive (another motion)", harmonic_rate / 1e6);
  std::printf("%-44s %16.2f\n", layered ? "DEM in the loop (1 mode, three layers)" : "DEM in the loop (1 mode)",
              coupled_rate / 1e6);
  std::printf("%-44s %16.3f\n", "ratio to the replay (target >= 0.9)", coupled_rate / replay_rate);
  std::printf("site amplitude %.4g m, energy error %.2e\n", site_amplitude, energy_error);
  return 0;
}
