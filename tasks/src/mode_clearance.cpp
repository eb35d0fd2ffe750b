// The clearance search of task kind modes (modes.hpp, ModeClearanceSearchResult): each
// candidate clearance (with a buffered wall's lining, if searched) a variant of the case whose
// target mode is calibrated from DEM steady states (run_modes with a calibration of that mode
// alone), the best by the mode's added damping over the search's strokes, and the DEM decays
// of it and its neighbours.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "mode_calibration.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "task_support.hpp"

namespace pdamp::tasks::detail {

namespace {

using nlohmann::json;
using Search = case_file::ModesClearanceSearch;

/// The variant's task: the search's strokes as the backbone, its mode calibrated with the
/// search's settings, and with `verify` that mode's decays as the dem_check.
json variant_task(const Search& s, bool verify) {
  const case_file::ModesCalibrationSpec& spec = s.calibration;
  json task = {{"clearance_search", nullptr},
               {"backbone_min_amplitude_m", s.min_amplitude_m},
               {"backbone_max_amplitude_m", s.max_amplitude_m},
               {"backbone_points", s.amplitude_points},
               {"calibration",
                {{"modes", {s.mode + 1}},
                 {"strokes_per_decade", spec.strokes_per_decade},
                 {"stiffness_softening", spec.stiffness_softening}}},
               {"dem_check", nullptr}};
  if (verify) {
    const case_file::ModesDemCheck& v = *s.verify;
    task["dem_check"] = {{"modes", {s.mode + 1}},
                         {"amplitudes_m", v.amplitudes_m},
                         {"periods", v.periods},
                         {"amplitude_fraction", v.amplitude_fraction},
                         {"tolerance_relative", v.tolerance_relative},
                         {"forced_start_periods", v.forced_start_periods}};
  }
  return task;
}

std::string millimetres(double m) { return base::format_number(m * 1e3, 4) + " mm"; }

double mean(const std::vector<double>& values) {
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

/// The candidates' grid: ascending t, within each t ascending h (the thicknesses searched, or
/// the case's own lining alone).
struct Grid {
  std::vector<double> clearances_m, thicknesses_m;
  std::size_t index(std::size_t h, std::size_t t) const { return t * clearances_m.size() + h; }
  std::size_t size() const { return clearances_m.size() * thicknesses_m.size(); }
};

std::string candidate_name(const ModeClearanceCandidate& candidate, bool lined) {
  return "h = " + millimetres(candidate.clearance_m) +
         (lined ? ", lining " + millimetres(candidate.wall_layer_thickness_m) : std::string());
}

}  // namespace

ModeClearanceSearchResult search_mode_clearance(const case_file::Case& c, const std::filesystem::path& cache_dir,
                                                base::RunHooks& hooks, std::vector<std::string>& warnings) {
  const Search& s = *c.task.modes->clearance_search;
  ModeClearanceSearchResult out;
  out.settings = s;
  out.amplitudes_m = spaced(s.min_amplitude_m, s.max_amplitude_m, s.amplitude_points, true);
  ModesOptions options;
  options.calibrated = true;
  options.calibration_cache = cache_dir;
  const bool lined = !s.wall_layer_thicknesses_m.empty();
  const Grid grid{s.clearances_m,
                  lined ? s.wall_layer_thicknesses_m
                        : std::vector<double>{c.dampers.front().layers.front().compartment.layer.thickness_m}};
  if (lined && s.calibration.stiffness_softening * c.dem.stiffness_softening < 1.0)
    warnings.push_back("clearance search: the calibration softens every Young's modulus by " +
                       base::format_number(s.calibration.stiffness_softening * c.dem.stiffness_softening, 3) +
                       ", the lining's too, whose compliance is what its thickness changes: the linings are compared "
                       "softened (/task/clearance_search/calibration/stiffness_softening 1 compares them as built)");
  // A candidate: the lining's thickness first (the container as it is), then the clearance
  // between the linings (the container lengthened or shortened along the drive).
  const auto variant = [&](std::size_t k, bool verify) {
    const std::size_t h = k % grid.clearances_m.size(), t = k / grid.clearances_m.size();
    // The key of the step that may be refused: the lining first, then the clearance.
    std::string key = "/task/clearance_search/wall_layer_thicknesses_m/" + std::to_string(t);
    try {
      const case_file::Case lining =
          lined ? case_file::with_merge_patch(c, case_file::wall_layer_patch(c, grid.thicknesses_m[t])) : c;
      key = "/task/clearance_search/clearances_m/" + std::to_string(h);
      json patch = case_file::clearance_patch(lining, grid.clearances_m[h]);
      patch["task"] = variant_task(s, verify);
      return case_file::with_merge_patch(lining, patch);
    } catch (const base::InputError& e) {  // the candidate's bed does not fit, for one
      throw base::InputError(c.path, key,
                             "h = " + millimetres(grid.clearances_m[h]) +
                                 (lined ? ", lining " + millimetres(grid.thicknesses_m[t]) : std::string()) +
                                 ": the case with this candidate is refused (" + e.pointer() + ": " + e.rule() + ")");
    }
  };

  // Every candidate read before any DEM work: one the case refuses stops the search at once.
  std::vector<case_file::Case> variants;
  for (std::size_t k = 0; k < grid.size(); ++k) {
    variants.push_back(variant(k, false));
    const case_file::Case& vc = variants.back();
    ModeClearanceCandidate candidate;
    candidate.clearance_m = grid.clearances_m[k % grid.clearances_m.size()];
    candidate.wall_layer_thickness_m = grid.thicknesses_m[k / grid.clearances_m.size()];
    candidate.inner_length_m = vc.dampers.front().layers.front().container.inner_length(vc.dampers.front().drive_axis);
    if (c.buffer && candidate.wall_layer_thickness_m > 0.0) {
      // The lining must survive the buffer's design impact (docs/hertz_and_buffer.md).
      candidate.layer_tip_strain = formulas::layer_tip_strain(c.buffer->input, candidate.wall_layer_thickness_m);
      candidate.buildable = candidate.layer_tip_strain <= c.buffer->input.allowable_strain;
    }
    out.candidates.push_back(std::move(candidate));
  }
  if (std::none_of(out.candidates.begin(), out.candidates.end(), [](const auto& k) { return k.buildable; }))
    throw base::InputError(c.path,
                           lined ? "/task/clearance_search/wall_layer_thicknesses_m"
                                 : "/dampers/0/layers/0/wall_layer/thickness_m",
                           "every lining is strained beyond the buffer's allowable strain " +
                               base::format_number(c.buffer->input.allowable_strain, 3) +
                               " by its design impact: list thicker ones (pdamp buffer sizes the thinnest)");
  for (std::size_t k = 0; k < grid.size(); ++k) {
    ModeClearanceCandidate& candidate = out.candidates[k];
    if (!candidate.buildable) {
      warnings.push_back("clearance search, " + candidate_name(candidate, lined) + ": its tip strain " +
                         base::format_number(candidate.layer_tip_strain, 3) + " under the buffer's design impact "
                         "exceeds the allowable " + base::format_number(c.buffer->input.allowable_strain, 3) +
                         ": not run");
      continue;
    }
    hooks.note("pdamp modes (clearance search): candidate " + std::to_string(k + 1) + " of " +
               std::to_string(grid.size()) + ", " + candidate_name(candidate, lined));
    const ModesResult r = run_modes(variants[k], options, hooks);
    for (const auto& p : r.backbones.at(r.backbone_of_mode.at(s.mode)).points) {
      candidate.added_damping_ratios.push_back(p.added_damping_ratio);
      candidate.converged = candidate.converged && p.converged;
    }
    const auto& zeta = candidate.added_damping_ratios;
    candidate.objective = s.objective == Search::Objective::kWorst ? *std::min_element(zeta.begin(), zeta.end()) : mean(zeta);
    candidate.calibration = r.calibrations.front();
    if (!candidate.converged)
      warnings.push_back("clearance search, " + candidate_name(candidate, lined) +
                         ": some backbone points did not converge");
  }
  // NaN objectives (no converged backbone, or not built) never win.
  for (std::size_t k = 0; k < out.candidates.size(); ++k) {
    const double objective = out.candidates[k].objective;
    if (std::isfinite(objective) && !(objective <= out.candidates[out.chosen].objective)) out.chosen = k;
  }
  const std::size_t chosen_h = out.chosen % grid.clearances_m.size(), chosen_t = out.chosen / grid.clearances_m.size();
  const ModeClearanceCandidate& best = out.candidates[out.chosen];
  if (chosen_h == 0 || chosen_h + 1 == grid.clearances_m.size())
    warnings.push_back("clearance search: the best clearance is the " +
                       std::string(chosen_h == 0 ? "smallest" : "largest") + " candidate, h = " +
                       millimetres(best.clearance_m) + ": the optimum may lie " + (chosen_h == 0 ? "below" : "above") +
                       " the candidates (extend /task/clearance_search/clearances_m where a bed can be built)");
  // A thinner lining than the chosen one that was listed but not built is the strength
  // bound, not the search's edge: no warning then.
  const bool thinnest = chosen_t == 0, thickest = chosen_t + 1 == grid.thicknesses_m.size();
  if (lined && grid.thicknesses_m.size() > 1 && (thinnest || thickest))
    warnings.push_back("clearance search: the best lining is the " + std::string(thickest ? "thickest" : "thinnest") +
                       " candidate, " + millimetres(best.wall_layer_thickness_m) + ": the optimum may lie " +
                       (thickest ? "above" : "below") + " the candidates (extend /task/clearance_search/wall_layer_thicknesses_m)");

  if (!s.verify) return out;
  out.verified = true;
  // The chosen candidate and its neighbours: the next clearances at its lining, the next
  // buildable linings at its clearance.
  std::vector<std::size_t> checked{out.chosen};
  if (chosen_h > 0) checked.push_back(grid.index(chosen_h - 1, chosen_t));
  if (chosen_h + 1 < grid.clearances_m.size()) checked.push_back(grid.index(chosen_h + 1, chosen_t));
  if (chosen_t > 0 && out.candidates[grid.index(chosen_h, chosen_t - 1)].buildable)
    checked.push_back(grid.index(chosen_h, chosen_t - 1));
  if (chosen_t + 1 < grid.thicknesses_m.size()) checked.push_back(grid.index(chosen_h, chosen_t + 1));
  for (const std::size_t k : checked) {
    ModeClearanceCandidate& candidate = out.candidates[k];
    hooks.note("pdamp modes (clearance search): DEM check of " + candidate_name(candidate, lined) +
               (k == out.chosen ? " (chosen)" : " (neighbour)"));
    const ModesResult r = run_modes(variant(k, true), options, hooks);
    candidate.checks = r.dem_checks;
    candidate.checks_passed = r.dem_checks_passed();
    std::vector<double> predicted, dem;
    for (const auto& check : candidate.checks) {
      predicted.push_back(check.predicted_damping_ratio);
      dem.push_back(check.dem_damping_ratio);
    }
    candidate.predicted_check_mean = mean(predicted);
    candidate.dem_check_mean = mean(dem);
    for (const auto& w : r.warnings)  // a decay cut short of its measure (the rest are the case's own)
      if (w.rfind("pdamp modes (dem_check", 0) == 0)
        warnings.push_back("clearance search, " + candidate_name(candidate, lined) + ": " + w);
  }
  const ModeClearanceCandidate& chosen = out.candidates[out.chosen];
  out.chosen_agrees = chosen.checks_passed;
  // A neighbour beats the choice when the DEM gives it more added damping than the chosen
  // clearance by more than the tolerance on the whole damping ratio (bare plus added): the
  // same measure the decays pass by.
  double bare = 0.0;
  for (const auto& check : chosen.checks) bare += check.bare_damping_ratio / static_cast<double>(chosen.checks.size());
  const double allowance = s.verify->tolerance_relative * (bare + chosen.dem_check_mean);
  out.ranking_agrees = true;
  for (const std::size_t k : checked)
    if (!(out.candidates[k].dem_check_mean - chosen.dem_check_mean <= allowance)) out.ranking_agrees = false;
  out.passed = out.chosen_agrees && out.ranking_agrees;
  return out;
}

}  // namespace pdamp::tasks::detail
