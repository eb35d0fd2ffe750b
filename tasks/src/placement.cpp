// Task kind placement (placement.hpp).
#include "pdamp/tasks/placement.hpp"

#include <algorithm>

#include "pdamp/case_file/placement_problem.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace opt = optimizer;
namespace st = structure;
using nlohmann::json;

const base::Fields<PlacementSiteCheck>& PlacementSiteCheck::fields() {
  using S = PlacementSiteCheck;
  static const auto f =
      base::Fields<S>()
          .field("role", &S::role, "", "chosen or other")
          .derived("site", [](const S& s) { return s.predicted.site; }, "", "the point")
          .derived("position_m", [](const S& s) { return s.predicted.position_m; }, "m", "along the beam (null: a point)",
                   base::kNullable)
          .derived("objective_at_amplitude", [](const S& s) { return s.predicted.objective; }, "1",
                   "the placement's objective at the stated amplitudes")
          .field("predicted_objective", &S::predicted_objective, "1", "the objective of the decays, predicted",
                 base::kNullable)
          .field("dem_objective", &S::dem_objective, "1", "the same by the DEM", base::kNullable)
          .field("relative_difference", &S::relative_difference, "1", "(predicted - DEM)/DEM", base::kNullable)
          .field("modes", &S::modes, "", "each target mode's decay");
  return f;
}

const base::Fields<PlacementVerification>& PlacementVerification::fields() {
  using V = PlacementVerification;
  static const auto f =
      base::Fields<V>()
          .derived("tolerance_relative", [](const V& v) { return v.settings.tolerance_relative; }, "1",
                   "the chosen site's objective must lie this close to the DEM's")
          .derived("periods", [](const V& v) { return v.settings.periods; }, "", "each decay's length in periods")
          .derived("amplitude_fraction", [](const V& v) { return v.settings.amplitude_fraction; }, "1",
                   "the damping ratio is measured down to this fraction of the start")
          .derived("require_ranking", [](const V& v) { return v.settings.require_ranking; }, "",
                   "the DEM must rank the chosen site above the other")
          .field("sites", &V::sites, "", "the chosen site, then the other")
          .field("chosen_agrees", &V::chosen_agrees, "", "the chosen site's prediction within tolerance")
          .field("ranking_agrees", &V::ranking_agrees, "", "the DEM ranks the chosen site above the other")
          .field("passed", &V::passed, "", "the verification's verdict");
  return f;
}

namespace {

/// The objective of per-mode damping ratios, as the placement's (weighted mean or worst).
double objective_of(const std::vector<ModeDecayCheck>& modes, const case_file::PlacementTask& task, bool dem) {
  double sum = 0.0, weights = 0.0, worst = INFINITY;
  for (std::size_t k = 0; k < modes.size(); ++k) {
    const double zeta = dem ? modes[k].dem_damping_ratio : modes[k].predicted_damping_ratio;
    sum += task.targets[k].weight * zeta;
    weights += task.targets[k].weight;
    worst = std::min(worst, zeta);
  }
  return task.objective == opt::PlacementObjective::kWorstMode ? worst : sum / weights;
}

/// The site the verification compares with the chosen one: the task's, else the evaluated
/// site nearest half the chosen objective (on a beam at least a quarter of the range away).
opt::PlacementPoint other_site(const case_file::Case& c, const case_file::PlacementProblem& p,
                               const opt::PlacementResult& r) {
  const case_file::PlacementTask& task = *c.task.placement;
  const auto& v = *task.verify;
  if (p.beam && v.other_position_m) {
    const st::ModalModel modal = opt::beam_model_with_site(*p.beam, *v.other_position_m, r.best.site);
    opt::PlacementPoint point = opt::evaluate_placement(modal, r.best.site, p.options);
    point.position_m = *v.other_position_m;
    return point;
  }
  const opt::PlacementPoint* other = nullptr;
  const double range = p.beam ? p.beam->max_position_m - p.beam->min_position_m : 0.0;
  for (const auto& point : r.scan) {
    const bool elsewhere = p.beam ? std::abs(point.position_m - r.best.position_m) >= 0.25 * range
                                  : (v.other_point.empty() ? point.site != r.best.site : point.site == v.other_point);
    if (!elsewhere) continue;
    if (!other || std::abs(point.objective - 0.5 * r.best.objective) < std::abs(other->objective - 0.5 * r.best.objective))
      other = &point;
  }
  if (!other) throw base::InputError(c.path, "/task/verify", "there is no other site to compare the chosen one with");
  return *other;
}

PlacementVerification verify_placement(const case_file::Case& c, const case_file::PlacementProblem& p,
                                       const opt::PlacementResult& r, base::RunHooks& hooks) {
  const case_file::PlacementTask& task = *c.task.placement;
  PlacementVerification out;
  out.settings = *task.verify;
  for (const auto& [role, point] : {std::pair{std::string("chosen"), r.best}, {std::string("other"), other_site(c, p, r)}}) {
    PlacementSiteCheck site;
    site.role = role;
    site.predicted = point;
    const st::ModalModel modal = p.beam ? opt::beam_model_with_site(*p.beam, point.position_m, point.site) : p.modal;
    const ModeDecayWindow window{out.settings.periods, out.settings.amplitude_fraction};
    for (const auto& m : point.modes) {
      const std::string label = "pdamp optimize --verify (" + role + " site, mode " + std::to_string(m.mode + 1) + ")";
      site.modes.push_back(mode_decay_check(c, task.damper_index, modal, p.options.damper, point.site, m.mode,
                                            m.modal_amplitude, m.natural_frequency_hz, window, label,
                                            "/task/verify/periods", hooks));
    }
    site.predicted_objective = objective_of(site.modes, task, false);
    site.dem_objective = objective_of(site.modes, task, true);
    site.relative_difference = (site.predicted_objective - site.dem_objective) / site.dem_objective;
    out.sites.push_back(std::move(site));
  }
  out.chosen_agrees = std::abs(out.sites[0].relative_difference) <= out.settings.tolerance_relative;
  out.ranking_agrees = out.sites[0].dem_objective > out.sites[1].dem_objective;
  out.passed = out.chosen_agrees && (out.ranking_agrees || !out.settings.require_ranking);
  return out;
}

}  // namespace

