// Task kind frf (frf.hpp).
#include "pdamp/tasks/frf.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <cmath>
#include <map>
#include <numbers>

#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/tasks/case_checks.hpp"
#include "pdamp/tasks/decay.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

namespace st = structure;
using case_file::Case;
using nlohmann::json;
using base::format_number;
using base::InputError;
using base::NumericalError;

namespace {

/// --dem-signal linear: the longest sweep accepted, s (simulated), per direction.
constexpr double kMaxSweepDuration_s = 1e5;

const char* const kDemPeakNote =
    "frequency_hz: vertex of the parabola through the largest point and its neighbours; band: where the points "
    "stay >= 0.9 of the largest (linear between points), its centre a flat top's better-conditioned resonance "
    "frequency; indistinguishable: the points within two standard errors of the largest; maximum: from the point "
    "below them to the point above (where a curve with one maximum peaks); standard error = spread/sqrt(analysed "
    "periods); damping_ratio: half-power width (f2 - f1)/(2 f) between the points (null where a side does not fall "
    "to 1/sqrt(2) of the largest)";

bool base_excitation(const Case& c) { return c.task.frf->excitation == case_file::FrfTask::Excitation::kBase; }

/// The frf task's excitation, checked against the modal model (InputError naming /task/excitation).
st::Excitation task_excitation(const Case& c, const st::ModalModel& modal) {
  const auto& task = *c.task.frf;
  st::Excitation excitation;
  excitation.direction = {task.direction[0], task.direction[1]};
  if (task.excitation == case_file::FrfTask::Excitation::kBase) {
    excitation.kind = st::Excitation::Kind::kBaseTranslation;
    excitation.amplitude = task.base_amplitude_m;
  } else {
    excitation.kind = st::Excitation::Kind::kPointForce;
    excitation.amplitude = task.force_amplitude_n;
    excitation.point = task.force_point;
  }
  if (const auto problems = excitation.validate(modal); !problems.empty())
    throw InputError(c.path, "/task/excitation", problems.front());
  return excitation;
}

/// The harmonic balance over the frf task's frequencies for the setup's loss models.
st::FrequencyResponse task_harmonic_balance(const Case& c, const detail::Setup& setup, const st::Excitation& excitation) {
  const auto& task = *c.task.frf;
  st::HarmonicBalanceOptions options;
  options.frequencies_hz = detail::spaced(task.min_frequency_hz, task.max_frequency_hz, task.points,
                                          task.spacing == surrogate::AxisSpacing::kLog);
  return detail::call_solver(c, "/task", [&] { return st::harmonic_balance(setup.s.modal, setup.s.dampers, excitation, options); });
}

/// The structure without particles over the task's band (the containers empty): linear,
/// so only each frequency's linear outputs count; the stroke range, which the solver asks
/// of dampers without layers, is a formality.
st::FrequencyResponse without_beds_response(const Case& c, detail::Setup setup) {
  for (auto& d : setup.s.dampers) d.layers.clear();
  const auto& task = *c.task.frf;
  st::HarmonicBalanceOptions options;
  options.frequencies_hz = detail::spaced(task.min_frequency_hz, task.max_frequency_hz, task.points,
                                          task.spacing == surrogate::AxisSpacing::kLog);
  options.stroke_min_m = 1e-6;
  options.stroke_max_m = 1.0;
  return detail::call_solver(c, "/task", [&] {
    return st::harmonic_balance(setup.s.modal, setup.s.dampers, task_excitation(c, setup.s.modal), options);
  });
}

/// pdamp frf --method formulas|field: the harmonic balance, its checks and warnings.
HarmonicFrf harmonic_frf(const Case& c, detail::Setup& setup) {
  HarmonicFrf out;
  out.method = setup.method;
  out.damper_names = detail::damper_names(setup);
  out.spacing = c.task.frf->spacing;
  out.response = task_harmonic_balance(c, setup, task_excitation(c, setup.s.modal));
  const auto& response = out.response;
  std::size_t with_state = 0;
  for (const auto& p : response.points)
    if (!p.roots.empty() || !p.held_at_jump.empty()) ++with_state;
  if (with_state == 0)
    throw NumericalError("pdamp frf: no first-harmonic response found at any frequency (" + response.brief_report() +
                         "); check the excitation amplitude against the layers' stroke range, or try --method formulas");
  for (const auto& p : response.peaks)
    if (!std::isfinite(p.frequency_hz) || !std::isfinite(p.magnitude))
      throw NumericalError("pdamp frf: a response peak is not finite (" + response.brief_report() + ")");
  setup.warnings.add(response.warnings);
  out.converged = response.outcome == st::FrequencyResponse::Outcome::kConverged;
  if (!out.converged)
    setup.warnings.add("some roots did not converge (" + std::to_string(response.unconverged_starts) +
                       " Newton starts failed): the response may miss branches");
  return out;
}

/// The harmonic-balance FRF of one loss method as --compare runs it (warnings prefixed).
HarmonicFrf compared_response(const Case& c, detail::Setup& setup) {
  HarmonicFrf out;
  out.method = setup.method;
  out.damper_names = detail::damper_names(setup);
  out.response = task_harmonic_balance(c, setup, task_excitation(c, setup.s.modal));
  const auto& response = out.response;
  for (const auto& p : response.peaks)
    if (!std::isfinite(p.frequency_hz) || !std::isfinite(p.magnitude))
      throw NumericalError("pdamp frf --compare: a response peak is not finite (" + response.brief_report() + ")");
  const std::string method(case_file::to_string(setup.method));
  setup.warnings.add(response.warnings, method + ": ");
  out.converged = response.outcome == st::FrequencyResponse::Outcome::kConverged;
  if (!out.converged)
    setup.warnings.add(method + ": some roots did not converge (" + std::to_string(response.unconverged_starts) +
                       " Newton starts failed): the response may miss branches");
  return out;
}

/// The frf task's harmonic co-simulation options: excitation, each frequency settled to a
/// steady state, the case's DEM settings; the excitation checked (InputError naming /task/excitation).
st::SteadyStateRun dem_frf_options(const Case& c, const st::ModalModel& modal, const st::SteadyStateSettling& settling) {
  const auto& task = *c.task.frf;
  const bool base_motion = base_excitation(c);
  st::SteadyStateRun options;
  options.excitation.kind = base_motion ? st::CosimulationExcitationKind::kBaseTranslation : st::CosimulationExcitationKind::kPointForce;
  options.excitation.direction = {task.direction[0], task.direction[1]};
  options.excitation.amplitude = base_motion ? task.base_amplitude_m : task.force_amplitude_n;
  options.excitation.point = base_motion ? std::string() : task.force_point;
  options.analysed_periods = c.dem.simulation.analysed_periods;
  options.bed_settling_time_s = c.dem.simulation.settling_time_s;
  task_excitation(c, modal);  // the excitation's own checks first
  return st::stepped_sine_options(options, settling);
}

/// The settling of each frequency: the options' rule with the case's /dem/transient_periods
/// as the least transient.
st::SteadyStateSettling case_settling(const Case& c, st::SteadyStateSettling settling) {
  settling.min_transient_periods = c.dem.simulation.transient_periods;
  settling.max_transient_periods = std::max(settling.max_transient_periods, settling.min_transient_periods);
  return settling;
}

/// Refuses (InputError naming the flags) a stepped sine whose points would fall on one
/// frequency: equal requested frequencies, or two that round to the same whole steps per
/// period of the sweep's step.
void check_distinct_frequencies(const std::vector<double>& frequencies_hz, double time_step_s, int points) {
  const std::vector<std::int64_t> steps = st::stepped_sine_steps_per_period(frequencies_hz, time_step_s);
  for (std::size_t i = 1; i < frequencies_hz.size(); ++i)
    if (steps[i] == steps[i - 1] || !(frequencies_hz[i] > frequencies_hz[i - 1]))
      throw InputError("--dem-points, --dem-min-frequency, --dem-max-frequency", "",
                       std::to_string(points) + " points over [" + format_number(frequencies_hz.front(), 10) + ", " +
                           format_number(frequencies_hz.back(), 10) + "] Hz: points " + std::to_string(i) + " and " +
                           std::to_string(i + 1) + " (" + format_number(frequencies_hz[i - 1], 10) + " and " +
                           format_number(frequencies_hz[i], 10) + " Hz) fall on one frequency (" +
                           std::to_string(steps[i]) + " steps of " + format_number(time_step_s, 4) +
                           " s per period): fewer points or a wider band");
}

/// The warnings of a branch's points: the co-simulation's, a point that did not settle, an
/// energy ledger that does not close.
std::vector<std::string> branch_warnings(const st::SteppedSineBranch& branch, const st::SteadyStateSettling& settling) {
  std::vector<std::string> out;
  for (const auto& p : branch.points) {
    out.insert(out.end(), p.warnings.begin(), p.warnings.end());
    if (!p.converged) {
      const std::string head = std::string(st::to_string(branch.sweep)) + " sweep at " + format_number(p.frequency_hz, 5) + " Hz: not converged after " +
                               std::to_string(p.transient_periods) + " transient periods: ";
      const std::string tail = ": the point is marked unconverged and left out of the stable curve";
      if (p.window_periods < 2)
        out.push_back(head + "no two periods to compare (fewer than the " + std::to_string(st::kConvergenceWindowPeriods) +
                      " of the convergence window; raise --dem-max-periods)" + tail);
      else
        out.push_back(head + "the site amplitude's period-to-period change reached " +
                      format_number(p.window_max_relative_change, 3) + " (across the window " +
                      format_number(p.window_relative_drift, 3) + ", relative spread " +
                      format_number(p.window_relative_spread, 3) + ") over the last " + std::to_string(p.window_periods) +
                      " periods" +
                      (p.window_periods < static_cast<int>(st::kConvergenceWindowPeriods)
                           ? ", fewer than the " + std::to_string(st::kConvergenceWindowPeriods) +
                                 " of the convergence window (raise --dem-max-periods)"
                           : ", above the tolerance " + format_number(settling.stable_tolerance)) +
                      tail);
    }
    if (p.energy_error > 0.01)
      out.push_back(std::string(st::to_string(branch.sweep)) + " sweep at " + format_number(p.frequency_hz, 5) +
                    " Hz: the co-simulation's energy ledger "
                    "closes to " + format_number(p.energy_error, 3) + " only: a smaller /dem/time_step_s");
  }
  return out;
}

/// The stepped sine over the band, up and down, the directions as jobs of `executor` (a
/// direction cannot be split: each frequency continues from the previous one's state).
SteppedSineFrf stepped_sine(const Case& c, detail::Setup& setup, const DemFrfOptions& o, base::RunHooks& hooks, base::Executor& executor) {
  const st::ModalModel& modal = setup.s.modal;
  auto dampers = detail::dem_dampers(c);
  const st::SteadyStateSettling settling = case_settling(c, o.settling);
  const st::SteadyStateRun options = dem_frf_options(c, modal, settling);
  SteppedSineFrf out;
  out.frequencies_hz = detail::spaced(o.min_frequency_hz, o.max_frequency_hz, o.points, false);
  const double spacing = (o.max_frequency_hz - o.min_frequency_hz) / std::max(o.points - 1, 1);
  for (const double f : o.extra_frequencies_hz) {
    const bool near_grid = std::any_of(out.frequencies_hz.begin(), out.frequencies_hz.end(),
                                       [&](double g) { return std::abs(g - f) < 0.25 * spacing; });
    if (!near_grid) out.frequencies_hz.insert(std::upper_bound(out.frequencies_hz.begin(), out.frequencies_hz.end(), f), f);
  }
  out.analysed_periods = options.analysed_periods;
  out.settling = settling;
  for (const double f : out.frequencies_hz) {  // every point's options checked before any runs
    st::SteadyStateRun o = options;
    o.excitation.frequency_hz = f;
    detail::check_cosimulation(c, modal, dampers, o);
  }
  out.time_step_s = detail::call_dem(c, [&] { return st::stepped_sine_time_step(modal, dampers, options, out.frequencies_hz); });
  check_distinct_frequencies(out.frequencies_hz, out.time_step_s, o.points);
  std::vector<std::pair<st::SweepDirection, std::vector<double>>> directions;
  for (const auto d : o.directions)
    directions.push_back({d, d == st::SweepDirection::kUp
                                 ? out.frequencies_hz
                                 : std::vector<double>(out.frequencies_hz.rbegin(), out.frequencies_hz.rend())});
  out.parallel = base::parallel_jobs(executor, directions.size());
  {
    // At most max_transient_periods + analysed_periods a point (fewer once its transient
    // has converged), every direction: an upper bound, said as one (not refused on it).
    double simulated_s = 0.0;
    for (const double f : out.frequencies_hz)
      simulated_s += static_cast<double>(settling.max_transient_periods + options.analysed_periods) / f;
    const auto steps = static_cast<std::int64_t>(std::ceil(static_cast<double>(directions.size()) * simulated_s /
                                                           out.time_step_s));
    CoupledRunEstimate e = estimate_coupled_steps(dampers, out.time_step_s, steps);
    e.wall_time_s /= out.parallel ? 2.0 : 1.0;
    hooks.note("pdamp frf (dem): at most " + estimate_text(e) + " (a point ends early once its transient converges)");
  }
  // Two sweeps on two cores: one thread each (the worlds' own OpenMP would oversubscribe).
  // On several processes too, so that a direction run elsewhere is the serial run's bit for bit.
  if (out.parallel)
    for (auto& d : dampers) d.world.threads = 1;
  if (executor.processes() > 1)
    hooks.note("pdamp frf (dem): " + std::to_string(directions.size()) + " sweep direction(s) over " +
               std::to_string(executor.processes()) + " MPI ranks; progress lines only of a direction run on rank 0");
  const auto started = std::chrono::steady_clock::now();
  const std::size_t n = out.frequencies_hz.size();
  out.branches = base::run_jobs<st::SteppedSineBranch>(
      executor, directions.size(), out.parallel,
      [&](std::size_t k) {
        // Named references, not a structured binding: clang 14 cannot capture bindings in lambdas.
        const st::SweepDirection sweep = directions.at(k).first;
        const std::string sweep_name(st::to_string(sweep));
        const std::vector<double>& frequencies = directions.at(k).second;
        const auto label = [&](std::size_t i) {
          return "pdamp frf (dem) " + sweep_name + " " + std::to_string(i + 1) + "/" + std::to_string(n) + " " +
                 format_number(frequencies[i], 5) + " Hz";
        };
        // One progress line per direction: the point and its stage (stepped_sine_branch).
        base::LabelledHooks direction(hooks, "pdamp frf (dem) " + sweep_name);
        auto branch = detail::call_dem(
            c, [&] { return st::stepped_sine_branch(modal, dampers, options, frequencies, sweep, out.time_step_s, direction); });
        // The point that stopped the branch is the first without a result; a completed branch has none.
        detail::check_outcome(branch.outcome, branch.message, label(std::min(branch.points.size(), n - 1)));
        for (std::size_t i = 0; i < branch.points.size(); ++i)
          for (double m : branch.points[i].magnitude)
            if (!std::isfinite(m)) throw NumericalError(label(i) + ": the steady-state amplitude is not finite");
        return branch;
      },
      &out.mpi);
  out.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (const auto& b : out.branches) setup.warnings.add(branch_warnings(b, settling));
  for (const auto& d : dampers) out.damper_names.push_back(d.name);
  return out;
}

/// The default rate from the formulas' harmonic balance (its largest first-output peak), or
/// from the lightest-damped mode in the band when that peak has no half-power band.
double default_sweep_rate(const Case& c, detail::Setup& formulas, const DemFrfOptions& o, std::string& basis) {
  const auto response = task_harmonic_balance(c, formulas, task_excitation(c, formulas.s.modal));
  double f = NAN, zeta = NAN;
  if (const st::ResponsePeak* p = first_output_peak(response); p && std::isfinite(p->damping_ratio) && p->damping_ratio > 0)
    f = p->frequency_hz, zeta = p->damping_ratio, basis = "the formulas' resonance";
  if (!std::isfinite(zeta)) {
    const auto& modal = formulas.s.modal;
    for (Eigen::Index j = 0; j < modal.mode_count(); ++j) {
      const double fj = modal.natural_frequencies_hz[j], zj = std::max(modal.damping_ratios[j], 1e-4);
      if (fj >= o.min_frequency_hz && fj <= o.max_frequency_hz && !(zj >= zeta)) f = fj, zeta = zj;
    }
    basis = "the lightest-damped bare mode in the band";
  }
  if (!std::isfinite(zeta))
    throw InputError("--dem-sweep-rate", "", "not given, and neither a resonance of the formulas nor a mode lies in [" +
                                                 format_number(o.min_frequency_hz) + ", " + format_number(o.max_frequency_hz) +
                                                 "] Hz: give the rate in Hz/s");
  basis += " (" + format_number(f, 4) + " Hz, zeta " + format_number(zeta, 3) + ")";
  return st::quasi_stationary_sweep_rate(f, zeta);
}

/// --dem-signal linear: per direction, the structure brought to its steady state at the
/// band's start, then a linear sine sweep to the other end; the directions in parallel.
LinearSweepFrf linear_sweep(const Case& c, detail::Setup& setup, const DemFrfOptions& o, base::RunHooks& hooks) {
  const st::ModalModel& modal = setup.s.modal;
  auto dampers = detail::dem_dampers(c);
  const st::SteadyStateSettling settling = case_settling(c, o.settling);
  const st::SteadyStateRun steady = dem_frf_options(c, modal, settling);
  LinearSweepFrf out;
  out.min_frequency_hz = o.min_frequency_hz;
  out.max_frequency_hz = o.max_frequency_hz;
  out.rate_basis = "--dem-sweep-rate";
  out.rate_hz_s = o.sweep_rate_hz_s ? *o.sweep_rate_hz_s : default_sweep_rate(c, setup, o, out.rate_basis);
  out.duration_s = (o.max_frequency_hz - o.min_frequency_hz) / out.rate_hz_s;
  if (!(out.duration_s <= kMaxSweepDuration_s))
    throw InputError("--dem-sweep-rate", "", format_number(out.rate_hz_s) + " Hz/s: the sweep over [" +
                                                 format_number(o.min_frequency_hz) + ", " + format_number(o.max_frequency_hz) +
                                                 "] Hz would take " + format_number(out.duration_s) + " s (at most " +
                                                 format_number(kMaxSweepDuration_s) + " s): a faster rate or a narrower band");
  out.sweeps.resize(o.directions.size());
  out.parallel = o.directions.size() > 1 && std::thread::hardware_concurrency() >= 2;
  if (out.parallel)
    for (auto& d : dampers) d.world.threads = 1;
  const auto up = [](st::SweepDirection d) { return d == st::SweepDirection::kUp; };
  for (const auto direction : o.directions) {  // every run's options checked before any starts
    const st::SweepRun run = st::linear_sweep_run(steady, up(direction) ? o.min_frequency_hz : o.max_frequency_hz,
                                                  up(direction) ? o.max_frequency_hz : o.min_frequency_hz, out.rate_hz_s);
    detail::check_cosimulation(c, modal, dampers, run);
    detail::call_dem(c, [&] { return st::cosimulation_time_step(modal, dampers, run); });
  }
  const auto started = std::chrono::steady_clock::now();
  base::for_each_concurrently(out.sweeps.size(), out.parallel, [&](std::size_t k) {
    const st::SweepDirection direction = o.directions[k];
    const double start = up(direction) ? o.min_frequency_hz : o.max_frequency_hz;
    const double end = up(direction) ? o.max_frequency_hz : o.min_frequency_hz;
    const std::string label = "pdamp frf (dem) linear " + std::string(st::to_string(direction));
    const std::string labels[2] = {label + " start " + format_number(start, 5) + " Hz", label + " sweep"};
    base::LabelledHooks labelled(hooks, label);
    auto s = detail::call_dem(
        c, [&] { return st::linear_sine_sweep(modal, dampers, steady, direction, start, end, out.rate_hz_s, labelled); });
    detail::check_outcome(s.outcome, s.message, labels[s.cycles.empty() && s.start_transient_periods == 0 ? 0 : 1]);
    for (const auto& cycle : s.cycles)
      for (double m : cycle.site_amplitude_per_excitation)
        if (!std::isfinite(m)) throw NumericalError(label + ": a cycle's amplitude is not finite");
    if (!s.start_stable)
      s.warnings.push_back(std::string(st::to_string(s.sweep)) + " sweep: the steady state at " + format_number(s.start_hz, 5) +
                           " Hz was not reached within " + std::to_string(settling.max_transient_periods) +
                           " periods: the sweep's first cycles may carry the transient");
    if (s.energy_error > 0.01)
      s.warnings.push_back(std::string(st::to_string(s.sweep)) + " sweep: the co-simulation's energy ledger closes to " +
                           format_number(s.energy_error, 3) + " only: a smaller /dem/time_step_s");
    out.sweeps[k] = std::move(s);
  });
  out.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (const auto& s : out.sweeps) setup.warnings.add(s.warnings);
  for (const auto& d : dampers) out.damper_names.push_back(d.name);
  return out;
}

/// A branch's resonance of output `output` named `name`.
DemPeak dem_peak(const std::string& name, const st::SteppedSineBranch& branch, const st::SteppedSinePeak& bp) {
  const st::SteppedSinePoint& top = *bp.ascending[bp.peak.index];
  DemPeak out;
  out.output = name;
  out.sweep = branch.sweep;
  out.frequency_hz = bp.peak.frequency_hz;
  out.largest_point_frequency_hz = top.frequency_hz;
  out.magnitude = bp.peak.magnitude;
  if (bp.output == 0) out.magnitude_standard_error = top.standard_error;
  out.band_low_hz = bp.peak.band.low_hz;
  out.band_high_hz = bp.peak.band.high_hz;
  out.band_centre_hz = bp.peak.band_centre_hz;
  out.indistinguishable_low_hz = bp.peak.indistinguishable_low_hz;
  out.indistinguishable_high_hz = bp.peak.indistinguishable_high_hz;
  out.maximum_low_hz = bp.peak.maximum_low_hz;
  out.maximum_high_hz = bp.peak.maximum_high_hz;
  out.damping_ratio = bp.peak.damping_ratio;
  return out;
}

/// A linear sweep's resonance of output `output` named `name` (NaN where none was found).
DemPeak sweep_peak(const std::string& name, const st::LinearSineSweep& s, std::size_t output) {
  const st::SweepPeak& sp = s.peaks[output];
  DemPeak out;
  out.output = name;
  out.sweep = s.sweep;
  if (!sp.found()) return out;
  out.frequency_hz = sp.peak.frequency_hz;
  out.magnitude = sp.peak.magnitude;
  out.magnitude_standard_error = sp.standard_error();
  out.band_low_hz = sp.peak.band.low_hz;
  out.band_high_hz = sp.peak.band.high_hz;
  out.band_centre_hz = sp.peak.band_centre_hz;
  out.damping_ratio = sp.peak.damping_ratio;
  return out;
}

/// How a method's largest first-output peak agrees with a DEM branch's (none without a peak).
std::optional<PeakAgreement> peak_agreement(const st::ResponsePeak* peak, const st::SampledPeak& dem) {
  if (!peak) return std::nullopt;
  PeakAgreement a;
  a.frequency_hz = peak->frequency_hz;
  a.band_centre_hz = peak->band_centre_hz;
  a.magnitude = peak->magnitude;
  a.frequency_relative_difference = (peak->frequency_hz - dem.frequency_hz) / dem.frequency_hz;
  a.band_centre_relative_difference = (peak->band_centre_hz - dem.band_centre_hz) / dem.band_centre_hz;
  a.magnitude_relative_difference = (peak->magnitude - dem.magnitude) / dem.magnitude;
  a.damping_ratio = peak->damping_ratio;
  a.dem_damping_ratio = dem.damping_ratio;
  a.frequency_within_dem_indistinguishable =
      peak->frequency_hz >= dem.indistinguishable_low_hz && peak->frequency_hz <= dem.indistinguishable_high_hz;
  a.frequency_within_dem_maximum = peak->frequency_hz >= dem.maximum_low_hz && peak->frequency_hz <= dem.maximum_high_hz;
  return a;
}

json harmonic_result(const FrfResult& r, const HarmonicFrf& h, const OutputFolder& folder) {
  const auto& response = h.response;
  const bool base_motion = r.base_excitation;
  std::size_t held = 0;
  for (const auto& p : response.points)
    if (!p.held_at_jump.empty()) ++held;
  // Branches: the frequency span and stability of each.
  struct BranchInfo {
    double f_min = INFINITY, f_max = -INFINITY, x_max = 0.0;
    std::size_t points = 0, stable = 0, unstable = 0, marginal = 0;
  };
  std::map<int, BranchInfo> info;
  for (const auto& p : response.points)
    for (const auto& root : p.roots) {
      auto& b = info[root.branch_id];
      b.f_min = std::min(b.f_min, p.frequency_hz);
      b.f_max = std::max(b.f_max, p.frequency_hz);
      if (!root.damper_amplitudes_m.empty()) b.x_max = std::max(b.x_max, root.damper_amplitudes_m.front());
      ++b.points;
      (root.stability == st::Stability::kStable ? b.stable : root.stability == st::Stability::kUnstable ? b.unstable : b.marginal)++;
    }
  json branches = json::array();
  for (const auto& [id, b] : info)
    branches.push_back({{"branch", id}, {"min_frequency_hz", b.f_min}, {"max_frequency_hz", b.f_max},
                        {"points", b.points}, {"stable_points", b.stable}, {"unstable_points", b.unstable},
                        {"marginal_points", b.marginal}, {"max_amplitude_m", b.x_max}});
  json jumps = json::array();
  for (const auto& e : response.branch_ends) {
    json j = {{"kind", branch_end_kind(e.kind)}, {"frequency_hz", e.frequency_hz}, {"amplitude_m", e.damper_amplitude_m},
              {"branch", e.branch_id}, {"branch_exists_below", e.ends_toward_higher_frequency}};
    if (e.kind == st::BranchEnd::Kind::kFold) j["other_branch"] = e.other_branch_id;
    jumps.push_back(std::move(j));
  }
  const json peaks = base::to_json(peak_summaries(response.peaks, response.output_names));
  json frf = {{"file", folder.file("frf.csv")},
              {"branches_file", folder.file("frf_branches.csv")},
              {"plot", folder.file("frf.png")},
              {"method", case_file::to_string(h.method)},
              {"outputs", response.output_names},
              {"magnitude", magnitude_description(r)},
              {"excitation", base_motion ? "base" : "force"},
              {"frequencies", {{"min_hz", response.points.front().frequency_hz},
                               {"max_hz", response.points.back().frequency_hz},
                               {"points", response.points.size()},
                               {"spacing", h.spacing == surrogate::AxisSpacing::kLog ? "log" : "linear"}}},
              {"peaks", peaks},
              {"linear_peaks", base::to_json(peak_summaries(response.linear_peaks, response.output_names))},
              {"jumps", jumps},
              {"branches", branches},
              {"held_at_jump_points", held},
              {"outcome", h.converged ? "converged" : "some_roots_not_converged"},
              {"loss_evaluations", response.loss_evaluations},
              {"solve_time_s", response.solve_time_s},
              {"report", response.brief_report()},
              {"warnings", r.warnings}};
  json result = {{"task", "frf"}, {"case", r.case_name}, {"method", case_file::to_string(h.method)}};
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["branches"] = branches;
  result["frf"] = frf;
  return result;
}

const char* const kConvergenceRule =
    "a point's transient ends once, over the last convergence_window_periods periods (and after at least "
    "min_transient_periods, the case's /dem/transient_periods), every period-to-period change of the first site's "
    "amplitude and its change across the window are at most stable_tolerance of the window's mean; otherwise after "
    "max_transient_periods, and the point is converged = false";

json stepped_result(const FrfResult& r, const SteppedSineFrf& s, const OutputFolder& folder) {
  const bool base_motion = r.base_excitation;
  const auto& names = s.damper_names;
  json peaks = json::array(), list = json::array();
  for (const auto& branch : s.branches) {
    for (std::size_t d = 0; d < names.size(); ++d)
      peaks.push_back(base::to_json(dem_peak(names[d], branch, st::stepped_sine_peak(branch, d))));
    for (const auto& p : branch.points) list.push_back(base::to_json(p, &names));
  }
  const std::string bed_state =
      "each direction (up, down) continues from frequency to frequency with the previous one's final state: modes "
      "(q, dq/dt), the bed (particles and contacts) and the drive's phase; the bed is settled once, before a "
      "direction's first frequency";
  json sweeps = json::array();
  for (const auto& b : s.branches) sweeps.push_back(st::to_string(b.sweep));
  json frf = {{"file", folder.file("frf_dem.csv")},
              {"plot", folder.file("frf_dem.png")},
              {"method", "dem"},
              {"outputs", names},
              {"magnitude", magnitude_description(r)},
              {"excitation", base_motion ? "base" : "force"},
              {"frequencies", {{"min_hz", s.frequencies_hz.front()}, {"max_hz", s.frequencies_hz.back()},
                               {"points", s.frequencies_hz.size()}, {"spacing", "linear"}}},
              {"points", list},
              {"peaks", peaks},
              {"peak_note", kDemPeakNote},
              {"bed_carried_over", true},
              {"stepped_sine", {{"sweeps", sweeps},
                                {"parallel", s.parallel},
                                {"bed_state", bed_state}, {"bed_carried_over", true},
                                {"drive", "sin(2 pi f (t - t_i) + pi/2) from each frequency's start t_i: the junctions "
                                          "are at the turning point, the base displacement and velocity (or the "
                                          "force) continuous"},
                                {"time_step_s", s.time_step_s},
                                {"min_transient_periods", s.settling.min_transient_periods},
                                {"max_transient_periods", s.settling.max_transient_periods},
                                {"stable_tolerance", s.settling.stable_tolerance},
                                {"convergence_window_periods", st::kConvergenceWindowPeriods},
                                {"convergence_rule", kConvergenceRule},
                                {"analysed_periods", s.analysed_periods}}},
              {"solve_time_s", s.solve_time_s},
              {"warnings", r.warnings}};
  json result = {{"task", "frf"}, {"case", r.case_name}, {"method", "dem"}};
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["branches"] = json::array();
  result["bed_carried_over"] = true;
  result["frf"] = frf;
  if (!s.mpi.is_null()) result["mpi"] = s.mpi;
  return result;
}

json linear_result(const FrfResult& r, const LinearSweepFrf& l, const OutputFolder& folder) {
  const bool base_motion = r.base_excitation;
  const auto& names = l.damper_names;
  json peaks = json::array(), list = json::array(), runs = json::array();
  for (const auto& s : l.sweeps) {
    for (std::size_t d = 0; d < names.size(); ++d) peaks.push_back(DemPeak::sweep_fields().to_json(sweep_peak(names[d], s, d)));
    runs.push_back(base::to_json(s));
    for (const auto& cycle : s.cycles) {
      json point = base::to_json(cycle, &names);
      point["sweep"] = st::to_string(s.sweep);
      list.push_back(std::move(point));
    }
  }
  json frf = {{"file", folder.file("frf_dem_sweep.csv")},
              {"plot", folder.file("frf_dem_sweep.png")},
              {"method", "dem"},
              {"signal", "linear_sweep"},
              {"outputs", names},
              {"magnitude", magnitude_description(r)},
              {"excitation", base_motion ? "base" : "force"},
              {"rate_hz_per_s", l.rate_hz_s},
              {"rate_basis", l.rate_basis},
              {"quasi_stationary_ratio_default", 100.0},
              {"sweeps", runs},
              {"parallel", l.parallel},
              {"points", list},
              {"peaks", peaks},
              {"peak_note", "the peak is read off moving means of " + std::to_string(st::kSweepWindowCycles) +
                                " consecutive cycles (standard error: their spread over the root of the count); a "
                                "sweep's response lags its drive by about a response time, so an up sweep's peak "
                                "sits above the steady one and a down sweep's below, by about rate x response time"},
              {"solve_time_s", l.solve_time_s},
              {"warnings", r.warnings}};
  json result = {{"task", "frf"}, {"case", r.case_name}, {"method", "dem"}, {"signal", "linear_sweep"}};
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["frf"] = frf;
  return result;
}

json compare_result(const FrfResult& r, const OutputFolder& folder) {
  const auto& f_response = r.harmonic->response;
  const std::vector<std::string>& names = f_response.output_names;
  const std::string output = names.empty() ? std::string() : names.front();
  json dem_list = json::array(), dem_peaks = json::array();
  for (const auto& branch : r.stepped->branches) {
    const st::SteppedSinePeak bp = st::stepped_sine_peak(branch);
    for (const st::SteppedSinePoint* p : bp.ascending) dem_list.push_back(st::SteppedSinePoint::summary_fields().to_json(*p));
    dem_peaks.push_back(base::to_json(dem_peak(output, branch, bp)));
  }
  const json f_peaks = base::to_json(peak_summaries(f_response.peaks, names));
  const json field_peaks =
      r.field ? base::to_json(peak_summaries(r.field->response.peaks, r.field->response.output_names)) : json(nullptr);
  json compare = {
      {"output", output},
      {"formulas", {{"peaks", f_peaks}}},
      {"field", r.field ? json{{"peaks", field_peaks}} : json(nullptr)},
      {"dem", {{"peaks", dem_peaks}, {"points", dem_list}, {"bed_carried_over", true}, {"peak_note", kDemPeakNote}}},
      {"agreement_definition", "(method - dem) / dem of the largest peak of the first output, per DEM sweep direction"},
      {"agreement", base::to_json(r.agreement)},
      {"file", folder.file("frf_compare.csv")},
      {"plot", folder.file("frf_compare.png")},
      {"dem_solve_time_s", r.stepped->solve_time_s}};
  json result = {{"task", "frf"}, {"case", r.case_name}, {"method", "compare"}};
  result["file"] = compare["file"];
  result["peaks"] = f_peaks;  // the contract's peaks: the formulas' (compare holds all three)
  result["branches"] = json::array();
  result["compare"] = compare;
  return result;
}

}  // namespace

