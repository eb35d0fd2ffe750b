// What a co-simulation run gives (docs/cosimulation.md): the sampled histories, the steady
// state's first harmonics, a sweep's cycles, the energy ledger, the stage times, the beds'
// snapshots; and the steady-state test of a harmonic run's transient.
#pragma once

#include <complex>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/base/record.hpp"
#include "pdamp/dem_reference/run_recorder.hpp"
#include "pdamp/dem_reference/summary.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace pdamp::structure {

/// Sampled histories (row s = sample s; first sample at t = 0, the coupling's start).
struct CosimulationHistory {
  std::vector<double> time_s;
  Eigen::MatrixXd modal_displacements;  ///< samples x modes, q (relative for base motion)
  Eigen::MatrixXd site_displacement_m;  ///< samples x dampers: absolute site motion along n, m
  Eigen::MatrixXd site_rotation_rad;    ///< samples x dampers: site rotation about z, rad
  /// samples x dampers: force the bed exerts on the container along n, N (−load·a), the mean
  /// over the steps since the previous sample (the first sample: its own step): an impact
  /// lasts a few steps, and a value read at the sample alone would alias it
  Eigen::MatrixXd container_load_n;
  /// samples x dampers: moment the bed exerts on the container about the rotation axis, N m,
  /// the mean over the same steps
  Eigen::MatrixXd container_moment_nm;
  /// Per damper, the bed's force and moment summed over the steps since the last sample, and
  /// their count: what the next sample averages (a run continued from a checkpoint between two
  /// samples goes on with them).
  std::vector<double> pending_load_sum_n, pending_moment_sum_nm;
  std::int64_t pending_steps = 0;
};

/// First harmonics at Ω over whole periods (harmonic kinds), as complex amplitudes against
/// the excitation's sin ψ, ψ = Ω(t − t₀) + φ (the drive's phase): y(t) ≈ Im(Ŷ e^{iψ}),
/// Ŷ = i·(2/N) Σ_k y_k e^{−iψ_k} over the N steps of each period (y = Y sin ψ gives Ŷ = Y;
/// y = Y cos ψ gives Ŷ = iY).
struct CosimulationSteadyState {
  /// The frequency run, Hz: the requested one, except in a continuation whose carried-over
  /// step dt does not divide its period: then 1/(N·dt), N = round(1/(f·dt)) whole steps
  /// (a relative change of at most 1/(2N); a warning above 1e-4).
  double frequency_hz = 0.0;
  int transient_periods = 0;  ///< periods run before the analysed ones
  int analysed_periods = 0;
  bool stable = false;        ///< settle_until_stable: the transient converged (false when not asked)
  /// The convergence test's window when the transient ended (converged, or at its cap):
  /// the last min(kConvergenceWindowPeriods, transient periods) per-period amplitudes of the
  /// first site (amplitude_window); periods 0 and NaN measures with fewer than two.
  int window_periods = 0;
  double window_max_relative_change = std::numeric_limits<double>::quiet_NaN();
  double window_relative_drift = std::numeric_limits<double>::quiet_NaN();
  double window_relative_spread = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXcd modal_amplitudes;                    ///< q̂_j
  std::vector<std::complex<double>> site_amplitudes_m;  ///< ŷ_d along n (absolute), m
  /// |ŷ_d| per unit excitation: transmissibility |ŷ/U| (base) or receptance |ŷ/F| in m/N.
  std::vector<double> site_amplitude_per_excitation;
  /// |ŷ| of the first damper's site in each period run (transient and analysed), m.
  std::vector<double> period_site_amplitudes_m;
  /// F̂_d: the force the container applies to its bed along n, N (the convention above).
  std::vector<std::complex<double>> bed_force_amplitudes_n;
  /// Each bed's reduced loss factor and apparent mass in the loop, by the Level II measure
  /// (docs/theory.md §1, formulas::ComplexPower) on F̂_d and V̂_d = iΩŷ_d: P = ½F̂ conj V̂,
  /// η* = (Re P/Ω)/(½ m_bed |V̂|²), m_app/m_bed = Im(F̂ conj V̂)/(Ω|V̂|² m_bed). They make
  /// a stepped-sine point comparable with pdamp dem and with the field at the same (f, X).
  std::vector<double> bed_reduced_loss_factor;
  std::vector<double> bed_apparent_mass_fraction;
};

