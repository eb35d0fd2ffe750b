// Parallel, resumable sweeps over a grid or a list of points with a JSON-lines results file.
#include "pdamp/surrogate/sweep.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "field_format.hpp"
#include "file_io.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/strict_object.hpp"
#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;
using nlohmann::json;

namespace {

constexpr std::string_view kSweepFormat = "pdamp.field_sweep";
constexpr int kSweepFormatVersion = 1;
constexpr int kMaxThreads = 256;
/// Relative agreement of a saved point's drive with the grid node it claims.
constexpr double kDriveTolerance = 1e-9;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// What a sweep visits, by index: a grid's nodes (their drives from the grid and the
/// clearance) or a list of points (a sensitivity study's variants), and what identifies
/// them in the results file's header.
struct Points {
  std::size_t count = 0;
  std::function<DrivePoint(std::size_t)> drive;
  json identity;           ///< header entries: {"axes": [..]} for a grid, {"points": ..} for a list
  std::string noun;        ///< "grid node" or "point" (messages)
};

Points grid_points(const Grid& grid, double clearance_m) {
  return {grid.size(), [&grid, clearance_m](std::size_t k) { return drive_point(grid, k, clearance_m); },
          json{{"axes", json::array({json(detail::axis_json(grid.axis0)), json(detail::axis_json(grid.axis1))})}},
          "grid node"};
}

Points list_points(const SweepPoints& points) {
  return {points.drives.size(), [&points](std::size_t k) { return points.drives[k]; },
          json{{"points", points.identity}}, "point"};
}

/// The header line that identifies a sweep; a results file resumes only if its header is equal.
json sweep_header(const Points& points, const SweepOptions& options) {
  json header = {{"format", kSweepFormat},
          {"format_version", kSweepFormatVersion},
          {"source", to_string(options.source)},
          {"case_hash", options.case_hash},
          {"model_version", options.model_version},
          {"clearance_m", options.clearance_m},
          {"bed_mass_kg", options.bed_mass_kg}};
  header.update(points.identity);
  // Only a sharded sweep records its shard: the whole grid's header stays as it was
  // before shards existed, so that such logs still resume.
  if (options.shard_count > 1) header["shard"] = {{"index", options.shard_index}, {"count", options.shard_count}};
  return header;
}

/// The indices of options' shard, ascending.
std::vector<std::size_t> shard_nodes(std::size_t count, const SweepOptions& options) {
  std::vector<std::size_t> nodes;
  for (std::size_t k = static_cast<std::size_t>(options.shard_index); k < count;
       k += static_cast<std::size_t>(options.shard_count))
    nodes.push_back(k);
  return nodes;
}

std::string point_line(std::size_t index, const DrivePoint& drive, const FieldPoint& p, double wall_time_s) {
  json line = base::to_json(p);
  line["index"] = index;
  line["drive"] = {{"frequency_hz", drive.frequency_hz}, {"amplitude_m", drive.amplitude_m}};
  line["wall_time_s"] = wall_time_s;
  return line.dump() + "\n";
}

/// Makes an evaluator's point storable: status ok or failed, derived columns filled in.
FieldPoint checked_point(FieldPoint p, const DrivePoint& drive, const SweepOptions& options) {
  const std::string where = "evaluator at frequency_hz = " + format_number(drive.frequency_hz, 12) +
                            ", amplitude_m = " + format_number(drive.amplitude_m, 12);
  if (p.status == PointStatus::kMissing) {
    throw base::NumericalError(where + ": returned status \"missing\"; return \"ok\" or \"failed\"");
  }
  if (p.status == PointStatus::kFailed) {
    p.eta_star = p.eta_star_stderr = p.e_diss_j = p.apparent_mass_kg = p.apparent_mass_fraction = FieldPoint::kUnknown;
    return p;
  }
  if (!std::isfinite(p.eta_star))
    throw base::NumericalError(where + ": returned status \"ok\" with eta_star = " + format_number(p.eta_star, 12));
  if (std::isnan(p.e_diss_j)) {
    const double velocity = 2.0 * formulas::kPi * drive.frequency_hz * drive.amplitude_m;  // |V*| = XΩ
    p.e_diss_j = p.eta_star * 0.5 * options.bed_mass_kg * velocity * velocity;
  }
  if (std::isnan(p.apparent_mass_fraction) && std::isfinite(p.apparent_mass_kg)) {
    p.apparent_mass_fraction = p.apparent_mass_kg / options.bed_mass_kg;
  }
  if (!std::isfinite(p.e_diss_j) || std::isinf(p.apparent_mass_kg) || std::isinf(p.apparent_mass_fraction) ||
      !(std::isnan(p.eta_star_stderr) || (p.eta_star_stderr >= 0.0 && std::isfinite(p.eta_star_stderr)))) {
    throw base::NumericalError(where + ": returned non-finite values (e_diss_j = " + format_number(p.e_diss_j, 12) +
                               ", eta_star_stderr = " + format_number(p.eta_star_stderr, 12) + ")");
  }
  return p;
}

/// An open, exclusively locked results file.
class ResultsFile {
 public:
  explicit ResultsFile(const std::filesystem::path& path) : path_(path) {
    const std::string label = detail::file_label(path);
    // O_NONBLOCK: a FIFO given as the results file must fail here, not hang a read later.
    fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_NONBLOCK | O_NOCTTY | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      const int error = errno;
      if (error == EISDIR) throw std::invalid_argument(label + ": is a directory, not a sweep results file");
      throw std::runtime_error(label + ": cannot open the sweep results file (" + std::strerror(error) + ")");
    }
    struct stat info {};
    if (::fstat(fd_, &info) != 0 || !S_ISREG(info.st_mode)) {
      ::close(fd_);
      throw std::invalid_argument(
          label + ": is not a regular file (a FIFO, socket or device); a sweep results file must be one");
    }
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw std::runtime_error(label +
                               ": another sweep is writing this results file; wait for it or use "
                               "another file");
    }
  }
  ResultsFile(const ResultsFile&) = delete;
  ResultsFile& operator=(const ResultsFile&) = delete;
  ~ResultsFile() { ::close(fd_); }

  /// Drops everything after byte `size` (a partly written last line) and appends from there.
  void truncate_to(std::size_t size) {
    if (::ftruncate(fd_, static_cast<off_t>(size)) != 0 || ::lseek(fd_, 0, SEEK_END) < 0) {
      throw std::runtime_error(path_.string() + ": cannot truncate the damaged last line (" + std::strerror(errno) +
                               ")");
    }
  }
  void append(std::string_view line) { detail::write_all_synced(fd_, line, path_); }

 private:
  std::filesystem::path path_;
  int fd_ = -1;
};

