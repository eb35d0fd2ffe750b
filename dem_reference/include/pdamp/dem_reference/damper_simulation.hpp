// One damper under harmonic container motion: transient, analysed periods, measures.
// The run is assembled from the run machinery that other drivers share (docs/dem.md
// "Run machinery"): drive_time_step.hpp, run_recorder.hpp, run_measures.hpp,
// motion_modes.hpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pdamp/base/run_hooks.hpp"
#include "pdamp/dem_reference/motion_modes.hpp"
#include "pdamp/dem_reference/run_measures.hpp"
#include "pdamp/dem_reference/run_recorder.hpp"
#include "pdamp/dem_reference/summary.hpp"
#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference {

namespace limits {
/// Stroke X, m: (0, 10]; no damper strokes further (and 2XΩ must stay <= 1000 m/s).
inline constexpr double kMaxAmplitude_m = 10.0;
/// Drive frequency, Hz: [0.01, 10000]. Below 0.01 Hz a period is over 100 s of tiny
/// steps (~1e9 of them); above 10 kHz the container is no rigid body.
inline constexpr double kMinFrequency_hz = 0.01;
inline constexpr double kMaxFrequency_hz = 1e4;
/// Settling, s: -1 (automatic) or [0, 100]; a bed falls through any damper in < 1 s.
inline constexpr double kMaxSettlingTime_s = 100.0;
/// Transient [0, 100000] and analysed [1, 100000] periods: more is no design run.
inline constexpr int kMaxPeriods = 100'000;
/// Samples per period [16, 100000] of the recorded block series (the measures come from
/// every step and do not depend on it); above 1e5 the blocks get shorter than a contact
/// and the time step is cut to fit.
inline constexpr int kMinSamplesPerPeriod = 16;
inline constexpr int kMaxSamplesPerPeriod = 100'000;
/// samples_per_period × analysed_periods: the recorded signals keep 9 doubles per
/// sample (RunEstimate::signal_bytes), 1e7 samples are ~720 MB.
inline constexpr long long kMaxRecordedSamples = 10'000'000;
/// Snapshots: [0, min(recorded samples, 10000)] (one per block at most; each holds
/// every particle: RunEstimate::snapshot_bytes).
inline constexpr int kMaxSnapshots = 10'000;
}  // namespace limits

/// A harmonic DEM run (docs/theory.md §1): x_c = X sin(Ωt) along drive_axis.
struct DamperSimulationOptions {
  WorldOptions world;
  Vec3 drive_axis{1.0, 0.0, 0.0};  ///< direction of the drive (normalised), world = body frame at rest
  double amplitude_m = 0.04;       ///< stroke X, m, in (0, 10]
  double frequency_hz = 2.0;       ///< f, Hz, in [0.01, 10000]
  /// Settling under gravity with the container at rest before the drive starts, s, in
  /// [0, 100]; −1 = automatic (lattice: 0.01 s; random: 2√(2L/|g|) + 0.02 s; no gravity: 0).
  double settling_time_s = -1.0;
  /// How the drive reaches the stroke X (docs/dem.md "Approach"): 0 (default) from rest,
  /// the bed settled and then driven at X; a stroke X_a > X: from above, as in a decay,
  /// the drive runs approach_hold_periods at X_a, then lowers its stroke linearly to X over
  /// approach_ramp_periods (x_c = A(t) sin Ωt, A linear, the velocity A'sin Ωt + AΩ cos Ωt),
  /// then the transient and analysed periods at X. Below the collect-and-collide onset the
  /// state a bed keeps depends on this history. In [0, 10] m; 0 or > amplitude_m.
  double approach_amplitude_m = 0.0;
  int approach_hold_periods = 5;   ///< periods at X_a, in [0, 100000] (approach only)
  int approach_ramp_periods = 10;  ///< periods of the linear ramp X_a -> X, in [1, 100000] (approach only)
  int transient_periods = 5;       ///< periods discarded before the analysis, in [0, 100000]
  int analysed_periods = 10;       ///< whole periods analysed, in [1, 100000]
  /// Samples per period of the recorded signals (block averages of whole steps; the
  /// time step is reduced so that a period is a whole number of blocks), in [16, 100000];
  /// samples_per_period × analysed_periods <= 1e7. Only the series use it: η*, E_diss,
  /// m_app and the per-period η* come from the Fourier coefficient at Ω accumulated every
  /// step (formulas::DriveBinAccumulator), so they do not alias and do not depend on it.
  ///
  /// Time step (world.integration): automatic = min(t_c(v)/steps_per_contact,
  /// rayleigh_fraction·T_R) at v = max(max_impact_speed_m_s, 2XΩ + √(2|g|H_free)),
  /// H_free = H − 2r_min (the largest free fall of a sphere). A user time_step_s above
  /// that is accepted up to the stability limit min(T_R, t_c(v)/20), with a warning giving
  /// the steps per contact at v and the restitution error bound (0.6 ln²ε + 0.1)/N;
  /// above the stability limit it is refused.
  int samples_per_period = 1000;
  /// Particle snapshots kept, evenly spaced over the analysed periods, in
  /// [0, min(samples_per_period × analysed_periods, 10000)].
  int snapshots = 0;

