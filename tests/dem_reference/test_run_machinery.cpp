// The run machinery (docs/dem.md "Run machinery") driven from outside run_harmonic: the time-step rule,
// settling, the block recorder, the drive-bin measure, the energy ledger and the motion
// accumulator, fed step by step by a harmonic and by a two-tone driver of the test's own.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/drive_time_step.hpp"
#include "pdamp/dem_reference/motion_modes.hpp"
#include "pdamp/dem_reference/run_measures.hpp"
#include "pdamp/dem_reference/run_recorder.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using dem_test::kPi;

double along_x(const dr::Vec3& v) { return v[0]; }

/// A small damper: 8 steel spheres r = 5 mm (4 × 2 × 1 lattice) collected against −x in
/// the shipped 160 × 61 × 40 mm box, E/100, ε = 0.8, μ = 0.3, gravity −z, 2 Hz along x at
/// X = 0.45·h_roll; 1 transient and 2 analysed periods of 32 blocks.
dr::DamperSimulationOptions small_damper() {
  auto o = dem_test::shipped_layer(0.45, 0.8, 0.3, 0.0, 100.0);
  auto& c = o.world.compartments.front();
  c.particles.front().count = 8;
  c.lattice_counts = {4, 2, 1};
  o.transient_periods = 1;
  o.analysed_periods = 2;
  o.samples_per_period = 32;
  return o;
}

/// The harmonic drive's timing as run_harmonic derives it (V = X·2πf in its order).
dr::DriveTiming harmonic_timing(const dr::DamperSimulationOptions& o) {
  dr::DriveTiming t;
  t.period_s = 1.0 / o.frequency_hz;
  t.blocks_per_period = o.samples_per_period;
  t.impact_speed_m_s = dr::drive_impact_speed(o.world, o.amplitude_m * 2.0 * kPi * o.frequency_hz);
  return t;
}

/// x_c(t) = X₁ sin Ωt + X₃ sin(3Ωt + φ) along x: a prescribed drive with two tones, no
/// harmonic of which run_harmonic knows.
struct TwoTone {
  double x1_m, x3_m, omega_rad_s, phase_rad;
  dr::ContainerState state(double t) const {
    dr::ContainerState s;
    s.position_m = {x1_m * std::sin(omega_rad_s * t) + x3_m * std::sin(3.0 * omega_rad_s * t + phase_rad), 0.0, 0.0};
    s.velocity_m_s = {x1_m * omega_rad_s * std::cos(omega_rad_s * t) +
                          3.0 * x3_m * omega_rad_s * std::cos(3.0 * omega_rad_s * t + phase_rad),
                      0.0, 0.0};
    return s;
  }
  double peak_speed_m_s() const { return (x1_m + 3.0 * x3_m) * omega_rad_s; }
};

}  // namespace