const base::Fields<PeakSummary>& PeakSummary::fields() {
  using P = PeakSummary;
  static const auto f =
      base::Fields<P>()
          .field("output", &P::output, "", "the output (a damper's site or a named point)")
          .field("frequency_hz", &P::frequency_hz, "Hz", "parabola through the largest point and its neighbours")
          .field("magnitude", &P::magnitude, "1 or m/N", "the largest point's magnitude")
          .field("damping_ratio", &P::damping_ratio, "1", "half-power width (f2 - f1)/(2 f) (null: a side is missing)",
                 base::kNullable)
          .field("band_centre_hz", &P::band_centre_hz, "Hz", "centre of the band at >= 0.9 of the peak",
                 base::kNullable);
  return f;
}

std::vector<PeakSummary> peak_summaries(const std::vector<st::ResponsePeak>& peaks, const std::vector<std::string>& names) {
  std::vector<PeakSummary> out;
  for (const auto& p : peaks)
    out.push_back({p.output < names.size() ? names[p.output] : std::to_string(p.output), p.frequency_hz, p.magnitude,
                   p.damping_ratio, p.band_centre_hz});
  return out;
}

const base::Fields<DemPeak>& DemPeak::fields() {
  using P = DemPeak;
  static const auto f =
      base::Fields<P>()
          .field("output", &P::output, "", "the damper whose site this is")
          .field("sweep", &P::sweep, "", "the direction: up or down")
          .field("frequency_hz", &P::frequency_hz, "Hz", "vertex of the parabola through the largest point and its neighbours",
                 base::kNullable)
          .field("largest_point_frequency_hz", &P::largest_point_frequency_hz, "Hz", "the largest point's frequency")
          .field("magnitude", &P::magnitude, "1 or m/N", "the largest point's magnitude", base::kNullable)
          .field("magnitude_standard_error", &P::magnitude_standard_error, "1 or m/N",
                 "its standard error (the first output's only)", base::kNullable)
          .field("band_low_hz", &P::band_low_hz, "Hz", "low edge of the band at >= 0.9 of the peak", base::kNullable)
          .field("band_high_hz", &P::band_high_hz, "Hz", "high edge of that band", base::kNullable)
          .field("band_centre_hz", &P::band_centre_hz, "Hz", "its centre", base::kNullable)
          .field("indistinguishable_low_hz", &P::indistinguishable_low_hz, "Hz",
                 "lowest point within two standard errors of the largest")
          .field("indistinguishable_high_hz", &P::indistinguishable_high_hz, "Hz",
                 "highest point within two standard errors of the largest")
          .field("maximum_low_hz", &P::maximum_low_hz, "Hz",
                 "the point below the lowest of those (the sampled curve's maximum lies above it)")
          .field("maximum_high_hz", &P::maximum_high_hz, "Hz",
                 "the point above the highest of those (the sampled curve's maximum lies below it)")
          .field("damping_ratio", &P::damping_ratio, "1", "half-power width between the points", base::kNullable);
  return f;
}

