// The DEM-in-the-loop frequency response: stepped sine and linear sine sweep
// (dem_frequency_response.hpp).
#include "pdamp/structure/dem_frequency_response.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "pdamp/base/number_text.hpp"

namespace pdamp::structure {

std::string_view to_string(SweepDirection direction) { return direction == SweepDirection::kUp ? "up" : "down"; }

const base::Fields<SteppedSinePoint>& SteppedSinePoint::fields() {
  using P = SteppedSinePoint;
  static const auto f =
      base::Fields<P>()
          .field("sweep", &P::sweep, "", "the direction: up or down")
          .field("frequency_hz", &P::frequency_hz, "Hz", "the frequency as run (whole steps per period)")
          .field("requested_frequency_hz", &P::requested_frequency_hz, "Hz", "the frequency asked for")
          .field("magnitude", &P::magnitude, "1 or m/N",
                 "first-harmonic amplitude of each damper's site per unit excitation", base::kPerOutput)
          .field("phase_deg", &P::phase_deg, "deg", "phase of each damper site's first harmonic", base::kPerOutput)
          .field("bed_eta_star", &P::bed_eta_star, "1", "each bed's reduced loss factor in the loop",
                 base::kPerOutput | base::kNullable)
          .field("bed_apparent_mass_fraction", &P::bed_apparent_mass_fraction, "1",
                 "each bed's apparent mass over its mass in the loop", base::kPerOutput | base::kNullable)
          .field("magnitude_spread", &P::spread, "1 or m/N",
                 "sample standard deviation of the analysed periods' first-site amplitude", base::kNullable)
          .field("magnitude_standard_error", &P::standard_error, "1 or m/N",
                 "the spread over the root of the analysed periods", base::kNullable)
          .field("energy_error", &P::energy_error, "1", "relative error of the co-simulation's energy ledger")
          .field("transient_periods", &P::transient_periods, "", "periods run before the analysed ones")
          .field("analysed_periods", &P::analysed_periods, "", "periods analysed")
          .derived("periods", [](const P& p) { return p.periods(); }, "", "periods run at this frequency")
          .derived("first_magnitude", [](const P& p) { return p.magnitude.front(); }, "1 or m/N",
                   "the first damper site's magnitude", base::kHidden)
          .field("converged", &P::converged, "", "the transient converged before the analysed periods")
          .field("stable", &P::stable, "", "= converged (the former name)")
          .group("convergence", "the convergence window when the transient ended",
                 base::Fields<P>()
                     .field("window_periods", &P::window_periods, "", "periods in the window")
                     .field("max_relative_change", &P::window_max_relative_change, "1",
                            "largest period-to-period change of the first site's amplitude", base::kNullable)
                     .field("relative_drift", &P::window_relative_drift, "1", "change across the window",
                            base::kNullable)
                     .field("relative_spread", &P::window_relative_spread, "1",
                            "relative standard deviation over the window", base::kNullable)
                     .field("period_magnitudes", &P::period_magnitudes, "1 or m/N",
                            "first-site amplitude of every period run, per unit excitation"))
          .field("steps", &P::steps, "", "integration steps")
          .field("time_step_s", &P::time_step_s, "s", "the integration step")
          .field("solve_time_s", &P::wall_time_s, "s", "wall time")
          .field("warnings", &P::warnings, "", "the co-simulation's warnings", base::kHidden);
  return f;
}

const base::Fields<SteppedSinePoint>& SteppedSinePoint::summary_fields() {
  static const auto f = fields().view({"sweep", "frequency_hz", "magnitude=first_magnitude", "magnitude_spread",
                                       "magnitude_standard_error", "energy_error", "converged", "stable", "periods",
                                       "convergence_max_relative_change=convergence/max_relative_change"});
  return f;
}

const base::Fields<LinearSineSweep>& LinearSineSweep::fields() {
  using S = LinearSineSweep;
  static const auto f =
      base::Fields<S>()
          .field("sweep", &S::sweep, "", "the direction: up or down")
          .field("start_hz", &S::start_hz, "Hz", "the frequency it starts from, at its steady state")
          .field("end_hz", &S::end_hz, "Hz", "the frequency it ends at")
          .field("rate_hz_per_s", &S::rate_hz_s, "Hz/s", "the sweep rate")
          .field("duration_s", &S::duration_s, "s", "the sweep's duration")
          .derived("cycles", [](const S& s) { return s.cycles.size(); }, "", "drive cycles analysed")
          .field("start_transient_periods", &S::start_transient_periods, "", "periods to the steady state at the start")
          .field("start_stable", &S::start_stable, "", "the steady state at the start was reached")
          .field("energy_error", &S::energy_error, "1", "relative error of the co-simulation's energy ledger")
          .field("steps", &S::steps, "", "integration steps")
          .field("time_step_s", &S::time_step_s, "s", "the integration step")
          .field("solve_time_s", &S::wall_time_s, "s", "wall time");
  return f;
}

const base::Fields<SteppedSineBranch>& SteppedSineBranch::fields() {
  using B = SteppedSineBranch;
  static const auto f = base::Fields<B>()
                            .field("sweep", &B::sweep, "", "the direction: up or down")
                            .field("points", &B::points, "", "the points in the order run")
                            .field("wall_time_s", &B::wall_time_s, "s", "wall time of the branch")
                            .field("outcome", &B::outcome, "", "completed, or why the branch stopped")
                            .field("message", &B::message, "", "what stopped the branch");
  return f;
}

SteadyStateRun stepped_sine_options(SteadyStateRun steady, const SteadyStateSettling& settling) {
  steady.transient_periods = std::max(settling.max_transient_periods, settling.min_transient_periods);
  steady.min_transient_periods = settling.min_transient_periods;
  steady.settle_until_stable = true;
  steady.stable_tolerance = settling.stable_tolerance;
  steady.excitation_phase_rad = std::numbers::pi / 2.0;
  return steady;
}

std::vector<std::int64_t> stepped_sine_steps_per_period(const std::vector<double>& frequencies_hz, double time_step_s) {
  std::vector<std::int64_t> out;
  for (const double f : frequencies_hz)
    out.push_back(std::max<std::int64_t>(1, std::llround(1.0 / (f * time_step_s))));
  return out;
}

double stepped_sine_time_step(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const SteadyStateRun& run, const std::vector<double>& frequencies_hz) {
  double dt = INFINITY;
  for (const double f : frequencies_hz) {
    SteadyStateRun o = run;
    o.excitation.frequency_hz = f;
    dt = std::min(dt, cosimulation_time_step(model, dampers, o).time_step_s);
  }
  return dt;
}

namespace {

/// Point `index` of `count` at `frequency_hz`: its reports as "<k>/<n> <f> Hz <stage>" with
/// the share of the branch done (a point's end time is an upper bound, so its share is capped).
class PointHooks : public base::ForwardingHooks {
 public:
  PointHooks(base::RunHooks& inner, std::size_t index, std::size_t count, double frequency_hz)
      : ForwardingHooks(inner), index_(index), count_(count),
        name_(std::to_string(index + 1) + "/" + std::to_string(count) + " " + base::format_number(frequency_hz, 4) +
              " Hz ") {}
  void progress(const base::Progress& p) override {
    base::Progress point = p;
    point.stage = name_ + p.stage;
    const double share = p.total > 0.0 ? std::min(1.0, p.done / p.total) : 0.0;
    point.fraction_done = (static_cast<double>(index_) + share) / static_cast<double>(count_);
    inner_.progress(point);
  }

