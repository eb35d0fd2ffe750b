// Co-simulation: a ModalModel integrated in time with one reference-DEM World per damper,
// the bed in the loop (docs/theory.md §7.8, docs/cosimulation.md).
#pragma once

#include <complex>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/base/record.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/summary.hpp"
#include "pdamp/dem_reference/run_recorder.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/dem_reference/world_options.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// A particle damper whose bed is a DEM World. The container is rigid; its body frame is
/// the World's frame at rest (gravity, compartments and placement as in `world`). The
/// container's origin is the site: it moves along `container_drive_axis` by the site's
/// displacement along `drive_direction` n, along c = rotation axis × drive axis by its
/// displacement across the drive (t = z × n), and, with `rotation`, turns about
/// `container_rotation_axis` by the site's rotation about the structure's z. The bed's load
/// along the drive and across it (and its moment about the rotation axis) returns to the
/// structure; the empty container is a point mass in x and y with its rotary inertia, as in
/// damper_coupling.hpp (mass_with_containers_kg).
struct CosimulationDamper {
  std::string name;                           ///< label for reports and messages
  std::string point;                          ///< named point of the ModalModel (the site)
  Eigen::Vector2d drive_direction{1.0, 0.0};  ///< unit vector n in the structure's x-y plane
  double container_mass_kg = 0.0;             ///< empty container m_c, kg, >= 0, finite
  double container_rotary_inertia_kg_m2 = 0.0; ///< about the out-of-plane axis at the site, kg·m², >= 0 (Damper)
  /// The bed. integration.time_step_s is overwritten by the co-simulation's common step
  /// and max_impact_speed_m_s raised to the drive's (CosimulationOptions); threads as given.
  dem_reference::WorldOptions world;
  /// Unit vector of the container frame that follows n (the DEM's drive axis).
  dem_reference::Vec3 container_drive_axis{1.0, 0.0, 0.0};
  /// Unit vector of the container frame that is the structure's z (out of the plane),
  /// perpendicular to container_drive_axis: the axis of the site's rotation.
  dem_reference::Vec3 container_rotation_axis{0.0, 0.0, 1.0};
  /// true: the container turns with the site (orientation and angular velocity passed to
  /// World::step) and the bed's moment about the rotation axis returns to the modes;
  /// false: the container only translates (a warning names the modes that rotate the site).
  bool rotation = true;
  /// One line per violated rule (field = value: rule), without the "dampers[i]." prefix.
  std::vector<std::string> validate(const ModalModel& model) const;
};

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

struct CosimulationOptions {
  CosimulationExcitation excitation;
  /// q(0), q̇(0) of the modes (relative to the base for base motion); empty = 0, else one per
  /// mode, finite. A free decay needs one of them non-zero.
  Eigen::VectorXd initial_modal_displacements;
  Eigen::VectorXd initial_modal_velocities;
  /// Free decay: simulated time, s, > 0. Linear sweep: the sweep's time, s, > 0. Harmonic
  /// kinds at one frequency: ignored (periods below).
  double duration_s = 0.0;
  /// Harmonic kinds: 0 (default) drives at excitation.frequency_hz; > 0 makes the drive a
  /// linear sine sweep whose instantaneous frequency runs from excitation.frequency_hz at the
  /// run's start to this, Hz, in [0.01, 10000], over duration_s: ψ(τ) = φ + 2π(f₀τ + ½rτ²),
  /// r = (f₁ − f₀)/duration_s (up or down). The base then moves as U sin ψ (its acceleration
  /// U(ψ̈ cos ψ − ψ̇² sin ψ) loads the modes), a force as F sin ψ. The periods and the
  /// steady-state test below are ignored; the run reports each drive cycle's first harmonic
  /// (CosimulationResult::sweep_cycles) instead of steady_state. The step is planned at the
  /// sweep's highest frequency, the peak site speed from the linear response over the band.
  double sweep_end_frequency_hz = 0.0;
  /// Harmonic kinds: periods run before the analysis, >= 0; with settle_until_stable the
  /// largest number allowed (the run stops settling earlier once converged).
  int transient_periods = 0;
  /// Harmonic kinds with settle_until_stable: periods the transient runs at least before the
  /// convergence test may end it, in [0, transient_periods] (the case's /dem/transient_periods
  /// in a stepped sine).
  int min_transient_periods = 0;
  /// Harmonic kinds: whole periods of the DFT (steady-state amplitudes), >= 1.
  int analysed_periods = 1;
  /// Harmonic kinds: end the transient once the first damper's site amplitude along its
  /// drive (|DFT at Ω| of each period) has converged: amplitude_window over the last
  /// kConvergenceWindowPeriods periods, every period-to-period change and the change across
  /// the window at most stable_tolerance of the window's mean (amplitudes_converged).
  bool settle_until_stable = false;
  double stable_tolerance = 1e-3;  ///< in (0, 1)
  /// Bed settling before the coupling starts, with the structure held in its initial state
  /// and the container at rest there (dem_reference::settle), s: −1 = automatic
  /// (dem_reference::automatic_settling_time_s of each world), else [0, 100].
  double bed_settling_time_s = -1.0;
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
  /// Progress callback interval, wall-clock s, > 0.
  double progress_interval_s = 0.5;
  /// Harmonic kinds: phase φ of the drive at the coupling's start, rad, finite: the base
  /// moves as U·sin(Ω(t − t₀) + φ), the force is F·sin(Ω(t − t₀) + φ). 0 (default) is the
  /// historical sin Ωt. A continuation of a harmonic CosimulationState ignores it: its drive
  /// starts at the state's excitation_phase_rad (the signal continues, docs/cosimulation.md §6).
  double excitation_phase_rad = 0.0;
  /// Particle snapshots of every bed, evenly spaced over the coupled run (the last at its
  /// planned end), for ParaView; in [0, dem_reference::limits::kMaxSnapshots]. 0: none.
  int snapshots = 0;