// Reference: run_harmonic itself. The parts fed with the same harmonic states in the same
// order perform the same IEEE operations, so the measures agree to the last bit; the
// tolerance (1e-12 relative) leaves room only for round-off, not for any difference of
// method (a step more or less would change η* in the third digit).
TEST_CASE("the run machinery fed the harmonic drive step by step reproduces run_harmonic", "[dem_reference]") {
  const auto o = small_damper();
  const dr::DamperResult reference = dr::run_harmonic(o);
  REQUIRE(reference.summary.outcome == dr::Outcome::kCompleted);

  const dr::DriveTimeStep plan = dr::drive_time_step(o.world, harmonic_timing(o));
  const double dt = plan.time_step_s;
  CHECK(dt == reference.time_step_s);
  const dr::HarmonicMotion motion(o.drive_axis, o.amplitude_m, o.frequency_hz);
  const dr::ContainerState start = motion.state(0.0);
  dr::ContainerState rest = start;
  rest.velocity_m_s = {0.0, 0.0, 0.0};
  dr::World world(plan.world, rest);
  const auto settle_steps =
      static_cast<std::int64_t>(std::ceil(dr::automatic_settling_time_s(plan.world) / dt));
  REQUIRE(dr::settle(world, start, settle_steps));
  // The settled bed's contacts per sphere (the ParaView snapshots' `contacts`): every sphere
  // rests on something; a pair contact counts for both spheres, the rest are wall contacts,
  // at least one for each sphere touching a wall.
  const std::vector<int> contacts = world.contacts_per_particle();
  REQUIRE(contacts.size() == static_cast<std::size_t>(world.particle_count()));
  int total = 0;
  for (const int c : contacts) {
    CHECK(c >= 1);
    total += c;
  }
  CHECK(total - 2 * world.contact_count() >= world.contact_census({0.0, 0.0, -1.0}).touching_walls);
  dr::MotionModeAccumulator modes(world, plan.world, motion.axis());
  const std::int64_t transient = plan.steps_per_period * o.transient_periods;
  for (std::int64_t k = 1; k <= transient; ++k) world.step(motion.state(static_cast<double>(k) * dt));

  dr::BlockRecorderOptions recording;
  recording.drive_axis = motion.axis();
  recording.time_step_s = dt;
  recording.steps_per_block = plan.steps_per_block;
  recording.blocks_per_period = o.samples_per_period;
  recording.periods = o.analysed_periods;
  recording.start_step = transient;
  recording.prescribed_motion = &motion;
  dr::BlockRecorder recorder(recording);
  dr::DriveBinMeasure drive_bin(plan.steps_per_period, o.frequency_hz, world.bed_mass_kg());
  const dr::EnergyLedger ledger(world.energy());
  const std::int64_t last = transient + plan.steps_per_period * o.analysed_periods;
  for (std::int64_t k = transient + 1; k <= last; ++k) {
    const dr::ContainerState state = motion.state(static_cast<double>(k) * dt);
    const dr::ContainerLoad& load = world.step(state);
    drive_bin.add(k, along_x(load.force_n), along_x(state.velocity_m_s));
    if (recorder.record_step(world)) modes.sample_block(world);
  }
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);
  CHECK(world.step_count() == reference.summary.steps);

  const dr::DriveBinMeasures measures = drive_bin.result();
  const dr::EnergyBalance balance = ledger.balance(world.energy());
  INFO("eta* " << measures.eta_star << " vs " << reference.eta_star << ", m_app " << measures.apparent_mass_kg
               << " vs " << reference.apparent_mass_kg << ", balance error " << balance.relative_error << " vs "
               << reference.energy_balance_error);
  CHECK(measures.eta_star == Approx(reference.eta_star).epsilon(1e-12));
  CHECK(measures.apparent_mass_kg == Approx(reference.apparent_mass_kg).epsilon(1e-12));
  CHECK(balance.relative_error == Approx(reference.energy_balance_error).epsilon(1e-12));
  CHECK(measures.eta_star_per_period.size() == reference.eta_star_per_period.size());
  CHECK(recorder.series().force_n.size() == reference.series.force_n.size());
  CHECK(recorder.series().force_n.back() == Approx(reference.series.force_n.back()).epsilon(1e-12));
  dr::MotionReference drive;
  drive.angular_frequency_rad_s = motion.angular_frequency_rad_s();
  drive.velocity_amplitude_m_s = motion.velocity_amplitude_m_s();
  drive.intensity = motion.intensity();
  const dr::MotionIndicators indicators = modes.indicators(recorder, measures, drive);
  CHECK(indicators.phase_locked_stroke == Approx(reference.indicators.phase_locked_stroke).epsilon(1e-12));
  CHECK(dr::classify_motion(indicators, measures.eta_star, drive.intensity) == reference.motion_mode);
}