/// Explains how two sweep headers differ, key by key.
std::string header_difference(const json& saved, const json& wanted) {
  std::string text;
  for (const auto& [key, value] : wanted.items()) {
    const auto it = saved.find(key);
    if (it == saved.end() || *it != value) {
      std::string was = it == saved.end() ? std::string("absent") : it->dump();
      if (key == "axes") was = "other axes";
      text += (text.empty() ? "" : "; ") + key + ": file " + was + ", this sweep " +
              (key == "axes" ? std::string("the grid asked for") : value.dump());
    }
  }
  return text.empty() ? "unknown keys in the header" : text;
}

/// What a results file holds, checked against this sweep.
struct SavedPoints {
  std::size_t resumed = 0;         ///< points read back (marked in `done`)
  std::size_t complete_bytes = 0;  ///< bytes of newline-terminated lines; the rest is a cut write
  std::string warning;             ///< about a dropped partial last line ("" if none)
};

/// Reads the newline-terminated lines of a results file's `text` into `points` and
/// `done`. Only complete lines count: a last line without its newline is the append of
/// a killed run (SIGTERM or power loss mid-write) and is dropped with a warning, so its
/// point is computed again. Every complete line is checked strictly: a damaged line
/// before the end cannot come from a kill, so it throws std::invalid_argument, as does a
/// header of another sweep.
SavedPoints read_saved_points(const std::string& text, const std::string& file_name, const Points& nodes,
                              const SweepOptions& options, std::vector<FieldPoint>& points, std::vector<bool>& done) {
  SavedPoints saved;
  const std::size_t last_newline = text.rfind('\n');
  saved.complete_bytes = last_newline == std::string::npos ? 0 : last_newline + 1;
  const auto complete_end = text.begin() + static_cast<std::ptrdiff_t>(saved.complete_bytes);
  const auto complete_lines = static_cast<std::size_t>(std::count(text.begin(), complete_end, '\n'));
  if (saved.complete_bytes < text.size()) {
    saved.warning = file_name + ": line " + std::to_string(complete_lines + 1) + ": cut short (" +
                    std::to_string(text.size() - saved.complete_bytes) +
                    " bytes without a newline, the write of a killed run); dropped, " +
                    (complete_lines == 0 ? "the sweep starts again" : "its point is computed again");
  }
  const json header = sweep_header(nodes, options);
  const std::string damaged = ": the results file is damaged; delete or move it to start the sweep again";
  std::size_t line_number = 0;
  std::size_t begin = 0;
  while (begin < saved.complete_bytes) {
    const std::size_t end = text.find('\n', begin);
    const std::string line = text.substr(begin, end - begin);
    begin = end + 1;
    ++line_number;
    const std::string context = file_name + ": line " + std::to_string(line_number);
    json value;
    try {
      // parse_json_document also refuses a repeated key, which no writer of ours produces.
      value = base::parse_json_document(line, context);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(e.what() + damaged);
    }
    if (line_number == 1) {
      if (value != header) {
        // printable(): the difference quotes the file's values, and dump() leaves DEL and
        // other bytes that are not JSON control characters as they are (fuzz_sweep_log).
        throw std::invalid_argument(base::printable(
            file_name + ": line 1: this results file belongs to another sweep (" + header_difference(value, header) +
            "); delete or move it to start a new sweep, its points are not mixed in"));
      }
      continue;
    }
    try {
      base::StrictObject object(value, "", context);
      const long long index = object.integer("index", 0, static_cast<long long>(nodes.count) - 1);
      const auto k = static_cast<std::size_t>(index);
      if (done[k]) object.fail("index", std::to_string(index) + " appears twice");
      if (!in_shard(k, options.shard_index, options.shard_count)) {
        object.fail("index", std::to_string(index) + " is not a node of shard " + std::to_string(options.shard_index) +
                                 "/" + std::to_string(options.shard_count));
      }
      const DrivePoint node = nodes.drive(k);
      base::StrictObject drive(object.required("drive"), "/drive", context);
      const double f = drive.number("frequency_hz", true, "Hz");
      const double x = drive.number("amplitude_m", true, "m");
      drive.finish();
      if (std::abs(f - node.frequency_hz) > kDriveTolerance * node.frequency_hz ||
          std::abs(x - node.amplitude_m) > kDriveTolerance * node.amplitude_m) {
        std::ostringstream what;  // a stream: GCC 12 flags "(" + std::string with a false -Wrestrict
        what << "(" << format_number(f, 12) << " Hz, " << format_number(x, 12) << " m) is not " << nodes.noun << " "
             << k << " (" << format_number(node.frequency_hz, 12) << " Hz, " << format_number(node.amplitude_m, 12)
             << " m)";
        object.fail("drive", what.str());
      }
      auto nullable_number = [&](std::string_view key) {
        const json& v = object.required(key);
        return v.is_null() ? FieldPoint::kUnknown : object.number_value(v, object.pointer(key), false);
      };
      FieldPoint p;
      p.eta_star = nullable_number("eta_star");
      p.eta_star_stderr = nullable_number("eta_star_stderr");
      if (p.eta_star_stderr < 0.0)
        object.fail("eta_star_stderr", format_number(p.eta_star_stderr, 12) + ": must be >= 0 or null");
      p.e_diss_j = nullable_number("e_diss_j");
      p.apparent_mass_kg = nullable_number("apparent_mass_kg");
      p.apparent_mass_fraction = nullable_number("apparent_mass_fraction");
      if (const std::string problem = field_value_problem(p.eta_star, p.apparent_mass_fraction); !problem.empty())
        object.fail(problem.starts_with("eta_star") ? "eta_star" : "apparent_mass_fraction",
                    problem.substr(problem.find('=') + 2));
      p.motion_mode = object.string("motion_mode");
      if (detail::has_control_byte(p.motion_mode))
        object.fail("motion_mode", "\"" + p.motion_mode + "\" holds control characters (must be printable text)");
      const std::string status = object.string("status");
      const auto parsed = point_status_from_string(status);
      if (!parsed || *parsed == PointStatus::kMissing)
        object.fail("status", "is \"" + status + "\", must be \"ok\" or \"failed\"");
      p.status = *parsed;
      if (p.status == PointStatus::kOk && (std::isnan(p.eta_star) || std::isnan(p.e_diss_j))) {
        object.fail("eta_star", "null: an ok point needs eta_star and e_diss_j");
      }
      const double wall_time_s = object.number("wall_time_s", false, "s");
      if (wall_time_s < 0.0) object.fail("wall_time_s", format_number(wall_time_s, 12) + ": must be >= 0 (in s)");
      object.finish();
      points[k] = std::move(p);
      done[k] = true;
      ++saved.resumed;
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(e.what() + damaged);
    }
  }
  return saved;
}

