// The single-damper closed forms as studies (closed_forms.hpp).
#include "pdamp/tasks/closed_forms.hpp"

#include <algorithm>

#include "pdamp/base/run_errors.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
using nlohmann::json;

json to_json(const fm::OptimumStroke& o) {
  return {{"model", fm::to_string(o.model)},          {"clearance_m", o.clearance_m},
          {"x_opt_m", o.x_opt_m},                     {"x_opt_ideal_m", o.x_opt_ideal_m},
          {"x_onset_m", o.x_onset_m},                 {"calibration_factor", o.calibration_factor},
          {"eta_star_peak", o.eta_star_peak},         {"eta_star_onset", o.eta_star_onset}};
}

StrokeSizing size_for_stroke(fm::DamperModel model, double stroke_m, const fm::ModelOptions& options) {
  StrokeSizing out;
  out.model = model;
  out.stroke_m = stroke_m;
  out.clearance_m = fm::clearance_for_stroke(model, stroke_m, options);
  out.at = fm::optimum_stroke(model, out.clearance_m, options);
  return out;
}

json to_json(const StrokeSizing& s) {
  return {{"model", fm::to_string(s.model)}, {"stroke_m", s.stroke_m}, {"clearance_m", s.clearance_m},
          {"x_opt_ideal_m", s.at.x_opt_ideal_m}, {"x_onset_m", s.at.x_onset_m}};
}

std::vector<CurvePoint> eta_curve(fm::DamperModel model, double clearance_m, double frequency_hz,
                                  const fm::ModelOptions& options, double x_min_m, double x_max_m, int points) {
  std::vector<CurvePoint> curve;
  curve.reserve(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) {
    const double x = x_min_m + (x_max_m - x_min_m) * i / (points - 1);
    curve.push_back({x, fm::reduced_loss_factor(model, clearance_m, x, frequency_hz, options)});
  }
  return curve;
}

LossPoint loss_point(const fm::LossResult& loss, double bed_mass_kg, double frequency_hz) {
  LossPoint p;
  p.loss = loss;
  p.bed_mass_kg = bed_mass_kg;
  p.frequency_hz = frequency_hz;
  p.e_diss_j = fm::dissipated_energy_measure(loss.eta_star, bed_mass_kg, loss.velocity_amplitude_m_s);
  p.energy_per_cycle_j = fm::energy_per_cycle(p.e_diss_j);
  p.equivalent_damping_n_s_m = loss.eta_star * bed_mass_kg * 2.0 * fm::kPi * frequency_hz;
  return p;
}

json to_json(const LossPoint& p) {
  const auto& loss = p.loss;
  return {{"model", fm::to_string(loss.model_requested)},
          {"model_used", fm::to_string(loss.model_used)},
          {"eta_star", loss.eta_star},
          {"e_diss_j", p.e_diss_j},
          {"energy_per_cycle_j", p.energy_per_cycle_j},
          {"equivalent_damping_n_s_m", p.equivalent_damping_n_s_m},
          {"regime", fm::to_string(loss.regime)},
          {"inertia_factor", loss.inertia_factor},
          {"intensity", loss.intensity},
          {"stroke_over_onset", loss.stroke_over_onset},
          {"velocity_amplitude_m_s", loss.velocity_amplitude_m_s},
          {"bed_mass_kg", p.bed_mass_kg},
          {"warnings", loss.warnings}};
}

LossStudy run_loss(const LossOptions& o) {
  LossStudy out;
  out.options = o;
  const auto loss = fm::reduced_loss_factor(o.model, o.clearance_m, o.amplitude_m, o.frequency_hz, o.model_options);
  out.point = loss_point(loss, o.bed_mass_kg.value_or(1.0), o.frequency_hz);
  out.warnings = loss.warnings;
  // eta* needs no mass, the energies do: say which mass they are for.
  if (!o.bed_mass_kg)
    out.warnings.push_back("no --bed-mass given: e_diss_j, energy_per_cycle_j and equivalent_damping_n_s_m are for a 1 kg "
                           "bed (they scale with the bed mass; eta* does not)");
  if (o.with_curve) {
    // A nested bed's Coulomb block has no onset or peak: its curve alone.
    if (loss.model_used != fm::DamperModel::kCoulombBlock)
      out.landmarks = fm::optimum_stroke(loss.model_used, o.clearance_m, o.model_options);
    else
      out.landmarks.clearance_m = o.clearance_m;
    const double x_max = std::max(1.5 * o.clearance_m, 1.2 * o.amplitude_m);
    out.curve = eta_curve(o.model, o.clearance_m, o.frequency_hz, o.model_options, 0.02 * o.clearance_m, x_max, 301);
  }
  return out;
}

json to_json(const LossStudy& s) {
  json out = to_json(s.point);
  out.update({{"clearance_m", s.options.clearance_m}, {"amplitude_m", s.options.amplitude_m},
              {"frequency_hz", s.options.frequency_hz}});
  return out;
}

json to_json(const fm::BufferDesign& b) {
  return {{"model", b.model == fm::BufferModel::kLayered ? "layered" : "half_space"},
          {"layer_thickness_m", b.layer_thickness_m},   {"allowable_strain", b.allowable_strain},
          {"impact_velocity_m_s", b.impact_velocity_m_s},
          {"max_penetration_m", b.max_penetration_m},   {"contact_time_s", b.contact_time_s},
          {"contact_time_over_period", b.contact_time_over_period},
          {"effective_mass_kg", b.effective_mass_kg},   {"max_force_n", b.max_force_n},
          {"contact_radius_m", b.contact_radius_m},
          {"contact_radius_over_thickness", b.contact_radius_over_thickness},
          {"half_space_thickness_m", b.half_space_thickness_m},
          {"layered_compression_of_half_space_design", b.layered_compression_of_half_space_design},
          {"assumptions", b.assumptions},
          {"warnings", b.warnings}};
}

void require_finite(const json& result) {
  if (const auto bad = detail::non_finite_number(result))
    throw base::NumericalError("the result " + *bad + " is not finite: the inputs lie where the model cannot be evaluated");
}

}  // namespace pdamp::tasks
