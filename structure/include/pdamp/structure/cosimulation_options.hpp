// The runs a co-simulation does (docs/cosimulation.md): a free decay from an initial modal
// state, a harmonic drive at one frequency to its steady state, a linear sine sweep. Each
// kind has its own options; what every run shares is CosimulationSettings.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

enum class CosimulationExcitationKind {
  kFreeDecay,        ///< no load: the release from the initial modal state
  kBaseTranslation,  ///< u_base = U·e·sin(Ωt), every support moving rigidly
  kPointForce,       ///< F(t) = F·e·sin(Ωt) at a named point
};

/// The excitation (structure frame, x-y plane).
struct CosimulationExcitation {
  CosimulationExcitationKind kind = CosimulationExcitationKind::kFreeDecay;
  Eigen::Vector2d direction{0.0, 1.0};  ///< unit vector e (harmonic kinds)
  double amplitude = 0.0;               ///< U in m (base) or F in N (force), > 0 for the harmonic kinds
  double frequency_hz = 0.0;            ///< f = Ω/2π, Hz, > 0 for the harmonic kinds
  std::string point;                    ///< kPointForce: named point where F acts
};

/// The harmonic runs' default drive: a base translation (its amplitude and frequency to set).
inline CosimulationExcitation base_translation() {
  CosimulationExcitation e;
  e.kind = CosimulationExcitationKind::kBaseTranslation;
  return e;
}

/// What every coupled run shares.
struct CosimulationSettings {
  /// q(0), q̇(0) of the modes (relative to the base for base motion); empty = 0, else one per
  /// mode, finite. A free decay needs one of them non-zero.
  Eigen::VectorXd initial_modal_displacements;
  Eigen::VectorXd initial_modal_velocities;
  /// Bed settling before the coupling starts, with the structure held in its initial state
  /// and the container at rest there (dem_reference::settle), s: −1 = automatic
  /// (dem_reference::automatic_settling_time_s of each world), else [0, 100].
  double bed_settling_time_s = -1.0;
  /// A start from steady forced vibration (a decay released as a shaker is cut off): after
  /// settling, each bed is driven for this many whole periods of forced_start_frequency_hz,
  /// its container moving as its start pose times a(t)·cos(2πft) (translation and rotation; the
  /// run ends at the start pose, at rest), so that the coupled run begins with the bed in
  /// its steady state at the start amplitude rather than as placed. 0: none, [0, 10000].
  /// Needs a start at rest (zero initial modal velocities) and no base motion.
  int forced_start_periods = 0;
  double forced_start_frequency_hz = 0.0;  ///< Hz, > 0 and finite with forced_start_periods
  /// The forced start's amplitude rises to this factor on the start pose half-way and eases
  /// back (1 + (P − 1)·sin²(π t/T)): the bed is released on the descending branch, as in a
  /// decay that began higher. [1, 10]; 1: a constant amplitude.
  double forced_start_peak_factor = 1.0;
  /// Output sampling of the time histories, s: rounded to whole steps (at least one);
  /// 0 = automatic: period/64 for the harmonic kinds, duration/2000 for a free decay.
  double sample_interval_s = 0.0;
  /// Peak site speed along the drive the time-step rule assumes (dem_reference::
  /// drive_impact_speed), m/s, >= 0; 0 = automatic: free decay from the initial energy
  /// (√(2E₀ bᵀM⁻¹b), a bound), harmonic from twice the linear response without beds.
  double peak_site_speed_m_s = 0.0;
  /// Common time step, s: 0 = automatic (the smallest of the worlds' steps; harmonic: with
  /// whole steps per period by dem_reference::drive_time_step), else at most every world's
  /// automatic bound (otherwise refused).
  double time_step_s = 0.0;
  /// Progress report interval, wall-clock s, > 0.
  double progress_interval_s = 0.5;
  /// Particle snapshots of every bed, evenly spaced over the coupled run (the last at its
  /// planned end), for ParaView; in [0, dem_reference::limits::kMaxSnapshots]. 0: none.
  int snapshots = 0;
};

/// The structure and its beds released from the initial modal state, unloaded.
struct DecayRun : CosimulationSettings {
  double duration_s = 0.0;  ///< simulated time, s, > 0
};

/// A harmonic drive at one frequency (kBaseTranslation or kPointForce), run through its
/// transient to whole analysed periods: the steady state's first harmonics.
struct SteadyStateRun : CosimulationSettings {
  CosimulationExcitation excitation = base_translation();
  /// Phase φ of the drive at the coupling's start, rad, finite: the base moves as
  /// U·sin(Ω(t − t₀) + φ), the force is F·sin(Ω(t − t₀) + φ). 0 (default) is the historical
  /// sin Ωt. A continuation of a harmonic CosimulationState ignores it: its drive starts at
  /// the state's excitation_phase_rad (the signal continues, docs/cosimulation.md §6).
  double excitation_phase_rad = 0.0;
  /// Periods run before the analysis, >= 0; with settle_until_stable the largest number
  /// allowed (the run stops settling earlier once converged).
  int transient_periods = 0;
  /// With settle_until_stable: periods the transient runs at least before the convergence
  /// test may end it, in [0, transient_periods] (the case's /dem/transient_periods in a
  /// stepped sine).
  int min_transient_periods = 0;
  /// Whole periods of the DFT (steady-state amplitudes), >= 1.
  int analysed_periods = 1;
  /// End the transient once the first damper's site amplitude along its drive (|DFT at Ω|
  /// of each period) has converged: amplitude_window over the last kConvergenceWindowPeriods
  /// periods, every period-to-period change and the change across the window at most
  /// stable_tolerance of the window's mean (amplitudes_converged).
  bool settle_until_stable = false;
  double stable_tolerance = 1e-3;  ///< in (0, 1)
};

/// A linear sine sweep: the drive's instantaneous frequency runs from excitation.frequency_hz
/// at the run's start to sweep_end_frequency_hz over duration_s, ψ(τ) = φ + 2π(f₀τ + ½rτ²),
/// r = (f₁ − f₀)/duration_s (up or down). The base then moves as U sin ψ (its acceleration
/// U(ψ̈ cos ψ − ψ̇² sin ψ) loads the modes), a force as F sin ψ. The run reports each drive
/// cycle's first harmonic (CosimulationResult::sweep_cycles). The step is planned at the
/// sweep's highest frequency, the peak site speed from the linear response over the band.
struct SweepRun : CosimulationSettings {
  CosimulationExcitation excitation = base_translation();
  double excitation_phase_rad = 0.0;    ///< φ at the start, rad, as SteadyStateRun's
  double sweep_end_frequency_hz = 0.0;  ///< f₁, Hz, in [0.01, 10000]
  double duration_s = 0.0;              ///< the sweep's time, s, > 0
};

/// One run of a co-simulation.
using CosimulationRun = std::variant<DecayRun, SteadyStateRun, SweepRun>;

/// What every kind shares.
const CosimulationSettings& settings_of(const CosimulationRun& run);

/// All violations, one line each, "field = value: rule" (prefix "cosimulation.").
std::vector<std::string> validate(const CosimulationRun& run, const ModalModel& model);

}  // namespace pdamp::structure
