// Checkpoint files of long runs (checkpoint.hpp).
#include "pdamp/tasks/checkpoint.hpp"

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/output_file.hpp"

namespace pdamp::tasks {

std::string read_checkpoint(const CheckpointFile& file, const dem_reference::CheckpointHeader& expected) {
  const std::string shown = base::printable(file.path.string());
  if (!std::filesystem::exists(file.path))
    throw base::InputError("--resume", "", "no checkpoint " + shown + " to continue (the run completed, or never started)");
  auto decoded = dem_reference::decode_checkpoint(
      base::read_input_file(file.path.string(), dem_reference::kMaxCheckpointBytes), file.path.string());
  const auto& h = decoded.header;
  const auto refuse = [&](const std::string& key, const std::string& saved, const std::string& here) {
    throw base::InputError(
        file.path.string(), "/" + key,
        "'" + saved + "' in the checkpoint, '" + here + "' for this run: it belongs to another " +
            (key == "kind" ? "command" : key == "physics_model_version" ? "pdamp version" : "case or settings") +
            " (run without --resume to start again)");
  };
  if (h.kind != expected.kind) refuse("kind", h.kind, expected.kind);
  if (h.case_hash != expected.case_hash) refuse("case_hash", h.case_hash, expected.case_hash);
  if (h.physics_model_version != expected.physics_model_version)
    refuse("physics_model_version", std::to_string(h.physics_model_version), std::to_string(expected.physics_model_version));
  if (h.settings != expected.settings) refuse("settings", h.settings, expected.settings);
  return std::move(decoded.payload);
}

void write_checkpoint(const CheckpointFile& file, const dem_reference::CheckpointHeader& header, const std::string& payload) {
  base::write_file_atomically(file.path, dem_reference::encode_checkpoint(header, payload));
}

std::string resume_advice(const CheckpointFile& file, const dem_reference::CheckpointHeader& header) {
  return "the run stopped at t = " + base::format_number(header.simulated_time_s, 6) + " of " +
         base::format_number(header.end_time_s, 6) + " s and wrote " + base::printable(file.path.string()) +
         ": run the same command with --resume to continue";
}

}  // namespace pdamp::tasks