/// One drive cycle of a linear sweep (ψ from φ + 2πk to φ + 2π(k + 1)): first harmonics
/// against sin ψ over the cycle, Ŷ = (i/π) ∫ y e^{−iψ} dψ (the steady-state convention above,
/// weighted by dψ = ψ̇ dt so that the cycle's varying rate is accounted for), and the bed
/// measures of CosimulationSteadyState from them. A sweep slow enough to be quasi-stationary
/// (docs/cosimulation.md §6) gives the steady-state FRF cycle by cycle.
struct CosimulationSweepCycle {
  double time_s = 0.0;       ///< the cycle's middle, s (the history's clock)
  double frequency_hz = 0.0; ///< the cycle's mean frequency, 1/(its duration), Hz
  std::vector<std::complex<double>> site_amplitudes_m;  ///< ŷ_d along n, m
  std::vector<double> site_amplitude_per_excitation;    ///< |ŷ_d| / U or / F
  std::vector<std::complex<double>> bed_force_amplitudes_n;
  std::vector<double> bed_reduced_loss_factor;
  std::vector<double> bed_apparent_mass_fraction;
  /// A cycle of a result (its per-damper values keyed by the dampers' names).
  static const base::Fields<CosimulationSweepCycle>& fields();
};

/// Energy over the coupled run in one inertial frame, J (docs/cosimulation.md §4).
/// For base motion the rigid carried-mass term ½m_rigid u̇_b² is left out of both sides
/// (a truncated modal model does not know m_rigid; it cancels exactly).
struct CosimulationEnergy {
  double excitation_work_j = 0.0;           ///< ∫F·v_point dt, or ∫R·u̇_b dt (base reaction)
  double structural_damping_j = 0.0;        ///< ∫q̇ᵀCq̇ dt
  double delta_structure_kinetic_j = 0.0;   ///< structure + containers, absolute velocities
  double delta_structure_potential_j = 0.0; ///< ½qᵀKq
  double dem_normal_damping_j = 0.0;        ///< Σ over the worlds
  double dem_friction_j = 0.0;
  double dem_rolling_j = 0.0;
  double delta_bed_kinetic_j = 0.0;
  double delta_bed_potential_j = 0.0;
  double delta_bed_elastic_j = 0.0;
  double container_work_j = 0.0;            ///< the worlds' own account of the work on the beds (cross-check)
  /// |W − (D_s + D_dem + ΔE_s + ΔE_bed)| / max(|W|, D_s + D_dem, |ΔE_s|).
  double relative_error = 0.0;
  double dem_dissipated_j() const { return dem_normal_damping_j + dem_friction_j + dem_rolling_j; }
};

/// Wall-clock time of each stage of the coupled steps, s (docs/cosimulation.md §8): where a
/// run's time goes. The stages are timed on every kCosimulationTimingStride-th step and the
/// times scaled by it (two clock reads per stage on every step would cost about a tenth of a
/// small bed's step), so they are estimates; they read nothing the run computes and change no
/// result. A prime stride: no periodic event of the loop (samples, periods, progress every 256
/// steps) falls on the timed steps more often than on the others, unless its period is a
/// multiple of it.
struct CosimulationStageTimes {
  double settling_s = 0.0;          ///< the beds settling before the coupling (timed whole)
  double modal_kick_drift_s = 0.0;  ///< v_{k+½} = v_k + ½dt q̈_k, q_{k+1} = q_k + dt v_{k+½}, the drive at t_{k+1}
  double bed_steps_s = 0.0;         ///< the containers moved to t_{k+1}, World::step of each bed, its load read
  double closing_kick_s = 0.0;      ///< g_{k+1}, (M + ½dt C) v_{k+1} = M v_{k+½} + ½dt g_{k+1}, q̈_{k+1}
  double ledger_s = 0.0;            ///< the step's structural damping and excitation work (trapezoid, §4)
  double measures_s = 0.0;          ///< the sampled histories and the first harmonics (steady state, sweep cycles)
  double coupled_s() const { return modal_kick_drift_s + bed_steps_s + closing_kick_s + ledger_s + measures_s; }
};
/// Steps per timed step of CosimulationStageTimes.
inline constexpr std::int64_t kCosimulationTimingStride = 31;

