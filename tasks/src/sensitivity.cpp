// pdamp sensitivity as a study (sensitivity.hpp).
#include "pdamp/tasks/sensitivity.hpp"

#include <algorithm>

#include <cmath>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
using nlohmann::json;
using base::format_number;

SensitivityStudy sensitivity_study(const case_file::Case& c) {
  const detail::SingleDamper single = detail::single_damper(c, "pdamp sensitivity");
  SensitivityStudy study;
  study.frequency_hz = c.sensitivity ? c.sensitivity->frequency_hz : c.excitation.frequency_hz;
  double x = c.sensitivity ? c.sensitivity->amplitude_m : c.excitation.amplitude_m.value_or(0.0);
  if (!(x > 0.0)) {
    const auto family = single.damper.model == fm::DamperModel::kBouncing ? fm::DamperModel::kBouncing
                                                                           : fm::DamperModel::kRolling;
    x = fm::optimum_stroke(family, single.layer.clearance_m, case_file::layer_model_options(single.damper, single.layer)).x_opt_m;
  }
  study.amplitude_m = x;
  study.variants = case_file::sensitivity_variants(c, study.warnings);
  study.points.identity = json::array();
  for (const auto& v : study.variants) {
    study.points.drives.push_back({study.frequency_hz, study.amplitude_m});
    study.points.identity.push_back({{"parameter", v.parameter}, {"value", v.value}});
  }
  return study;
}

namespace {

/// What evaluates variant k: the DEM at the study's drive, or the closed form.
surrogate::PointEvaluator variant_evaluator(const case_file::SensitivityVariant& v, bool dem, double x, double f) {
  if (dem) {
    auto options = case_file::dem_options(v.variant, 0, x, f);
    options.world.threads = 1;  // the study runs variants in parallel instead
    return surrogate::dem_evaluator(options);
  }
  const detail::SingleDamper d = detail::single_damper(v.variant, "pdamp sensitivity");
  return surrogate::formula_evaluator(d.damper.model, d.layer.clearance_m, d.layer.bed_mass_kg, case_file::layer_model_options(d.damper, d.layer));
}

surrogate::SweepOptions study_sweep(const case_file::Case& c, const std::string& source) {
  surrogate::SweepOptions sweep = field_sweep_options(c, source);
  sweep.threads = source == "dem" ? (c.sensitivity ? c.sensitivity->threads : c.field.threads) : 1;
  return sweep;
}

/// The rows of a study's points (a run's, a shard's or a merge's).
SensitivityResult study_result(const case_file::Case& c, const SensitivityStudy& study,
                               const surrogate::PointSweepResult& result, const std::string& source) {
  const double f = study.frequency_hz, x = study.amplitude_m;
  SensitivityResult out;
  out.case_name = c.name;
  out.source = source;
  out.frequency_hz = f;
  out.amplitude_m = x;
  out.warnings = study.warnings;
  out.warnings.insert(out.warnings.end(), result.summary.warnings.begin(), result.summary.warnings.end());
  const surrogate::FieldPoint& base = result.points.front();
  const bool base_ok = base.status == surrogate::PointStatus::kOk;
  for (std::size_t k = 0; k < study.variants.size(); ++k) {
    const auto& v = study.variants[k];
    const auto& p = result.points[k];
    const detail::SingleDamper d = detail::single_damper(v.variant, "pdamp sensitivity");
    const auto closed = fm::reduced_loss_factor(d.damper.model, d.layer.clearance_m, x, f, case_file::layer_model_options(d.damper, d.layer));
    const bool ok = p.status == surrogate::PointStatus::kOk;
    SensitivityRow row;
    row.parameter = v.parameter;
    row.value = k == 0 ? NAN : v.value;
    row.unit = v.unit;
    row.status = surrogate::to_string(p.status);
    row.eta_star = ok ? p.eta_star : NAN;
    row.eta_star_stderr = ok ? p.eta_star_stderr : NAN;
    row.delta_eta_star = ok && base_ok ? p.eta_star - base.eta_star : NAN;
    row.motion_mode = p.motion_mode;
    row.apparent_mass_fraction = p.apparent_mass_fraction;
    row.closed_form_eta_star = closed.eta_star;
    row.closed_form_regime = fm::to_string(closed.regime);
    row.clearance_m = d.layer.clearance_m;
    row.bed_mass_kg = d.layer.bed_mass_kg;
    row.intensity = x * std::pow(2.0 * fm::kPi * f, 2) / fm::kStandardGravity;
    out.rows.push_back(std::move(row));
  }
  out.baseline_eta_star = base_ok ? base.eta_star : NAN;
  return out;
}

}  // namespace

