// Closed-form collect-and-collide models of a particle damper (docs/physics.md §2-4).
//
// One ideal model serves both regimes: the bed moves as one block that leaves a wall
// at maximum container velocity, travels relative to the container, and hits the
// opposite wall fully inelastically. A bed of spheres rolling on the base (inertia
// I = κ m r²) moves relative to the container with 1/(1+κ) of the free-flight
// relative acceleration, so it is the free block with clearance (1+κ)h and with all
// its relative kinetic energy (translation and spin, factor 1+κ) lost per impact:
//   bouncing: κ = 0;   rolling solid spheres: κ = 2/5.
// Derivations: docs/collect_and_collide.md.
#pragma once

#include <optional>
#include <cstddef>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace pdamp::formulas {

/// Standard gravity g, m/s^2 (intensity Γ = XΩ²/g).
inline constexpr double kStandardGravity = 9.80665;
inline constexpr double kPi = 3.14159265358979323846;

enum class DamperModel { kRolling, kBouncing, kScattered, kAuto };
std::string_view to_string(DamperModel model);
/// "rolling", "bouncing", "scattered", "auto"; std::nullopt for anything else.
std::optional<DamperModel> damper_model_from_string(std::string_view name);

/// Which orbit the ideal model is on at a given stroke.
enum class MotionRegime {
  kCollectAndCollide,  ///< X >= X_opt_ideal: impact at φ* <= π, bed rides with the wall
  kSubPeak,            ///< X_onset <= X < X_opt_ideal: symmetric orbit, impact at π + ψ
  kScattered,          ///< X < X_onset: no synchronous orbit, empirical fit (§4)
};
std::string_view to_string(MotionRegime regime);

/// Empirical scattered-state law (docs/physics.md §4) in s = X/X_onset < 1:
///   η*(s) = jump_fraction · η*_onset · s^exponent
/// where η*_onset is the ideal orbit's value at the onset of the model in use, so
/// jump_fraction < 1 is the height of the jump into the collect-and-collide state.
/// Largest jump_fraction: the scattered state just below the cliff can dissipate more
/// than the ideal orbit at its onset (the DEM of the 36-sphere case: 1.10 at s = 0.93);
/// twice the onset value is far beyond anything seen and catches unit mistakes.
inline constexpr double kMaxJumpFraction = 2.0;

struct ScatteredFit {
  double jump_fraction = 0.5;  ///< η*(s→1⁻)/η*_onset, dimensionless, in [0, kMaxJumpFraction]
  double exponent = 2.0;       ///< power of s, dimensionless, in [0, 10]
  double s_min = 0.0;          ///< lowest s the fit was made on (validity), [0, 1)
  double s_max = 1.0;          ///< highest s the fit was made on, [s_min, 1]: above it the law is extrapolated
  // Quality of a fit to data (NaN or 0 when not fitted: the provisional default).
  double reduced_chi_squared = std::numeric_limits<double>::quiet_NaN();  ///< χ²/(n − 2), ≈ 1 for a good fit
  double jump_fraction_stderr = std::numeric_limits<double>::quiet_NaN(); ///< standard error of jump_fraction
  double exponent_stderr = std::numeric_limits<double>::quiet_NaN();      ///< standard error of exponent
  std::size_t points = 0;                                                 ///< samples fitted
  /// Defaults are provisional until fitted to DEM points (docs/effective_fields.md §6).
  bool provisional = true;
  std::string source = "provisional default";
  /// One line per violated rule ("exponent = 12: must be in [0, 10]"); empty if valid.
  std::vector<std::string> validate() const;
};

/// Model constants with their defaults; all dimensionless.
struct ModelOptions {
  /// κ = I/(m r²) of the rolling spheres: 2/5 solid, 2/3 thin-walled hollow; (0, 1].
  double rolling_inertia_factor = 0.4;
  /// c in x_opt_m = c·x_opt_ideal_m for rolling: 0.8976 puts the design stroke at
  /// 0.4 h_roll as in the source study's experiments and DEM; (0, 2].
  double rolling_calibration = 0.8976;
  /// c for bouncing: the ideal optimum h/π is the design value; (0, 2].
  double bouncing_calibration = 1.0;
  ScatteredFit scattered;
  /// The ideal models assume no gravity along the drive; true adds a warning.
  bool gravity_along_drive = false;
  /// Gravity presses the bed on a base across the drive (a horizontal drive on Earth:
  /// the default, and what the rolling model needs). With it, at high intensity the
  /// bed can stay nearly at rest on the base while the container moves around it (the
  /// decoupled state, docs/dem.md), in place of the bouncing orbit: true makes the
  /// bouncing model warn for X < h. false: no gravity, or gravity along the drive only.
  bool gravity_across_drive = true;
  /// Sliding friction μ between the spheres and the base, dimensionless, in [0, 10]
  /// (default 0.3, dry steel on steel; a case takes its DEM contact's). It sets where
  /// `auto` leaves rolling: spheres roll without slip while μ >= κΓ/(1+κ).
  double base_friction = 0.3;
  /// One line per violated rule ("rolling_inertia_factor = 1.5: must be in (0, 1]"),
  /// the fit's lines prefixed "scattered."; empty if valid.
  std::vector<std::string> validate() const;
};