/// Reads the saved points of a results file (or starts it): fills `points` and `done`,
/// returns how many were resumed and adds a warning for a dropped partial last line.
std::size_t resume(ResultsFile& file, const std::filesystem::path& path, const Points& nodes, const SweepOptions& options,
                   std::vector<FieldPoint>& points, std::vector<bool>& done, std::vector<std::string>& warnings) {
  // read_text_file (base::read_input_file) again refuses anything but a regular file.
  const std::string text = detail::read_text_file(path);
  const SavedPoints saved = read_saved_points(text, detail::file_label(path), nodes, options, points, done);
  if (!saved.warning.empty()) warnings.push_back(saved.warning);
  if (saved.complete_bytes == 0) {  // new file, or only a cut header: start it
    file.truncate_to(0);
    file.append(sweep_header(nodes, options).dump() + "\n");
    detail::sync_parent_folder(path);
    return 0;
  }
  // Only now that every complete line was checked: drop the partial one and append after the rest.
  file.truncate_to(saved.complete_bytes);
  return saved.resumed;
}

}  // namespace

std::vector<std::string> SweepOptions::validate() const {
  std::vector<std::string> problems;
  if (model_version < 0) problems.push_back("model_version = " + std::to_string(model_version) + ": must be >= 0");
  if (!positive_finite(clearance_m))
    problems.push_back("clearance_m = " + format_number(clearance_m, 12) + ": must be > 0 and finite");
  if (!positive_finite(bed_mass_kg))
    problems.push_back("bed_mass_kg = " + format_number(bed_mass_kg, 12) + ": must be > 0 and finite");
  if (threads < 1 || threads > kMaxThreads) {
    problems.push_back("threads = " + std::to_string(threads) + ": must be in [1, " + std::to_string(kMaxThreads) +
                       "]");
  }
  if (shard_count < 1 || shard_count > kMaxShards) {
    problems.push_back("shard_count = " + std::to_string(shard_count) + ": must be in [1, " +
                       std::to_string(kMaxShards) + "]");
  } else if (shard_index < 0 || shard_index >= shard_count) {
    problems.push_back("shard_index = " + std::to_string(shard_index) + ": must be in [0, " +
                       std::to_string(shard_count - 1) + "]");
  }
  return problems;
}

