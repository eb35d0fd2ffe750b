// Task kind damper_design (damper_design.hpp).
#include "pdamp/tasks/damper_design.hpp"

#include "pdamp/base/input_error.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
using nlohmann::json;

namespace {

/// `auto` in a design: rolling when the base friction keeps the spheres rolling at its
/// design stroke (Γ <= Γ_slip, formulas::slip_intensity), else bouncing.
fm::DamperModel design_family(const detail::SingleDamper& single, const case_file::Case& c) {
  if (single.damper.model != fm::DamperModel::kAuto) return single.damper.model;
  const auto options = case_file::layer_model_options(single.damper, single.layer);
  if (!options.gravity_across_drive) return fm::DamperModel::kBouncing;
  const auto rolling = fm::optimum_stroke(fm::DamperModel::kRolling, single.layer.clearance_m, options);
  const double omega = 2.0 * fm::kPi * c.excitation.frequency_hz;
  return rolling.x_opt_m * omega * omega / fm::kStandardGravity <= fm::slip_intensity(options) ? fm::DamperModel::kRolling
                                                                                                : fm::DamperModel::kBouncing;
}

}  // namespace

DamperDesignResult run_damper_design(const case_file::Case& c, base::Executor& executor) {
  executor.primary_only();  // the closed forms: nothing to spread
  DamperDesignResult out;
  const detail::SingleDamper single = detail::single_damper(c, "the damper_design task");
  try {
    const auto& d = single.damper;
    const auto& layer = single.layer;
    const auto model_options = case_file::layer_model_options(d, layer);
    out.case_name = c.name;
    out.family = design_family(single, c);
    out.clearance_m = layer.clearance_m;
    out.bed_mass_kg = layer.bed_mass_kg;
    out.frequency_hz = c.excitation.frequency_hz;
    const double f = c.excitation.frequency_hz;
    out.optimum = fm::optimum_stroke(out.family, layer.clearance_m, model_options);
    out.warnings = case_file::settled_bed_warnings(c);
    const auto design_point = fm::reduced_loss_factor(out.family, layer.clearance_m, out.optimum.x_opt_m, f, model_options);
    out.eta_star_at_design = design_point.eta_star;
    out.intensity_at_design = design_point.intensity;
    out.warnings.insert(out.warnings.end(), design_point.warnings.begin(), design_point.warnings.end());
    if (c.design.target_stroke_m) {
      const double h = fm::clearance_for_stroke(out.family, *c.design.target_stroke_m, model_options);
      out.sizing = DamperDesignResult::Sizing{*c.design.target_stroke_m, h, layer.bed.bed_extent_m + h};
    }
    if (c.excitation.amplitude_m) {
      const auto op = fm::reduced_loss_factor(d.model, layer.clearance_m, *c.excitation.amplitude_m, f, model_options);
      out.operating_point = loss_point(op, layer.bed_mass_kg, f);
      out.operating_amplitude_m = *c.excitation.amplitude_m;
      out.warnings.insert(out.warnings.end(), op.warnings.begin(), op.warnings.end());
    }
    if (c.buffer) {
      out.buffer = fm::size_buffer_layer(c.buffer->input);
      out.buffer_layer_material = c.buffer->layer_material;
      out.warnings.insert(out.warnings.end(), out.buffer->warnings.begin(), out.buffer->warnings.end());
    }
    out.curve = eta_curve(d.model == fm::DamperModel::kAuto ? fm::DamperModel::kAuto : out.family, layer.clearance_m, f,
                          model_options, c.design.sweep_min_over_clearance * layer.clearance_m,
                          c.design.sweep_max_over_clearance * layer.clearance_m, c.design.sweep_points);
  } catch (const std::invalid_argument& e) {
    throw base::InputError(c.path, "", std::string("the closed forms refuse this case: ") + e.what());
  }
  if (const auto bad = detail::non_finite_number(to_json(out)))
    throw base::InputError(c.path, "", "the design result " + *bad + " is not finite: the case lies outside the closed forms");
  return out;
}

json to_json(const DamperDesignResult& r) {
  json result = {{"task", "damper_design"}, {"case", r.case_name}, {"model", fm::to_string(r.family)},
                 {"clearance_m", r.clearance_m}, {"bed_mass_kg", r.bed_mass_kg}, {"optimum", base::to_json(r.optimum)}};
  result["optimum"]["eta_star_at_design"] = r.eta_star_at_design;
  result["optimum"]["intensity_at_design"] = r.intensity_at_design;
  if (r.sizing)
    result["sizing"] = {{"target_stroke_m", r.sizing->target_stroke_m},
                        {"clearance_m", r.sizing->clearance_m},
                        {"container_inner_length_along_drive_m", r.sizing->container_inner_length_along_drive_m}};
  if (r.operating_point) {
    result["operating_point"] = base::to_json(*r.operating_point);
    result["operating_point"]["amplitude_m"] = r.operating_amplitude_m;
  }
  if (r.buffer) {
    result["buffer"] = base::to_json(*r.buffer);
    result["buffer"]["layer_material"] = r.buffer_layer_material;
  }
  return result;
}

}  // namespace pdamp::tasks
