// pdamp dem as a study: the reference DEM of a case's damper under harmonic motion, checked
// and costed before it starts, checkpointed while it runs, compared with the closed form.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/tasks/checkpoint.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// A DEM run's options and cost, checked before it starts (no job that cannot finish is
/// started): every option in range (base::InputError naming the case key), the time
/// step below its bound, the memory within what is available. `damper`: the case's damper
/// the options are of.
dem_reference::RunEstimate check_dem_run(const case_file::Case& c, std::size_t damper,
                                         const dem_reference::DamperSimulationOptions& options);
/// The DEM's initial bed built as a run would build it (inner structures, wall layers): a
/// bed that does not fit is refused (InputError naming its key) before any output.
void check_dem_placement(const case_file::Case& c, std::size_t damper, const dem_reference::DamperSimulationOptions& options);
/// Memory this process may still use, bytes: MemAvailable, lowered to what a cgroup v2
/// limit leaves; infinity when neither can be read.
double available_memory_bytes();
/// InputError naming /dem when `runs_at_once` runs of `estimate` do not fit in `available` bytes.
void check_memory(const case_file::Case& c, std::size_t damper, const dem_reference::RunEstimate& estimate,
                  double runs_at_once);
/// The longest estimated wall time a DEM run starts with unless the user accepts it
/// (RunHooks::long_runs_accepted; the command line's --accept-long-run): a week. The estimate
/// is at the benchmark rate of the machine class pdamp is measured on (RunEstimate).
inline constexpr double kMaxDemWallTime_s = 7.0 * 86400.0;
/// InputError naming `pointer` of the case when `wall_time_s` exceeds kMaxDemWallTime_s and
/// the hooks do not accept it; `what` names the run and `reduce` the keys that shorten it.
void check_wall_time(const case_file::Case& c, double wall_time_s, const std::string& what, const std::string& pointer,
                     const std::string& reduce, base::RunHooks& hooks);
/// The same with the acceptance given directly (a sweep's options carry it).
void check_wall_time(const case_file::Case& c, double wall_time_s, const std::string& what, const std::string& pointer,
                     const std::string& reduce, bool accepted);
/// "N particles, S steps of dt s = P particle-steps, about T s at R particle-steps/s; memory about M".
std::string estimate_text(const dem_reference::RunEstimate& estimate);
/// "1.2 MB" or "3.4 GB".
std::string megabytes(double bytes);
/// The DEM's advice names its options ("lower integration.time_step_s"); the user edits the
/// case keys they come from (/dem/time_step_s).
std::string case_key_names(const std::string& advice);

struct DemRunOptions {
  std::optional<double> amplitude_m;   ///< stroke X, m (default: the case's excitation.amplitude_m)
  std::optional<double> frequency_hz;  ///< f, Hz (default: the case's excitation.frequency_hz)
  std::optional<int> analysed_periods; ///< default: the case's dem.analysed_periods
  std::optional<int> threads;          ///< OpenMP threads, 0 = all (default: the case's dem.threads)
  std::optional<int> snapshots;        ///< particle snapshots kept (default: the case's dem.snapshots)
  std::string label = "pdamp dem";     ///< names the run in progress lines and notes
};

/// A checked DEM run, ready to start.
struct DemRunPlan {
  dem_reference::DamperSimulationOptions options;
  dem_reference::RunEstimate estimate;
  double amplitude_m = 0.0;
  double frequency_hz = 0.0;
  std::string label;
};
/// Every check of the run, before any output (InputError for a missing stroke, an option
/// out of range, a bed that does not fit, a run that does not fit in memory).
DemRunPlan plan_dem(const case_file::Case& c, const DemRunOptions& options);

struct DemRunResult {
  std::string case_name;
  double amplitude_m = 0.0;
  double frequency_hz = 0.0;
  dem_reference::DamperResult dem;
  dem_reference::WorldOptions world;  ///< the run's world (the containers' geometry for ParaView)
  dem_reference::Vec3 drive_axis{1.0, 0.0, 0.0};
  /// The drive's approach (/dem/approach): 0 from rest, else the stroke it came down from.
  double approach_amplitude_m = 0.0;
  int approach_hold_periods = 0, approach_ramp_periods = 0;
  formulas::LossResult closed_form;  ///< the case's model at the same point and the DEM's clearance
  std::vector<std::string> warnings;
};
/// Runs the plan: progress through `hooks`; with a checkpoint path, a checkpoint at period
/// ends whenever the hooks say one is due, and base::Interrupted (after saving one)
/// when they ask to stop; with file.resume, from the saved state (bit for bit the
/// uninterrupted run). A DEM that goes unstable or fails: base::NumericalError. One run: on
/// the primary process alone (on another: base::JobsServedElsewhere).
DemRunResult run_dem(const case_file::Case& c, const DemRunPlan& plan, const CheckpointFile& checkpoint, base::RunHooks& hooks,
                     base::Executor& executor = base::local_executor());

/// pdamp dem's result keys: the DEM's measures, case, amplitude, frequency, closed_form.
nlohmann::json to_json(const DemRunResult& result);

}  // namespace pdamp::tasks
