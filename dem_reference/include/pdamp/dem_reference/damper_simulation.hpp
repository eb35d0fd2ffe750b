// One damper under harmonic container motion: transient, analysed periods, measures.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/dem_reference/summary.hpp"
#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference {

/// A harmonic DEM run (PHYSICS.md §1): x_c = X sin(Ωt) along drive_axis.
struct DamperSimulationOptions {
  WorldOptions world;
  Vec3 drive_axis{1.0, 0.0, 0.0};  ///< direction of the drive (normalised), world = body frame at rest
  double amplitude_m = 0.04;       ///< stroke X, m, > 0
  double frequency_hz = 2.0;       ///< f, Hz, > 0
  /// Settling under gravity with the container at rest before the drive starts, s;
  /// −1 = automatic (lattice: 0.01 s; random: 2√(2L/|g|) + 0.02 s; no gravity: 0).
  double settling_time_s = -1.0;
  int transient_periods = 5;       ///< periods discarded before the analysis, >= 0
  int analysed_periods = 10;       ///< whole periods analysed, >= 1
  /// Samples per period of the recorded signals (block averages of whole steps; the
  /// time step is reduced so that a period is a whole number of blocks), >= 16.
  int samples_per_period = 1000;
  /// Particle snapshots kept, evenly spaced over the analysed periods, >= 0.
  int snapshots = 0;

  /// All violations, one line each, prefixed by `prefix` (world fields included).
  std::vector<std::string> validate(const std::string& prefix = "dem.") const;
};

/// Motion modes of PHYSICS.md (criteria in docs/dem.md "Motion modes").
enum class MotionMode {
  kSolidLike,
  kRollingCollectAndCollide,
  kBouncingCollectAndCollide,
  kScattering,
  kLocalFluidisation,
  kGlobalFluidisation,
  kDecoupled,
};
/// "solid_like", "rolling_collect_and_collide", "bouncing_collect_and_collide",
/// "scattering", "local_fluidisation", "global_fluidisation", "decoupled".
std::string_view to_string(MotionMode mode);

/// The numbers the motion-mode label is decided from (averages over the analysed periods).
struct MotionIndicators {
  /// Peak-to-peak travel of the bed's centre of mass relative to the container along
  /// the drive, over the clearance h (≈ 1 when the bed crosses the clearance).
  double relative_stroke_over_clearance = 0.0;
  /// Correlation of that relative motion between consecutive periods, in [−1, 1]
  /// (≈ 1: synchronous with the drive).
  double period_correlation = 0.0;
  /// Coefficient of variation of the per-period η* (0: every period alike).
  double eta_star_variation = 0.0;
  double apparent_mass_fraction = 0.0;  ///< m_app/m_bed
  /// Particles touching the wall that gravity presses them on (mean fraction, 0 without gravity).
  double base_contact_fraction = 0.0;
  /// Particles touching nothing (mean fraction).
  double airborne_fraction = 0.0;
  /// Mean extent of the bed along the drive over its packed extent (1 = packed).
  double spread_over_packed = 0.0;
};

/// Signals over the analysed periods, one sample per block (block averages).
struct TimeSeries {
  std::vector<double> time_s;
  std::vector<double> container_position_m;    ///< along the drive, m
  std::vector<double> container_velocity_m_s;  ///< along the drive, m/s
  std::vector<double> force_n;                 ///< container → particles along the drive, N
  std::vector<double> bed_relative_position_m; ///< bed centre of mass − container, along the drive, m
  std::vector<double> bed_momentum_kg_m_s;     ///< along the drive, kg·m/s
  std::vector<double> kinetic_energy_j;        ///< particles, J
};

/// Particle state at one time (ParaView output).
struct ParticleSnapshot {
  double time_s = 0.0;
  std::vector<Vec3> positions_m;
  std::vector<Vec3> velocities_m_s;
  std::vector<Vec3> angular_velocities_rad_s;
  std::vector<double> radii_m;
  std::vector<int> compartments;
};

/// Energy balance over the analysed periods: work of the container against the
/// dissipation in the contacts plus the change of the particles' energy.
struct EnergyBalance {
  double container_work_j = 0.0;
  double normal_damping_j = 0.0;
  double friction_j = 0.0;
  double rolling_j = 0.0;
  double delta_kinetic_j = 0.0;
  double delta_potential_j = 0.0;
  double delta_elastic_j = 0.0;
  /// |W − (D + ΔE)| / max(|W|, D): target < 0.02.
  double relative_error = 0.0;
};

struct DamperResult {
  Summary summary;
  double eta_star = 0.0;               ///< reduced loss factor from complex power (PHYSICS.md §1)
  double eta_star_stderr = 0.0;        ///< standard error of the mean of the per-period values
  /// η* from the energy balance instead: (D + ΔE)/(n·π·m_bed·V²) (independent check).
  double eta_star_energy_balance = 0.0;
  double e_diss_j = 0.0;               ///< Re(P)/Ω, J
  double energy_per_cycle_j = 0.0;     ///< 2π·E_diss, J
  double apparent_mass_kg = 0.0;       ///< Im(F*·conj V*)/(Ω|V*|²), kg
  double energy_balance_error = 0.0;   ///< = energy.relative_error
  double particle_steps_per_s = 0.0;   ///< whole run (settling, transient, analysis, recording)
  MotionMode motion_mode = MotionMode::kScattering;
  MotionIndicators indicators;
  double clearance_m = 0.0;            ///< h of compartment 0 (collected bed), m
  std::vector<double> compartment_clearances_m;
  double bed_mass_kg = 0.0;
  double velocity_amplitude_m_s = 0.0; ///< V = XΩ
  double intensity = 0.0;              ///< Γ = XΩ²/g
  double time_step_s = 0.0;
  int steps_per_period = 0;
  std::vector<double> eta_star_per_period;
  EnergyBalance energy;
  TimeSeries series;
  std::vector<ParticleSnapshot> snapshots;
  std::vector<std::string> warnings;   ///< validity-range remarks (INTERFACE.md)
};

/// Progress of a run, reported about twice a second.
struct Progress {
  std::string_view stage;        ///< "settling", "transient", "analysis"
  double simulated_time_s = 0.0; ///< since the drive started (negative while settling)
  double end_time_s = 0.0;       ///< simulated time at the end of the run
  double steps_per_s = 0.0;
  double eta_s = 0.0;            ///< estimated wall time left
};
using ProgressCallback = std::function<void(const Progress&)>;

/// Runs settling, transient_periods and analysed_periods of the harmonic drive and
/// computes the measures. Bad options: std::invalid_argument (all violations, one per
/// line; particles that do not fit name the numbers). A detected instability returns
/// with summary.outcome = kUnstable and advice in summary.message (measures unset).
DamperResult run_harmonic(const DamperSimulationOptions& options,
                          const ProgressCallback& progress = {});

}  // namespace pdamp::dem_reference
