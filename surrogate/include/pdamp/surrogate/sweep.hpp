// Sweep engine: fills an effective field point by point (DEM, formulas), in parallel,
// saving every finished point at once so that a killed sweep resumes where it stopped.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/run_hooks.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/grid.hpp"

namespace pdamp::surrogate {

/// The damper's response at drive frequency f (Hz) and stroke X (m). Called from up to
/// SweepOptions::threads threads at once, so it must be thread-safe; one call may take
/// minutes and may use threads of its own. Return status kOk with a finite η*, or
/// kFailed (values ignored; say why in motion_mode) to record a point that cannot be
/// computed; throwing stops the sweep (the exception reaches run_sweep's caller).
using PointEvaluator = std::function<FieldPoint(double frequency_hz, double amplitude_m)>;

/// What a sweep writes where, and the identity that guards its results file.
struct SweepOptions {
  /// JSON-lines results file (header line, then one line per finished point, each
  /// fsynced at once). If it exists, the sweep resumes from it. Empty: nothing is saved.
  std::filesystem::path results_path;
  FieldSource source = FieldSource::kDem;  ///< recorded in the provenance
  std::string case_hash;                   ///< case_hash() of the case; a different hash refuses to resume
  int model_version = 0;                   ///< physics-model version of the evaluator, >= 0; ditto
  double approach_amplitude_m = 0.0;       ///< recorded in the provenance (Provenance::approach_amplitude_m)
  double clearance_m = 0.0;                ///< damper clearance h, m, > 0 (turns (Γ, X/h) nodes into drives)
  double bed_mass_kg = 0.0;  ///< m_bed, kg, > 0 (E_diss and m_app/m_bed where the evaluator leaves them NaN)
  int threads = 2;           ///< points evaluated at once, [1, 256]
  /// Job arrays (Slurm): this sweep evaluates only the grid nodes k with
  /// k % shard_count == shard_index (in_shard). Interleaved rather than in blocks, so
  /// that the expensive nodes (high strokes of every frequency) spread over the shards.
  /// shard_count in [1, kMaxShards], shard_index in [0, shard_count); 0/1 is the whole grid.
  int shard_index = 0;
  int shard_count = 1;
  /// The stage of the progress reports (base::Progress::stage): what a point is to the user
  /// ("points" of a field, a sensitivity study's "runs").
  std::string progress_stage = "points";
  /// One line per violated rule ("threads = 0: must be in [1, 256]"); empty if valid.
  std::vector<std::string> validate() const;
};

/// Most shards a sweep may be split into (a Slurm array holds up to a few 10^4 tasks).
inline constexpr int kMaxShards = 100000;

/// True if grid node `index` belongs to shard shard_index of shard_count (see SweepOptions).
inline bool in_shard(std::size_t index, int shard_index, int shard_count) {
  return index % static_cast<std::size_t>(shard_count) == static_cast<std::size_t>(shard_index);
}

struct SweepSummary {
  std::size_t points_total = 0;     ///< nodes of this sweep's shard (the whole grid unless sharded)
  std::size_t points_resumed = 0;   ///< read back from the results file
  std::size_t points_computed = 0;  ///< evaluated in this run (ok or failed)
  std::size_t points_failed = 0;    ///< status kFailed among all points
  double wall_time_s = 0.0;         ///< this run
  /// One line each, for the user: a partial last line of the results file (a write cut
  /// by a kill) that was dropped, "<file>: line N: cut short (...); dropped, ...".
  std::vector<std::string> warnings;
  /// "18 points: 6 resumed, 12 computed (0 failed) in 12.3 s".
  std::string brief_report() const;
};

struct SweepResult {
  /// Every node of the shard filled (ok or failed), provenance stamped now; nodes of
  /// other shards keep status kMissing (all NaN), so a shard's field is not a full one.
  EffectiveField field;
  SweepSummary summary;
};

/// Evaluates every grid node of options' shard not yet in the results file,
/// options.threads at a time, and returns the field (the caller writes it with
/// write_effective_field; a shard's field is written by merge_sweep_shards instead).
///
/// Results file: line 1 is a header {format "pdamp.field_sweep", format_version, source,
/// case_hash, model_version, clearance_m, bed_mass_kg, axes}, plus shard {index, count}
/// for a sharded sweep (shard_count > 1; absent for the whole grid, so that logs written
/// before shards existed still resume); every further line is one
/// finished point {index, drive {frequency_hz, amplitude_m}, values, status, wall_time_s},
/// written and fsynced under a mutex as soon as the point is done. Resuming re-reads the
/// file: a header that differs from this sweep's (another case, model version, source,
/// clearance, bed mass, grid or shard) throws std::invalid_argument telling the user to delete
/// or move the file, so stale points are never mixed in; a last line without its newline
/// (a write cut by SIGTERM or a crash) is truncated away, recomputed and reported in
/// SweepSummary::warnings; any other damaged line (bad JSON, a repeated key, a value
/// out of range, a node of another shard) throws std::invalid_argument naming the line. A results path that is a
/// directory, FIFO or device throws std::invalid_argument at once. A second sweep on the
/// same file at the same time is refused (std::runtime_error; the file is locked with flock).
///
/// Ok points with NaN e_diss_j get η*·½ m_bed (XΩ)² (docs/theory.md §1), and NaN
/// apparent_mass_fraction gets apparent_mass_kg/m_bed.
///
/// Progress goes to hooks.progress (no label: the caller names the sweep with
/// base::LabelledHooks; stage options.progress_stage, counts_points): once before the first
/// point is evaluated (done = the resumed points, 0 for a new sweep, so the user sees a line
/// at once) and after each finished point: points done (resumed ones included), points of
/// the shard, and eta_s, the estimated seconds left (NaN until this run has finished a
/// point). Called from worker threads, one call at a time. hooks.stop_requested() is asked
/// before each point starts.
///
/// If the evaluator or hooks.progress throws, or a stop is requested, no new point is
/// started, points in flight finish and are saved, and the first exception is rethrown
/// (for a stop base::Interrupted with the signal, saying where the finished points are): a
/// killed, stopped or failed sweep loses at most the points in flight. An evaluator
/// returning status ok with a non-finite η*, or status missing, counts as throwing
/// std::runtime_error. Throws std::invalid_argument for an invalid grid or options,
/// std::runtime_error for I/O.
SweepResult run_sweep(const Grid& grid, const PointEvaluator& evaluator, const SweepOptions& options,
                      base::RunHooks& hooks = base::silent_hooks());
/// The same with an evaluator of the node index k (Grid::index order; its drive is
/// drive_point(grid, k, options.clearance_m)): for callers that hand nodes to other
/// processes by number.
SweepResult run_sweep(const Grid& grid, const std::function<FieldPoint(std::size_t node)>& evaluator,
                      const SweepOptions& options, base::RunHooks& hooks = base::silent_hooks());

/// Grid nodes a run_sweep(grid, evaluator, options) would evaluate now: the nodes of
/// options' shard (grid.size() unless sharded) minus the points already saved in options.results_path (0 saved if the path is
/// empty or does not exist; a cut last line counts as not saved). Reads the file without
/// writing or locking it, so a caller can estimate the run time (the CLI multiplies by
/// its time per point) before starting. Throws what run_sweep would throw before its
/// first point: std::invalid_argument for an invalid grid or options (kMaxGridNodes
/// included), a results file of another sweep, a damaged line, a directory or FIFO.
std::size_t pending_sweep_points(const Grid& grid, const SweepOptions& options);

/// Joins the results files of the shards of one sweep (run_sweep with shard_count = n
/// and shard_index 0..n-1, in any order) into the field a serial run_sweep(grid, ...,
/// options) returns: the same values point for point, provenance stamped now.
/// options.results_path, shard_index and shard_count are ignored; the other identity
/// fields (source, case_hash, model_version, clearance_m, bed_mass_kg) and the grid say
/// which sweep is expected, `expected_label` names where they come from in messages
/// (e.g. the case file). Reads the files without writing or locking them. Throws
/// std::invalid_argument, naming the files involved, for: a file that cannot be read or
/// whose header is not a sweep header ("<file>: line 1: ..."); two files whose headers
/// differ in anything but the shard ("<a> and <b>: are not shards of one sweep (key: a
/// .., b ..)"); a header that differs from the expected one ("<file>: line 1: is a shard
/// of another sweep than <expected_label> (key: file .., expected ..)"); shard counts
/// that differ, a shard given twice, a shard missing; a damaged line or a node of another
/// shard (as run_sweep, with the line number); a shard whose points are not all saved
/// (its sweep was stopped: rerun it, it resumes). SweepSummary: points_total =
/// points_resumed = grid.size(), nothing computed; warnings for cut last lines.
SweepResult merge_sweep_shards(const Grid& grid, const SweepOptions& options,
                               const std::vector<std::filesystem::path>& shard_logs,
                               const std::string& expected_label = "this sweep");

/// A sweep over a list of points instead of a grid's nodes: a sensitivity study's variants
/// of one damper at its design drive. The same machinery as run_sweep (parallel, saved point
/// by point, resumable, shardable, merged by merge_point_sweep_shards): the results file's
/// header carries `identity` under "points" where a grid sweep has its axes, so a file of
/// another list is refused as one of another grid is.
struct SweepPoints {
  std::vector<DrivePoint> drives;  ///< one per point (the drive its line records), > 0 and finite
  nlohmann::json identity;         ///< what the points are (e.g. the variants' names and values)
  /// One line per violated rule ("drives[2].amplitude_m = 0: must be > 0 and finite").
  std::vector<std::string> validate() const;
};
/// The response of point k (thread-safe, as PointEvaluator).
using PointIndexEvaluator = std::function<FieldPoint(std::size_t index)>;
struct PointSweepResult {
  std::vector<FieldPoint> points;  ///< one per point; of other shards status kMissing
  SweepSummary summary;
};
/// run_sweep over `points` (the same results file, resume, shard, hooks and error rules).
PointSweepResult run_point_sweep(const SweepPoints& points, const PointIndexEvaluator& evaluator,
                                 const SweepOptions& options, base::RunHooks& hooks = base::silent_hooks());
/// pending_sweep_points for a list of points.
std::size_t pending_point_sweep(const SweepPoints& points, const SweepOptions& options);
/// merge_sweep_shards for a list of points.
PointSweepResult merge_point_sweep_shards(const SweepPoints& points, const SweepOptions& options,
                                          const std::vector<std::filesystem::path>& shard_logs,
                                          const std::string& expected_label = "this sweep");

/// Evaluator of the closed forms (formulas::reduced_loss_factor) for one damper: η*,
/// stderr 0 (exact), E_diss = η*·½ m_bed (XΩ)², apparent mass not given (NaN; the closed
/// forms model dissipation only), motion_mode the regime name (formulas::to_string of the
/// MotionRegime). Microseconds per point: run it with threads = 1 and no
/// results file. Throws std::invalid_argument now for a bad clearance, bed mass or options.
PointEvaluator formula_evaluator(formulas::DamperModel model, double clearance_m, double bed_mass_kg,
                                 const formulas::ModelOptions& options = {});

}  // namespace pdamp::surrogate
