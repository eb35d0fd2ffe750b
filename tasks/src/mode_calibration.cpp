// Calibrated modes of task kind modes (modes.hpp, ModeCalibration): the first damper's bed as
// a DEM effective field around each mode's frequency, cached in the calibration folder.
#include <cmath>
#include <filesystem>

#include "mode_calibration.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/tasks/bed_calibration.hpp"
#include "pdamp/tasks/field.hpp"

namespace pdamp::tasks::detail {

namespace {

using nlohmann::json;

/// Raised whenever what a calibration field holds or how it is run changes: part of every key.
/// 2: every point approached from 25 % above the largest (1: the largest from rest).
constexpr int kModeCalibrationVersion = 2;
/// The frequency nodes lie this fraction beyond the bed carried whole and the containers
/// empty, so that an apparent mass measured a little outside [0, m_bed] stays in the field.
constexpr double kFrequencyMargin = 0.01;

/// The field's grid as the case's `field` section writes it (docs/cases.md).
json calibration_grid(const ModeCalibration& m, int threads) {
  return {{"axes", "frequency_amplitude"},
          {"axis0", {{"min", m.min_frequency_hz}, {"max", m.max_frequency_hz}, {"count", 2}, {"spacing", "linear"}}},
          {"axis1",
           {{"min", m.min_amplitude_m}, {"max", m.max_amplitude_m}, {"count", m.amplitude_points}, {"spacing", "log"}}},
          {"threads", threads}};
}

/// Why a cached field is not this calibration's ("" when it is): the identity its sweep
/// stamps (the bed's physics hash, model version, approach) and the grid.
std::string cache_problem(const surrogate::EffectiveField& field, const FieldPlan& plan) {
  if (field.provenance.source != surrogate::FieldSource::kDem) return "it is not a DEM field";
  if (field.provenance.case_hash != plan.sweep.case_hash)
    return "it belongs to another bed (case hash " + field.provenance.case_hash + ")";
  if (field.provenance.model_version != plan.sweep.model_version)
    return "it was made by DEM model version " + std::to_string(field.provenance.model_version);
  if (field.provenance.approach_amplitude_m != plan.sweep.approach_amplitude_m) return "its points were approached otherwise";
  if (!(field.grid == plan.grid)) return "its grid is not the calibration's";
  for (const auto& p : field.points)
    if (p.status != surrogate::PointStatus::kOk) return "a point of it is not ok";
  return "";
}

/// The strokes at which the frequency nodes found the bed in different motion modes (m): there
/// every node takes the point of the smallest η*. A bed can hold two states at one stroke (at
/// the clearance search's h = 11.3 mm and 4 mm: scattering with η* = 0.107 and m_app = 0.31
/// m_bed at one node, decoupled with 0.027 at the other), and which one a decay passes through
/// depends on its history; a design does not count on the damping of the upper one. Where the
/// labels change with the frequency without two states (a regime boundary) the η* lie close and
/// the change is small.
std::vector<double> take_lower_branch_where_states_differ(surrogate::EffectiveField& field) {
  std::vector<double> strokes;
  const auto& grid = field.grid;
  for (std::size_t i1 = 0; i1 < grid.axis1.size(); ++i1) {
    std::size_t lowest = grid.index(0, i1);
    bool mixed = false;
    for (std::size_t i0 = 1; i0 < grid.axis0.size(); ++i0) {
      const std::size_t k = grid.index(i0, i1);
      mixed = mixed || field.points[k].motion_mode != field.points[lowest].motion_mode;
      if (field.points[k].eta_star < field.points[lowest].eta_star) lowest = k;
    }
    if (!mixed) continue;
    strokes.push_back(grid.axis1.values[i1]);
    const surrogate::FieldPoint lower = field.points[lowest];
    for (std::size_t i0 = 0; i0 < grid.axis0.size(); ++i0) field.points[grid.index(i0, i1)] = lower;
  }
  return strokes;
}

}  // namespace

ModeCalibration calibrate_mode(const case_file::Case& c, const case_file::ModesCalibrationSpec& spec,
                               const ModeCalibrationRange& range, const std::filesystem::path& cache_dir,
                               base::RunHooks& hooks) {
  ModeCalibration m;
  m.mode = range.mode;
  m.min_frequency_hz = range.carried_frequency_hz * (1.0 - kFrequencyMargin);
  m.max_frequency_hz = range.empty_frequency_hz * (1.0 + kFrequencyMargin);
  m.min_amplitude_m = range.min_amplitude_m;
  m.max_amplitude_m = range.max_amplitude_m;
  const double decades = std::log10(range.max_amplitude_m / range.min_amplitude_m);
  m.amplitude_points = std::max(2, static_cast<int>(std::ceil(decades * spec.strokes_per_decade - 1e-9)) + 1);

  // The calibration's case: the grid, the softening, another seed, and every point approached
  // from 25 % above the largest (the descending branch a decay follows). A point
  // run from rest shows the bed as placed for its first periods: the largest stroke of a
  // search's fields came out up to 9 times its neighbours' from rest, in line once approached.
  // Its excitation only has to lie below the approach.
  const double approach_m = kDescendingBranchFactor * m.max_amplitude_m;
  json grid = calibration_grid(m, c.field.threads);
  const case_file::Case fc = case_file::with_merge_patch(
      c, {{"field", grid},
          {"dem",
           {{"stiffness_softening", c.dem.stiffness_softening * spec.stiffness_softening},
            {"seed", case_file::other_seed(c)},
            {"approach", {{"amplitude_m", approach_m}}}}},
          {"excitation", {{"frequency_hz", m.max_frequency_hz}, {"amplitude_m", m.min_amplitude_m}}}});
  grid.erase("threads");  // how many points run at once changes no point
  m.key = surrogate::case_hash({{"physics", case_file::physics_hash(fc, "dem")},
                                {"grid", grid},
                                {"approach", fc.resolved.at("dem").value("approach", json())},
                                {"dem_model_version", surrogate::dem_model_version()},
                                {"calibration_version", kModeCalibrationVersion}});
  const std::string stem = base::safe_file_name(c.dampers.front().name) + "_mode" + std::to_string(m.mode + 1) + "_" + m.key;
  m.file = cache_dir / (stem + ".json");
  const std::string label = "pdamp modes (calibration, mode " + std::to_string(m.mode + 1) + ")";

  FieldOptions options;
  options.source = "dem";
  options.results_log = cache_dir / (stem + ".jsonl");  // an interrupted calibration resumes its points
  options.label = label;
  FieldPlan plan;
  try {  // also refuses a results log of another sweep
    plan = plan_field(fc, options, base::local_executor());
  } catch (const base::InputError& e) {  // the field's keys are the calibration's, not the user's
    throw base::InputError(c.path, "/task/calibration", "its DEM field of mode " + std::to_string(m.mode + 1) +
                                                            " is refused: " + e.what());
  }
  if (std::filesystem::exists(m.file)) {
    std::string problem;
    try {
      m.field = surrogate::read_effective_field(m.file);
      problem = cache_problem(m.field, plan);
    } catch (const std::exception& e) {
      problem = e.what();
    }
    if (problem.empty()) {
      m.cached = true;
      m.lower_branch_strokes_m = take_lower_branch_where_states_differ(m.field);
      return m;
    }
    hooks.note(label + ": the cached field " + base::printable(m.file.string()) + " is run again: " + problem);
  }
  FieldResult result = run_field(fc, plan, hooks, base::local_executor());
  m.wall_time_s = result.summary.wall_time_s;
  if (result.summary.points_failed > 0)
    throw base::NumericalError(label + ": " + std::to_string(result.summary.points_failed) + " of the field's " +
                               std::to_string(plan.grid.size()) + " DEM points failed (" + result.sweep_report +
                               "); the log " + base::printable(options.results_log.string()) + " names them");
  m.field = std::move(result.field);
  surrogate::write_effective_field(m.field, m.file);
  std::error_code ignored;
  std::filesystem::remove(options.results_log, ignored);  // the field holds every point now
  m.lower_branch_strokes_m = take_lower_branch_where_states_differ(m.field);  // the cache keeps the DEM's points
  return m;
}

}  // namespace pdamp::tasks::detail