SensitivityPlan plan_sensitivity(const case_file::Case& c, const SensitivityOptions& options, const base::Executor& executor) {
  SensitivityPlan plan;
  plan.options = options;
  plan.study = sensitivity_study(c);
  const bool dem = options.source == "dem";
  plan.sweep = study_sweep(c, options.source);
  plan.sweep.shard_index = options.shard_index;
  plan.sweep.shard_count = options.shard_count;
  plan.sweep.results_path = options.results_log;
  const double f = plan.study.frequency_hz, x = plan.study.amplitude_m;
  // Every variant's DEM checked and costed before any work (exit 2 naming its key).
  double wall_time_s = 0.0, particle_steps = 0.0;
  if (dem)
    for (const auto& v : plan.study.variants) {
      auto o = case_file::dem_options(v.variant, 0, x, f);
      o.world.threads = 1;
      const auto e = check_dem_run(v.variant, 0, o);
      check_dem_placement(v.variant, 0, o);
      check_wall_time(v.variant, e.wall_time_s, "the DEM run of " + v.parameter, "/dem",
                      "fewer /dem/analysed_periods or /dem/transient_periods, a larger /dem/time_step_s, or fewer "
                      "particles",
                      options.accept_long_runs);
      wall_time_s += e.wall_time_s;
      particle_steps += e.particle_steps;
    }
  std::size_t pending = 0;
  try {
    pending = surrogate::pending_point_sweep(plan.study.points, plan.sweep);
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, "/sensitivity", e.what());
  }
  if (dem) {
    const double variants = static_cast<double>(plan.study.variants.size());
    const double at_once = std::min<double>(executor.concurrency(plan.sweep.threads), variants);
    plan.estimate = std::to_string(plan.study.variants.size()) + " DEM runs at f = " + format_number(f) + " Hz, X = " +
                    format_number(x) + " m (" + std::to_string(pending) + " to run), about " +
                    format_number(particle_steps * static_cast<double>(pending) / variants, 3) + " particle-steps, " +
                    format_number(wall_time_s * static_cast<double>(pending) / variants / at_once, 3) + " s on " +
                    format_number(at_once) + " threads" +
                    (executor.processes() > 1 ? ", spread over " + std::to_string(executor.processes()) + " MPI ranks" : "");
  }
  return plan;
}

SensitivityResult run_sensitivity(const case_file::Case& c, const SensitivityPlan& plan, base::RunHooks& hooks,
                                  base::Executor& executor) {
  const auto& study = plan.study;
  const bool dem = plan.options.source == "dem";
  std::vector<surrogate::PointEvaluator> evaluators;
  for (const auto& v : study.variants) evaluators.push_back(variant_evaluator(v, dem, study.amplitude_m, study.frequency_hz));
  base::Jobs<surrogate::FieldPoint> jobs(
      executor, [&](std::size_t k) { return evaluators.at(k)(study.frequency_hz, study.amplitude_m); });
  surrogate::SweepOptions sweep = plan.sweep;
  sweep.threads = executor.concurrency(sweep.threads);
  if (dem) {
    hooks.note(plan.options.label + ": " + plan.estimate);
  }
  // A DEM study reports its runs and stops on request; the closed forms take microseconds.
  sweep.progress_stage = "runs";
  base::LabelledHooks labelled(hooks, plan.options.label);
  const auto result = surrogate::run_point_sweep(study.points, [&](std::size_t k) { return jobs(k); }, sweep,
                                                 dem ? labelled : base::silent_hooks());
  jobs.end();  // the study is this process's alone (some runs from its log): the others' part ends
  SensitivityResult out = study_result(c, study, result, plan.options.source);
  out.sweep_report = result.summary.brief_report();
  out.mpi = jobs.balance();
  return out;
}

SensitivityResult merge_sensitivity(const case_file::Case& c, const std::string& source,
                                    const std::vector<std::filesystem::path>& logs) {
  const SensitivityStudy study = sensitivity_study(c);
  const auto result = surrogate::merge_point_sweep_shards(study.points, field_sweep_options(c, source), logs, c.path);
  SensitivityResult out = study_result(c, study, result, source);
  out.sweep_report = "merged " + std::to_string(logs.size()) + " shard files: " +
                     std::to_string(result.summary.points_total) + " variants (" +
                     std::to_string(result.summary.points_failed) + " failed)";
  return out;
}

