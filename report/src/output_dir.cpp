// The output folder of a run (output_dir.hpp): staged result files committed as one set, plots.
#include "pdamp/report/output_dir.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "pdamp/report/external_program.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/output_file.hpp"

namespace pdamp::report {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStagingPrefix = ".pdamp-staging-";
constexpr const char* kManifest = ".pdamp-outputs.json";

/// A staging folder ".pdamp-staging-<pid>" whose process is gone (killed during a
/// run) is garbage: nothing else uses that name.
void remove_stale_staging(const fs::path& dir) {
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kStagingPrefix, 0) != 0) continue;
    if (base::names_a_dead_process(std::string_view(name).substr(std::string(kStagingPrefix).size())))
      fs::remove_all(entry.path(), error);
  }
}

/// What the previous run recorded: its files (only plain names of this folder count, so a
/// tampered manifest cannot delete anything outside it) and its owner.
struct PreviousOutputs {
  std::vector<std::string> files;
  OutputOwner owner;
};
PreviousOutputs previous_outputs(const fs::path& dir) {
  PreviousOutputs out;
  try {
    const auto doc = base::parse_json_document(base::read_input_file((dir / kManifest).string()), kManifest);
    for (const auto& item : doc.at("files")) {
      const std::string name = item.get<std::string>();
      if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos || name[0] == '.') continue;
      out.files.push_back(name);
    }
    if (doc.contains("command") && doc["command"].is_string()) out.owner.command = doc["command"].get<std::string>();
    if (doc.contains("input") && doc["input"].is_string()) out.owner.input = doc["input"].get<std::string>();
  } catch (const std::exception&) {
    // no manifest (first run) or an unreadable one: nothing is removed
  }
  return out;
}

std::string owner_text(const OutputOwner& owner) {
  return "pdamp " + owner.command + (owner.input.empty() ? "" : " on " + base::printable(owner.input));
}

/// Whether a picture gnuplot wrote is whole: a PNG ends with its IEND chunk, an SVG with its
/// closing tag (other files are taken as they are).
bool complete_picture(const fs::path& path) {
  const std::string name = path.filename().string();
  const auto ends_with = [&](std::string_view suffix) {
    return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (!ends_with(".png") && !ends_with(".svg")) return true;
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (ends_with(".png")) return text.size() >= 12 && text.compare(text.size() - 8, 4, "IEND") == 0;
  const auto end = text.rfind("</svg>");
  return end != std::string::npos && text.find_first_not_of(" \t\r\n", end + 6) == std::string::npos;
}

/// Blocks SIGINT, SIGTERM and SIGHUP for its lifetime: the renames of a commit are
/// done as a whole (a signal that arrives is delivered afterwards).
class SignalBlock {
 public:
  SignalBlock() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&set, s);
    ::sigprocmask(SIG_BLOCK, &set, &old_);
  }
  ~SignalBlock() { ::sigprocmask(SIG_SETMASK, &old_, nullptr); }

 private:
  sigset_t old_;
};

}  // namespace

