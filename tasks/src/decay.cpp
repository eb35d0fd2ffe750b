// Task kind decay (decay.hpp).
#include "pdamp/tasks/decay.hpp"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <optional>
#include <sstream>

#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/drive_time_step.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/tasks/case_checks.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

namespace st = structure;
using case_file::Case;
using nlohmann::json;
using base::format_number;
using base::InputError;
using base::NumericalError;

namespace {

/// Free-decay samples: about 50 per period of the first mode, at least 2000, at most 20000
/// (the averaging and the DEM in the loop alike).
constexpr double kDecaySamplesPerPeriod = 50.0;
constexpr double kDecayMinSamples = 2000.0;
constexpr double kDecayMaxSamples = 20000.0;

double decay_samples(const st::ModalModel& modal, double duration_s) {
  return std::clamp(std::ceil(kDecaySamplesPerPeriod * modal.natural_frequencies_hz[0] * duration_s), kDecayMinSamples,
                    kDecayMaxSamples);
}

/// Wall-clock seconds a segment aims at: short enough that an interrupted run stops soon,
/// long enough that its start (no allocation, a few vector copies) costs nothing.
constexpr double kSegmentWallSeconds = 2.0;
/// The first segment (settling included, no rate known yet): this fraction of the run.
constexpr double kFirstSegmentFraction = 0.01;
/// A segment is at most this many times the last one.
constexpr std::int64_t kSegmentGrowth = 4;

/// What must match for a resume besides the case's physics: the structure, the task, the
/// run's own settings (duration, sampling, q0, step) and the caller's (a design).
std::string decay_settings(const Case& c, const st::DecayRun& o, double dt, const std::string& own) {
  std::ostringstream s;
  s.precision(17);
  s << "structure " << surrogate::case_hash(c.resolved.value("structure", json())) << "; task "
    << surrogate::case_hash(c.resolved.value("task", json())) << "; duration_s " << o.duration_s
    << "; sample_interval_s " << o.sample_interval_s << "; time_step_s " << dt << "; snapshots " << o.snapshots << "; q0";
  for (Eigen::Index j = 0; j < o.initial_modal_displacements.size(); ++j) s << ' ' << o.initial_modal_displacements[j];
  if (!own.empty()) s << "; " << own;
  return s.str();
}

/// One co-simulation run of `options`, its refusals as the case's errors; a stop request
/// ends it keeping nothing (base::Interrupted).
st::CosimulationResult cosimulate_case(const Case& c, const st::ModalModel& modal,
                                       const std::vector<st::CosimulationDamper>& dampers, const st::DecayRun& options,
                                       const std::string& label, base::RunHooks& hooks, const DecayStop* stop) {
  detail::check_cosimulation(c, modal, dampers, options);
  base::LabelledHooks labelled(hooks, label);
  auto r = detail::call_dem(c, [&] {
    if (stop == nullptr) return st::cosimulate(modal, dampers, options, labelled);
    // Segments of a twentieth of a period give the bits of the whole run (Cosimulation).
    st::Cosimulation run(modal, dampers, options, labelled);
    const double steps_per_period = 1.0 / (stop->frequency_hz * run.time_step_s());
    double first = 0.0, peak = 0.0;
    for (std::int64_t sample = 1; !run.finished(); ++sample) {
      const auto target = std::llround(steps_per_period * static_cast<double>(sample) / DecayStop::kSamplesPerPeriod);
      run.advance(std::max<std::int64_t>(1, target - run.steps_done()));
      if (run.stop_signal() != 0)
        throw base::Interrupted(run.stop_signal(), "the co-simulation stopped; it had no checkpoint, so nothing was kept");
      peak = std::max(peak, std::abs(run.state().modal_displacements[stop->mode]));
      if (sample % DecayStop::kSamplesPerPeriod != 0) continue;
      if (sample == DecayStop::kSamplesPerPeriod) first = peak;
      else if (peak < stop->below * first) break;
      peak = 0.0;
    }
    return std::move(run).result();
  });
  detail::check_outcome(r.outcome, r.message, label);
  return r;
}

/// The decay of `options` in segments, checkpointed (DemDecayCheckpoint): one run
/// (structure::Cosimulation) advanced a segment at a time, its state saved between segments
/// when the hooks say so; segments give the bits of one uninterrupted run.
st::CosimulationResult checkpointed_decay(const Case& c, const st::ModalModel& modal,
                                          const std::vector<st::CosimulationDamper>& dampers,
                                          const st::DecayRun& options, const std::string& label,
                                          const std::string& estimate, const DemDecayCheckpoint& cp, base::RunHooks& hooks) {
  detail::check_cosimulation(c, modal, dampers, options);
  const double dt = detail::call_dem(c, [&] { return st::cosimulation_time_step(modal, dampers, options).time_step_s; });
  const std::int64_t sample_every = std::max<std::int64_t>(1, std::llround(options.sample_interval_s / dt));
  const std::int64_t total = std::llround(options.duration_s / dt);
  dem_reference::CheckpointHeader header;
  header.kind = cp.kind;
  header.case_hash = case_file::physics_hash(c, "dem");
  header.physics_model_version = dem_reference::kPhysicsModelVersion;
  header.settings = decay_settings(c, options, dt, cp.settings);
  header.end_time_s = static_cast<double>(total) * dt;
  const std::string shown = base::printable(cp.file.path.string());
  base::LabelledHooks labelled(hooks, label);

  std::optional<st::Cosimulation> run;
  if (cp.file.resume) {
    const std::string payload = read_checkpoint(cp.file, header);
    try {
      dem_reference::StateReader in(payload, "checkpoint state");
      run.emplace(st::Cosimulation::restore(modal, dampers, options, in, labelled));
      in.finish();
    } catch (const std::invalid_argument& e) {
      throw InputError(cp.file.path.string(), "", e.what());
    }
    const std::int64_t done = run->steps_done();
    if (done <= 0 || done > total || run->total_steps() != total)
      throw InputError(cp.file.path.string(), "", "its step count " + std::to_string(done) + " does not fit this run's " +
                                                      std::to_string(total) + " steps");
    hooks.note(estimate);
    hooks.note(label + ": resuming at t = " + format_number(static_cast<double>(done) * dt, 6) + " s of " +
               format_number(header.end_time_s, 6) + " s from " + shown);
  } else {
    hooks.note(estimate);
    if (std::filesystem::exists(cp.file.path))
      hooks.note("pdamp: warning: " + shown + " of an earlier run is replaced (--resume continues it)");
    try {
      run.emplace(detail::call_dem(c, [&] { return st::Cosimulation(modal, dampers, options, labelled); }));
    } catch (const base::Interrupted& e) {  // no checkpoint holds the beds' settling
      throw base::Interrupted(e.signal_number(), "the run stopped while its beds settled, before its first checkpoint: "
                                                 "run the same command again");
    }
  }

  auto last_checkpoint = std::chrono::steady_clock::now();
  std::int64_t segment = sample_every * std::max<std::int64_t>(1, std::llround(kFirstSegmentFraction *
                                                                                static_cast<double>(total / sample_every)));
  while (!run->finished()) {
    const auto started = std::chrono::steady_clock::now();
    // A stop request is met inside the segment (a segment of a big bed can be long).
    const std::int64_t steps = run->advance(segment);
    if (run->finished() && run->steps_done() < total) {  // a World stopped
      const auto r = run->result();
      detail::check_outcome(r.outcome, r.message, label);
    }
    // The next segment: about kSegmentWallSeconds at this segment's rate, whole sample
    // intervals, at most kSegmentGrowth times this one (a short first segment, settling and
    // all, measures its rate poorly).
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double rate = static_cast<double>(steps) / std::max(wall, 1e-3);
    // A progress line per segment (the run's own lines come only from long segments).
    labelled.progress({"", "decay", static_cast<double>(run->steps_done()) * dt, header.end_time_s, false, rate, NAN});
    segment = std::min(kSegmentGrowth * std::max<std::int64_t>(steps, 1),
                       sample_every * std::max<std::int64_t>(1, std::llround(kSegmentWallSeconds * rate /
                                                                             static_cast<double>(sample_every))));
    segment = std::max(segment, sample_every);
    const int signal = run->stop_signal() != 0 ? run->stop_signal() : hooks.stop_requested();
    const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint).count();
    // At the end a stop still gets a checkpoint: the results are not written yet.
    if (signal != 0 || (!run->finished() && hooks.checkpoint_due(since))) {
      header.simulated_time_s = static_cast<double>(run->steps_done()) * dt;
      dem_reference::StateWriter out;
      run->save(out);
      write_checkpoint(cp.file, header, out.bytes());
      last_checkpoint = std::chrono::steady_clock::now();
    }
    if (signal != 0) throw base::Interrupted(signal, resume_advice(cp.file, header));
  }
  auto result = std::move(*run).result();
  detail::check_outcome(result.outcome, result.message, label);
  return result;
}