Tornado tornado(const SensitivityResult& study) {
  Tornado out;
  const double baseline = study.baseline_eta_star;
  for (const auto& r : study.rows) {
    if (r.parameter == "baseline" || r.status != "ok" || !std::isfinite(r.eta_star)) continue;
    auto it = std::find_if(out.bars.begin(), out.bars.end(), [&](const TornadoBar& b) { return b.parameter == r.parameter; });
    if (it == out.bars.end())
      it = out.bars.insert(out.bars.end(), TornadoBar{r.parameter, r.eta_star, r.eta_star, r.value, r.value,
                                                      r.eta_star_stderr, r.eta_star_stderr, 0.0});
    if (r.eta_star < it->low) it->low = r.eta_star, it->value_at_low = r.value, it->stderr_at_low = r.eta_star_stderr;
    if (r.eta_star > it->high) it->high = r.eta_star, it->value_at_high = r.value, it->stderr_at_high = r.eta_star_stderr;
    if (std::isfinite(baseline)) it->effect = std::max(it->effect, std::abs(r.eta_star - baseline));
  }
  // "No effect": within round-off of the baseline (1e-12 relative), what a closed form
  // that does not take the parameter gives; a DEM run always moves η* more than that.
  const double round_off = 1e-12 * std::max(1.0, std::abs(baseline));
  for (auto it = out.bars.begin(); it != out.bars.end();) {
    if (std::isfinite(baseline) && it->effect <= round_off) {
      out.without_effect.push_back(it->parameter);
      it = out.bars.erase(it);
    } else {
      ++it;
    }
  }
  std::stable_sort(out.bars.begin(), out.bars.end(), [](const TornadoBar& a, const TornadoBar& b) { return a.effect < b.effect; });
  return out;
}

const base::Fields<SensitivityRow>& SensitivityRow::fields() {
  using R = SensitivityRow;
  static const auto f =
      base::Fields<R>()
          .field("parameter", &R::parameter, "", "baseline, then the parameters varied one at a time")
          .field("value", &R::value, "the row's unit", "the parameter's value (null: the baseline)", base::kNullable)
          .field("unit", &R::unit, "", "the value's unit")
          .field("status", &R::status, "", "ok, failed or missing (another shard's)")
          .field("eta_star", &R::eta_star, "1", "reduced loss factor", base::kNullable)
          .field("eta_star_stderr", &R::eta_star_stderr, "1", "its standard error", base::kNullable)
          .field("delta_eta_star", &R::delta_eta_star, "1", "eta* - the baseline's", base::kNullable)
          .field("motion_mode", &R::motion_mode, "", "the bed's motion mode")
          .field("apparent_mass_fraction", &R::apparent_mass_fraction, "1", "apparent mass over bed mass",
                 base::kNullable)
          .field("closed_form_eta_star", &R::closed_form_eta_star, "1", "the closed forms' eta* at the same point",
                 base::kNullable)
          .field("closed_form_regime", &R::closed_form_regime, "", "the closed forms' regime")
          .field("clearance_m", &R::clearance_m, "m", "the clearance of the variant")
          .field("bed_mass_kg", &R::bed_mass_kg, "kg", "the bed mass of the variant")
          .field("intensity", &R::intensity, "1", "X Omega^2 / g");
  return f;
}

const base::Fields<TornadoBar>& TornadoBar::fields() {
  using B = TornadoBar;
  static const auto f =
      base::Fields<B>()
          .field("parameter", &B::parameter, "", "the parameter varied")
          .field("effect", &B::effect, "1", "largest |eta* - the baseline's| over its values")
          .field("eta_star_low", &B::low, "1", "the lowest eta* over its values")
          .field("eta_star_high", &B::high, "1", "the highest")
          .field("value_at_low", &B::value_at_low, "the parameter's unit", "the value giving the lowest",
                 base::kNullable)
          .field("value_at_high", &B::value_at_high, "the parameter's unit", "the value giving the highest",
                 base::kNullable)
          .field("eta_star_stderr_at_low", &B::stderr_at_low, "1", "the lowest's standard error", base::kHidden)
          .field("eta_star_stderr_at_high", &B::stderr_at_high, "1", "the highest's standard error", base::kHidden);
  return f;
}

json to_json(const SensitivityResult& r) {
  const Tornado t = tornado(r);
  const std::vector<TornadoBar> largest_first(t.bars.rbegin(), t.bars.rend());
  return {{"case", r.case_name}, {"source", r.source}, {"frequency_hz", r.frequency_hz},
          {"amplitude_m", r.amplitude_m}, {"rows", base::to_json(r.rows)}, {"tornado", base::to_json(largest_first)},
          {"without_effect", t.without_effect}, {"sweep", r.sweep_report}};
}

}  // namespace pdamp::tasks
