// Result files written atomically, gnuplot plots, and readable tables.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace pdamp::cli {

/// Collects a command's result files in a staging folder inside DIR and moves each
/// into place with rename() only when all are complete, so an interrupted or failed
/// command leaves no partial file (INTERFACE.md: -o DIR writes atomically).
class OutputDir {
 public:
  explicit OutputDir(std::filesystem::path dir);
  ~OutputDir();  ///< removes the staging folder if commit() was not reached
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Stages a text file; returns its final path.
  std::filesystem::path add(const std::string& name, const std::string& content);
  std::filesystem::path add_json(const std::string& name, const nlohmann::json& value);
  /// Registers `name` and returns its path in the staging folder, for writers that
  /// take a path (they must have written it before commit()).
  std::filesystem::path staged_path(const std::string& name);
  /// Stages a gnuplot script and, when gnuplot is installed, runs it in the staging
  /// folder; the script must write `outputs` (e.g. eta.png, eta.svg). Without gnuplot
  /// the script and data stay for later use and a warning is returned.
  std::vector<std::string> add_plot(const std::string& script_name, const std::string& script,
                                    const std::vector<std::string>& outputs);
  /// Moves every staged file into DIR. Returns the final paths.
  std::vector<std::string> commit();
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  std::filesystem::path staging_;
  std::vector<std::string> names_;
};

/// Writes `content` to `path` through a temporary file and rename().
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

/// True when a gnuplot executable is on PATH.
bool gnuplot_available();

/// Two-column "name  value" table for the readable (non --json) output.
std::string key_value_table(const std::vector<std::pair<std::string, std::string>>& rows);
std::string format_number(double value, int significant = 6);

}  // namespace pdamp::cli