std::vector<std::string> SweepPoints::validate() const {
  std::vector<std::string> problems;
  if (drives.empty()) problems.push_back("drives: must hold at least one point");
  for (std::size_t k = 0; k < drives.size(); ++k) {
    if (!positive_finite(drives[k].frequency_hz))
      problems.push_back("drives[" + std::to_string(k) +
                         "].frequency_hz = " + format_number(drives[k].frequency_hz, 12) + ": must be > 0 and finite");
    if (!positive_finite(drives[k].amplitude_m))
      problems.push_back("drives[" + std::to_string(k) + "].amplitude_m = " + format_number(drives[k].amplitude_m, 12) +
                         ": must be > 0 and finite");
  }
  return problems;
}

std::string SweepSummary::brief_report() const {
  std::ostringstream out;
  out.precision(3);
  out << points_total << " points: " << points_resumed << " resumed, " << points_computed << " computed ("
      << points_failed << " failed) in " << std::fixed << wall_time_s << " s";
  return out.str();
}

namespace {

/// The evaluator of one point: its index and drive.
using IndexEvaluator = std::function<FieldPoint(std::size_t index, const DrivePoint& drive)>;

/// run_sweep and run_point_sweep: every point of options' shard not yet in the results
/// file, options.threads at a time (the documentation of run_sweep says the rest).
PointSweepResult run_points(const Points& all, const IndexEvaluator& evaluator, const SweepOptions& options,
                            base::RunHooks& hooks) {
  detail::throw_if_any(options.validate(), "sweep options");
  const auto start = Clock::now();
  const std::vector<std::size_t> nodes = shard_nodes(all.count, options);
  const std::size_t total = nodes.size();

  std::vector<FieldPoint> points(all.count);
  std::vector<bool> done(all.count, false);
  std::optional<ResultsFile> file;
  std::size_t resumed = 0;
  std::vector<std::string> warnings;
  if (!options.results_path.empty()) {
    file.emplace(options.results_path);
    resumed = resume(*file, options.results_path, all, options, points, done, warnings);
  }
  std::vector<std::size_t> pending;
  for (const std::size_t k : nodes) {
    if (!done[k]) pending.push_back(k);
  }

  std::mutex mutex;  // guards points, the file, the counters, the progress reports and `error`
  std::exception_ptr error;
  std::atomic<bool> stop{false};
  std::size_t computed = 0;
  auto report_progress = [&] {
    const double elapsed = seconds_since(start);
    const std::size_t left = pending.size() - computed;
    // Wall time per finished point of this run already reflects the parallelism.
    const double eta_s = computed == 0 ? std::numeric_limits<double>::quiet_NaN()
                                       : elapsed * static_cast<double>(left) / static_cast<double>(computed);
    base::Progress p;
    p.stage = options.progress_stage;
    p.done = static_cast<double>(resumed + computed);
    p.total = static_cast<double>(total);
    p.counts_points = true;
    p.eta_s = eta_s;
    hooks.progress(p);
  };
  auto fail = [&](std::exception_ptr e) {
    std::lock_guard lock(mutex);
    if (!error) error = e;
    stop = true;
  };
  // Pending point `slot`, unless a point failed, the progress report threw or the hooks ask
  // to stop: then no further point starts (those written so far stay in the results file
  // for a resume).
  auto compute = [&](std::size_t slot) {
    if (stop) return;
    if (const int signal = hooks.stop_requested(); signal != 0) {
      fail(std::make_exception_ptr(base::Interrupted(
          signal, file ? "the sweep stopped; its finished points are saved in " + detail::file_label(options.results_path) +
                             ": the same command resumes from them"
                       : "the sweep stopped; it had no results file, so nothing was kept")));
      return;
    }
    const std::size_t k = pending[slot];
    try {
      const DrivePoint drive = all.drive(k);
      const auto point_start = Clock::now();
      FieldPoint p = checked_point(evaluator(k, drive), drive, options);
      const double wall_time_s = seconds_since(point_start);
      std::lock_guard lock(mutex);
      if (file) file->append(point_line(k, drive, p, wall_time_s));
      points[k] = std::move(p);
      ++computed;
      report_progress();
    } catch (...) {
      fail(std::current_exception());
    }
  };

  try {
    report_progress();
  } catch (...) {
    fail(std::current_exception());
  }
  // Each thread takes the next pending point in order; one thread (or one point): this one.
  // compute() catches every error, so the first to fail is rethrown here, after all end.
  const std::size_t workers = std::min<std::size_t>(static_cast<std::size_t>(options.threads), pending.size());
  base::for_each_concurrently(pending.size(), workers > 1, compute, workers);
  if (error) std::rethrow_exception(error);

  PointSweepResult result;
  result.points = std::move(points);
  result.summary.points_total = total;
  result.summary.points_resumed = resumed;
  result.summary.points_computed = computed;
  result.summary.warnings = std::move(warnings);
  for (const auto& p : result.points) {
    if (p.status == PointStatus::kFailed) ++result.summary.points_failed;
  }
  result.summary.wall_time_s = seconds_since(start);
  return result;
}

/// A field of `grid` from the points of a grid sweep, provenance stamped now.
EffectiveField field_of(const Grid& grid, std::vector<FieldPoint> points, const SweepOptions& options) {
  EffectiveField field;
  field.grid = grid;
  field.points = std::move(points);
  field.provenance = make_provenance(options.source, options.case_hash, options.model_version);
  field.provenance.approach_amplitude_m = options.approach_amplitude_m;
  field.clearance_m = options.clearance_m;
  field.bed_mass_kg = options.bed_mass_kg;
  return field;
}

std::size_t pending_points(const Points& all, const SweepOptions& options) {
  detail::throw_if_any(options.validate(), "sweep options");
  const std::size_t total = shard_nodes(all.count, options).size();
  if (options.results_path.empty()) return total;
  std::error_code error;
  // exists() follows links: a dangling link is "nothing saved yet", as run_sweep creates its target.
  if (!std::filesystem::exists(options.results_path, error)) return total;
  std::vector<FieldPoint> points(all.count);
  std::vector<bool> done(all.count, false);
  // Read only, without the lock: a sweep running now may append meanwhile, which at worst
  // makes the count a little high (a cut last line is dropped, as on resume).
  const SavedPoints saved = read_saved_points(detail::read_text_file(options.results_path),
                                              detail::file_label(options.results_path), all, options, points, done);
  return total - saved.resumed;
}

}  // namespace