  /// All violations, one line each, "field = value: rule" (prefix "cosimulation.").
  std::vector<std::string> validate(const ModalModel& model) const;
};

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
  /// CosimulationOptions::snapshots: per snapshot time, every bed (damper order).
  std::vector<std::vector<BedSnapshot>> bed_snapshots;
  /// Where the wall time went, s (not in checkpoints: a restored run's are its own process's).
  CosimulationStageTimes stage_times;
};

struct CosimulationProgress {
  std::string_view stage;          ///< "settling", "transient", "analysis", "decay"
  double simulated_time_s = 0.0;   ///< since the coupling started
  double end_time_s = 0.0;         ///< planned end (harmonic: with all transient periods)
  double steps_per_s = 0.0;
};
/// Called about every progress_interval_s of wall time, settling included; an exception it
/// throws ends the run there (a stop request while the beds settle, before any checkpoint).
using CosimulationProgressCallback = std::function<void(const CosimulationProgress&)>;

/// The end of a co-simulation run, to be continued by the next (a stepped sine: each
/// frequency starts from the previous one's final state, bed included). Filled by
/// cosimulate(…, state, …); pass it back unchanged. It owns the worlds: the particles, their
/// contacts (tangential springs, rolling history), the container pose and the time step.
struct CosimulationState {
  std::vector<dem_reference::World> worlds;  ///< one per damper, at the end of the last run
  Eigen::VectorXd modal_displacements;       ///< q at the end (relative for base motion)
  Eigen::VectorXd modal_velocities;          ///< q̇ at the end
  double time_s = 0.0;                       ///< coupled time since the first run's start, s
  std::int64_t steps = 0;                    ///< coupled steps since the first run's start
  double time_step_s = 0.0;                  ///< the worlds' step, s (fixed for all continuations)
  /// The excitation of the last run (after a sweep: its frequency the sweep's end frequency).
  CosimulationExcitation excitation;
  /// Harmonic: the drive's phase ψ at the end, rad, in [0, 2π). Runs at one frequency end on
  /// whole periods, so this is their start phase; the next run starts its sine there.
  double excitation_phase_rad = 0.0;
  /// The energy account since the first run's start (docs/cosimulation.md §4): what one run
  /// of the combined length reports, to the bit. Its running sums (work, structural damping)
  /// continue from run to run; its changes are taken from the first start's references below.
  /// A run split into segments (checkpoints) reports this as its whole.
  CosimulationEnergy energy_since_start;
  double start_structure_kinetic_j = 0.0;    ///< T' at the first start, J
  double start_structure_potential_j = 0.0;  ///< ½qᵀKq at the first start, J
  std::vector<dem_reference::EnergyAccount> start_world_energy;  ///< each world's account at the first start
  /// true once a run has filled the state (worlds built, beds settled).
  bool started() const { return !worlds.empty(); }
};

