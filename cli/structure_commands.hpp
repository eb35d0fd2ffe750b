// The Level III subcommands (pdamp modes, frf, decay) and the structure tasks of pdamp run:
// a format-2 case through case_file::structure_setup and the structure solvers.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "args.hpp"
#include "commands.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::cli {

/// `--method formulas|field|dem` (default formulas), shared with pdamp run.
extern const FlagSpec kMethodFlag;
/// The stepped sine's flags of pdamp frf --method dem (--dem-points, --dem-min-frequency,
/// --dem-max-frequency, --dem-sweep); pdamp run lists them among its flags to accept them
/// on an frf task (without them, run uses the defaults).
extern const std::vector<FlagSpec> kDemSweepFlags;

/// The loss models `--method` asks for (formulas, the default, or field); InputError for
/// dem (a co-simulation, not a loss model) and anything else.
case_file::LossMethod loss_method(const ParsedArgs& args);
/// pdamp modes, frf and decay, in the order `pdamp --help` lists them.
std::vector<Command> structure_commands();

/// Runs the case's task of kind modes, frf or decay exactly as the command of that name
/// (pdamp run). Other kinds are not structure tasks: std::logic_error.
int run_structure_task(const ParsedArgs& args, const case_file::Case& c);

/// The settling of a simulated site displacement: the envelope is the largest |y − y_s|
/// over each whole period of the dominant mode (placed at its time); settled where the
/// envelope, interpolated in ln between the last period at or above the threshold and the
/// next, crosses it, if no later period rises above it again.
struct SimulatedSettling {
  std::vector<double> envelope_time_s, envelope_m;  ///< one per whole period
  std::vector<double> sample_envelope_m;            ///< the envelope at every sample (linear in ln between periods)
  double settling_time_s = NAN;                     ///< s; NaN: not settled within the record
  double frequency_hz = NAN;  ///< from the zero crossings of y − y_s up to settling (or the whole record)
  double damping_ratio = NAN;
};

/// A DEM-in-the-loop free decay of the first damper's site (pdamp decay --method dem,
/// pdamp optimize --verify).
struct DemDecay {
  structure::CosimulationResult cosimulation;
  SimulatedSettling settling;
  double static_offset_m = 0.0;        ///< y_s: the beds' weight along the drives, m
  double initial_envelope_m = 0.0;     ///< Σ_j |b_j| |q0_j| at the first damper's site, m
  double threshold_m = 0.0;            ///< settling_threshold · initial_envelope_m, m
  double dominant_frequency_hz = 0.0;  ///< of the dominant mode with the empty containers
  Eigen::Index dominant_mode = 0;      ///< 0-based
  std::vector<std::string> warnings;   ///< the co-simulation's, not settled, energy ledger above 1%
};

/// Checkpoints of a DEM-in-the-loop decay (issue 13 §4, docs/cosimulation.md §7): the run
/// goes in segments of whole sample intervals (about 2 s of wall time each) and writes its
/// state (worlds, modes, the history so far) to `file` every `interval_s` of wall time and
/// when SIGINT, SIGTERM or SIGHUP arrives (then it ends by the signal, saying how to resume).
/// With `resume` it continues from `file`, refusing a checkpoint of another kind, case,
/// model version or settings; a completed run removes the file. Empty `file`: one
/// uninterrupted run, no checkpoints.
struct DemCheckpoint {
  std::filesystem::path file;
  std::string kind = "decay_dem";  ///< what the checkpoint continues ("verify_chosen", ...)
  std::string settings;            ///< the caller's own settings (a design): part of the match
  bool resume = false;
  double interval_s = 60.0;        ///< wall-clock seconds between checkpoints, >= 0 (0: every segment)
};
/// `--resume` and `--checkpoint-interval` (pdamp decay --method dem, optimize --verify, run).
extern const std::vector<FlagSpec> kCheckpointFlags;
/// The payload of cp.file when its header has `expected`'s kind, case hash, model version and
/// settings; InputError naming the file and the key that differs, or the damage, otherwise.
std::string read_checkpoint_payload(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& expected);
/// cp.file written atomically (a temporary file and a rename) with `header` and `payload`.
void write_checkpoint_file(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& header,
                           const std::string& payload);
/// "stopped at t = … of … s and wrote FILE: run the same command with --resume to continue".
std::string checkpoint_advice(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& header);
/// The checkpoint of a DEM run named `name` in the -o folder of `args` (InputError for
/// --resume without -o, or a bad --checkpoint-interval); no file without -o.
DemCheckpoint dem_checkpoint(const ParsedArgs& args, const std::string& name, const std::string& kind);

/// Co-simulates the free decay of `modal` with `dampers` (their beds as DEM worlds,
/// structure::cosimulate) from rest at q0 over task.duration_s, and measures its settling
/// against task.settling_threshold; with a checkpoint file, in segments (DemCheckpoint). `containers`: the same dampers as the structure sees
/// them (their layers are ignored; drive shapes and the static offset of the case's beds).
/// Progress lines on stderr start with `label`; `duration_pointer` is named in the
/// not-settled warning. Exit 2 (InputError) for refused options, 3 for a World that stops.
DemDecay run_dem_decay(const case_file::Case& c, const structure::ModalModel& modal,
                       std::vector<structure::Damper> containers,
                       const std::vector<structure::CosimulationDamper>& dampers, const Eigen::VectorXd& q0,
                       const case_file::DecayTask& task, const std::string& label, const std::string& duration_pointer,
                       const DemCheckpoint& checkpoint = {});

}  // namespace pdamp::cli