SweepResult run_sweep(const Grid& grid, const PointEvaluator& evaluator, const SweepOptions& options,
                      base::RunHooks& hooks) {
  if (!evaluator) throw std::invalid_argument("sweep evaluator: must be callable");
  return run_sweep(
      grid,
      [&](std::size_t k) {
        const DrivePoint drive = drive_point(grid, k, options.clearance_m);
        return evaluator(drive.frequency_hz, drive.amplitude_m);
      },
      options, hooks);
}

SweepResult run_sweep(const Grid& grid, const std::function<FieldPoint(std::size_t node)>& evaluator,
                      const SweepOptions& options, base::RunHooks& hooks) {
  detail::throw_if_any(grid.validate(), "sweep grid");
  detail::throw_if_any(options.validate(), "sweep options");
  if (!evaluator) throw std::invalid_argument("sweep evaluator: must be callable");
  PointSweepResult r = run_points(
      grid_points(grid, options.clearance_m), [&evaluator](std::size_t k, const DrivePoint&) { return evaluator(k); },
      options, hooks);
  return {field_of(grid, std::move(r.points), options), std::move(r.summary)};
}

PointSweepResult run_point_sweep(const SweepPoints& points, const PointIndexEvaluator& evaluator,
                                 const SweepOptions& options, base::RunHooks& hooks) {
  detail::throw_if_any(points.validate(), "sweep points");
  if (!evaluator) throw std::invalid_argument("sweep evaluator: must be callable");
  return run_points(list_points(points), [&evaluator](std::size_t k, const DrivePoint&) { return evaluator(k); },
                    options, hooks);
}

