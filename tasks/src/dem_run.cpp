// pdamp dem as a study (dem_run.hpp).
#include "pdamp/tasks/dem_run.hpp"

#include <fstream>
#include <limits>
#include <regex>
#include <sstream>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
using nlohmann::json;
using base::format_number;
using base::InputError;

double available_memory_bytes() {
  double available = std::numeric_limits<double>::infinity();
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kib = 0.0;
    meminfo >> kib;
    if (key == "MemAvailable:") available = kib * 1024.0;
    meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  std::ifstream limit("/sys/fs/cgroup/memory.max"), current("/sys/fs/cgroup/memory.current");
  double max_bytes = 0.0, used = 0.0;
  if (limit >> max_bytes && current >> used) available = std::min(available, max_bytes - used);  // "max": no limit
  return available;
}

std::string megabytes(double bytes) {
  return bytes >= 1e9 ? format_number(bytes / 1e9, 3) + " GB" : format_number(bytes / 1e6, 3) + " MB";
}

void check_memory(const case_file::Case& c, std::size_t damper, const dem_reference::RunEstimate& e, double runs_at_once) {
  const double available = available_memory_bytes();
  if (!(runs_at_once * static_cast<double>(e.memory_bytes) > available)) return;
  const std::string counts = c.format_version == 1 ? "/damper/particles/count"
                                                   : "/dampers/" + std::to_string(damper) + "/layers/*/particles/count";
  throw InputError(c.path, "/dem",
                   "the DEM needs about " + megabytes(runs_at_once * static_cast<double>(e.memory_bytes)) + " (" +
                       std::to_string(e.particles) + " particles, " + std::to_string(e.recorded_samples) +
                       " recorded samples = samples_per_period x analysed_periods, " + std::to_string(e.snapshots) +
                       " snapshots" + (runs_at_once > 1 ? ", " + format_number(runs_at_once, 3) + " runs at once" : "") +
                       "), more than the " + megabytes(available) +
                       " available: reduce /dem/samples_per_period, /dem/analysed_periods, /dem/snapshots or " + counts);
}

dem_reference::RunEstimate check_dem_run(const case_file::Case& c, std::size_t damper,
                                         const dem_reference::DamperSimulationOptions& options) {
  const auto problems = options.validate("");
  if (!problems.empty()) throw case_file::dem_case_error(c, damper, problems.front());
  dem_reference::RunEstimate e;
  try {
    e = dem_reference::estimate_run(options);
  } catch (const std::invalid_argument& error) {  // the time step above its bound
    const std::string what = error.what();
    throw case_file::dem_case_error(c, damper, what.substr(0, what.find('\n')));
  }
  check_memory(c, damper, e, 1.0);
  return e;
}

void check_dem_placement(const case_file::Case& c, std::size_t damper, const dem_reference::DamperSimulationOptions& options) {
  try {
    dem_reference::check_initial_placement(options);
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    throw case_file::dem_case_error(c, damper, what.substr(0, what.find('\n')));
  }
}

std::string case_key_names(const std::string& advice) {
  static const std::regex kOption(R"(\bintegration\.(\w+))");
  return std::regex_replace(advice, kOption, "/dem/$1");
}

void check_wall_time(const case_file::Case& c, double wall_time_s, const std::string& what, const std::string& pointer,
                     const std::string& reduce, base::RunHooks& hooks) {
  check_wall_time(c, wall_time_s, what, pointer, reduce, hooks.long_runs_accepted());
}

void check_wall_time(const case_file::Case& c, double wall_time_s, const std::string& what, const std::string& pointer,
                     const std::string& reduce, bool accepted) {
  if (!(wall_time_s > kMaxDemWallTime_s) || accepted) return;
  throw InputError(c.path, pointer,
                   what + " is estimated at about " + format_number(wall_time_s / 86400.0, 3) +
                       " days of wall time, more than the limit of " + format_number(kMaxDemWallTime_s / 86400.0, 3) +
                       " days: " + reduce + ", or pass --accept-long-run to start it anyway");
}

std::string estimate_text(const dem_reference::RunEstimate& e) {
  return std::to_string(e.particles) + " particles, " + std::to_string(e.total_steps) + " steps of " +
         format_number(e.time_step_s, 3) + " s = " + format_number(e.particle_steps, 3) + " particle-steps, about " +
         format_number(e.wall_time_s, 2) + " s at " + format_number(e.particle_steps_per_s, 2) +
         " particle-steps/s; memory about " + megabytes(static_cast<double>(e.memory_bytes));
}

DemRunPlan plan_dem(const case_file::Case& c, const DemRunOptions& o) {
  (void)detail::single_damper(c, "pdamp dem");
  DemRunPlan plan;
  plan.label = o.label;
  plan.frequency_hz = o.frequency_hz.value_or(c.excitation.frequency_hz);
  if (!o.amplitude_m && !c.excitation.amplitude_m)
    throw InputError(c.path, "/excitation/amplitude_m", "required by pdamp dem (or give --amplitude M)");
  plan.amplitude_m = o.amplitude_m.value_or(c.excitation.amplitude_m.value_or(0.0));
  plan.options = case_file::dem_options(c, 0, plan.amplitude_m, plan.frequency_hz);
  if (o.analysed_periods) plan.options.analysed_periods = *o.analysed_periods;
  if (o.threads) plan.options.world.threads = *o.threads;
  if (o.snapshots) plan.options.snapshots = *o.snapshots;
  plan.estimate = check_dem_run(c, 0, plan.options);
  check_dem_placement(c, 0, plan.options);
  return plan;
}

