// The clearance search of task kind modes (modes.hpp, ModeClearanceSearchResult): each
// candidate clearance a variant of the case whose target mode is calibrated from DEM steady
// states (run_modes with a calibration of that mode alone), the best by the mode's added
// damping over the search's strokes, and the DEM decays of it and its neighbours.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "mode_calibration.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
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
  const auto variant = [&](std::size_t k, bool verify) {
    json patch = case_file::clearance_patch(c, s.clearances_m[k]);
    patch["task"] = variant_task(s, verify);
    try {
      return case_file::with_merge_patch(c, patch);
    } catch (const base::InputError& e) {  // the candidate's bed does not fit, for one
      throw base::InputError(c.path, "/task/clearance_search/clearances_m/" + std::to_string(k),
                             millimetres(s.clearances_m[k]) + ": the case with this clearance is refused (" +
                                 e.pointer() + ": " + e.rule() + ")");
    }
  };

  // Every candidate read before any DEM work: one the case refuses stops the search at once.
  std::vector<case_file::Case> variants;
  for (std::size_t k = 0; k < s.clearances_m.size(); ++k) variants.push_back(variant(k, false));
  for (std::size_t k = 0; k < s.clearances_m.size(); ++k) {
    hooks.note("pdamp modes (clearance search): candidate " + std::to_string(k + 1) + " of " +
               std::to_string(s.clearances_m.size()) + ", h = " + millimetres(s.clearances_m[k]));
    const case_file::Case& vc = variants[k];
    const ModesResult r = run_modes(vc, options, hooks);
    ModeClearanceCandidate candidate;
    candidate.clearance_m = s.clearances_m[k];
    candidate.inner_length_m = vc.dampers.front().layers.front().container.inner_length(vc.dampers.front().drive_axis);
    for (const auto& p : r.backbones.at(r.backbone_of_mode.at(s.mode)).points) {
      candidate.added_damping_ratios.push_back(p.added_damping_ratio);
      candidate.converged = candidate.converged && p.converged;
    }
    const auto& zeta = candidate.added_damping_ratios;
    candidate.objective = s.objective == Search::Objective::kWorst ? *std::min_element(zeta.begin(), zeta.end()) : mean(zeta);
    candidate.calibration = r.calibrations.front();
    if (!candidate.converged)
      warnings.push_back("clearance search, h = " + millimetres(candidate.clearance_m) +
                         ": some backbone points did not converge");
    out.candidates.push_back(std::move(candidate));
  }
  // NaN objectives (no converged backbone) never win.
  for (std::size_t k = 0; k < out.candidates.size(); ++k) {
    const double objective = out.candidates[k].objective;
    if (std::isfinite(objective) && !(objective <= out.candidates[out.chosen].objective)) out.chosen = k;
  }
  if (out.chosen == 0 || out.chosen + 1 == out.candidates.size())
    warnings.push_back("clearance search: the best clearance is the " +
                       std::string(out.chosen == 0 ? "smallest" : "largest") + " candidate, h = " +
                       millimetres(out.candidates[out.chosen].clearance_m) + ": the optimum may lie " +
                       (out.chosen == 0 ? "below" : "above") +
                       " the candidates (extend /task/clearance_search/clearances_m where a bed can be built)");

  if (!s.verify) return out;
  out.verified = true;
  const std::size_t first = out.chosen == 0 ? 0 : out.chosen - 1;
  const std::size_t last = std::min(out.chosen + 1, out.candidates.size() - 1);
  for (std::size_t k = first; k <= last; ++k) {
    ModeClearanceCandidate& candidate = out.candidates[k];
    hooks.note("pdamp modes (clearance search): DEM check of h = " + millimetres(candidate.clearance_m) +
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
        warnings.push_back("clearance search, h = " + millimetres(candidate.clearance_m) + ": " + w);
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
  for (std::size_t k = first; k <= last; ++k)
    if (k != out.chosen && !(out.candidates[k].dem_check_mean - chosen.dem_check_mean <= allowance))
      out.ranking_agrees = false;
  out.passed = out.chosen_agrees && out.ranking_agrees;
  return out;
}

}  // namespace pdamp::tasks::detail