OutputDir::OutputDir(fs::path dir, std::string flag, OutputOwner owner, bool overwrite)
    : dir_(std::move(dir)), owner_(std::move(owner)) {
  const std::string shown = base::printable(dir_.string());
  if (dir_.empty()) throw base::InputError(flag, "", "'': an empty path is not an output directory");
  std::error_code error;
  const auto status = fs::status(dir_, error);
  if (fs::exists(status) && !fs::is_directory(status))
    throw base::InputError(flag, "", "'" + shown + "' exists and is not a directory");
  fs::create_directories(dir_, error);
  if (error || !fs::is_directory(dir_))
    throw base::InputError(flag, "", "'" + shown + "': cannot create the output directory (" +
                                   (error ? error.message() : std::string("not a directory")) + ")");
  // One run writes a folder at a time: two runs into one folder would overwrite each
  // other's checkpoint and set (each saying it wrote them). The lock goes with the process.
  // The folder itself is locked (flock on its descriptor): no lock file is left behind.
  lock_fd_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_fd_ < 0) {
    std::ostringstream what;  // a stream: GCC 12 flags this chain of + with a false -Wrestrict
    what << "'" << shown << "': cannot open the folder to lock it (" << std::strerror(errno) << ")";
    throw base::InputError(flag, "", what.str());
  }
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw base::InputError(flag, "", "'" + shown + "': another pdamp run is writing into this folder; wait for "
                                                "it, or use another folder");
  }
  // A commit removes the previous set: refused when that set is another owner's (a user who
  // reuses a folder name would lose another study's results, hours of DEM).
  if (const PreviousOutputs previous = previous_outputs(dir_);
      !overwrite && !previous.owner.command.empty() && !owner_.command.empty() && !(previous.owner == owner_)) {
    std::string files;
    for (std::size_t k = 0; k < previous.files.size() && k < 4; ++k)
      files += (k ? ", " : "") + base::printable(previous.files[k]);
    if (previous.files.size() > 4) files += ", ... (" + std::to_string(previous.files.size()) + " files)";
    throw base::InputError(flag, "", "'" + shown + "' holds the outputs of " + owner_text(previous.owner) + " (" +
                                                files + "), which this run would replace: pass --overwrite, or choose "
                                                "another folder");
  }
  remove_stale_staging(dir_);
  staging_ = dir_ / (kStagingPrefix + std::to_string(::getpid()));
  fs::remove_all(staging_, error);
  if (!fs::create_directory(staging_, error) || ::access(staging_.c_str(), W_OK) != 0) {
    fs::remove(staging_, error);
    throw base::InputError(flag, "", "'" + shown + "': cannot write into the output directory");
  }
}

OutputDir::~OutputDir() {
  std::error_code error;
  fs::remove_all(staging_, error);
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the folder's lock
  // After a commit signals stay deferred until pdamp exits: one that arrives now finds
  // the results complete, and main says so (finished()).
  if (writing_ && !committed_) end_output_phase();
}

void OutputDir::start_writing() {
  if (!writing_) {
    writing_ = true;
    begin_output_phase();
  }
  if (!finish_despite_signals_) stop_if_interrupted();
}

fs::path OutputDir::add(const std::string& name, const std::string& content) {
  start_writing();
  // Written in full and fsynced now (an ofstream reports a full disk for the last buffer
  // only at close, unchecked): a failure ends the run before any rename.
  base::write_file_synced(staging_ / name, content, dir_ / name);
  names_.push_back(name);
  return dir_ / name;
}

fs::path OutputDir::staged_path(const std::string& name) {
  start_writing();
  names_.push_back(name);
  return staging_ / name;
}

fs::path OutputDir::in_place(const std::string& name) {
  in_place_.push_back(name);
  return dir_ / name;
}

fs::path OutputDir::add_json(const std::string& name, const nlohmann::json& value) {
  return add(name, value.dump(2) + "\n");
}

bool gnuplot_available() {
  static const bool available = find_executable("gnuplot").has_value();
  return available;
}

std::vector<std::string> OutputDir::add_plot(const std::string& script_name, const std::string& script,
                                             const std::vector<std::string>& outputs) {
  add(script_name, script);
  const auto gnuplot = find_executable("gnuplot");
  if (!gnuplot)
    return {"gnuplot not found: wrote " + script_name + " and its data; run 'gnuplot " + script_name +
            "' in the output directory for the plots"};
  const std::string log = script_name + ".log";
  const int status = run_program(*gnuplot, {script_name}, staging_, staging_ / log);
  if (!finish_despite_signals_) stop_if_interrupted();  // gnuplot ended by Ctrl-C: its pictures may be cut short
  std::vector<std::string> warnings;
  if (status != 0) {
    // A failed run may leave truncated pictures: keep only the log, for the reason.
    names_.push_back(log);
    warnings.push_back("gnuplot failed on " + script_name + " (see " + log + "); data files are written");
    return warnings;
  }
  for (const auto& name : outputs) {
    if (!fs::exists(staging_ / name)) {
      warnings.push_back("gnuplot did not produce " + name);
      continue;
    }
    // gnuplot exits 0 with a picture cut short when the disk fills: such a set must not
    // replace a good one (an exception here ends the run before any rename).
    if (!complete_picture(staging_ / name))
      throw std::runtime_error(base::printable((dir_ / name).string()) +
                               ": gnuplot wrote it incomplete (a full disk?); the folder's earlier results are kept");
    names_.push_back(name);
  }
  return warnings;
}

