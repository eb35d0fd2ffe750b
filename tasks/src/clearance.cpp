// Task kind clearance (clearance.hpp).
#include "pdamp/tasks/clearance.hpp"

#include <algorithm>
#include <chrono>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/tasks/case_checks.hpp"

namespace pdamp::tasks {

namespace opt = optimizer;
namespace st = structure;
using nlohmann::json;

std::string_view to_string(DemRanking ranking) {
  switch (ranking) {
    case DemRanking::kChosen: return "chosen";
    case DemRanking::kHigher: return "higher";
    case DemRanking::kIndistinguishable: return "indistinguishable";
    case DemRanking::kLower: return "lower";
  }
  return "";
}

const base::Fields<ClearanceCheck>& ClearanceCheck::fields() {
  using C = ClearanceCheck;
  static const auto f =
      base::Fields<C>()
          .field("factor", &C::factor, "1", "on the chosen clearance")
          .field("clearance_m", &C::clearance_m, "m", "h")
          .field("predicted_peak", &C::predicted_peak, "1",
                 "the sizing's objective there: the largest non-unstable or held |X/U| over the band")
          .field("predicted_frequency_hz", &C::predicted_frequency_hz, "Hz", "its frequency")
          .field("predicted_band_centre_hz", &C::predicted_band_centre_hz, "Hz",
                 "centre of the 0.9 band of the harmonic balance's largest peak (null: no peak found)", base::kNullable)
          .field("predicted_sweep_peak", &C::predicted_sweep_peak, "1",
                 "the largest |X/U| slow sweeps up and down reach on the predicted branches")
          .field("dem_sweep", &C::dem_sweep, "", "the stepped sine direction of the larger DEM peak")
          .field("dem_peak", &C::dem_peak, "1", "the DEM's largest |X/U| (of the larger direction)", base::kNullable)
          .field("dem_peak_standard_error", &C::dem_peak_standard_error, "1", "over its analysed periods",
                 base::kNullable)
          .field("dem_frequency_hz", &C::dem_frequency_hz, "Hz", "the DEM peak's frequency", base::kNullable)
          .field("dem_band_centre_hz", &C::dem_band_centre_hz, "Hz", "centre of the DEM's 0.9 band", base::kNullable)
          .field("peak_relative_difference", &C::peak_relative_difference, "1", "(predicted sweep peak - DEM)/DEM",
                 base::kNullable)
          .field("band_centre_relative_difference", &C::band_centre_relative_difference, "1",
                 "(predicted - DEM)/DEM of the band centre", base::kNullable)
          .field("ranking", &C::ranking, "",
                 "a neighbour's DEM peak against the chosen one's: higher, indistinguishable (within twice their "
                 "combined standard error) or lower")
          .field("unconverged_points", &C::unconverged_points, "", "DEM points analysed before their transient converged")
          .field("solve_time_s", &C::wall_time_s, "s", "wall time of the DEM stepped sine");
  return f;
}

const base::Fields<ClearanceVerification>& ClearanceVerification::fields() {
  using V = ClearanceVerification;
  static const auto f =
      base::Fields<V>()
          .derived("tolerance_relative", [](const V& v) { return v.settings.tolerance_relative; }, "1",
                   "the chosen clearance's peak and band centre must lie this close to the DEM's")
          .derived("require_ranking", [](const V& v) { return v.settings.require_ranking; }, "",
                   "the DEM's lowest peak must be the chosen clearance's")
          .field("checks", &V::checks, "", "the chosen clearance, then its neighbours")
          .field("chosen_agrees", &V::chosen_agrees, "", "the chosen clearance's prediction within tolerance")
          .field("ranking_agrees", &V::ranking_agrees, "",
                 "the DEM puts no neighbour below the chosen clearance where the predicted sweeps put it above")
          .field("ranking_resolved", &V::ranking_resolved, "", "every neighbour's DEM peak lies above the chosen one's")
          .field("neighbours_agree", &V::neighbours_agree, "",
                 "every neighbour's DEM peak within tolerance of its predicted sweep peak (reported, not judged)")
          .field("passed", &V::passed, "", "the verification's verdict");
  return f;
}

double predicted_sweep_peak(const st::FrequencyResponse& response) {
  const auto states = [](const st::FrequencyPoint& p) {
    std::vector<double> out;
    for (const auto& root : p.roots)
      if (root.stability != st::Stability::kUnstable && !root.outputs.empty()) out.push_back(std::abs(root.outputs.front()));
    for (const auto& held : p.held_at_jump)
      if (!held.outputs.empty()) out.push_back(std::abs(held.outputs.front()));
    return out;
  };
  const auto sweep = [&](auto first, auto last) {
    double current = NAN, peak = NAN;
    for (auto p = first; p != last; ++p) {
      const std::vector<double> candidates = states(*p);
      if (candidates.empty()) continue;
      current = std::isfinite(current)
                    ? *std::min_element(candidates.begin(), candidates.end(),
                                        [&](double a, double b) {
                                          return std::abs(std::log(a / current)) < std::abs(std::log(b / current));
                                        })
                    : *std::min_element(candidates.begin(), candidates.end());
      peak = std::isfinite(peak) ? std::max(peak, current) : current;
    }
    return peak;
  };
  const double up = sweep(response.points.begin(), response.points.end());
  const double down = sweep(response.points.rbegin(), response.points.rend());
  return std::isfinite(up) && std::isfinite(down) ? std::max(up, down) : std::isfinite(up) ? up : down;
}

namespace {

opt::ClearanceOnStructureOptions sizing_options(const case_file::Case& c) {
  const case_file::ClearanceTask& task = *c.task.clearance;
  const case_file::DamperSpec& damper = c.dampers.front();
  const case_file::LayerSpec& layer = damper.layers.front();
  opt::ClearanceOnStructureOptions o;
  o.site = damper.site;
  o.drive_direction = {damper.drive_direction[0], damper.drive_direction[1]};
  o.container_mass_kg = damper.container_mass_kg;
  o.bed_mass_kg = layer.bed_mass_kg;
  o.model = damper.model;
  o.model_options = case_file::layer_model_options(damper, layer);
  o.base_amplitude_m = task.band.base_amplitude_m;
  o.base_direction = {task.band.direction[0], task.band.direction[1]};
  o.mode = task.mode;
  o.frequency_min_hz = task.band.min_frequency_hz;
  o.frequency_max_hz = task.band.max_frequency_hz;
  o.frequency_points = task.band.points;
  o.objective = task.objective;
  o.clearance_min_m = task.min_clearance_m;
  o.clearance_max_m = task.max_clearance_m;
  return o;
}

/// The prediction and the DEM stepped sine of `variant`, the case at clearance
/// `predicted.clearance_m` (factor·h): the peak and its frequency are the sizing's objective
/// there, the band centre the harmonic balance's peak of the variant.
ClearanceCheck check_clearance(const case_file::Case& variant, const case_file::ClearanceVerifySpec& v, double factor,
                               const opt::ClearanceResponse& predicted, base::RunHooks& hooks,
                               std::vector<std::string>& warnings) {
  ClearanceCheck out;
  out.factor = factor;
  out.clearance_m = predicted.clearance_m;
  out.predicted_peak = predicted.peak_transmissibility;
  out.predicted_frequency_hz = predicted.peak_frequency_hz;
  const std::string label = "h = " + base::format_number(out.clearance_m * 1e3, 4) + " mm";
  out.formulas = run_frf(variant, FrfOptions{FrfMethod::kFormulas, {}}, hooks, base::local_executor());
  if (const st::ResponsePeak* peak = first_output_peak(out.formulas.harmonic->response))
    out.predicted_band_centre_hz = peak->band_centre_hz;
  out.predicted_sweep_peak = predicted_sweep_peak(out.formulas.harmonic->response);
  FrfOptions dem{FrfMethod::kDem, {}};
  dem.dem.points = v.dem_points;
  dem.dem.min_frequency_hz = v.dem_min_frequency_hz;
  dem.dem.max_frequency_hz = v.dem_max_frequency_hz;
  dem.dem.settling.stable_tolerance = v.dem_tolerance;
  dem.dem.settling.max_transient_periods = v.dem_max_periods;
  if (std::isfinite(out.predicted_frequency_hz)) dem.dem.extra_frequencies_hz = {out.predicted_frequency_hz};
  base::LabelledHooks labelled(hooks, label);
  out.dem = run_frf(variant, dem, labelled, base::local_executor());
  out.wall_time_s = out.dem.stepped->solve_time_s;
  for (const auto& w : out.dem.warnings) warnings.push_back(label + ": " + w);
  for (const auto& branch : out.dem.stepped->branches) {
    for (const auto& point : branch.points) out.unconverged_points += point.converged ? 0 : 1;
    const st::SteppedSinePeak bp = st::stepped_sine_peak(branch);
    if (!(bp.peak.magnitude > out.dem_peak) && std::isfinite(out.dem_peak)) continue;
    const st::SteppedSinePoint& top = *bp.ascending[bp.peak.index];
    out.dem_sweep = branch.sweep;
    out.dem_peak = bp.peak.magnitude;
    out.dem_peak_standard_error = top.standard_error;
    out.dem_frequency_hz = bp.peak.frequency_hz;
    out.dem_band_centre_hz = bp.peak.band_centre_hz;
  }
  out.peak_relative_difference = (out.predicted_sweep_peak - out.dem_peak) / out.dem_peak;
  out.band_centre_relative_difference = (out.predicted_band_centre_hz - out.dem_band_centre_hz) / out.dem_band_centre_hz;
  return out;
}

ClearanceVerification verify_clearance(const case_file::Case& c, const case_file::ClearanceVerifySpec& v,
                                       const st::ModalModel& modal, const opt::ClearanceOnStructureOptions& o,
                                       double chosen_m, base::RunHooks& hooks, std::vector<std::string>& warnings) {
  ClearanceVerification out;
  out.settings = v;
  std::vector<double> factors{1.0};
  factors.insert(factors.end(), v.clearance_factors.begin(), v.clearance_factors.end());
  // Every clearance read as a case before any DEM runs: one the reader refuses stops nothing half-way.
  std::vector<case_file::Case> variants;
  for (const double factor : factors) variants.push_back(case_file::with_clearance(c, factor * chosen_m));
  for (std::size_t k = 0; k < factors.size(); ++k)
    out.checks.push_back(check_clearance(variants[k], v, factors[k],
                                         opt::clearance_response(modal, o, factors[k] * chosen_m), hooks, warnings));
  const ClearanceCheck& chosen = out.checks.front();
  out.chosen_agrees = std::abs(chosen.peak_relative_difference) <= v.tolerance_relative &&
                      std::abs(chosen.band_centre_relative_difference) <= v.tolerance_relative;
  for (auto k = out.checks.begin() + 1; k != out.checks.end(); ++k) {
    // The standard errors are over the analysed periods of one realisation of the bed; a NaN
    // one (a single analysed period) counts as 0.
    const auto se = [](double e) { return std::isfinite(e) ? e : 0.0; };
    const double noise = 2.0 * std::hypot(se(chosen.dem_peak_standard_error), se(k->dem_peak_standard_error));
    const double above = k->dem_peak - chosen.dem_peak;
    k->ranking = above > noise ? DemRanking::kHigher : above < -noise ? DemRanking::kLower : DemRanking::kIndistinguishable;
  }
  out.ranking_agrees = std::none_of(out.checks.begin() + 1, out.checks.end(), [&](const ClearanceCheck& n) {
    return n.ranking == DemRanking::kLower && n.predicted_sweep_peak > chosen.predicted_sweep_peak;
  });
  out.neighbours_agree = std::all_of(out.checks.begin() + 1, out.checks.end(), [&](const ClearanceCheck& n) {
    return std::abs(n.peak_relative_difference) <= v.tolerance_relative;
  });
  out.ranking_resolved = std::all_of(out.checks.begin() + 1, out.checks.end(),
                                     [](const ClearanceCheck& n) { return n.ranking == DemRanking::kHigher; });
  out.passed = out.chosen_agrees && (out.ranking_agrees || !v.require_ranking);
  return out;
}

}  // namespace

ClearanceStudy run_clearance(const case_file::Case& c, const ClearanceOptions& options, base::RunHooks& hooks,
                             base::Executor& executor) {
  executor.primary_only();  // one sizing and a few stepped sines, each on this process's threads
  require_task(c, case_file::TaskKind::kClearance);
  const case_file::ClearanceTask& task = *c.task.clearance;
  const case_file::StructureSetup setup = case_file::structure_setup(c, case_file::LossMethod::kFormulas);
  const opt::ClearanceOnStructureOptions o = sizing_options(c);
  opt::Options solver = opt::clearance_on_structure_solver_options();
  solver.backend = options.backend.value_or(*opt::backend_from_string(task.backend));
  ClearanceStudy out;
  out.case_name = c.name;
  out.damper = c.dampers.front().name;
  out.mode = task.mode;
  out.objective = task.objective;
  out.base_amplitude_m = task.band.base_amplitude_m;
  out.warnings = setup.warnings;
  try {
    out.sizing = opt::size_clearance_on_structure(setup.modal, o, solver);
    out.current = opt::clearance_response(setup.modal, o, c.dampers.front().layers.front().clearance_m);
    // The solver's range (size_clearance_on_structure: the closed form /3 and ·3 by default).
    const double lo = o.clearance_min_m.value_or(out.sizing.estimate.clearance_m / 3.0);
    const double hi = o.clearance_max_m.value_or(out.sizing.estimate.clearance_m * 3.0);
    for (int k = 0; k < ClearanceStudy::kScanPoints; ++k)
      out.scan.push_back(opt::clearance_response(
          setup.modal, o, lo * std::pow(hi / lo, static_cast<double>(k) / (ClearanceStudy::kScanPoints - 1))));
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, "/task", e.what());
  }
  if (!std::isfinite(out.sizing.response.peak_transmissibility))
    throw base::NumericalError("pdamp optimize: the clearance objective is not finite");
  const bool verify = !options.skip_verify && (task.verify || options.force_verify);
  if (verify)
    out.verification = verify_clearance(c, task.verify.value_or(case_file::ClearanceVerifySpec{
                                                                   .dem_min_frequency_hz = task.band.min_frequency_hz,
                                                                   .dem_max_frequency_hz = task.band.max_frequency_hz}),
                                        setup.modal, o, out.sizing.clearance_m, hooks, out.warnings);
  return out;
}

json to_json(const ClearanceStudy& study) {
  const auto& s = study.sizing.summary;
  return {{"task", "clearance"},
          {"case", study.case_name},
          {"damper", study.damper},
          {"mode", study.mode + 1},
          {"objective", std::string(opt::to_string(study.objective))},
          {"base_amplitude_m", study.base_amplitude_m},
          {"design", base::to_json(study.sizing.response)},
          {"current", base::to_json(study.current)},
          {"estimate", base::to_json(study.sizing.estimate)},
          {"solver", {{"backend", std::string(opt::to_string(s.backend))},
                      {"outcome", std::string(opt::to_string(s.outcome))},
                      {"evaluations", s.evaluations},
                      {"report", s.brief_report()}}},
          {"verification", study.verification ? base::to_json(*study.verification) : json(nullptr)},
          {"solve_time_s", study.sizing.solve_time_s}};
}

}  // namespace pdamp::tasks