/// The loss models' own sentences (with numbers) at one sample: each layer at its damper's
/// amplitude and the frequency the decay uses for the dominant mode there (its backbone's
/// natural frequency with containers and beds, structure::backbone_point).
void add_loss_messages(detail::Warnings& warnings, const detail::Setup& setup, const st::CoupledModel& coupled,
                       const st::DecaySample& s, const std::string& when) {
  Eigen::Index dominant = 0;
  s.modal_amplitudes.maxCoeff(&dominant);
  const double f =
      st::backbone_point(coupled, static_cast<int>(dominant), s.modal_amplitudes[dominant]).natural_frequency_hz;
  if (!std::isfinite(f)) return;
  for (std::size_t d = 0; d < setup.s.dampers.size(); ++d) {
    const double x = s.damper_amplitudes_m[d];
    if (!(x > 0.0)) continue;
    for (const auto& layer : setup.s.dampers[d].layers)
      for (const auto& m : layer.loss_model->warning_messages(f, x))
        warnings.add(when + ", " + setup.s.dampers[d].name + "/" + layer.name + " (X = " + format_number(x, 4) +
                     " m, f = " + format_number(f, 4) + " Hz): " + m);
  }
}

/// The averaged solver's options for the case's release from q0.
st::FreeDecayOptions averaged_decay_options(const Case& c, const st::ModalModel& modal, const Eigen::VectorXd& q0) {
  const auto& task = *c.task.decay;
  st::FreeDecayOptions options;
  options.initial_modal_amplitudes = q0.cwiseAbs();  // released from rest: a_j = |q_j(0)|
  options.duration_s = task.duration_s;
  options.threshold_fraction = task.settling_threshold;
  options.sample_times_s = st::uniform_sample_times(task.duration_s, static_cast<int>(decay_samples(modal, task.duration_s)) + 1);
  if (const auto problems = options.validate(modal.mode_count()); !problems.empty())
    throw InputError(c.path, "/task", problems.front());
  return options;
}