DemRunResult run_dem(const case_file::Case& c, const DemRunPlan& plan, const CheckpointFile& checkpoint, base::RunHooks& hooks,
                     base::Executor& executor) {
  executor.primary_only();  // one DEM run (its own threads): nothing to spread
  const auto& options = plan.options;
  const double x = plan.amplitude_m, f = plan.frequency_hz;
  const bool checkpointing = !checkpoint.path.empty();

  // Checkpoints at period ends (docs/dem.md "Checkpoints"): when the hooks say one is due,
  // and when they ask to stop (then Interrupted follows).
  dem_reference::CheckpointHeader header;
  header.kind = "dem";
  header.case_hash = case_file::physics_hash(c, "dem");
  header.physics_model_version = dem_reference::kPhysicsModelVersion;
  {
    std::ostringstream settings;
    settings.precision(17);
    settings << "amplitude_m " << x << "; frequency_hz " << f << "; transient_periods " << options.transient_periods
             << "; analysed_periods " << options.analysed_periods << "; samples_per_period " << options.samples_per_period
             << "; snapshots " << options.snapshots << "; threads " << options.world.threads;
    header.settings = settings.str();
  }
  header.end_time_s = (options.transient_periods + options.analysed_periods) / f;
  // The checkpoint file takes the states. Without one the run still asks the hooks whether
  // to stop (a library caller's KeyboardInterrupt, docs/python.md) and nothing is written.
  struct FileSink : dem_reference::CheckpointSink {
    const CheckpointFile& file;
    dem_reference::CheckpointHeader& header;
    bool wrote = false;
    FileSink(const CheckpointFile& f, dem_reference::CheckpointHeader& h) : file(f), header(h) {}
    void store(const std::string& state, double simulated_time_s) override {
      header.simulated_time_s = simulated_time_s;
      write_checkpoint(file, header, state);
      wrote = true;
    }
  } sink(checkpoint, header);
  dem_reference::CheckpointStorage saving;
  if (checkpointing) saving.sink = &sink;
  if (checkpoint.resume) saving.resume_state = read_checkpoint(checkpoint, header);  // refused before any work
  check_wall_time(c, plan.estimate.wall_time_s, plan.label, "/dem",
                  "fewer /dem/analysed_periods or /dem/transient_periods, a larger /dem/time_step_s, or fewer particles",
                  hooks);
  hooks.note(plan.label + ": " + estimate_text(plan.estimate));
  if (checkpoint.resume) {
    hooks.note(plan.label + ": resuming from " + base::printable(checkpoint.path.string()));
  } else if (checkpointing && std::filesystem::exists(checkpoint.path)) {
    hooks.note("pdamp: warning: " + base::printable(checkpoint.path.string()) +
               " of an earlier run is replaced (--resume continues it)");
  }

  DemRunResult out;
  out.case_name = c.name;
  out.amplitude_m = x;
  out.frequency_hz = f;
  out.world = options.world;
  out.drive_axis = options.drive_axis;
  if (options.approach_amplitude_m > 0.0) {
    out.approach_amplitude_m = options.approach_amplitude_m;
    out.approach_hold_periods = options.approach_hold_periods;
    out.approach_ramp_periods = options.approach_ramp_periods;
  }
  try {
    base::LabelledHooks labelled(hooks, plan.label);
    out.dem = dem_reference::run_harmonic(options, labelled, saving);
  } catch (const std::invalid_argument& e) {  // e.g. a time step above the stable bound, a resume that does not fit
    throw InputError(checkpoint.resume ? checkpoint.path.string() : c.path, checkpoint.resume ? "" : "/dem", e.what());
  }
  if (out.dem.stopped)
    throw base::Interrupted(hooks.stop_requested(),
                                   !checkpointing ? "the run stopped; it had no checkpoint file, so nothing was kept"
                                   : sink.wrote || checkpoint.resume
                                       ? resume_advice(checkpoint, header)
                                       : "the run stopped while its bed settled, before its first checkpoint: run the "
                                         "same command again");
  if (out.dem.summary.outcome == dem_reference::Outcome::kUnstable)
    throw base::NumericalError("DEM unstable: " + case_key_names(out.dem.summary.message));
  if (out.dem.summary.outcome != dem_reference::Outcome::kCompleted)  // a step threw (on any thread)
    throw base::NumericalError("DEM failed: " + case_key_names(out.dem.summary.message));

  // The closed form at the same point, for comparison (same model family as the case).
  const auto& damper = c.dampers.front();
  out.closed_form = fm::reduced_loss_factor(damper.model, out.dem.clearance_m, x, f,
                                            case_file::layer_model_options(damper, damper.layers.front()));
  out.warnings = out.dem.warnings;
  return out;
}

json to_json(const DemRunResult& r) {
  json out = base::to_json(r.dem);
  out.update({{"case", r.case_name}, {"amplitude_m", r.amplitude_m}, {"frequency_hz", r.frequency_hz}});
  if (r.approach_amplitude_m > 0.0)
    out["approach"] = {{"from_amplitude_m", r.approach_amplitude_m}, {"hold_periods", r.approach_hold_periods},
                       {"ramp_periods", r.approach_ramp_periods}};
  out["closed_form"] = {{"eta_star", r.closed_form.eta_star}, {"model_used", fm::to_string(r.closed_form.model_used)},
                        {"regime", fm::to_string(r.closed_form.regime)}};
  return out;
}

}  // namespace pdamp::tasks