 private:
  std::size_t index_, count_;
  std::string name_;
};

}  // namespace

SteppedSineBranch stepped_sine_branch(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                      SteadyStateRun run, const std::vector<double>& frequencies_hz,
                                      SweepDirection sweep, double time_step_s, base::RunHooks& hooks) {
  SteppedSineBranch branch;
  branch.sweep = sweep;
  CosimulationState state;  // the bed, the modes and the drive's phase, carried over
  for (std::size_t i = 0; i < frequencies_hz.size(); ++i) {
    run.excitation.frequency_hz = frequencies_hz[i];
    run.time_step_s = state.started() ? 0.0 : time_step_s;
    PointHooks point(hooks, i, frequencies_hz.size(), frequencies_hz[i]);
    const auto r = cosimulate(model, dampers, run, state, point);
    branch.wall_time_s += r.wall_time_s;
    if (r.outcome != dem_reference::Outcome::kCompleted) {
      branch.outcome = r.outcome;
      branch.message = r.message;
      return branch;
    }
    const auto& ss = r.steady_state;
    SteppedSinePoint p;
    p.sweep = sweep;
    p.frequency_hz = ss.frequency_hz;
    p.requested_frequency_hz = frequencies_hz[i];
    for (std::size_t d = 0; d < dampers.size(); ++d) {
      p.magnitude.push_back(ss.site_amplitude_per_excitation.at(d));
      p.phase_deg.push_back(std::arg(ss.site_amplitudes_m.at(d)) * 180.0 / std::numbers::pi);
      p.bed_eta_star.push_back(ss.bed_reduced_loss_factor.at(d));
      p.bed_apparent_mass_fraction.push_back(ss.bed_apparent_mass_fraction.at(d));
    }
    // Spread: sample standard deviation of the analysed periods' |ŷ| of the first site, per unit excitation.
    const auto& per = ss.period_site_amplitudes_m;
    const std::size_t na = static_cast<std::size_t>(std::max(ss.analysed_periods, 0));
    if (na >= 2 && per.size() >= na) {
      double mean = 0.0, var = 0.0;
      for (std::size_t k = per.size() - na; k < per.size(); ++k) mean += per[k];
      mean /= static_cast<double>(na);
      for (std::size_t k = per.size() - na; k < per.size(); ++k) var += (per[k] - mean) * (per[k] - mean);
      p.spread = std::sqrt(var / static_cast<double>(na - 1)) / run.excitation.amplitude;
      p.standard_error = p.spread / std::sqrt(static_cast<double>(na));
    }
    p.energy_error = r.energy.relative_error;
    p.transient_periods = ss.transient_periods;
    p.analysed_periods = ss.analysed_periods;
    p.converged = p.stable = ss.stable;
    p.window_periods = ss.window_periods;
    p.window_max_relative_change = ss.window_max_relative_change;
    p.window_relative_drift = ss.window_relative_drift;
    p.window_relative_spread = ss.window_relative_spread;
    for (const double a : per) p.period_magnitudes.push_back(a / run.excitation.amplitude);
    p.steps = r.steps;
    p.time_step_s = r.time_step_s;
    p.wall_time_s = r.wall_time_s;
    p.warnings = r.warnings;
    branch.points.push_back(std::move(p));
  }
  return branch;
}

SteppedSinePeak stepped_sine_peak(const SteppedSineBranch& branch, std::size_t output) {
  SteppedSinePeak out;
  out.output = output;
  for (const auto& p : branch.points) out.ascending.push_back(&p);
  std::sort(out.ascending.begin(), out.ascending.end(),
            [](const SteppedSinePoint* a, const SteppedSinePoint* b) { return a->frequency_hz < b->frequency_hz; });
  std::vector<double> f, m, se;
  for (const SteppedSinePoint* p : out.ascending) {
    f.push_back(p->frequency_hz);
    m.push_back(p->magnitude.at(output));
    se.push_back(output == 0 && std::isfinite(p->standard_error) ? p->standard_error : 0.0);
  }
  out.peak = sampled_peak(f, m, se);
  return out;
}

double quasi_stationary_sweep_rate(double frequency_hz, double damping_ratio, double quasi_stationary_ratio) {
  return 4.0 * std::numbers::pi * damping_ratio * damping_ratio * frequency_hz * frequency_hz / quasi_stationary_ratio;
}

SweepPeak sweep_peak(const std::vector<CosimulationSweepCycle>& cycles, std::size_t output) {
  SweepPeak out;
  std::vector<std::pair<double, double>> fm;
  for (const auto& c : cycles) fm.push_back({c.frequency_hz, c.site_amplitude_per_excitation.at(output)});
  std::sort(fm.begin(), fm.end());
  const std::size_t w = kSweepWindowCycles;
  for (std::size_t i = 0; i + w <= fm.size(); ++i) {
    double f = 0.0, m = 0.0, ss = 0.0;
    for (std::size_t k = i; k < i + w; ++k) f += fm[k].first, m += fm[k].second;
    f /= static_cast<double>(w);
    m /= static_cast<double>(w);
    for (std::size_t k = i; k < i + w; ++k) ss += (fm[k].second - m) * (fm[k].second - m);
    out.window_frequency_hz.push_back(f);
    out.window_magnitude.push_back(m);
    out.window_standard_error.push_back(std::sqrt(ss / static_cast<double>(w - 1)) / std::sqrt(static_cast<double>(w)));
  }
  if (out.found()) out.peak = sampled_peak(out.window_frequency_hz, out.window_magnitude, out.window_standard_error);
  return out;
}

SweepRun linear_sweep_run(const SteadyStateRun& steady, double start_hz, double end_hz, double rate_hz_s) {
  SweepRun run;
  static_cast<CosimulationSettings&>(run) = steady;
  run.excitation = steady.excitation;
  run.excitation.frequency_hz = start_hz;
  run.excitation_phase_rad = steady.excitation_phase_rad;
  run.sweep_end_frequency_hz = end_hz;
  run.duration_s = std::abs(end_hz - start_hz) / rate_hz_s;
  return run;
}

LinearSineSweep linear_sine_sweep(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                  const SteadyStateRun& steady, SweepDirection sweep, double start_hz, double end_hz,
                                  double rate_hz_s, base::RunHooks& hooks) {
  LinearSineSweep s;
  s.sweep = sweep;
  s.start_hz = start_hz;
  s.end_hz = end_hz;
  s.rate_hz_s = rate_hz_s;
  s.duration_s = std::abs(end_hz - start_hz) / rate_hz_s;
  const SweepRun run = linear_sweep_run(steady, start_hz, end_hz, rate_hz_s);
  SteadyStateRun start = steady;  // the steady state at the start, on the sweep's step
  start.excitation.frequency_hz = start_hz;
  start.time_step_s = cosimulation_time_step(model, dampers, run).time_step_s;
  CosimulationState state;
  base::LabelledHooks starting(hooks, "start " + base::format_number(start_hz, 5) + " Hz");
  const auto first = cosimulate(model, dampers, start, state, starting);
  s.wall_time_s = first.wall_time_s;
  s.steps = first.steps;
  for (const auto& w : first.warnings) s.warnings.push_back(std::string(to_string(sweep)) + " sweep: " + w);
  if (first.outcome != dem_reference::Outcome::kCompleted) {
    s.outcome = first.outcome;
    s.message = first.message;
    return s;
  }
  s.start_transient_periods = first.steady_state.transient_periods;
  s.start_stable = first.steady_state.stable;
  base::LabelledHooks sweeping(hooks, "sweep");
  const auto r = cosimulate(model, dampers, run, state, sweeping);
  for (const auto& w : r.warnings) s.warnings.push_back(std::string(to_string(sweep)) + " sweep: " + w);
  s.wall_time_s += r.wall_time_s;
  s.steps += r.steps;
  if (r.outcome != dem_reference::Outcome::kCompleted) {
    s.outcome = r.outcome;
    s.message = r.message;
    return s;
  }
  s.cycles = r.sweep_cycles;
  s.energy_error = r.energy.relative_error;
  s.time_step_s = r.time_step_s;
  for (std::size_t d = 0; d < dampers.size(); ++d) s.peaks.push_back(sweep_peak(s.cycles, d));
  return s;
}

}  // namespace pdamp::structure