const base::Fields<DemPeak>& DemPeak::sweep_fields() {
  static const auto f = fields().view({"output", "sweep", "frequency_hz", "magnitude", "magnitude_standard_error",
                                       "band_low_hz", "band_high_hz", "band_centre_hz", "damping_ratio"});
  return f;
}

const base::Fields<PeakAgreement>& PeakAgreement::fields() {
  using A = PeakAgreement;
  static const auto f =
      base::Fields<A>()
          .field("frequency_hz", &A::frequency_hz, "Hz", "the method's peak frequency")
          .field("band_centre_hz", &A::band_centre_hz, "Hz", "the method's 0.9 band centre", base::kNullable)
          .field("magnitude", &A::magnitude, "1 or m/N", "the method's peak magnitude")
          .field("frequency_relative_difference", &A::frequency_relative_difference, "1", "(method - dem)/dem",
                 base::kNullable)
          .field("band_centre_relative_difference", &A::band_centre_relative_difference, "1", "(method - dem)/dem",
                 base::kNullable)
          .field("magnitude_relative_difference", &A::magnitude_relative_difference, "1", "(method - dem)/dem",
                 base::kNullable)
          .field("damping_ratio", &A::damping_ratio, "1", "the method's half-power damping ratio", base::kNullable)
          .field("dem_damping_ratio", &A::dem_damping_ratio, "1", "the DEM's", base::kNullable)
          .field("frequency_within_dem_indistinguishable", &A::frequency_within_dem_indistinguishable, "",
                 "the method's peak lies among the DEM points that cannot be told from the largest")
          .field("frequency_within_dem_maximum", &A::frequency_within_dem_maximum, "",
                 "the method's peak lies where the DEM's maximum can be: between the points either side of those");
  return f;
}