/// Runs the co-simulation. The modal equations
///   M q̈ + C q̇ + K q = f_exc(t) − Σ_d (b_d F_d + r_d M_d),   M = diag(m_j) + Σ m_c Φ_dᵀΦ_d,
/// (F_d, M_d: what container d applies to its bed along n and about the rotation axis; b_d,
/// r_d the site's drive and rotation shapes) are advanced with the worlds' step dt by
/// velocity Verlet with the damping term trapezoidal (implicit, exact solve): the structure
/// and the beds form one leapfrog, second order, with no lag in the coupling.
/// Throws std::invalid_argument for invalid inputs (every violation, one per line) and for a
/// step the structure cannot take (ω_max·dt > 0.2). A Cosimulation (cosimulation_run.hpp)
/// advanced to its end: use that class to run the steps in segments.
CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationOptions& options,
                              const CosimulationProgressCallback& progress = {});

/// The same run, continuing `state` when it has started, and leaving the run's end in it.
/// - Fresh (state.started() false): as above (worlds built, beds settled); then the state
///   holds the worlds, q, q̇, t, dt, the excitation and the drive's end phase.
/// - Continuation: no new worlds, no settling; q(0), q̇(0) are the state's (the options'
///   initial_modal_* must be empty); dt is the state's (options.time_step_s must be 0 or
///   equal); the excitation must have the state's kind, direction, amplitude and point
///   (harmonic: the frequency may change; a free decay continues a free decay only); a
///   harmonic drive starts at the state's end phase, so the base displacement and the force
///   are continuous at the junction (with φ = π/2 the base velocity too, docs/cosimulation.md
///   §6); history times continue from state.time_s. Two runs continued at one frequency are
///   bit-identical to one run of the combined length (tests/structure/test_cosimulation.cpp).
///   A new frequency whose automatic step is > 10% below the carried dt warns (plan the
///   sweep's dt at its most demanding frequency: cosimulation_time_step()).
/// Throws std::invalid_argument as above, and for a state that does not fit (one line each).
CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationOptions& options, CosimulationState& state,
                              const CosimulationProgressCallback& progress = {});

/// Checkpoints of a co-simulation run in segments (docs/cosimulation.md §6b).
/// save_cosimulation_state writes a started state: each world's integration settings and
/// whole state (World::save_state), q, q̇, the time, steps, step and the excitation with its
/// phase. restore_cosimulation_state builds the worlds from `dampers` (their World options
/// with the saved integration settings) and restores them, so that continuing the restored
/// state is bit for bit continuing the saved one. std::invalid_argument naming the field when
/// the state does not fit the model and dampers (mode or damper count, another bed) or is
/// damaged.
void save_cosimulation_state(const CosimulationState& state, dem_reference::StateWriter& out);
CosimulationState restore_cosimulation_state(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                             dem_reference::StateReader& in);

/// A free decay's result so far, for a checkpoint: the histories, the counters, the
/// frequencies with the containers and the warnings (the energy account is the state's) (harmonic results are not
/// written: only a free decay is run in segments). restore_cosimulation_result refuses a
/// result of another shape (modes, dampers) naming the field.
void save_cosimulation_result(const CosimulationResult& result, dem_reference::StateWriter& out);
CosimulationResult restore_cosimulation_result(dem_reference::StateReader& in, Eigen::Index modes, std::size_t dampers);

/// Appends the result of a continuation to the result of the runs before it (a free decay
/// run in segments, each continuing the state the last one left): the histories without the
/// continuation's first sample (the last one's final sample again), the counters summed, the
/// continuation's outcome, final states and warnings not yet listed, the stage times summed,
/// and the energy account of `state` since the first start (CosimulationState::
/// energy_since_start: a sum of the runs' own accounts would differ from one run's in the
/// last bits). Segments of whole
/// sample intervals (options.sample_interval_s fixed) give the histories one run records.
void append_continuation(CosimulationResult& total, const CosimulationResult& next, const CosimulationState& state);

/// The common step a fresh cosimulate() would take for these inputs, s, and its whole steps
/// per period (harmonic, else 0), without building worlds (a stepped sine takes the smallest
/// over its frequencies as options.time_step_s of its first run). Throws as cosimulate().
struct CosimulationTimeStep {
  double time_step_s = 0.0;
  std::int64_t steps_per_period = 0;
  std::vector<std::string> warnings;
};
CosimulationTimeStep cosimulation_time_step(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                            const CosimulationOptions& options);

/// Rodrigues rotation about a unit axis by angle θ (rad), row-major (body → world).
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

dem_reference::Matrix3 rotation_about(const dem_reference::Vec3& unit_axis, double angle_rad);

}  // namespace pdamp::structure
