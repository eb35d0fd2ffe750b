// Task kind decay (pdamp decay): the free decay of a structure with its dampers from the
// task's initial state, by averaging on the layers' loss models (formulas or field) or by
// the DEM in the loop (checkpointed in segments, resumable); the DEM decay also serves the
// design verification.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/sampled_decay.hpp"
#include "pdamp/tasks/checkpoint.hpp"
#include "pdamp/tasks/output_folder.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// The checkpoints of a DEM decay: its file, what it continues ("decay_dem",
/// "verify_chosen", ...) and the caller's own settings that a resume must match (a design).
struct DemDecayCheckpoint {
  CheckpointFile file;
  std::string kind = "decay_dem";
  std::string settings;
};

/// A DEM-in-the-loop free decay of the first damper's site.
struct DemDecay {
  structure::CosimulationResult cosimulation;
  structure::SampledSettling settling;
  double static_offset_m = 0.0;        ///< y_s: the beds' weight along the drives, m
  double initial_envelope_m = 0.0;     ///< Σ_j |b_j| |q0_j| at the first damper's site, m
  double threshold_m = 0.0;            ///< settling_threshold · initial_envelope_m, m
  double dominant_frequency_hz = 0.0;  ///< of the dominant mode with the empty containers
  Eigen::Index dominant_mode = 0;      ///< 0-based
  std::vector<std::string> warnings;   ///< the co-simulation's, not settled, energy ledger above 1%
};

/// Ends a DEM decay at the end of the first whole period (of frequency_hz, from the release)
/// in which the largest |q_mode|, sampled kSamplesPerPeriod times, is below `below` times the
/// first period's: a measure over the periods above a larger fraction then has all its
/// periods (a sampled sine's peak is at least cos(π/20) = 0.988 of the true one).
struct DecayStop {
  Eigen::Index mode = 0;
  double frequency_hz = 0.0;
  double below = 0.0;
  static constexpr int kSamplesPerPeriod = 20;
};

/// A DEM decay released from steady forced vibration (structure::CosimulationSettings::
/// forced_start_periods): the beds driven `periods` whole periods of frequency_hz first.
struct ForcedStart {
  int periods = 0;  ///< 0: released from the beds as placed and settled
  double frequency_hz = 0.0;
  double peak_factor = 1.0;  ///< structure::CosimulationSettings::forced_start_peak_factor
};

/// Co-simulates the free decay of `modal` with `dampers` (their beds as DEM worlds) from
/// rest at q0 over task.duration_s and measures its settling against
/// task.settling_threshold (structure::sampled_settling). With a checkpoint file the run
/// goes in segments of whole sample intervals (about 2 s of wall time each), saves its
/// state when the hooks say a checkpoint is due, and when they ask to stop saves one and
/// throws base::Interrupted; with file.resume it continues from the file (bit for
/// bit the uninterrupted run). `containers`: the same dampers as the structure sees them
/// (drive shapes and the static offset of the case's beds). Progress lines carry `label`;
/// `duration_pointer` is named in the not-settled warning; `snapshots`: every bed's particles
/// that many times, evenly over the decay (CosimulationResult::bed_snapshots, for ParaView).
/// InputError for refused options,
/// base::NumericalError for a World that stops.
/// `stop` (without a checkpoint file only) ends the decay early once it is below what a
/// measure of it uses.
DemDecay dem_decay(const case_file::Case& c, const structure::ModalModel& modal, std::vector<structure::Damper> containers,
                   const std::vector<structure::CosimulationDamper>& dampers, const Eigen::VectorXd& q0,
                   const case_file::DecayTask& task, const std::string& label, const std::string& duration_pointer,
                   const DemDecayCheckpoint& checkpoint, base::RunHooks& hooks, int snapshots = 0,
                   const DecayStop* stop = nullptr, const ForcedStart& forced = {});

/// The cost of a DEM-in-the-loop run before it starts, computed without building its
/// worlds: the coupled step, the steps, every bed's particles, and the memory of its worlds
/// (dem_reference::estimate_world) and its sampled history; wall time at the benchmark
/// rates (the worlds step one after the other, each at its own rate).
struct CoupledRunEstimate {
  int particles = 0;
  std::size_t beds = 0;
  double time_step_s = 0.0;
  std::int64_t steps = 0;       ///< settling and decay
  double particle_steps = 0.0;
  double wall_time_s = 0.0;
  double memory_bytes = 0.0;
};
/// `steps` coupled steps of `dt` with the worlds of `dampers` (no history).
CoupledRunEstimate estimate_coupled_steps(const std::vector<structure::CosimulationDamper>& dampers, double time_step_s,
                                          std::int64_t steps);