const base::Fields<BranchAgreement>& BranchAgreement::fields() {
  using B = BranchAgreement;
  static const auto f =
      base::Fields<B>()
          .derived("reference", [](const B& b) { return "dem " + std::string(st::to_string(b.sweep)); }, "",
                   "the DEM direction compared with")
          .field("formulas", &B::formulas, "", "the closed forms' agreement (null: no peak)")
          .field("field", &B::field, "", "the effective fields' agreement (null: no field)");
  return f;
}

const st::ResponsePeak* first_output_peak(const st::FrequencyResponse& r) {
  const st::ResponsePeak* best = nullptr;
  for (const auto& p : r.peaks)
    if (p.output == 0 && (!best || p.magnitude > best->magnitude)) best = &p;
  return best;
}

std::string_view branch_end_kind(st::BranchEnd::Kind kind) {
  switch (kind) {
    case st::BranchEnd::Kind::kFold: return "fold";
    case st::BranchEnd::Kind::kDiscontinuity: return "discontinuity";
    case st::BranchEnd::Kind::kStrokeRange: return "stroke_range";
  }
  return "";
}

DemFrfOptions default_dem_frf_options(const Case& c) {
  DemFrfOptions o;
  if (c.task.frf) {
    o.min_frequency_hz = c.task.frf->min_frequency_hz;
    o.max_frequency_hz = c.task.frf->max_frequency_hz;
  }
  return o;
}