/// One bed at one instant: its particles (world frame) and its container's position.
struct BedSnapshot {
  dem_reference::ParticleSnapshot particles;
  dem_reference::Vec3 container_position_m{0.0, 0.0, 0.0};
};

struct CosimulationResult {
  /// kCompleted; kUnstable / kFailed when a World stopped (message: the damper and the
  /// World's own reason and advice); the histories end there.
  dem_reference::Outcome outcome = dem_reference::Outcome::kCompleted;
  std::string message;
  double time_step_s = 0.0;
  std::int64_t steps = 0;              ///< coupled steps (bed settling not counted)
  std::int64_t steps_per_period = 0;   ///< harmonic kinds, else 0
  std::int64_t settling_steps = 0;
  double simulated_time_s = 0.0;       ///< coupled time of this run, s
  /// Time of the run's first sample, s: 0 for a fresh start, the state's time_s for a
  /// continuation (history times continue the previous run's).
  double start_time_s = 0.0;
  bool continued = false;              ///< the run continued a CosimulationState (no settling)
  double wall_time_s = 0.0;
  /// Natural frequencies with the empty containers (beds removed), Hz.
  Eigen::VectorXd frequencies_with_containers_hz;
  Eigen::VectorXd final_modal_displacements;  ///< q at the last step (relative for base motion)
  Eigen::VectorXd final_modal_velocities;     ///< q̇ at the last step
  CosimulationHistory history;
  CosimulationSteadyState steady_state;  ///< harmonic kinds at one frequency only
  std::vector<CosimulationSweepCycle> sweep_cycles;  ///< linear sweep only: the whole cycles run
  CosimulationEnergy energy;
  std::vector<dem_reference::WorldStatus> world_status;            ///< per damper
  std::vector<dem_reference::ContainerState> final_container_states;  ///< per damper
  std::vector<std::string> warnings;
  /// CosimulationSettings::snapshots: per snapshot time, every bed (damper order).
  std::vector<std::vector<BedSnapshot>> bed_snapshots;
  /// Where the wall time went, s (not in checkpoints: a restored run's are its own process's).
  CosimulationStageTimes stage_times;
};

/// Cycles averaged by each window of a linear sweep's peak (kSweepWindowCycles).
inline constexpr std::size_t kSettledWindowPeriods = 4;

/// Consecutive periods over which a harmonic run's transient must have converged.
inline constexpr std::size_t kConvergenceWindowPeriods = 8;

/// The per-period amplitudes a_1 … a_w of the last w = min(window, n) periods, relative to
/// their mean ā: the largest period-to-period change max|a_k − a_{k−1}|/ā, the change across
/// the window |a_w − a_1|/ā, and the sample standard deviation over ā. NaN measures (periods
/// 0) with fewer than two amplitudes or a mean that is not > 0.
struct AmplitudeWindow {
  int periods = 0;
  double max_relative_change = std::numeric_limits<double>::quiet_NaN();
  double relative_drift = std::numeric_limits<double>::quiet_NaN();
  double relative_spread = std::numeric_limits<double>::quiet_NaN();
};
AmplitudeWindow amplitude_window(const std::vector<double>& period_amplitudes,
                                 std::size_t window = kConvergenceWindowPeriods);

/// The steady-state test of a harmonic run (a stepped sine's points, a sweep's start): the
/// window holds `window` periods, every period-to-period change in it is at most
/// tolerance·ā, and so is the change across it (a slow drift of r per period changes the
/// window by (w − 1)r, so it must be below tolerance/(w − 1) per period). A beating or
/// drifting transient does not pass; a stationary series of relative scatter σ passes
/// nearly always for σ <= tolerance/5 and, for larger σ, only in a quieter stretch.
bool amplitudes_converged(const AmplitudeWindow& w, double tolerance, std::size_t window = kConvergenceWindowPeriods);

}  // namespace pdamp::structure
