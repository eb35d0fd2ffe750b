// The checkpoint file of a long run (a DEM run, a DEM-in-the-loop decay, a verification's
// decays): where it is saved, whether the run continues from it, and the checks that refuse
// a checkpoint of another run. When a checkpoint is saved is the RunHooks' to say.
#pragma once

#include <filesystem>
#include <string>

#include "pdamp/dem_reference/checkpoint.hpp"

namespace pdamp::tasks {

struct CheckpointFile {
  std::filesystem::path path;  ///< empty: the run saves no checkpoint
  bool resume = false;         ///< continue from `path` (it must exist and be this run's)
};

/// The payload of `file.path` when its header has `expected`'s kind, case hash, model
/// version and settings; base::InputError naming the file and the key that differs
/// (or "--resume" when there is no file), or the damage, otherwise.
std::string read_checkpoint(const CheckpointFile& file, const dem_reference::CheckpointHeader& expected);
/// `file.path` written atomically with `header` and `payload`.
void write_checkpoint(const CheckpointFile& file, const dem_reference::CheckpointHeader& header,
                      const std::string& payload);
/// "the run stopped at t = … of … s and wrote FILE: run the same command with --resume to continue".
std::string resume_advice(const CheckpointFile& file, const dem_reference::CheckpointHeader& header);

}  // namespace pdamp::tasks