std::size_t pending_sweep_points(const Grid& grid, const SweepOptions& options) {
  detail::throw_if_any(grid.validate(), "sweep grid");
  return pending_points(grid_points(grid, options.clearance_m), options);
}

std::size_t pending_point_sweep(const SweepPoints& points, const SweepOptions& options) {
  detail::throw_if_any(points.validate(), "sweep points");
  return pending_points(list_points(points), options);
}

namespace {

/// One shard's results file as merge_sweep_shards reads it.
struct ShardLog {
  std::string label;  ///< file_label of its path
  std::string text;   ///< the whole file
  json header;        ///< line 1
  int index = 0;      ///< its shard (0/1 for a log of the whole grid)
  int count = 1;
};

ShardLog read_shard_log(const std::filesystem::path& path) {
  ShardLog log;
  log.label = detail::file_label(path);
  log.text = detail::read_text_file(path);
  const std::string context = log.label + ": line 1";
  const std::size_t newline = log.text.find('\n');
  if (newline == std::string::npos)
    throw std::invalid_argument(context + ": no complete sweep header (an empty or cut file); not a shard's results file");
  log.header = base::parse_json_document(log.text.substr(0, newline), context);
  if (!log.header.is_object() || log.header.value("format", json()) != kSweepFormat)
    throw std::invalid_argument(context + ": not a sweep results file (format must be \"" + std::string(kSweepFormat) +
                                "\")");
  if (const auto shard = log.header.find("shard"); shard != log.header.end()) {
    const auto part = [&](const char* key) {
      const json& v = shard->is_object() ? shard->value(key, json()) : json();
      if (!v.is_number_integer()) throw std::invalid_argument(context + ": /shard/" + key + ": must be a whole number");
      return v.get<long long>();
    };
    const long long index = part("index"), count = part("count");
    if (count < 2 || count > kMaxShards || index < 0 || index >= count)
      throw std::invalid_argument(context + ": /shard: " + std::to_string(index) + "/" + std::to_string(count) +
                                  ": must be i/n with 0 <= i < n, 2 <= n <= " + std::to_string(kMaxShards));
    log.index = static_cast<int>(index);
    log.count = static_cast<int>(count);
    log.header.erase("shard");  // what remains is the sweep's identity
  }
  return log;
}

std::string shard_name(int index, int count) { return std::to_string(index) + "/" + std::to_string(count); }

/// How two identity headers differ, key by key, each value named by its source.
std::string identity_difference(const json& a, const std::string& a_label, const json& b, const std::string& b_label) {
  std::string text;
  json keys = a;
  keys.update(b);
  for (const auto& item : keys.items()) {
    const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture one
    const auto ia = a.find(key), ib = b.find(key);
    const bool in_a = ia != a.end(), in_b = ib != b.end();
    if (in_a && in_b && *ia == *ib) continue;
    const auto shown = [&](bool present, json::const_iterator it) {
      if (!present) return std::string("absent");
      return key == "axes" ? std::string("other axes") : it->dump();
    };
    text += (text.empty() ? "" : "; ") + key + ": " + a_label + " " + shown(in_a, ia) + ", " + b_label + " " +
            shown(in_b, ib);
  }
  return text;
}

}  // namespace