/// Ideal orbit of a block of inertia factor κ (0 bouncing, 2/5 rolling) at stroke X.
struct IdealOrbit {
  MotionRegime regime = MotionRegime::kScattered;
  double eta_star = 0.0;  ///< reduced loss factor η*, dimensionless; NaN when scattered
  /// Container phase Ωt at the impact, rad, counted from the instant the container
  /// velocity toward the wall being hit is largest (the detachment of the
  /// collect-and-collide orbit): φ* in (0, π] on kCollectAndCollide, π + ψ with
  /// ψ in [0, atan(2/π)] on kSubPeak; NaN when scattered.
  double impact_phase_rad = 0.0;
};
/// φ* in [0, π] solving φ − sin φ = r for r = h_eff/X in [0, π] (docs/physics.md §2), to a
/// few ulp: start from the inverse series at 0, φ ≈ (6r)^{1/3}(1 + (6r)^{2/3}/60 + ...),
/// or at π, then 1-3 safeguarded Newton steps on the convex φ − sin φ (summed as a
/// series below φ = 1, where the difference cancels); about 0.1 µs. Never fails on
/// [0, π]; throws std::domain_error outside it or for NaN.
double impact_phase(double clearance_over_stroke);
/// Ideal orbit at stroke X for clearance h of a bed with inertia factor κ in [0, 1]
/// (0: free block, bouncing; κ: rolling spheres, effective clearance (1+κ)h):
///   X >= (1+κ)h/π:                 φ* − sin φ* = (1+κ)h/X,  η* = (1 − cos φ*)²/(π(1+κ));
///   (1+κ)h/√(π²+4) <= X < (1+κ)h/π: π cos ψ + 2 sin ψ = (1+κ)h/X, η* = 4cos²ψ/(π(1+κ));
///   below: kScattered (NaN). Throws std::invalid_argument for κ outside [0, 1] or
///   h, X not > 0 and finite. Derivation: docs/collect_and_collide.md.
IdealOrbit ideal_orbit(double inertia_factor, double clearance_m, double stroke_m);
/// Smallest base friction coefficient μ at which a sphere of inertia factor κ (> 0)
/// rolls without slip on a base accelerating with amplitude Γg: μ_min = κΓ/(1+κ)
/// (friction needed κ m a_c/(1+κ) against μ m g). The rolling model also needs the
/// spin-down after a wall impact to be short, i.e. μ >> μ_min (docs, "What the ideal
/// model neglects"). Throws std::invalid_argument for κ outside (0, 1] or Γ < 0 / NaN.
double rolling_no_slip_friction(double inertia_factor, double intensity);

/// Landmarks of a model over stroke for one clearance.
struct OptimumStroke {
  DamperModel model = DamperModel::kRolling;
  double clearance_m = 0.0;
  double x_opt_m = 0.0;        ///< design stroke c·x_opt_ideal_m
  double x_opt_ideal_m = 0.0;  ///< ideal peak (1+κ)h/π
  double x_onset_m = 0.0;      ///< lowest stroke of the orbit (1+κ)h/√(π²+4)
  double eta_star_peak = 0.0;  ///< 4/(π(1+κ))
  double eta_star_onset = 0.0; ///< 4π/((π²+4)(1+κ))
  double calibration_factor = 1.0;
};
/// Onset, ideal peak and design stroke of the rolling (κ = options.rolling_inertia_factor)
/// or bouncing (κ = 0) model for clearance h: x_opt_ideal = (1+κ)h/π,
/// x_onset = (1+κ)h/√(π²+4), x_opt = c·x_opt_ideal (rolling default: 0.4 h).
/// model must be kRolling or kBouncing, clearance_m > 0 and finite, options valid
/// (std::invalid_argument otherwise).
OptimumStroke optimum_stroke(DamperModel model, double clearance_m, const ModelOptions& options = {});
/// Inverse of optimum_stroke: h = π X/(c(1+κ)) with x_opt_m(h) = stroke_m (> 0, finite);
/// same model and options rules as optimum_stroke.
double clearance_for_stroke(DamperModel model, double stroke_m, const ModelOptions& options = {});

