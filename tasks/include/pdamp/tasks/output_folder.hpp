// Where a task's files go, as its result JSON names them: the result keys "file" and "plot"
// hold the path of each file in the output folder, or null when the run writes none.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace pdamp::tasks {

struct OutputFolder {
  std::optional<std::filesystem::path> dir;  ///< none: the run writes no files
  /// The path of `name` in the folder, or null.
  nlohmann::json file(const std::string& name) const {
    return dir ? nlohmann::json((*dir / name).string()) : nlohmann::json(nullptr);
  }
};

}  // namespace pdamp::tasks
