#pragma once
// The frequency response of a structure with its beds as DEM worlds (the DEM in the loop,
// cosimulate): a stepped sine, each frequency continuing the previous one's state, and a
// linear sine sweep from the steady state at its start; their resonance measures.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pdamp/base/record.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/sampled_response.hpp"

namespace pdamp::structure {

/// The direction a frequency response is swept in.
enum class SweepDirection { kUp, kDown };
/// "up", "down".
std::string_view to_string(SweepDirection direction);

/// Settling to a steady state at each frequency of a stepped sine (and at a linear sweep's
/// start): the transient runs at least `min_transient_periods` and at most
/// `max_transient_periods` periods, and ends once the first site's per-period amplitude has
/// converged: over the last kConvergenceWindowPeriods periods every period-to-period change,
/// and the change across the window, at most `stable_tolerance` of the window's mean
/// (amplitudes_converged). A point that does not converge within the cap is analysed anyway
/// and reported unconverged. The default tolerance, 5%, refuses a beating or drifting
/// transient (a drift must be below 5%/7 per period) and passes a stationary bed whose
/// per-period amplitude scatters by up to about 1% at once; a bed scattering by several per
/// cent passes in a quieter stretch of 8 periods (the shipped beam case: 15-166 periods,
/// windows of 1.0-3.5% relative spread), and a subharmonic orbit (an amplitude repeating every
/// few periods) does not converge at all.
struct SteadyStateSettling {
  int min_transient_periods = 0;    ///< at least, per frequency, >= 0 (the case's /dem/transient_periods)
  int max_transient_periods = 200;  ///< at most, per frequency, >= 0 (raised to the minimum if below it)
  double stable_tolerance = 5e-2;   ///< amplitudes_converged's tolerance, (0, 1)
};

/// The co-simulation options of a stepped sine's points: `steady` with the settling rule and
/// the drive's phase π/2 at each frequency's start (U sin(Ω(t − t_i) + π/2): every run ends
/// on whole periods, so each junction is at the turning point, base displacement and
/// velocity, or the force, continuous).
SteadyStateRun stepped_sine_options(SteadyStateRun steady, const SteadyStateSettling& settling);

/// Whole steps per period of each frequency on the step `time_step_s` (N = round(1/(f·dt)),
/// the frequency run 1/(N·dt)); two equal counts are two points on one frequency.
std::vector<std::int64_t> stepped_sine_steps_per_period(const std::vector<double>& frequencies_hz, double time_step_s);

/// One frequency of a stepped sine.
struct SteppedSinePoint {
  SweepDirection sweep = SweepDirection::kUp;
  double frequency_hz = 0.0;           ///< as run (CosimulationSteadyState::frequency_hz)
  double requested_frequency_hz = 0.0;
  std::vector<double> magnitude, phase_deg;  ///< per damper: |ŷ_d| per unit excitation, arg ŷ_d in degrees
  std::vector<double> bed_eta_star, bed_apparent_mass_fraction;  ///< per damper, in the loop
  double spread = NAN;          ///< sample standard deviation of the analysed periods' |ŷ| of the first site, per unit excitation
  double standard_error = NAN;  ///< spread/√(analysed periods): periods taken as independent
  double energy_error = 0.0;
  int transient_periods = 0;  ///< periods run before the analysed ones
  int analysed_periods = 0;
  /// The transient converged (SteadyStateSettling) before the analysed periods; false: they
  /// may still carry it (a warning names the point).
  bool converged = false;
  bool stable = false;  ///< = converged (the former name)
  int periods() const { return transient_periods + analysed_periods; }  ///< periods run at this frequency
  /// The convergence window when the transient ended (CosimulationSteadyState::window_*):
  /// its periods, largest period-to-period change, change across it and relative standard
  /// deviation of the first site's per-period amplitude.
  int window_periods = 0;
  double window_max_relative_change = NAN, window_relative_drift = NAN, window_relative_spread = NAN;
  /// |ŷ| of the first site in each period run (transient and analysed), per unit excitation.
  std::vector<double> period_magnitudes;
  std::int64_t steps = 0;
  double time_step_s = 0.0, wall_time_s = 0.0;
  std::vector<std::string> warnings;  ///< the co-simulation's
  /// A point of a result (its per-damper values keyed by the dampers' names) and of a job.
  static const base::Fields<SteppedSinePoint>& fields();
  /// A point compared with the other methods: the first site's magnitude and convergence.
  static const base::Fields<SteppedSinePoint>& summary_fields();
};

/// One direction of a stepped sine: its points in the order run.
struct SteppedSineBranch {
  SweepDirection sweep = SweepDirection::kUp;
  std::vector<SteppedSinePoint> points;
  double wall_time_s = 0.0;
  /// kCompleted, or the outcome of the point that stopped the branch (its `message` says
  /// why; the points before it are kept).
  dem_reference::Outcome outcome = dem_reference::Outcome::kCompleted;
  std::string message;
  static const base::Fields<SteppedSineBranch>& fields();
};

/// The common step of a stepped sine over `frequencies`: the smallest automatic step (each
/// period then the nearest whole number of steps). std::invalid_argument as cosimulate.
double stepped_sine_time_step(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const SteadyStateRun& run, const std::vector<double>& frequencies_hz);

/// One direction of a stepped sine over `frequencies_hz` in the order given: each frequency
/// continues the previous one's final state (modes, bed, the drive's phase); the bed is
/// settled once, before the first. `run` from stepped_sine_options, validated. Each point's
/// progress reaches `hooks` as "<k>/<n> <f> Hz <stage>", with the share of the branch done;
/// a stop request throws base::Interrupted.
SteppedSineBranch stepped_sine_branch(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                      SteadyStateRun run, const std::vector<double>& frequencies_hz,
                                      SweepDirection sweep, double time_step_s, base::RunHooks& hooks);

/// The points of a branch in ascending frequency and their resonance measures (sampled_peak)
/// of one output; the standard errors are the first output's (its per-period amplitudes are
/// recorded), the others' peaks have none.
struct SteppedSinePeak {
  std::vector<const SteppedSinePoint*> ascending;
  SampledPeak peak;
  std::size_t output = 0;
};
SteppedSinePeak stepped_sine_peak(const SteppedSineBranch& branch, std::size_t output = 0);

/// The default rate of a linear sweep: the quasi-stationary ratio (docs/cosimulation.md §6),
/// the time spent in the half-power band over the response time, 4πζ²f²/r, at
/// `quasi_stationary_ratio` for a resonance at f with damping ratio ζ, Hz/s. The cycles' lag
/// error is first order in 1/ratio: 2.2% at 63 on a linear mode, halving with the rate, so
/// about 1.4% at 100, below the DEM bed's own cycle-to-cycle scatter (3-4%).
double quasi_stationary_sweep_rate(double frequency_hz, double damping_ratio, double quasi_stationary_ratio = 100.0);

/// The peak of a linear sweep is read off the means of this many consecutive cycles (the
/// window of kSettledWindowPeriods), their standard error the window's spread over its root.
inline constexpr std::size_t kSweepWindowCycles = kSettledWindowPeriods;

/// One output's resonance measures over a sweep, read off the moving means of
/// kSweepWindowCycles consecutive cycles (ascending frequency); none with fewer cycles.
struct SweepPeak {
  std::vector<double> window_frequency_hz, window_magnitude, window_standard_error;
  SampledPeak peak;
  bool found() const { return !window_magnitude.empty(); }
  double standard_error() const { return found() ? window_standard_error[peak.index] : NAN; }
};
SweepPeak sweep_peak(const std::vector<CosimulationSweepCycle>& cycles, std::size_t output);

/// One direction of a linear sine sweep: the steady state at the start frequency, then the
/// sweep to the end frequency continuing from it.
struct LinearSineSweep {
  SweepDirection sweep = SweepDirection::kUp;
  double start_hz = 0.0, end_hz = 0.0, rate_hz_s = 0.0, duration_s = 0.0;
  int start_transient_periods = 0;
  bool start_stable = false;
  std::vector<CosimulationSweepCycle> cycles;
  double energy_error = 0.0, time_step_s = 0.0, wall_time_s = 0.0;
  std::int64_t steps = 0;
  std::vector<std::string> warnings;  ///< the co-simulations', "<sweep> sweep: " before each
  std::vector<SweepPeak> peaks;  ///< per output
  dem_reference::Outcome outcome = dem_reference::Outcome::kCompleted;  ///< as SteppedSineBranch
  std::string message;
  /// The run's summary in a result (its cycles are points of their own).
  static const base::Fields<LinearSineSweep>& fields();
};

/// The sweep of linear_sine_sweep: `steady`'s settings and drive, from `start_hz` to `end_hz`
/// at `rate_hz_s`.
SweepRun linear_sweep_run(const SteadyStateRun& steady, double start_hz, double end_hz, double rate_hz_s);

/// Runs one direction: `steady` (stepped_sine_options) settles the structure at `start_hz`
/// on the sweep's step, then the sweep runs to `end_hz` at `rate_hz_s`. Progress reaches
/// `hooks` labelled "start <f> Hz", then "sweep"; a stop request throws base::Interrupted.
LinearSineSweep linear_sine_sweep(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                  const SteadyStateRun& steady, SweepDirection sweep, double start_hz, double end_hz,
                                  double rate_hz_s, base::RunHooks& hooks);

}  // namespace pdamp::structure