FrfResult run_frf(const Case& c, const FrfOptions& options, base::RunHooks& hooks, base::Executor& executor) {
  // Only the stepped sine's directions are spread: the harmonic balance and the linear sine
  // sweep (one co-simulation) run on the primary process alone.
  const bool stepped = options.method == FrfMethod::kCompare || (options.method == FrfMethod::kDem && !options.dem.linear_sweep);
  if (!stepped) executor.primary_only();
  require_task(c, case_file::TaskKind::kFrf);
  FrfResult out;
  out.case_name = c.name;
  out.method = options.method;
  out.base_excitation = base_excitation(c);
  switch (options.method) {
    case FrfMethod::kFormulas:
    case FrfMethod::kField: {
      detail::Setup setup = detail::make_setup(
          c, options.method == FrfMethod::kField ? case_file::LossMethod::kField : case_file::LossMethod::kFormulas);
      out.harmonic = harmonic_frf(c, setup);
      out.warnings = setup.warnings.list();
      break;
    }
    case FrfMethod::kDem: {
      detail::Setup setup = detail::make_setup(c, case_file::LossMethod::kFormulas, false);
      if (options.dem.linear_sweep) out.linear = linear_sweep(c, setup, options.dem, hooks);
      else out.stepped = stepped_sine(c, setup, options.dem, hooks, executor);
      out.without_beds = without_beds_response(c, setup);
      out.warnings = setup.warnings.list();
      break;
    }
    case FrfMethod::kCompare: {
      detail::Setup formulas = detail::make_setup(c, case_file::LossMethod::kFormulas);
      out.harmonic = compared_response(c, formulas);
      detail::Warnings& warnings = formulas.warnings;
      bool every_field = true;
      for (const auto& d : c.dampers)
        for (const auto& l : d.layers) every_field = every_field && !l.field_file.empty();
      if (every_field) {
        detail::Setup field = detail::make_setup(c, case_file::LossMethod::kField);
        out.field = compared_response(c, field);
        warnings.add(field.warnings.list());
      } else {
        warnings.add("--compare: the field curve is skipped: not every layer has a field_file (make one with pdamp field)");
      }
      detail::Setup dem = detail::make_setup(c, case_file::LossMethod::kFormulas, false);
      out.stepped = stepped_sine(c, dem, options.dem, hooks, executor);
      warnings.add(dem.warnings.list(), "dem: ");
      if (out.stepped->branches.empty() || out.stepped->branches.front().points.empty())
        throw NumericalError("pdamp frf --compare: the DEM sweep returned no points");
      for (const auto& branch : out.stepped->branches) {
        const st::SampledPeak dem = st::stepped_sine_peak(branch).peak;
        out.agreement.push_back({branch.sweep, peak_agreement(first_output_peak(out.harmonic->response), dem),
                                 out.field ? peak_agreement(first_output_peak(out.field->response), dem) : std::nullopt});
      }
      out.warnings = warnings.list();
      break;
    }
  }
  return out;
}

