// The single-damper closed forms as studies: the optimum stroke (pdamp optimum), the
// clearance for a stroke (pdamp size), the loss factor at one operating point with its
// eta*(X) curve (pdamp loss), the buffered-wall sizing (pdamp buffer), and their JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/record.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/hertz_impact.hpp"

namespace pdamp::tasks {

/// pdamp size: the clearance whose design stroke is `stroke_m`, and its landmarks.
struct StrokeSizing {
  formulas::DamperModel model = formulas::DamperModel::kRolling;
  double stroke_m = 0.0;       ///< the target stroke X, m
  double clearance_m = 0.0;    ///< h with x_opt(h) = X, m
  formulas::OptimumStroke at;  ///< the landmarks of that clearance
  static const base::Fields<StrokeSizing>& fields();
};
StrokeSizing size_for_stroke(formulas::DamperModel model, double stroke_m, const formulas::ModelOptions& options);

/// One point of a closed-form eta*(X) curve.
struct CurvePoint {
  double stroke_m = 0.0;
  formulas::LossResult loss;
};
/// eta*(X) of `model` at `points` strokes spaced evenly over [x_min_m, x_max_m].
std::vector<CurvePoint> eta_curve(formulas::DamperModel model, double clearance_m, double frequency_hz,
                                  const formulas::ModelOptions& options, double x_min_m, double x_max_m, int points);

/// The loss factor at one operating point, with the energies of a bed of `bed_mass_kg`
/// (docs/theory.md §2: E_diss = η* · ½ m_bed |V*|², the energy per cycle 2π E_diss, the
/// equivalent viscous damping η* m_bed Ω).
struct LossPoint {
  formulas::LossResult loss;
  double bed_mass_kg = 1.0;
  double frequency_hz = 0.0;
  double e_diss_j = 0.0;
  double energy_per_cycle_j = 0.0;
  double equivalent_damping_n_s_m = 0.0;
  static const base::Fields<LossPoint>& fields();
};
LossPoint loss_point(const formulas::LossResult& loss, double bed_mass_kg, double frequency_hz);

/// pdamp loss: what to evaluate.
struct LossOptions {
  formulas::DamperModel model = formulas::DamperModel::kAuto;
  double clearance_m = 0.0;
  double amplitude_m = 0.0;
  double frequency_hz = 0.0;
  std::optional<double> bed_mass_kg;  ///< none: 1 kg, and a warning says so
  formulas::ModelOptions model_options;
  bool with_curve = false;            ///< also the eta*(X) curve and its landmarks
};
struct LossStudy {
  LossOptions options;
  LossPoint point;
  std::vector<std::string> warnings;
  /// with_curve: eta*(X) over [0.02 h, max(1.5 h, 1.2 X)] (301 points) and the landmarks of
  /// the family that answered.
  std::vector<CurvePoint> curve;
  formulas::OptimumStroke landmarks;
};
LossStudy run_loss(const LossOptions& options);
/// The result keys of pdamp loss (without "warnings" and "files", which the caller adds).
nlohmann::json to_json(const LossStudy& study);

/// A closed form's result that holds a number that is not finite (a formula at the edge of
/// its range) is a numerical failure: base::NumericalError naming its JSON pointer.
void require_finite(const nlohmann::json& result);

}  // namespace pdamp::tasks