  /// All violations, one line each, prefixed by `prefix` (world fields included).
  std::vector<std::string> validate(const std::string& prefix = "dem.") const;
};

struct DamperResult {
  Summary summary;
  double eta_star = 0.0;               ///< reduced loss factor from complex power (docs/theory.md §1)
  double eta_star_stderr = 0.0;        ///< standard error of the mean of the per-period values (sample sd/√n)
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
  /// η* of each analysed period, from that period's drive bin (not from the blocks).
  std::vector<double> eta_star_per_period;
  EnergyBalance energy;
  TimeSeries series;
  std::vector<ParticleSnapshot> snapshots;
  std::vector<std::string> warnings;   ///< validity-range remarks (docs/command_line.md)
  /// The hooks asked the run to stop (RunHooks::stop_requested): after it stored its state
  /// (the run continues from it), or while the bed settled or approached, without one. The
  /// measures are unset.
  bool stopped = false;
  /// The result's numbers (not its series, snapshots and warnings, which go to files).
  static const base::Fields<DamperResult>& fields();
};

/// Where a harmonic run's checkpoints go (docs/dem.md "Checkpoints"): a file, memory. The
/// run hands over its whole state each time it takes one; the sink keeps it (the last
/// replaces the ones before) or throws, which ends the run with that exception.
class CheckpointSink {
 public:
  virtual ~CheckpointSink() = default;
  /// `state`: bytes that resume the run (CheckpointStorage::resume_state), taken
  /// `simulated_time_s` after the drive started.
  virtual void store(const std::string& state, double simulated_time_s) = 0;
};

/// The checkpoint data of a harmonic run: where its states go and the state it starts
/// from. When a checkpoint is taken and when the run stops are its hooks' (run_harmonic).
struct CheckpointStorage {
  /// Receives the run's state at each checkpoint; nullptr: none is kept (a stop still
  /// ends the run, with nothing written).
  CheckpointSink* sink = nullptr;
  /// Bytes an earlier run of the same options stored: the run starts there instead of
  /// settling, and its result is bit for bit the uninterrupted run's. Empty: a new run.
  std::string resume_state;
};

/// A harmonic run asks its hooks whether to stop every kStopPollSteps drive, settling or
/// approach steps (and at period ends): a period of a big bed can take an hour.
inline constexpr std::int64_t kStopPollSteps = 16;

