// The output folder of a run: result files staged and committed as one set, gnuplot plots.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"

namespace pdamp::report {

/// Collects a command's result files in a staging folder inside DIR and moves each
/// into place with rename() only when all are complete, so an interrupted or failed
/// command leaves no partial file (docs/command_line.md: -o DIR writes atomically). A run
/// replaces the whole set of files the previous run wrote into DIR (listed in
/// DIR/.pdamp-outputs.json), so the outputs of two runs never mix; files pdamp did not
/// write are never touched.
/// Who wrote a folder's outputs: the command and the file it ran on (recorded with them).
struct OutputOwner {
  std::string command;  ///< "run", "optimize", "field merge", ...; empty: not recorded
  std::string input;    ///< the command's input file, absolute; empty: none
  bool operator==(const OutputOwner&) const = default;
};

class OutputDir {
 public:
  /// Checks DIR before any work: InputError (exit 2) naming `flag` when the path is
  /// empty, exists and is not a directory, or cannot be created or written, and when DIR
  /// holds the outputs of another owner (another command, or the same command on another
  /// input: a commit would remove them) unless `overwrite`; a folder whose record names no
  /// owner (an older pdamp's) is taken as this owner's, and while another run holds DIR
  /// (flock on the folder itself, held for the life of the object). Removes staging
  /// folders that processes no longer alive left behind.
  explicit OutputDir(std::filesystem::path dir, std::string flag = "-o", OutputOwner owner = {},
                     bool overwrite = false);
  ~OutputDir();  ///< removes the staging folder if commit() was not reached
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Stages a text file; returns its final path.
  std::filesystem::path add(const std::string& name, const std::string& content);
  std::filesystem::path add_json(const std::string& name, const nlohmann::json& value);
  /// Registers `name` and returns its path in the staging folder, for writers that
  /// take a path (they must have written it before commit()).
  std::filesystem::path staged_path(const std::string& name);
  /// Registers a file that a resumable job writes directly in DIR (a sweep's
  /// results log), so that it counts as part of this run's set.
  std::filesystem::path in_place(const std::string& name);
  /// Stages a gnuplot script and, when gnuplot is installed, runs it in the staging
  /// folder (an argument vector, no shell); the script must write `outputs` (e.g.
  /// eta.png, eta.svg). Without gnuplot the script and data stay for later use and a
  /// warning is returned.
  std::vector<std::string> add_plot(const std::string& script_name, const std::string& script,
                                    const std::vector<std::string>& outputs);
  /// Moves every staged file into DIR, removes the previous run's files that this run
  /// did not write again, and records the new set. Returns the final paths.
  std::vector<std::string> commit();
  /// The results are complete and costly (a DEM run): a signal that arrives from now on
  /// no longer abandons the staged set; it is committed, and the signal ends pdamp after
  /// (main says the results are complete). Without this a signal stops the staging and
  /// removes it (a cheap command is simply run again).
  void finish_despite_signals() { finish_despite_signals_ = true; }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  void start_writing();

  std::filesystem::path dir_;
  OutputOwner owner_;
  int lock_fd_ = -1;  ///< flock'ed for the run's life: one run writes a folder at a time
  std::filesystem::path staging_;
  std::vector<std::string> names_;     // staged, moved by commit()
  std::vector<std::string> in_place_;  // already in DIR
  bool writing_ = false;
  bool committed_ = false;
  bool finish_despite_signals_ = false;
};

/// True when a gnuplot executable is on PATH.
bool gnuplot_available();

/// A gnuplot string expression of `text` that gnuplot takes verbatim: single-quoted
/// pieces (no backquote command substitution, no @macro expansion, no escapes inside
/// them) joined with "'" where the text has a quote, control characters (a newline
/// would end the command) replaced by spaces, and "]]>" broken by a space (the SVG
/// terminal writes titles as XML text, where it is not allowed). Use with `noenhanced` so
/// that ^ _ { } @ & show as typed.
std::string gnuplot_string(const std::string& text);

using base::safe_file_name;

/// Numbers in titles and labels (base::format_number).
using base::format_number;

}  // namespace pdamp::report
