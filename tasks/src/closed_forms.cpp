// The single-damper closed forms as studies (closed_forms.hpp).
#include "pdamp/tasks/closed_forms.hpp"

#include <algorithm>

#include "pdamp/base/run_errors.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
using nlohmann::json;

StrokeSizing size_for_stroke(fm::DamperModel model, double stroke_m, const fm::ModelOptions& options) {
  StrokeSizing out;
  out.model = model;
  out.stroke_m = stroke_m;
  out.clearance_m = fm::clearance_for_stroke(model, stroke_m, options);
  out.at = fm::optimum_stroke(model, out.clearance_m, options);
  return out;
}

const base::Fields<StrokeSizing>& StrokeSizing::fields() {
  using S = StrokeSizing;
  static const auto f =
      base::Fields<S>()
          .field("model", &S::model, "", "rolling or bouncing")
          .field("stroke_m", &S::stroke_m, "m", "the target stroke X")
          .field("clearance_m", &S::clearance_m, "m", "the clearance whose design stroke is X")
          .derived("x_opt_ideal_m", [](const S& s) { return s.at.x_opt_ideal_m; }, "m", "its ideal peak")
          .derived("x_onset_m", [](const S& s) { return s.at.x_onset_m; }, "m", "its onset: strokes below fall off the cliff");
  return f;
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

const base::Fields<LossPoint>& LossPoint::fields() {
  using P = LossPoint;
  static const auto f =
      base::Fields<P>()
          .derived("model", [](const P& p) { return p.loss.model_requested; }, "", "the model asked for")
          .derived("model_used", [](const P& p) { return p.loss.model_used; }, "", "the model that answered")
          .derived("eta_star", [](const P& p) { return p.loss.eta_star; }, "1", "reduced loss factor")
          .field("e_diss_j", &P::e_diss_j, "J", "energy dissipated per cycle, eta* 1/2 m_bed V^2")
          .field("energy_per_cycle_j", &P::energy_per_cycle_j, "J", "the same over a whole cycle, pi E_diss")
          .field("equivalent_damping_n_s_m", &P::equivalent_damping_n_s_m, "N s/m", "eta* m_bed Omega")
          .derived("regime", [](const P& p) { return p.loss.regime; }, "", "the bed's state")
          .derived("inertia_factor", [](const P& p) { return p.loss.inertia_factor; }, "1", "kappa of the rolling model")
          .derived("intensity", [](const P& p) { return p.loss.intensity; }, "1", "X Omega^2 / g")
          .derived("stroke_over_onset", [](const P& p) { return p.loss.stroke_over_onset; }, "1",
                   "the stroke over the onset of collect-and-collide")
          .derived("velocity_amplitude_m_s", [](const P& p) { return p.loss.velocity_amplitude_m_s; }, "m/s",
                   "the container's velocity amplitude")
          .field("bed_mass_kg", &P::bed_mass_kg, "kg", "the bed mass the energies are for")
          .derived("warnings", [](const P& p) { return p.loss.warnings; }, "", "the model's range warnings");
  return f;
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
  json out = base::to_json(s.point);
  out.update({{"clearance_m", s.options.clearance_m}, {"amplitude_m", s.options.amplitude_m},
              {"frequency_hz", s.options.frequency_hz}});
  return out;
}

void require_finite(const json& result) {
  if (const auto bad = detail::non_finite_number(result))
    throw base::NumericalError("the result " + *bad + " is not finite: the inputs lie where the model cannot be evaluated");
}

}  // namespace pdamp::tasks
