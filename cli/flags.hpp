// Flags several subcommands share, and what they map to.
#pragma once

#include <string>
#include <vector>

#include "args.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/tasks/checkpoint.hpp"

namespace pdamp::cli {

extern const FlagSpec kJsonFlag;
extern const FlagSpec kOutFlag;
/// --overwrite: -o DIR may replace the outputs of another command or case.
extern const FlagSpec kOverwriteFlag;
/// `--method formulas|field|dem` (default formulas): pdamp modes, frf, decay and run.
extern const FlagSpec kMethodFlag;
/// The stepped sine's and the linear sweep's flags of pdamp frf --method dem; pdamp run
/// accepts them on an frf task.
extern const std::vector<FlagSpec> kDemSweepFlags;
/// The flags of long DEM runs: `--resume`, `--checkpoint-interval` and `--accept-long-run`
/// (pdamp dem, decay --method dem, optimize --verify, run).
extern const std::vector<FlagSpec> kCheckpointFlags;
extern const FlagSpec kNoVerifyFlag;
/// --accept-long-run: a DEM run estimated beyond tasks::kMaxDemWallTime_s may start.
extern const FlagSpec kAcceptLongRunFlag;
/// --calibration-cache DIR (pdamp optimize and pdamp run on a filling_ratios task).
extern const FlagSpec kCalibrationCacheFlag;

/// The loss models `--method` asks for (formulas, the default, or field); InputError for
/// dem (a co-simulation, not a loss model) and anything else. `command` names who refuses dem.
case_file::LossMethod loss_method(const ParsedArgs& args, const std::string& command = "pdamp modes");
/// `--method dem` given.
bool dem_method(const ParsedArgs& args);

/// The checkpoint of a DEM run named `name` in the -o folder (InputError for --resume without -o).
tasks::CheckpointFile checkpoint_file(const ParsedArgs& args, const std::string& name);
/// --checkpoint-interval, s (default 60; 0: at every chance).
double checkpoint_interval(const ParsedArgs& args);
/// A warning for each length flag of `flags` given above 1 m: larger than any particle
/// damper's clearance or stroke (millimetres to decimetres), most likely millimetres typed
/// where the flag takes metres (`--clearance 100` is 100 m).
std::vector<std::string> length_scale_warnings(const ParsedArgs& args, const std::vector<std::string>& flags);
/// InputError when a checkpoint flag is given to a run that makes no checkpoints.
/// A flag that would do nothing is refused (exit 2) with `why`: the first of `flags` given.
void refuse_flags(const ParsedArgs& args, const std::vector<FlagSpec>& flags, const std::string& why);
void refuse_checkpoint_flags(const ParsedArgs& args, const std::string& why);

}  // namespace pdamp::cli