// Reference: conservation of energy under a drive run_harmonic cannot make. The ledger
// closes when the contact work is integrated finely: at 200 steps per contact the error
// of the stored-energy bookkeeping per impact is (dt/t_c)^{5/2} ~ 1e-6 of its energy
// (docs/dem.md, verification table), so 1e-3 leaves a wide margin. Independent of it, the
// container work over whole periods is the sum of the two tones' complex powers (the
// velocity has no other component): n·(E_cycle(Ω) + 3·E_cycle(3Ω)). That is a different
// quadrature of the same work (the bin holds F_k over its step, the work takes the
// trapezoid over Δx), differing at O((dt/t_c)²) per impact: 1e-3 relative.
TEST_CASE("the energy ledger closes and the drive bins account for the work of a two-tone drive",
          "[dem_reference]") {
  auto o = small_damper();
  o.world.integration.steps_per_contact = 200;
  const TwoTone drive{0.030, 0.004, 2.0 * kPi * o.frequency_hz, 0.7};
  dr::DriveTiming timing;
  timing.period_s = 1.0 / o.frequency_hz;
  timing.blocks_per_period = 3 * 16;  // whole steps per period of 3Ω too
  timing.impact_speed_m_s = dr::drive_impact_speed(o.world, drive.peak_speed_m_s());
  const dr::DriveTimeStep plan = dr::drive_time_step(o.world, timing);
  const double dt = plan.time_step_s;
  REQUIRE(plan.steps_per_period % 3 == 0);

  const dr::ContainerState start = drive.state(0.0);
  dr::ContainerState rest = start;
  rest.velocity_m_s = {0.0, 0.0, 0.0};
  dr::World world(plan.world, rest);
  const auto settle_steps = static_cast<std::int64_t>(std::ceil(dr::automatic_settling_time_s(plan.world) / dt));
  REQUIRE(dr::settle(world, start, settle_steps));
  for (std::int64_t k = 1; k <= plan.steps_per_period; ++k) world.step(drive.state(static_cast<double>(k) * dt));

  const int periods = 2;
  dr::BlockRecorderOptions recording;
  recording.time_step_s = dt;
  recording.steps_per_block = plan.steps_per_block;
  recording.blocks_per_period = timing.blocks_per_period;
  recording.periods = periods;
  recording.start_step = plan.steps_per_period;
  dr::BlockRecorder recorder(recording);  // no prescribed motion: block means of the positions
  const double m_bed = world.bed_mass_kg();
  dr::DriveBinMeasure fundamental(plan.steps_per_period, o.frequency_hz, m_bed);
  dr::DriveBinMeasure third(plan.steps_per_period / 3, 3.0 * o.frequency_hz, m_bed);
  const dr::EnergyLedger ledger(world.energy());
  for (std::int64_t k = plan.steps_per_period + 1; k <= (periods + 1) * plan.steps_per_period; ++k) {
    const dr::ContainerState state = drive.state(static_cast<double>(k) * dt);
    const dr::ContainerLoad& load = world.step(state);
    fundamental.add(k, along_x(load.force_n), along_x(state.velocity_m_s));
    third.add(k, along_x(load.force_n), along_x(state.velocity_m_s));
    recorder.record_step(world);
  }
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);
  const dr::EnergyBalance balance = ledger.balance(world.energy());
  const double bins_work = periods * (fundamental.result().energy_per_cycle_j + 3.0 * third.result().energy_per_cycle_j);
  INFO("work " << balance.container_work_j << " J, dissipated " << balance.dissipated_j() << " J, delta E "
               << balance.delta_energy_j() << " J, error " << balance.relative_error << "; bins " << bins_work << " J");
  CHECK(balance.dissipated_j() > 0.1 * balance.container_work_j);  // the bed does dissipate: a real test
  CHECK(balance.relative_error < 1e-3);
  CHECK(bins_work == Approx(balance.container_work_j).epsilon(1e-3));
  CHECK(third.completed_periods() == 3 * periods);
  // Without a prescribed motion the recorder keeps the block mean of the positions. The
  // mean of sin over a window w about t is sin(t)·sinc(Ωw/2): each tone's stroke X_j is
  // off the mid-time value by at most X_j(Ω_j w)²/24 (w = T/48: 2.1e-5 m and 2.6e-5 m).
  const double w = timing.period_s / timing.blocks_per_period;
  const double bound = (drive.x1_m * std::pow(drive.omega_rad_s * w, 2) +
                        drive.x3_m * std::pow(3.0 * drive.omega_rad_s * w, 2)) / 24.0;
  const auto& series = recorder.series();
  REQUIRE(series.container_position_m.size() == static_cast<std::size_t>(periods * timing.blocks_per_period));
  for (std::size_t b = 0; b < series.time_s.size(); ++b) {
    CHECK(std::abs(series.container_position_m[b] - drive.state(series.time_s[b]).position_m[0]) <= bound);
  }
}