/// The same release with the containers empty (the beds removed), judged against the
/// same threshold: what the particles are measured against. Without beds the model is
/// linear (structural damping only), so the averaged solver is exact for it whatever the
/// method of the decay with beds.
st::FreeDecay decay_without_beds(const Case& c, const detail::Setup& setup, const Eigen::VectorXd& q0, double threshold_m) {
  auto empty = setup.s.dampers;
  for (auto& d : empty) d.layers.clear();
  auto options = averaged_decay_options(c, setup.s.modal, q0);
  options.threshold_m = threshold_m;
  return detail::call_solver(c, "/task", [&] { return st::free_decay(setup.s.modal, empty, options); });
}

/// The free decay by averaging on the layers' loss models.
void averaged_decay(const Case& c, detail::Setup& setup, const Eigen::VectorXd& q0, DecayResult& out) {
  const auto& task = *c.task.decay;
  const auto& modal = setup.s.modal;
  const auto options = averaged_decay_options(c, modal, q0);
  out.decay = detail::call_solver(c, "/task", [&] { return st::free_decay(modal, setup.s.dampers, options); });
  const auto& decay = out.decay;
  for (const auto& s : decay.samples)
    if (!std::isfinite(s.threshold_measure_m) || !std::isfinite(s.mechanical_energy_j))
      throw NumericalError("pdamp decay: the envelope is not finite at t = " + format_number(s.time_s) + " s (" +
                           decay.brief_report() + ")");
  if (decay.samples.empty()) throw NumericalError("pdamp decay: the solver returned no samples (" + decay.brief_report() + ")");
  setup.warnings.add(decay.warnings);
  const bool settled = decay.outcome == st::FreeDecay::Outcome::kSettled;
  const auto coupled = detail::call_solver(c, "/dampers", [&] { return st::couple(modal, setup.s.dampers); });
  add_loss_messages(setup.warnings, setup, coupled, decay.samples.front(), "at the start");
  if (settled) {
    const auto at = std::lower_bound(decay.samples.begin(), decay.samples.end(), decay.settling_time_s,
                                     [](const st::DecaySample& s, double t) { return s.time_s < t; });
    add_loss_messages(setup.warnings, setup, coupled, at == decay.samples.end() ? decay.samples.back() : *at, "at settling");
  } else {
    setup.warnings.add("the decay did not settle within duration_s = " + format_number(task.duration_s) +
                       " s (envelope " + format_number(decay.samples.back().threshold_measure_m, 4) + " m, threshold " +
                       format_number(decay.threshold_used_m, 4) + " m): lengthen /task/duration_s");
  }
}

}  // namespace