/// Closed-form reduced loss factor at one operating point.
struct LossResult {
  DamperModel model_requested = DamperModel::kAuto;
  DamperModel model_used = DamperModel::kRolling;  ///< rolling or bouncing family (the nearer, in auto's slip band)
  /// κ of the block that answered: rolling_inertia_factor (rolling), 0 (bouncing), or
  /// auto's friction-limited value in between (auto_inertia_factor).
  double inertia_factor = 0.0;
  MotionRegime regime = MotionRegime::kScattered;
  double eta_star = 0.0;          ///< reduced loss factor η*, dimensionless
  double intensity = 0.0;         ///< Γ = XΩ²/g
  double velocity_amplitude_m_s = 0.0;  ///< |V*| = XΩ
  double impact_phase_rad = 0.0;  ///< NaN in the scattered state
  double stroke_over_onset = 0.0; ///< s = X/X_onset of the family used
  std::vector<std::string> warnings;  ///< validity-range violations (docs/interface.md)
  /// How many warnings apply (warnings.size(), also when reduced_loss_factor_counted
  /// leaves `warnings` empty).
  std::size_t warning_count = 0;
};
/// The inertia factor auto gives a bed at intensity Γ (docs/collect_and_collide.md §6):
/// with gravity across the drive the spheres roll without slip while the base friction
/// can hold them, Γ <= Γ_slip = μ(1+κ)/κ, and the block is the rolling one (κ); above,
/// they slide, friction μg cuts the relative acceleration A to A − μg, and the block
/// moves relative to the container as one with 1/(1+κ_eff) = 1 − μ/Γ, κ_eff = μ/(Γ − μ):
/// continuous at Γ_slip (1 − κ/(1+κ) = 1/(1+κ)) and tending to free flight (0) as Γ
/// grows. Without gravity across the drive (no base): 0.
double auto_inertia_factor(double intensity, const ModelOptions& options);
/// Γ_slip = μ(1+κ)/κ: the intensity up to which the base friction keeps spheres rolling.
double slip_intensity(const ModelOptions& options);
/// Onset stroke (1+κ)h/√(π²+4) and η* there, 4π/((π²+4)(1+κ)), of the block of inertia
/// factor κ (docs/physics.md §2-3).
double onset_stroke_m(double inertia_factor, double clearance_m);
double onset_reduced_loss_factor(double inertia_factor);

/// η* for clearance h (> 0), stroke X (> 0), frequency f (> 0), all finite
/// (std::invalid_argument naming the quantity otherwise, and for invalid options).
/// kAuto: the block of auto_inertia_factor (rolling up to Γ_slip, friction-limited
/// sliding above, free flight without gravity across the drive); below the onset every model gives the
/// scattered fit (kRolling and kBouncing with a warning, since their orbit does not
/// exist there). kScattered: the fit regardless of s (family chosen by Γ as in kAuto).
/// Warnings (one sentence each, with numbers): rolling above Γ_slip or without a base,
/// bouncing below Γ_slip on a base, auto in its slip band (Γ_slip < Γ < 20μ),
/// gravity along the drive, the orbit missing below its onset, the scattered fit
/// provisional or outside [s_min, 1), X/h > 10. No allocation when there is no warning.
LossResult reduced_loss_factor(DamperModel model, double clearance_m, double stroke_m,
                               double frequency_hz, const ModelOptions& options = {});
/// reduced_loss_factor for inner loops (surrogate::ClosedFormLossModel::evaluate, called
/// per RK4 stage and per harmonic-balance root): the same numbers and warning_count, but
/// the sentences are not written (`warnings` stays empty) and the options are not
/// re-validated (they must be valid: ModelOptions::validate() empty). Never allocates.
LossResult reduced_loss_factor_counted(DamperModel model, double clearance_m, double stroke_m,
                                       double frequency_hz, const ModelOptions& validated_options);

/// Energy measures from η* (docs/physics.md §1): E_diss = η*·½ m_bed |V*|² = Re(P)/Ω, J.
/// η* >= 0, m_bed > 0, |V*| >= 0, all finite (std::invalid_argument otherwise).
double dissipated_energy_measure(double eta_star, double bed_mass_kg, double velocity_amplitude_m_s);
/// Energy dissipated per cycle, 2π·E_diss, J; e_diss_j >= 0 and finite.
double energy_per_cycle(double e_diss_j);

}  // namespace pdamp::formulas