std::string magnitude_label(const FrfResult& r) {
  return r.base_excitation ? "transmissibility |X/U|" : "receptance |X/F| / (m/N)";
}

std::string magnitude_description(const FrfResult& r) {
  const std::string what = r.base_excitation ? "transmissibility |X/U| (absolute site motion over base amplitude)"
                                             : "receptance |X/F| in m/N";
  if (r.linear) return what + ", first harmonic of each drive cycle";
  if (r.method == FrfMethod::kDem) return what + ", first harmonic";
  return what;
}

std::vector<PeakSummary> response_peaks(const FrfResult& r) {
  const auto brief = [](const DemPeak& p) {
    return PeakSummary{p.output, p.frequency_hz, p.magnitude, p.damping_ratio, p.band_centre_hz};
  };
  std::vector<PeakSummary> out;
  switch (r.method) {
    case FrfMethod::kFormulas:
    case FrfMethod::kField: return peak_summaries(r.harmonic->response.peaks, r.harmonic->response.output_names);
    case FrfMethod::kDem:
      if (r.linear) {
        for (const auto& s : r.linear->sweeps)
          for (std::size_t d = 0; d < r.linear->damper_names.size(); ++d)
            out.push_back(brief(sweep_peak(r.linear->damper_names[d], s, d)));
      } else {
        for (const auto& branch : r.stepped->branches)
          for (std::size_t d = 0; d < r.stepped->damper_names.size(); ++d)
            out.push_back(brief(dem_peak(r.stepped->damper_names[d], branch, st::stepped_sine_peak(branch, d))));
      }
      return out;
    case FrfMethod::kCompare: return out;
  }
  return out;
}

json to_json(const FrfResult& r, const OutputFolder& folder) {
  switch (r.method) {
    case FrfMethod::kFormulas:
    case FrfMethod::kField: return harmonic_result(r, *r.harmonic, folder);
    case FrfMethod::kDem: return r.linear ? linear_result(r, *r.linear, folder) : stepped_result(r, *r.stepped, folder);
    case FrfMethod::kCompare: return compare_result(r, folder);
  }
  return nullptr;
}

}  // namespace pdamp::tasks