CoupledRunEstimate estimate_coupled_steps(const std::vector<st::CosimulationDamper>& dampers, double time_step_s,
                                          std::int64_t steps) {
  CoupledRunEstimate e;
  e.beds = dampers.size();
  e.time_step_s = time_step_s;
  e.steps = steps;
  for (const auto& d : dampers) {
    const dem_reference::WorldEstimate w = dem_reference::estimate_world(d.world);
    e.particles += w.particles;
    e.memory_bytes += static_cast<double>(w.memory_bytes);
    e.wall_time_s += static_cast<double>(w.particles) * static_cast<double>(steps) / w.particle_steps_per_s;
  }
  e.particle_steps = static_cast<double>(e.particles) * static_cast<double>(steps);
  return e;
}

st::DecayRun dem_decay_options(const Case& c, const st::ModalModel& modal, const Eigen::VectorXd& q0, double duration_s) {
  st::DecayRun options;
  options.initial_modal_displacements = q0;
  options.initial_modal_velocities = Eigen::VectorXd::Zero(q0.size());
  options.duration_s = duration_s;
  options.bed_settling_time_s = c.dem.simulation.settling_time_s;
  options.sample_interval_s = duration_s / decay_samples(modal, duration_s);
  return options;
}

CoupledRunEstimate estimate_coupled_decay(const Case& c, const st::ModalModel& modal,
                                            const std::vector<st::CosimulationDamper>& dampers,
                                            const st::DecayRun& options) {
  detail::check_cosimulation(c, modal, dampers, options);
  const double dt = detail::call_dem(c, [&] { return st::cosimulation_time_step(modal, dampers, options).time_step_s; });
  double settling_s = 0.0;
  for (const auto& d : dampers)
    settling_s = std::max(settling_s, options.bed_settling_time_s >= 0.0 ? options.bed_settling_time_s
                                                                         : dem_reference::automatic_settling_time_s(d.world));
  if (options.forced_start_periods > 0) settling_s += options.forced_start_periods / options.forced_start_frequency_hz;
  CoupledRunEstimate e = estimate_coupled_steps(dampers, dt, std::llround((options.duration_s + settling_s) / dt));
  // The sampled history: time, q and per bed its site's displacement, rotation, force and moment.
  const double samples = options.duration_s / options.sample_interval_s + 1.0;
  e.memory_bytes += samples * static_cast<double>(1 + modal.mode_count() + 4 * static_cast<Eigen::Index>(dampers.size())) *
                    sizeof(double);
  return e;
}