/// What a run will cost, computed without building the world (run_harmonic's time step
/// and step counts exactly; memory from the sizes the world reserves; wall time at a
/// measured rate). Hostile inputs (a huge sample count, snapshots of a large bed)
/// show here before they exhaust memory.
struct RunEstimate {
  int particles = 0;
  double time_step_s = 0.0;            ///< exactly as run_harmonic chooses it, s
  double impact_speed_m_s = 0.0;       ///< the speed the bound is taken at: max(max_impact_speed_m_s, 2XΩ + √(2|g|H_free)), m/s
  double steps_per_contact = 0.0;      ///< Hertz contact time at that speed / time_step_s
  double stability_limit_s = 0.0;      ///< largest user time step accepted: min(T_R, t_c/20), s
  std::vector<std::string> warnings;   ///< as run_harmonic will add them (a user step above the automatic bound)
  std::int64_t steps_per_period = 0;
  std::int64_t settling_steps = 0;
  std::int64_t approach_steps = 0;     ///< hold and ramp at and from approach_amplitude_m (0 from rest)
  std::int64_t transient_steps = 0;
  std::int64_t analysed_steps = 0;
  std::int64_t total_steps = 0;        ///< settling + approach + transient + analysed (= Summary::steps of a completed run)
  double particle_steps = 0.0;         ///< total_steps × particles (double: may exceed 2^63 for hostile input)
  /// analysed_periods × samples_per_period: the length of every TimeSeries column.
  std::int64_t recorded_samples = 0;
  int snapshots = 0;                   ///< snapshots kept
  // Memory, bytes.
  std::size_t particle_bytes = 0;      ///< particle arrays (struct of arrays)
  std::size_t neighbour_bytes = 0;     ///< Verlet rows (pairs and walls) and the cell grid, as reserved
  std::size_t contact_bytes = 0;       ///< contact history pools, as reserved
  std::size_t signal_bytes = 0;        ///< recorded signals and time series (9 doubles per sample) and per-period η*
  std::size_t snapshot_bytes = 0;      ///< snapshots × particles × 84 bytes
  std::size_t memory_bytes = 0;        ///< sum of the above
  /// Assumed rate, particle-steps/s: bench/results/cpp-2core/bench_dem.txt (2-core
  /// machine, steel spheres): serial worlds (threads = 1 or <= 1500 particles) below
  /// 10,000 particles 25e6 (36 and 1000 spheres: 24-28e6), larger serial worlds 11e6
  /// (100,000 spheres, 1 thread: 10.3-11.0e6), larger parallel worlds 21e6 (100,000
  /// spheres, 2 threads: 18.3-22.6e6; more threads are not measured and not assumed
  /// faster). Dense, colliding beds run slower than this by up to ~2.
  double particle_steps_per_s = 0.0;
  double wall_time_s = 0.0;            ///< particle_steps / particle_steps_per_s, s
};

/// The estimate of run_harmonic(options). Throws std::invalid_argument as run_harmonic
/// does for invalid options (all violations, one per line) or a time step above the
/// stability limit.
RunEstimate estimate_run(const DamperSimulationOptions& options);

/// One World of `world` right after construction, without building it: its particles,
/// the bytes its arrays reserve (particles, neighbour rows and cell grid, contact pools: as
/// RunEstimate counts them) and the assumed stepping rate (RunEstimate). For the cost of
/// runs that step worlds inside another loop (the co-simulation).
struct WorldEstimate {
  int particles = 0;
  std::size_t memory_bytes = 0;
  double particle_steps_per_s = 0.0;
};
WorldEstimate estimate_world(const WorldOptions& world);

/// Places the particles as run_harmonic would (lattice or random, inner structures and
/// wall layers in place) without building the world, and throws std::invalid_argument
/// as the world would when they do not fit ("compartments[0]: lattice site 0 at (...)
/// overlaps inner structure 0"). O(particles): the check that `pdamp validate` makes.
void check_initial_placement(const DamperSimulationOptions& options);

/// Runs settling, transient_periods and analysed_periods of the harmonic drive and
/// computes the measures. Bad options: std::invalid_argument (all violations, one per
/// line; particles that do not fit name the numbers). A detected instability returns
/// with summary.outcome = kUnstable and advice in summary.message (measures unset); a
/// failure during a step (e.g. a restitution model that throws, on any thread) returns
/// with kFailed and the exception's message. A resume_state that does not fit the options
/// throws std::invalid_argument naming the field.
///
/// What the run reports and asks, through `hooks` (docs/dem.md "Checkpoints"):
/// - progress: stage "setup" before the world is built (eta_s the RunEstimate's wall time,
///   no rate) and once it is built, then "settling", "approach", "transient" and "analysis"
///   about twice a second (the clock is read every stride of ~65,536 particle-steps) with
///   done = simulated time since the drive started (negative while settling and
///   approaching), total = the run's end, steps_per_s and eta_s. No label: the caller names
///   the run (base::LabelledHooks).
/// - checkpoints: at the end of every drive period of the transient and the analysis the run
///   asks checkpoint_due(wall seconds since its last checkpoint, or since it started); when
///   due it passes its whole state to checkpoints.sink (the World, the step, the motion-mode
///   sums and, once analysing, the drive bins, the energy ledger's opening and the recorded
///   series, block in progress and snapshots), then asks stop_requested().
/// - stop: stop_requested() is also asked every kStopPollSteps steps and at period ends;
///   nonzero stores the state at that step and ends the run (DamperResult::stopped), or,
///   while the bed still settles or approaches (phases no checkpoint holds), ends it without
///   storing. The caller throws base::Interrupted.
DamperResult run_harmonic(const DamperSimulationOptions& options, base::RunHooks& hooks = base::silent_hooks(),
                          const CheckpointStorage& checkpoints = {});

}  // namespace pdamp::dem_reference