/// The co-simulation options of a DEM-in-the-loop free decay of the case from q0 over
/// duration_s (sampled finely enough for the settling measure).
structure::DecayRun dem_decay_options(const case_file::Case& c, const structure::ModalModel& modal,
                                                 const Eigen::VectorXd& q0, double duration_s);
/// The estimate alone (InputError for options the co-simulation refuses).
CoupledRunEstimate estimate_coupled_decay(const case_file::Case& c, const structure::ModalModel& modal,
                                            const std::vector<structure::CosimulationDamper>& dampers,
                                            const structure::DecayRun& options);
/// The estimate of a decay of `options` (a free decay), and its checks: InputError naming
/// /dem when it cannot fit in the memory available, and check_wall_time (`duration_pointer`
/// names the duration to shorten). The one-line text for the user is estimate_text().
CoupledRunEstimate check_coupled_decay(const case_file::Case& c, const structure::ModalModel& modal,
                                         const std::vector<structure::CosimulationDamper>& dampers,
                                         const structure::DecayRun& options,
                                         const std::string& label, const std::string& duration_pointer, base::RunHooks& hooks);
/// "N particles in B beds, S coupled steps of dt s = P particle-steps, about T s; memory about M".
std::string estimate_text(const CoupledRunEstimate& estimate);

enum class DecayMethod { kFormulas, kField, kDem };

struct DecayOptions {
  DecayMethod method = DecayMethod::kFormulas;
  int snapshots = 0;  ///< kDem: every bed's particles this many times over the decay (ParaView)
  DemDecayCheckpoint checkpoint;  ///< kDem: where it saves its state (empty file: none)
};

struct DecayResult {
  std::string case_name;
  DecayMethod method = DecayMethod::kFormulas;
  std::vector<std::string> damper_names;
  std::string threshold_point;           ///< the first damper's site
  double threshold_fraction = 0.0;
  Eigen::VectorXd initial_modal_amplitudes;
  Eigen::Index modes = 0;
  structure::FreeDecay decay;            ///< kFormulas, kField
  DemDecay dem;                          ///< kDem
  structure::FreeDecay without_beds;     ///< the same release with the containers empty, same threshold
  std::vector<dem_reference::WorldOptions> bed_worlds;  ///< kDem: each damper's bed (the containers for ParaView)
  std::vector<std::string> warnings;
};
/// A decay's settling at the first damper's site, whichever method ran it.
struct DecaySummary {
  std::string method;              ///< formulas, field or dem
  double settling_time_s = NAN;    ///< NaN: not settled within the duration
  double damping_ratio = NAN;      ///< the equivalent damping ratio down to the threshold
  int dominant_mode = 1;           ///< from 1
  bool settled = false;
  std::string threshold_point;
  double threshold_m = NAN, threshold_fraction = NAN, initial_envelope_m = NAN;
  std::vector<double> initial_modal_amplitudes;
  double final_time_s = NAN, final_envelope_m = NAN;
  static const base::Fields<DecaySummary>& fields();
};
DecaySummary decay_summary(const DecayResult& result);

/// The same release with the containers empty, against the same threshold.
struct BareDecaySummary {
  double settling_time_s = NAN;
  bool settled = false;
  double damping_ratio = NAN, final_envelope_m = NAN;
  static const base::Fields<BareDecaySummary>& fields();
};
BareDecaySummary without_beds_summary(const DecayResult& result);

/// The decay study of a case whose task is kind decay (InputError naming /task otherwise).
/// One run: on the primary process alone (on another: base::JobsServedElsewhere).
DecayResult run_decay(const case_file::Case& c, const DecayOptions& options, base::RunHooks& hooks,
                      base::Executor& executor = base::local_executor());
/// The result keys (task, case, method, file, settling_time_s, damping_ratio, decay, ...).
nlohmann::json to_json(const DecayResult& result, const OutputFolder& folder);
/// The co-simulation's energy ledger (docs/cosimulation.md §4) as JSON.
nlohmann::json to_json(const structure::CosimulationEnergy& energy);

}  // namespace pdamp::tasks