PlacementStudy run_placement(const case_file::Case& c, const PlacementOptions& options, base::RunHooks& hooks,
                             base::Executor& executor) {
  executor.primary_only();  // the formulas or fields of a few sites, a few DEM decays: nothing to spread
  const case_file::PlacementTask& task = *c.task.placement;
  case_file::PlacementProblem p = case_file::placement_problem(c, options.method);
  opt::Options solver = opt::placement_solver_options();
  solver.backend = options.backend.value_or(*opt::backend_from_string(task.backend));
  PlacementStudy out;
  out.case_name = c.name;
  out.method = options.method;
  out.damper = p.options.damper.name;
  out.objective = p.options.objective;
  out.beam = p.beam.has_value();
  try {
    out.result = p.beam ? opt::optimize_placement_on_beam(*p.beam, p.options, solver, p.current_position_m)
                        : opt::optimize_placement_at_points(p.modal, p.candidate_points, p.options);
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, "/task", e.what());
  }
  out.warnings = p.warnings;
  out.warnings.insert(out.warnings.end(), out.result.warnings.begin(), out.result.warnings.end());
  if (!std::isfinite(out.result.best.objective))
    throw base::NumericalError("pdamp optimize: the placement objective is not finite");
  if (!options.skip_verify && (task.verify || options.force_verify)) {
    case_file::Case checked = c;
    if (!checked.task.placement->verify) checked.task.placement->verify = case_file::PlacementVerifySpec{};
    if (checked.dampers.size() != 1)
      throw base::InputError(c.path, "/dampers", "has " + std::to_string(c.dampers.size()) +
                                                      " dampers: the verification of a placement takes a case of one damper");
    out.verification = verify_placement(checked, p, out.result, hooks);
  }
  return out;
}

json to_json(const PlacementStudy& study) {
  const auto& r = study.result;
  const auto& s = r.summary;
  const json solver_json =
      r.refined ? json{{"backend", std::string(opt::to_string(s.backend))},
                       {"stages", "scan of " + std::to_string(r.scan.size()) + " positions, then a local refinement"},
                       {"outcome", std::string(opt::to_string(s.outcome))},
                       {"iterations", s.iterations},
                       {"evaluations", r.evaluations},
                       {"refinement_evaluations", s.evaluations},
                       {"message", s.message},
                       {"report", s.brief_report()}}
                : json{{"backend", "scan"},
                       {"stages", "every candidate point evaluated"},
                       {"outcome", "converged"},
                       {"iterations", 0},
                       {"evaluations", r.evaluations}};
  return {{"task", "placement"},
          {"case", study.case_name},
          {"method", std::string(case_file::to_string(study.method))},
          {"damper", study.damper},
          {"objective", {{"kind", std::string(opt::to_string(study.objective))}, {"unit", "damping ratio"},
                         {"value", r.best.objective}}},
          {"design", base::to_json(r.best)},
          {"current", r.current ? base::to_json(*r.current) : json(nullptr)},
          {"improvement_over_current",
           r.current && r.current->objective > 0.0 ? json(r.best.objective / r.current->objective) : json(nullptr)},
          {"sites_evaluated", r.scan.size()},
          {"solver", solver_json},
          {"verification", study.verification ? base::to_json(*study.verification) : json(nullptr)},
          {"solve_time_s", r.solve_time_s}};
}

}  // namespace pdamp::tasks