CoupledRunEstimate check_coupled_decay(const Case& c, const st::ModalModel& modal,
                                         const std::vector<st::CosimulationDamper>& dampers,
                                         const st::DecayRun& options, const std::string& label,
                                         const std::string& duration_pointer, base::RunHooks& hooks) {
  // A decay shorter than one period of the fastest mode it releases gives no history to
  // measure (once: exit 3 "the co-simulation returned no history" for 1e-6 s).
  double fastest_hz = 0.0;
  for (Eigen::Index j = 0; j < modal.mode_count(); ++j)
    if (j < options.initial_modal_displacements.size() && options.initial_modal_displacements[j] != 0.0)
      fastest_hz = std::max(fastest_hz, modal.natural_frequencies_hz[j]);
  if (fastest_hz > 0.0 && options.duration_s < 1.0 / fastest_hz)
    throw InputError(c.path, duration_pointer,
                     "= " + format_number(options.duration_s, 6) + " s: shorter than one period of the released mode at " +
                         format_number(fastest_hz, 6) + " Hz: at least " + format_number(1.0 / fastest_hz, 6) +
                         " s (a decay is measured over several)");
  const CoupledRunEstimate e = estimate_coupled_decay(c, modal, dampers, options);
  if (const double available = available_memory_bytes(); e.memory_bytes > available)
    throw InputError(c.path, "/dem",
                     label + " needs about " + megabytes(e.memory_bytes) + " (" + std::to_string(e.particles) +
                         " particles in " + std::to_string(e.beds) + " beds), more than the " + megabytes(available) +
                         " available: fewer particles (/dampers/*/layers/*/particles/count)");
  check_wall_time(c, e.wall_time_s, label, duration_pointer,
                  "a shorter " + duration_pointer + ", softer contacts (/dem/stiffness_softening) or fewer particles", hooks);
  return e;
}

std::string estimate_text(const CoupledRunEstimate& e) {
  return std::to_string(e.particles) + " particles in " + std::to_string(e.beds) + (e.beds == 1 ? " bed, " : " beds, ") +
         std::to_string(e.steps) + " coupled steps of " + format_number(e.time_step_s, 3) + " s = " +
         format_number(e.particle_steps, 3) + " particle-steps, about " + format_number(e.wall_time_s, 2) +
         " s; memory about " + megabytes(e.memory_bytes);
}

DemDecay dem_decay(const Case& c, const st::ModalModel& modal, std::vector<st::Damper> containers,
                   const std::vector<st::CosimulationDamper>& dampers, const Eigen::VectorXd& q0,
                   const case_file::DecayTask& task, const std::string& label, const std::string& duration_pointer,
                   const DemDecayCheckpoint& checkpoint, base::RunHooks& hooks, int snapshots,
                   const DecayStop* stop, const ForcedStart& forced) {
  for (auto& d : containers) d.layers.clear();
  const auto empty = detail::call_solver(c, "/dampers", [&] { return st::couple(modal, containers); });

  // The settling measure as the other methods: Σ_j |b_j| |q0_j| at the first damper's site.
  const Eigen::VectorXd weights = empty.drive_shapes.col(0).cwiseAbs();
  const double measure0 = weights.dot(q0.cwiseAbs());
  if (!(measure0 > 0.0))
    throw InputError(c.path, "/task/initial_state", "does not move the first damper's site along its drive");
  const double threshold = task.settling_threshold * measure0;
  Eigen::Index dominant = 0;
  weights.cwiseProduct(q0.cwiseAbs()).maxCoeff(&dominant);

  st::DecayRun options = dem_decay_options(c, modal, q0, task.duration_s);
  options.snapshots = snapshots;
  options.forced_start_periods = forced.periods;
  options.forced_start_frequency_hz = forced.frequency_hz;
  options.forced_start_peak_factor = forced.peak_factor;
  // Refused here when it cannot fit; said once a resume's checkpoint is accepted.
  const std::string estimate = label + ": " + estimate_text(check_coupled_decay(c, modal, dampers, options, label,
                                                                                duration_pointer, hooks));
  DemDecay out;
  if (checkpoint.file.path.empty()) {
    hooks.note(estimate);
    out.cosimulation = cosimulate_case(c, modal, dampers, options, label, hooks, stop);
  } else {
    out.cosimulation = checkpointed_decay(c, modal, dampers, options, label, estimate, checkpoint, hooks);
  }
  const auto& r = out.cosimulation;
  out.warnings = r.warnings;

  const auto& h = r.history;
  if (h.time_s.size() < 2) throw NumericalError(label + ": the co-simulation returned no history");
  const Eigen::VectorXd y = h.site_displacement_m.col(0);
  if (!y.allFinite()) throw NumericalError(label + ": the site displacement is not finite");
  std::vector<double> bed_masses, drive_gravity;
  for (const auto& spec : c.dampers) {
    double bed = 0.0;
    for (const auto& l : spec.layers) bed += l.bed_mass_kg;
    bed_masses.push_back(bed);
    drive_gravity.push_back(spec.gravity_m_s2[static_cast<std::size_t>(spec.drive_axis)]);
  }
  out.static_offset_m = st::static_site_offset(modal, empty.drive_shapes, bed_masses, drive_gravity);
  out.dominant_mode = dominant;
  out.dominant_frequency_hz = r.frequencies_with_containers_hz[dominant];
  out.initial_envelope_m = measure0;
  out.threshold_m = threshold;
  out.settling = st::sampled_settling(h.time_s, y, out.static_offset_m, 1.0 / out.dominant_frequency_hz, measure0,
                                      threshold, out.dominant_frequency_hz);
  if (!std::isfinite(out.settling.settling_time_s))
    out.warnings.push_back("the decay did not settle within duration_s = " + format_number(task.duration_s) +
                           " s (envelope " +
                           format_number(out.settling.envelope_m.empty() ? NAN : out.settling.envelope_m.back(), 4) +
                           " m, threshold " + format_number(threshold, 4) + " m): lengthen " + duration_pointer);
  if (r.energy.relative_error > 0.01)
    out.warnings.push_back("the co-simulation's energy ledger closes to " + format_number(r.energy.relative_error, 3) +
                           " only (docs/cosimulation.md §4): a smaller /dem/time_step_s");
  return out;
}

