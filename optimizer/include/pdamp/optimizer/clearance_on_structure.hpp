// Clearance on a structure: the clearance h of one particle damper on a
// base-excited modal model, where the damper's own stroke depends on h through the
// damping it adds at resonance. Either the damper runs at its design stroke at the
// resonance peak (X_peak(h) = x_opt(h)) or the FRF peak is lowest; both are solved on
// structure::harmonic_balance with a ClosedFormLossModel of clearance h, and compared
// with the single-mode closed form (docs/optimizer.md, "Clearance on a structure").
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/base/record.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/summary.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::optimizer {

enum class ClearanceObjective {
  /// X_peak(h) = x_opt(h): minimise (X_peak/x_opt − 1)², X_peak the damper amplitude at
  /// the FRF peak (largest non-unstable root or jump-held state), x_opt the design stroke
  /// of formulas::optimum_stroke (0.4 h rolling, h/π bouncing).
  kDesignStrokeAtResonance,
  /// minimise max over the frequency grid of the largest non-unstable (or held) |X/U|.
  kLowestPeak,
};
std::string_view to_string(ClearanceObjective objective);

struct ClearanceOnStructureOptions {
  std::string site;                            ///< named point of the ModalModel
  Eigen::Vector2d drive_direction{1.0, 0.0};   ///< unit vector n (the container's drive axis)
  double container_mass_kg = 0.0;              ///< empty container m_c, kg, >= 0
  double bed_mass_kg = 0.0;                    ///< m_bed, kg, > 0
  /// kRolling or kBouncing: their η* and m_app/m_bed depend on X/h only, which the closed
  /// form for h needs (kAuto's depend on Γ too; kScattered has no orbit).
  formulas::DamperModel model = formulas::DamperModel::kRolling;
  formulas::ModelOptions model_options;
  double base_amplitude_m = 0.0;               ///< U, m, > 0
  Eigen::Vector2d base_direction{1.0, 0.0};    ///< unit vector e of the base motion
  /// The mode tuned, in [0, modes): the closed form uses it alone; the harmonic balance
  /// uses every mode of the model.
  int mode = 0;
  /// Frequency grid of the harmonic balance: `frequency_points` evenly spaced points of
  /// [frequency_min_hz, frequency_max_hz], Hz (0 < min < max); in [5, 10000].
  double frequency_min_hz = 0.0;
  double frequency_max_hz = 0.0;
  int frequency_points = 200;
  /// Stroke scan of the harmonic balance, points per decade (>= 4; see HarmonicBalanceOptions).
  /// 12 (half the harmonic balance's default) changes the beam test's peak by < 1e-6.
  int scan_points_per_decade = 12;
  /// Stroke range scanned for roots, as multiples of h: [min, max]·h, 0 < min < max <= 10
  /// (10 h: the closed forms' validity). Only the peak matters here, which sits near the
  /// design stroke: the default [0.05, 10] skips the small off-resonance strokes and
  /// saves about 40 % of the scan of the loss model's own range [10⁻³, 10]·h.
  double stroke_min_over_clearance = 0.05;
  double stroke_max_over_clearance = 10.0;
  ClearanceObjective objective = ClearanceObjective::kDesignStrokeAtResonance;
  /// Search range of h, m; default: the closed-form estimate /3 and ·3.
  std::optional<double> clearance_min_m;
  std::optional<double> clearance_max_m;
  /// One line per violated rule ("bed_mass_kg = 0: must be > 0 and finite"), the model
  /// options' lines prefixed "model_options."; empty if valid. The site and mode are
  /// checked against the model by size_clearance_on_structure.
  std::vector<std::string> validate() const;
};

/// Solver settings that fit this 1-variable problem of a few ms per evaluation: the
/// global stage on with 16 evaluations (ISRES's first population: a random sampling of
/// the 1-D box, enough to land on the right side of the onset plateau and of the
/// high-amplitude cliff), COBYLA (the objective is a max over a grid, with kinks),
/// xtol_rel 1e-3 (h to 0.1 %, well inside the closed form's accuracy), 60 evaluations in all.
Options clearance_on_structure_solver_options();

/// The single-mode closed form (docs/optimizer.md): with the bed at its design point
/// (X/h = x_opt/h, η*_opt, m_app/m_bed there; all independent of h),
///   M = m_j + m_c|Φ_d|² + m_app b²,        b = Φ_dᵀn,  Φ_d the site's translation (mode j)
///   P = Γ_j·e + m_c Φ_d·e + m_app b (n·e)  (base load per unit base acceleration)
///   ω_r = ω_j √(m_j/M),  ζ_s' = ζ_j √(m_j/M),  ζ_add = ½ η*_opt m_bed b²/M,  Γ_eff = |b P|/M
///   X/U ≈ Γ_eff / (2(ζ_s' + ζ_add)),         h = U Γ_eff / (2 (x_opt/h)(ζ_s' + ζ_add)).
struct ClearanceEstimate {
  double clearance_m = 0.0;          ///< h from the closed form
  double transmissibility = 0.0;     ///< X/U at resonance at that h
  double damper_amplitude_m = 0.0;   ///< x_opt(h) = X at resonance
  double resonance_hz = 0.0;         ///< ω_r/2π
  double participation = 0.0;        ///< Γ_eff, dimensionless
  double structural_damping = 0.0;   ///< ζ_s'
  double added_damping = 0.0;        ///< ζ_add
  double mass_ratio = 0.0;           ///< μ = m_bed b²/M
  double eta_star_design = 0.0;      ///< η*_opt
  double apparent_mass_fraction = 0.0;  ///< m_app/m_bed at the design point
  double stroke_over_clearance = 0.0;   ///< x_opt/h
  static const base::Fields<ClearanceEstimate>& fields();
};
/// Throws std::invalid_argument for invalid options, an unknown site, a mode out of range,
/// a model without base participation, or a site that does not move along n in the mode.
ClearanceEstimate estimate_clearance_on_structure(const structure::ModalModel& model,
                                                  const ClearanceOnStructureOptions& options);

/// The response at one clearance (what the objective evaluates).
struct ClearanceResponse {
  double clearance_m = 0.0;
  double peak_transmissibility = 0.0;  ///< max over the grid of the largest non-unstable or held |X/U|
  double peak_frequency_hz = 0.0;      ///< grid frequency of that maximum
  double damper_amplitude_m = 0.0;     ///< X at the site along n there (absolute), m
  double onset_m = 0.0;                ///< X_onset(h)
  double design_stroke_m = 0.0;        ///< x_opt(h)
  bool held_at_onset = false;          ///< the peak is a jump-held state (the onset cliff)
  static const base::Fields<ClearanceResponse>& fields();
};
ClearanceResponse clearance_response(const structure::ModalModel& model, const ClearanceOnStructureOptions& options,
                                     double clearance_m);

struct ClearanceOnStructureResult {
  double clearance_m = 0.0;           ///< the solver's h
  ClearanceResponse response;         ///< at clearance_m
  ClearanceEstimate estimate;         ///< the closed form
  Summary summary;                    ///< variable "clearance_m"
  double solve_time_s = 0.0;          ///< wall clock of the whole sizing
};

/// Solves the sizing problem with solve(problem, solver_options) (1 variable h in the
/// clearance range). Throws as estimate_clearance_on_structure.
ClearanceOnStructureResult size_clearance_on_structure(const structure::ModalModel& model,
                                                       const ClearanceOnStructureOptions& options,
                                                       const Options& solver_options =
                                                           clearance_on_structure_solver_options());

}  // namespace pdamp::optimizer