std::vector<std::string> OutputDir::commit() {
  start_writing();
  std::vector<std::string> paths;
  // A result name taken by a folder (or a device) would stop the renames half-way:
  // refused before the first one, so the set is moved whole or not at all.
  std::error_code error;
  std::vector<std::string> targets = names_;
  targets.push_back(kManifest);
  for (const auto& name : targets) {
    const auto status = fs::symlink_status(dir_ / name, error);
    if (fs::exists(status) && !fs::is_regular_file(status))
      throw base::InputError("-o", "", "'" + base::printable((dir_ / name).string()) +
                                     "' exists and is not a file: move it away (pdamp writes " + name + " there)");
  }
  // Every staged file whole on disk before the first rename (a delayed write error of a
  // full disk shows in fsync), the record of the new set staged with them: a failure here
  // leaves the earlier set as it was.
  for (const auto& name : names_) base::sync_file(staging_ / name, dir_ / name);
  std::set<std::string> current(names_.begin(), names_.end());
  current.insert(in_place_.begin(), in_place_.end());
  const PreviousOutputs previous = previous_outputs(dir_);
  base::write_file_synced(staging_ / kManifest,
                                 nlohmann::json{{"format", "pdamp.outputs"}, {"files", current},
                                                {"command", owner_.command}, {"input", owner_.input}}
                                         .dump(2) + "\n",
                                 dir_ / kManifest);
  test_pause_point("commit");
  {
    const SignalBlock whole;
    for (const auto& name : names_) fs::rename(staging_ / name, dir_ / name);
    fs::rename(staging_ / kManifest, dir_ / kManifest);
    base::sync_parent_folder(dir_ / kManifest);
  }
  // The earlier set's files this run did not write again go last: a crash before here
  // leaves them as strays beside a complete new set, never a set with holes.
  for (const auto& old : previous.files)
    if (!current.count(old) && fs::is_regular_file(fs::symlink_status(dir_ / old, error))) fs::remove(dir_ / old, error);
  for (const auto& name : current) paths.push_back((dir_ / name).string());
  committed_ = true;
  test_pause_point("committed");
  return paths;
}

std::string gnuplot_string(const std::string& text) {
  // gnuplot 5.4 misreads a doubled quote at the start of a single-quoted string (a
  // title of three quotes and a letter is a syntax error), so a quote is spliced in as
  // the double-quoted string "'" instead: 'it'."'".'s'. A double-quoted string holding
  // only a quote has nothing to expand.
  std::string out, piece;
  const auto flush = [&] {
    if (piece.empty()) return;
    out += (out.empty() ? "'" : ".'") + piece + "'";
    piece.clear();
  };
  // gnuplot's SVG writes titles as text content, where "]]>" is not allowed (XML 1.0 §2.4):
  // a name holding it made the picture ill-formed. A space keeps it readable and inert.
  std::string inert;
  for (char c : text) {
    if (c == '>' && inert.size() >= 2 && inert[inert.size() - 1] == ']' && inert[inert.size() - 2] == ']') inert += ' ';
    inert += c;
  }
  for (char c : inert) {
    if (c == '\'') {
      flush();
      out += out.empty() ? "\"'\"" : ".\"'\"";
    } else {
      piece += static_cast<unsigned char>(c) < 0x20 || c == 0x7F ? ' ' : c;
    }
  }
  flush();
  return out.empty() ? "''" : out;
}

}  // namespace pdamp::report