DecayResult run_decay(const Case& c, const DecayOptions& options, base::RunHooks& hooks, base::Executor& executor) {
  executor.primary_only();  // one co-simulation, or none: nothing to spread
  require_task(c, case_file::TaskKind::kDecay);
  const bool dem = options.method == DecayMethod::kDem;
  detail::Setup setup = detail::make_setup(
      c, options.method == DecayMethod::kField ? case_file::LossMethod::kField : case_file::LossMethod::kFormulas, !dem);
  DecayResult out;
  out.case_name = c.name;
  out.method = options.method;
  out.damper_names = detail::damper_names(setup);
  out.threshold_point = setup.s.dampers.front().point;
  out.threshold_fraction = c.task.decay->settling_threshold;
  out.modes = setup.s.modal.mode_count();
  out.initial_modal_amplitudes = case_file::initial_modal_amplitudes(c, setup.s, *c.task.decay);
  if (!(out.initial_modal_amplitudes.cwiseAbs().maxCoeff() > 0.0))
    throw InputError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  if (dem) {
    const auto beds = detail::dem_dampers(c);
    for (const auto& d : beds) out.bed_worlds.push_back(d.world);
    out.dem = dem_decay(c, setup.s.modal, setup.s.dampers, beds, out.initial_modal_amplitudes,
                        *c.task.decay, "pdamp decay (dem)", "/task/duration_s", options.checkpoint, hooks,
                        options.snapshots);
    setup.warnings.add(out.dem.warnings);
  } else {
    averaged_decay(c, setup, out.initial_modal_amplitudes, out);
  }
  out.without_beds = decay_without_beds(c, setup, out.initial_modal_amplitudes,
                                        dem ? out.dem.threshold_m : out.decay.threshold_used_m);
  // A decay reaches every stroke from above: a DEM field built from rest (the ascending
  // branch) can hold another state near and below the onset.
  for (const auto& layer : setup.s.fields_from_rest)
    setup.warnings.add(layer + ": its DEM field was built from rest (the ascending branch); a decay follows the "
                               "descending one, which near and below the onset can differ: build the field with "
                               "/dem/approach (docs/dem.md, \"Approach\")");
  out.warnings = setup.warnings.list();
  return out;
}

json to_json(const st::CosimulationEnergy& e) {
  return {{"excitation_work_j", e.excitation_work_j},
          {"structural_damping_j", e.structural_damping_j},
          {"delta_structure_kinetic_j", e.delta_structure_kinetic_j},
          {"delta_structure_potential_j", e.delta_structure_potential_j},
          {"dem_dissipated_j", e.dem_dissipated_j()},
          {"dem_normal_damping_j", e.dem_normal_damping_j},
          {"dem_friction_j", e.dem_friction_j},
          {"dem_rolling_j", e.dem_rolling_j},
          {"delta_bed_kinetic_j", e.delta_bed_kinetic_j},
          {"delta_bed_potential_j", e.delta_bed_potential_j},
          {"delta_bed_elastic_j", e.delta_bed_elastic_j},
          {"container_work_j", e.container_work_j},
          {"relative_error", e.relative_error}};
}