// Reference: the rule of docs/dem.md "Integration and time step". Whole steps per period:
// dt·M equals the period to round-off (1e-12) and the step is the target shortened by
// less than one step per block. A user step 1.5 times the automatic bound at 50 steps per
// contact (given; below the stability limit min(T_R, t_c/20), since the bound is t_c/50 or
// T_R/4) is accepted with a
// warning stating its steps per contact, and the world built from the returned options
// accepts it; a step above the limit and a timing out of range are refused by name.
TEST_CASE("the time-step rule of a drive gives whole steps per period and warns or refuses user steps",
          "[dem_reference]") {
  auto o = small_damper();
  o.world.integration.steps_per_contact = 50;
  const dr::DriveTiming timing = harmonic_timing(o);
  const dr::DriveTimeStep automatic = dr::drive_time_step(o.world, timing);
  CHECK(automatic.steps_per_period == automatic.steps_per_block * timing.blocks_per_period);
  CHECK(automatic.time_step_s * static_cast<double>(automatic.steps_per_period) ==
        Approx(timing.period_s).epsilon(1e-12));
  CHECK(automatic.time_step_s <= automatic.bound.max_time_step_s);
  const double fraction = static_cast<double>(automatic.steps_per_block - 1) / automatic.steps_per_block;
  CHECK(automatic.time_step_s > fraction * automatic.bound.max_time_step_s);
  CHECK(automatic.impact_speed_m_s == timing.impact_speed_m_s);
  CHECK(automatic.warnings.empty());
  CHECK(automatic.world.integration.time_step_s == automatic.time_step_s);

  auto user = o.world;
  user.integration.time_step_s = 1.5 * automatic.bound.max_time_step_s;
  const dr::DriveTimeStep accepted = dr::drive_time_step(user, timing);
  CHECK(accepted.time_step_s <= user.integration.time_step_s);
  CHECK(accepted.time_step_s > automatic.bound.max_time_step_s);
  CHECK(accepted.steps_per_contact == Approx(accepted.bound.contact_time_s / accepted.time_step_s).epsilon(1e-12));
  REQUIRE(accepted.warnings.size() == 1);
  CHECK_THAT(accepted.warnings.front(), Catch::Contains("steps per contact at the impact speed"));
  CHECK_THAT(accepted.warnings.front(), Catch::Contains("at e = 0.8"));
  CHECK_NOTHROW(dr::World(accepted.world));

  auto too_big = o.world;
  too_big.integration.time_step_s = 1.01 * automatic.stability_limit_s;
  CHECK_THROWS_WITH(dr::drive_time_step(too_big, timing),
                    Catch::Contains("dem.integration.time_step_s") && Catch::Contains("stability limit"));
  dr::DriveTiming bad = timing;
  bad.period_s = 0.0;
  bad.blocks_per_period = 0;
  CHECK_THROWS_WITH(dr::drive_time_step(o.world, bad),
                    Catch::Contains("period_s = 0") && Catch::Contains("blocks_per_period = 0"));
}