namespace {

PointSweepResult merge_points(const Points& all, const SweepOptions& options,
                              const std::vector<std::filesystem::path>& shard_logs, const std::string& expected_label) {
  SweepOptions wanted = options;
  wanted.results_path.clear();
  wanted.shard_index = 0;
  wanted.shard_count = 1;
  detail::throw_if_any(wanted.validate(), "sweep options");
  if (shard_logs.empty()) throw std::invalid_argument("merge: no shard results files given");
  const auto start = Clock::now();

  std::vector<ShardLog> logs;
  for (const auto& path : shard_logs) logs.push_back(read_shard_log(path));
  // printable(): the differences quote the files' values (see read_saved_points).
  const ShardLog& first = logs.front();
  for (std::size_t i = 1; i < logs.size(); ++i) {
    if (logs[i].header != first.header) {
      throw std::invalid_argument(base::printable(
          first.label + " and " + logs[i].label + ": are not shards of one sweep (" +
          identity_difference(first.header, first.label, logs[i].header, logs[i].label) +
          "); merge only the shards of one pdamp field command"));
    }
  }
  const json expected = sweep_header(all, wanted);
  if (first.header != expected) {
    throw std::invalid_argument(base::printable(
        first.label + ": line 1: is a shard of another sweep than " + expected_label + " (" +
        identity_difference(first.header, first.label, expected, expected_label) + ")"));
  }
  // Which file holds which shard: every shard of one count exactly once.
  std::vector<const ShardLog*> by_index(static_cast<std::size_t>(first.count), nullptr);
  for (const auto& log : logs) {
    if (log.count != first.count) {
      throw std::invalid_argument(first.label + " is shard " + shard_name(first.index, first.count) + " but " +
                                  log.label + " is shard " + shard_name(log.index, log.count) +
                                  ": the shard counts differ");
    }
    const ShardLog*& slot = by_index[static_cast<std::size_t>(log.index)];
    if (slot != nullptr) {
      throw std::invalid_argument(slot->label + " and " + log.label + ": both are shard " +
                                  shard_name(log.index, log.count) + "; give each shard once");
    }
    slot = &log;
  }
  std::string missing;
  std::size_t missing_count = 0;
  for (std::size_t i = 0; i < by_index.size(); ++i) {
    if (by_index[i] != nullptr) continue;
    if (++missing_count <= 10) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  }
  if (missing_count > 0) {
    throw std::invalid_argument(std::string(missing_count == 1 ? "shard " : "shards ") + missing +
                                (missing_count > 10 ? ", ..." : "") + " of " + std::to_string(first.count) +
                                (missing_count == 1 ? " is" : " are") + " missing (" + std::to_string(logs.size()) +
                                " of " + std::to_string(first.count) + " shard files given)");
  }

  std::vector<FieldPoint> points(all.count);
  std::vector<bool> done(all.count, false);
  PointSweepResult result;
  for (const auto& log : logs) {
    SweepOptions shard = wanted;
    shard.shard_index = log.index;
    shard.shard_count = log.count;
    // The same strict reader as a resume: a damaged line is refused with its number,
    // and a node of another shard (so also a point in two files) is refused.
    const SavedPoints saved = read_saved_points(log.text, log.label, all, shard, points, done);
    if (!saved.warning.empty()) result.summary.warnings.push_back(saved.warning);
    const std::size_t nodes = shard_nodes(all.count, shard).size();
    if (saved.resumed != nodes) {
      throw std::invalid_argument(log.label + ": shard " + shard_name(log.index, log.count) + " is incomplete (" +
                                  std::to_string(saved.resumed) + " of " + std::to_string(nodes) +
                                  " points saved); rerun its command, it resumes, then merge");
    }
  }
  result.points = std::move(points);
  result.summary.points_total = all.count;
  result.summary.points_resumed = all.count;
  for (const auto& p : result.points) {
    if (p.status == PointStatus::kFailed) ++result.summary.points_failed;
  }
  result.summary.wall_time_s = seconds_since(start);
  return result;
}

}  // namespace

SweepResult merge_sweep_shards(const Grid& grid, const SweepOptions& options,
                               const std::vector<std::filesystem::path>& shard_logs,
                               const std::string& expected_label) {
  detail::throw_if_any(grid.validate(), "sweep grid");
  PointSweepResult r = merge_points(grid_points(grid, options.clearance_m), options, shard_logs, expected_label);
  return {field_of(grid, std::move(r.points), options), std::move(r.summary)};
}

PointSweepResult merge_point_sweep_shards(const SweepPoints& points, const SweepOptions& options,
                                          const std::vector<std::filesystem::path>& shard_logs,
                                          const std::string& expected_label) {
  detail::throw_if_any(points.validate(), "sweep points");
  return merge_points(list_points(points), options, shard_logs, expected_label);
}

}  // namespace pdamp::surrogate