namespace {

json without_beds_json(const DecayResult& res, const OutputFolder& folder) {
  json out = base::to_json(without_beds_summary(res));
  out["what"] = "the same release with the containers empty (beds removed), judged against the same threshold";
  out["file"] = folder.file("decay_without_beds.csv");
  return out;
}

json dem_decay_json(const DecayResult& res, const OutputFolder& folder) {
  const DemDecay& decay = res.dem;
  const auto& r = decay.cosimulation;
  const auto& h = r.history;
  const auto& settle = decay.settling;
  json envelope = json::array();
  for (std::size_t k = 0; k < settle.envelope_m.size(); ++k) envelope.push_back({settle.envelope_time_s[k], settle.envelope_m[k]});
  json d = base::to_json(decay_summary(res));
  d["file"] = folder.file("decay_dem.csv");
  d["plot"] = folder.file("decay_dem.png");
  d["static_offset_m"] = decay.static_offset_m;
  d["envelope"] = "the largest |y - static_offset_m| of the first damper's site along its drive over each whole period of "
                  "the dominant mode (with the empty containers)";
  d["envelope_period_s"] = 1.0 / decay.dominant_frequency_hz;
  d["envelope_points"] = envelope;
  d["frequency_hz"] = settle.frequency_hz;
  d["energy_error"] = r.energy.relative_error;
  d["energy"] = to_json(r.energy);
  d["structural_dissipated_energy_j"] = r.energy.structural_damping_j;
  d["dem_dissipated_energy_j"] = r.energy.dem_dissipated_j();
  d["samples"] = h.time_s.size();
  d["steps"] = r.steps;
  d["settling_steps"] = r.settling_steps;
  d["time_step_s"] = r.time_step_s;
  d["solve_time_s"] = r.wall_time_s;
  d["warnings"] = res.warnings;
  d["without_beds"] = without_beds_json(res, folder);
  json result = {{"task", "decay"}, {"case", res.case_name}, {"method", "dem"}};
  result["file"] = d["file"];
  result["settling_time_s"] = d["settling_time_s"];
  result["damping_ratio"] = d["damping_ratio"];
  result["energy_balance_error"] = r.energy.relative_error;
  result["decay"] = d;
  return result;
}

json averaged_decay_json(const DecayResult& res, const OutputFolder& folder) {
  const auto& decay = res.decay;
  const auto& first = decay.samples.front();
  const auto& last = decay.samples.back();
  json layers = json::array();
  double dissipated = last.structural_dissipated_energy_j;
  for (double e : last.layer_dissipated_energy_j) dissipated += e;
  for (std::size_t l = 0; l < decay.layer_names.size(); ++l)
    layers.push_back({{"name", decay.layer_names[l]},
                      {"dissipated_energy_j", last.layer_dissipated_energy_j[l]},
                      {"share", dissipated > 0.0 ? last.layer_dissipated_energy_j[l] / dissipated : 0.0}});
  json d = base::to_json(decay_summary(res));
  d["file"] = folder.file("decay.csv");
  d["plot"] = folder.file("decay.png");
  d["initial_energy_j"] = first.mechanical_energy_j;
  d["final_energy_j"] = last.mechanical_energy_j;
  d["structural_dissipated_energy_j"] = last.structural_dissipated_energy_j;
  d["layers"] = layers;
  d["samples"] = decay.samples.size();
  d["steps"] = decay.steps;
  d["solve_time_s"] = decay.solve_time_s;
  d["report"] = decay.brief_report();
  d["warnings"] = res.warnings;
  d["without_beds"] = without_beds_json(res, folder);
  json result = {{"task", "decay"}, {"case", res.case_name}, {"method", d["method"]}};
  result["file"] = d["file"];
  result["settling_time_s"] = d["settling_time_s"];
  result["damping_ratio"] = d["damping_ratio"];
  result["decay"] = d;
  return result;
}

}  // namespace

const base::Fields<DecaySummary>& DecaySummary::fields() {
  using D = DecaySummary;
  static const auto f =
      base::Fields<D>()
          .field("method", &D::method, "", "formulas, field or dem")
          .field("settling_time_s", &D::settling_time_s, "s", "when the envelope reached the threshold (null: not settled)",
                 base::kNullable)
          .field("damping_ratio", &D::damping_ratio, "1", "equivalent damping ratio down to the threshold",
                 base::kNullable)
          .field("dominant_mode", &D::dominant_mode, "", "the mode the envelope is taken over, from 1")
          .field("settled", &D::settled, "", "settled within the duration", base::kHidden)
          .derived("outcome", [](const D& d) { return std::string(d.settled ? "settled" : "not_settled"); }, "",
                   "settled or not_settled")
          .field("threshold_point", &D::threshold_point, "", "the first damper's site")
          .field("threshold_m", &D::threshold_m, "m", "the settling threshold")
          .field("threshold_fraction", &D::threshold_fraction, "1", "the threshold over the initial envelope")
          .field("initial_envelope_m", &D::initial_envelope_m, "m", "the envelope the decay starts from")
          .field("initial_modal_amplitudes", &D::initial_modal_amplitudes, "units of q", "the release, q0")
          .field("final_time_s", &D::final_time_s, "s", "the end of the record")
          .field("final_envelope_m", &D::final_envelope_m, "m", "the envelope at the end", base::kNullable);
  return f;
}

DecaySummary decay_summary(const DecayResult& r) {
  DecaySummary s;
  s.threshold_point = r.threshold_point;
  s.threshold_fraction = r.threshold_fraction;
  s.initial_modal_amplitudes.assign(r.initial_modal_amplitudes.data(),
                                    r.initial_modal_amplitudes.data() + r.initial_modal_amplitudes.size());
  if (r.method == DecayMethod::kDem) {
    const DemDecay& d = r.dem;
    s.method = "dem";
    s.settling_time_s = d.settling.settling_time_s;
    s.damping_ratio = d.settling.damping_ratio;
    s.dominant_mode = static_cast<int>(d.dominant_mode) + 1;
    s.settled = std::isfinite(d.settling.settling_time_s);
    s.threshold_m = d.threshold_m;
    s.initial_envelope_m = d.initial_envelope_m;
    s.final_time_s = d.cosimulation.history.time_s.back();
    s.final_envelope_m = d.settling.envelope_m.empty() ? NAN : d.settling.envelope_m.back();
    return s;
  }
  const auto& decay = r.decay;
  s.method = r.method == DecayMethod::kField ? "field" : "formulas";
  s.settling_time_s = decay.settling_time_s;
  s.damping_ratio = decay.equivalent_damping_ratio;
  s.dominant_mode = static_cast<int>(decay.dominant_mode) + 1;
  s.settled = decay.outcome == st::FreeDecay::Outcome::kSettled;
  s.threshold_m = decay.threshold_used_m;
  s.initial_envelope_m = decay.samples.front().threshold_measure_m;
  s.final_time_s = decay.samples.back().time_s;
  s.final_envelope_m = decay.samples.back().threshold_measure_m;
  return s;
}

const base::Fields<BareDecaySummary>& BareDecaySummary::fields() {
  using B = BareDecaySummary;
  static const auto f =
      base::Fields<B>()
          .field("settling_time_s", &B::settling_time_s, "s", "when the envelope reached the threshold (null: not settled)",
                 base::kNullable)
          .field("settled", &B::settled, "", "settled within the duration", base::kHidden)
          .derived("outcome", [](const B& b) { return std::string(b.settled ? "settled" : "not_settled"); }, "",
                   "settled or not_settled")
          .field("damping_ratio", &B::damping_ratio, "1", "equivalent damping ratio down to the threshold",
                 base::kNullable)
          .field("final_envelope_m", &B::final_envelope_m, "m", "the envelope at the end", base::kNullable);
  return f;
}

BareDecaySummary without_beds_summary(const DecayResult& r) {
  const auto& bare = r.without_beds;
  return {bare.settling_time_s, bare.outcome == st::FreeDecay::Outcome::kSettled, bare.equivalent_damping_ratio,
          bare.samples.empty() ? NAN : bare.samples.back().threshold_measure_m};
}

json to_json(const DecayResult& result, const OutputFolder& folder) {
  return result.method == DecayMethod::kDem ? dem_decay_json(result, folder) : averaged_decay_json(result, folder);
}

}  // namespace pdamp::tasks
