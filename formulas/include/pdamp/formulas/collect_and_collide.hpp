// Closed-form collect-and-collide models of a particle damper (docs/theory.md §2-4).
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

#include "pdamp/base/record.hpp"

namespace pdamp::formulas {

/// Standard gravity g, m/s^2 (intensity Γ = XΩ²/g).
inline constexpr double kStandardGravity = 9.80665;
inline constexpr double kPi = 3.14159265358979323846;

/// kCoulombBlock: a nested bed (ModelOptions::nested_bed), whose spheres cannot rotate: a
/// block on its base held by Coulomb friction (docs/theory.md §3.3). `auto` answers with it
/// for a nested bed; it has no collect-and-collide onset or peak (optimum_stroke refuses it).
enum class DamperModel { kRolling, kBouncing, kScattered, kAuto, kCoulombBlock };
std::string_view to_string(DamperModel model);
/// "rolling", "bouncing", "scattered", "auto", "coulomb_block"; std::nullopt for anything else.
std::optional<DamperModel> damper_model_from_string(std::string_view name);

/// Which orbit the ideal model is on at a given stroke.
enum class MotionRegime {
  kCollectAndCollide,  ///< X >= X_opt_ideal: impact at φ* <= π, bed rides with the wall
  kSubPeak,            ///< X_onset <= X < X_opt_ideal: symmetric orbit, impact at π + ψ
  kScattered,          ///< X < X_onset: no synchronous orbit: the scattered fit or the impact map (§4)
  kStuck,              ///< Coulomb block (nested bed) at Γ <= μ: carried by the base, η* = 0 (§3.3)
  kSliding,            ///< Coulomb block at Γ > μ: slides on its base, stick-slip or wall to wall (§3.3)
  kRollingTail,        ///< X < X_onset after collect-and-collide: rolls about its mean position, no impacts (§3.4)
};
std::string_view to_string(MotionRegime regime);

/// Empirical scattered-state law (docs/theory.md §4) in s = X/X_onset < 1:
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

/// What answers below the collect-and-collide onset (docs/theory.md §4).
enum class BelowOnsetModel {
  kScatteredFit,  ///< the empirical law of ScatteredFit (§4.1): the default
  kImpactMap,     ///< the plastic block's deterministic impact map, tabulated in cX/h (§4.2)
  /// A rolling bed that has come down from collect-and-collide (§3.4): it rolls about its
  /// mean position without reaching the walls (rolling_tail); beds that do not roll on a
  /// base, or have fewer than kMinRollingTailRows rows along the drive, keep the scattered fit.
  kRollingTail,
};
std::string_view to_string(BelowOnsetModel model);
/// "scattered_fit", "impact_map", "rolling_tail"; std::nullopt for anything else.
std::optional<BelowOnsetModel> below_onset_model_from_string(std::string_view name);

/// Fewest rows along the drive for the rolling tail (ModelOptions::rows_along_drive): the DEM
/// shows two rows still reaching the walls below the onset, four rows rolling off them.
inline constexpr double kMinRollingTailRows = 3.0;

/// Largest collective bed restitution accepted: K = (1+e_b)/(1−e_b) = 19 there, an onset at
/// 0.017 (1+κ)h; no bed of the DEM comes near it (one sphere: e_b <= (ε − κ)/(1+κ) < 0.72).
inline constexpr double kMaxBedRestitution = 0.9;

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
  /// Collective restitution e_b of the collected bed at a wall (docs/theory.md §3.1): the bed
  /// leaves the wall it has hit with e_b times its impact speed relative to the container.
  /// In [0, kMaxBedRestitution]. 0 (default): the plastic orbits of §2-3, bit for bit. A
  /// property of the bed, not of one contact: fit it from the DEM's jump and peak
  /// (fit_bed_restitution); one sphere bounds it by ε/(1+κ) (bed_restitution_bound).
  double bed_restitution = 0.0;
  /// Normal restitution ε of one sphere on the walls, in (0, 1], or NaN (default: unknown).
  /// Only checked against: bed_restitution above the one-sphere bound gets a warning. A case
  /// takes its DEM contact's constant restitution.
  double particle_restitution = std::numeric_limits<double>::quiet_NaN();
  /// The settled bed keeps spheres resting on two or more others (formulas::LatticeBed::
  /// settled_upper_spheres > 0): they cannot rotate, so with gravity across the drive `auto`
  /// takes the Coulomb block (docs/theory.md §3.3) and `rolling` warns. false: a bed one
  /// sphere high (after settling), which rolls.
  bool nested_bed = false;
  /// Below the onset, for a bed driven there from rest (a steady state, a field, a forced
  /// response): the scattered fit (default), the plastic block's impact map or the rolling tail.
  BelowOnsetModel below_onset = BelowOnsetModel::kScatteredFit;
  /// Below the onset, for a bed that has come down from collect-and-collide (a free decay
  /// released above the onset, surrogate::LossModel::evaluate_from_above): the rolling tail
  /// (default, docs/theory.md §3.4) or the law of a bed driven from rest.
  BelowOnsetModel below_onset_from_above = BelowOnsetModel::kRollingTail;
  /// Spheres one after another along the drive in a lane of the settled bed, > 0, or 0
  /// (default: unknown, a long bed). The rolling tail answers for kMinRollingTailRows or more:
  /// the DEM's beds of two rows still reach the walls below the onset (η* 0.03-0.2, docs/
  /// theory.md §3.4) and keep the law of a bed from rest.
  double rows_along_drive = 0.0;
  /// Rolling resistance μ_r of the spheres on the base, dimensionless, in [0, 1] (default 0:
  /// none, the DEM's default; a case takes its DEM contact's rolling_friction). The rolling
  /// tail's only loss: a resisting torque μ_r r m g.
  double rolling_resistance = 0.0;
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
/// φ* in [0, π] solving φ − sin φ = r for r = h_eff/X in [0, π] (docs/theory.md §2), to a
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
  static const base::Fields<OptimumStroke>& fields();
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
  std::vector<std::string> warnings;  ///< validity-range violations (docs/command_line.md)
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
/// factor κ (docs/theory.md §2-3).
double onset_stroke_m(double inertia_factor, double clearance_m);
double onset_reduced_loss_factor(double inertia_factor);

// ---- The rebounding bed: collective restitution e_b (docs/theory.md §3.1) ---------------
// A collected bed that rebounds from a wall as a whole with restitution e_b, K = (1+e_b)/(1−e_b),
// c = 1/(1+κ): its symmetric orbit (impacts at ψ and π + ψ) closes when
//   h/(cX) = πK cos ψ + 2 sin ψ = R_b cos(ψ − α_b),  R_b = √(π²K² + 4),  α_b = atan(2/(πK)),
// with η* = (4c/π) K cos²ψ and m_app/m_bed = κ/(1+κ) − (2c/π) K sin 2ψ. The branch joined to
// the peak (ψ = 0) is ψ = α_b − acos(h/(cX R_b)); it starts at the onset X_on = h/(c R_b)
// (saddle-node, ψ = α_b) and peaks at X_pk = h/(cπK) with η*_pk = 4cK/π. e_b = 0 gives §2-3.

/// K = (1+e_b)/(1−e_b) for e_b in [0, 1); throws std::invalid_argument outside.
double rebound_factor(double bed_restitution);
/// Onset X_on = h/(c√(π²K²+4)), m (the e_b = 0 value is onset_stroke_m's, bit for bit).
double onset_stroke_m(double inertia_factor, double clearance_m, double bed_restitution);
/// η* at the onset, (4c/π)K cos²α_b = 4cπK³/(π²K²+4).
double onset_reduced_loss_factor(double inertia_factor, double bed_restitution);
/// Peak X_pk = h(1−e_b)/(cπ(1+e_b)), m, and η*_pk = 4cK/π (e_b = 0: (1+κ)h/π and 4/(π(1+κ))).
double peak_stroke_m(double inertia_factor, double clearance_m, double bed_restitution);
double peak_reduced_loss_factor(double inertia_factor, double bed_restitution);

/// The rebounding block's symmetric orbit at stroke X (docs/theory.md §3.1). On the branch
/// joined to the peak, ψ = α_b − acos(h/(cX R_b)): ψ in (0, α_b] below the peak, ψ < 0 above
/// it, where the block leaves each wall before the container's velocity extreme with e_b
/// times its impact speed. That continuation holds while the relative velocity keeps its
/// sign through the flight, cos ψ >= 1/K (ψ >= −acos(1/K); only ψ = 0 for e_b = 0).
/// An event-driven simulation of the block (tests/formulas) follows it on both sides of the
/// peak; the DEM follows it only below the peak (reduced_loss_factor uses the DEM's tail above).
struct ReboundingOrbit {
  bool exists = false;             ///< X_on <= X and ψ >= −acos(1/K)
  double psi_rad = 0.0;            ///< departure phase ψ after the container's velocity extreme, rad
  double eta_star = 0.0;           ///< (4c/π) K cos²ψ
  double apparent_mass_fraction = 0.0;  ///< κ/(1+κ) − (2c/π) K sin 2ψ
};
/// κ in [0, 1], e_b in [0, kMaxBedRestitution], h and X > 0 and finite (std::invalid_argument).
ReboundingOrbit rebounding_orbit(double inertia_factor, double bed_restitution, double clearance_m,
                                 double stroke_m);

/// e_b of one sphere at a frictionless wall (docs/theory.md §3.1): rolling into it at u, it
/// leaves at −εu with its spin σ = u (σ = ωr); base friction, conserving u − κσ, brings it
/// back to rolling at −u(ε − κ)/(1+κ), so max(0, (ε − κ)/(1+κ)) (a sphere with ε <= κ does not
/// leave the wall). Bouncing (κ = 0): ε. ε in (0, 1], κ in [0, 1] (std::invalid_argument
/// otherwise).
double frictionless_wall_restitution(double particle_restitution, double inertia_factor);

/// Upper bound of e_b from one sphere (docs/theory.md §3.1): ε/(1+κ), the sphere that leaves
/// the wall at −εu without spin. Wall friction opposes the spin's slip at the wall and can
/// stop it, not reverse it, so a lone sphere lies between frictionless_wall_restitution
/// and this (the DEM, μ = 0.3: e_b 0.17-0.21 at ε = 0.3, 0.29-0.34 at ε = 0.5, above the
/// frictionless 0 and 0.071); a bed's spheres behind the front one only lower it. ε in
/// (0, 1], κ in [0, 1] (std::invalid_argument otherwise).
double bed_restitution_bound(double particle_restitution, double inertia_factor);

/// e_b of a bed from two DEM points (docs/theory.md §3.1): the jump (the lowest stroke at
/// which the bed is in collect-and-collide, X_on) and the peak (the largest η*, η*_pk). Each
/// alone gives e_b in closed form: K_on = √((h/(cX_on))² − 4)/π and K_pk = πη*_pk/(4c);
/// the fit takes the e_b in [0, kMaxBedRestitution] that minimises the sum of the squared
/// relative misfits of ln X_on and ln η*_pk (golden section), and reports both single
/// estimates (clamped to [0, kMaxBedRestitution]; a jump above the plastic onset gives 0)
/// and the two misfits: a bed the rebounding block describes has both close.
/// The peak's stroke is not used: above the peak the DEM follows η*_pk X_pk/X = 4h/(π²X)
/// whatever e_b, so the largest sampled η* may lie on that tail.
struct BedRestitutionFit {
  double bed_restitution = 0.0;     ///< e_b, best of both points
  double from_onset = 0.0;          ///< e_b from X_on alone
  double from_peak = 0.0;           ///< e_b from η*_pk alone
  double onset_misfit = 0.0;        ///< X_on(e_b)/X_on − 1 at the fitted e_b
  double peak_misfit = 0.0;         ///< η*_pk(e_b)/η*_pk − 1 at the fitted e_b
};
/// κ in [0, 1], h, X_on, η*_pk > 0 and finite (std::invalid_argument otherwise).
BedRestitutionFit fit_bed_restitution(double inertia_factor, double clearance_m, double onset_stroke_m,
                                      double peak_eta_star);

// ---- Below the onset: the plastic block's impact map (docs/theory.md §4.2) ---------------
/// The plastic block of §2 (κ = 0) below its onset, simulated: collected on the wall it
/// leaves at the container's velocity extreme, in free flight relative to the container
/// (relative acceleration −a_c), plastic at the walls, riding with a wall while it pushes.
/// A rolling bed is the same block with relative motion scaled by c = 1/(1+κ), so one table
/// serves every κ: η*_bed(X) = c·η*_map(ξ) with ξ = cX/h. The table is computed once per
/// process on first use (about 0.1 s): kImpactMapPoints strokes ξ_i = i·ξ_on/N, i = 1..N,
/// ξ_on = 1/√(π²+4), each averaged over kImpactMapCycles cycles after kImpactMapWarmCycles,
/// then smoothed by a moving average over kImpactMapSmoothingPoints neighbours (the chaotic
/// strokes scatter from point to point; the periodic windows, such as the one ending in the
/// near-zero dip at ξ = 0.157, are wider than the window and keep their shape).
inline constexpr int kImpactMapPoints = 270;
inline constexpr int kImpactMapWarmCycles = 100;
inline constexpr int kImpactMapCycles = 1000;
inline constexpr int kImpactMapSmoothingPoints = 5;
/// One stroke of the map, simulated (what the table holds before smoothing).
struct ImpactMapPoint {
  double stroke_over_clearance = 0.0;  ///< ξ = X/h of the block
  double eta_star = 0.0;               ///< impact losses per cycle / (π m V²)
  double impacts_per_cycle = 0.0;
  double apparent_mass_fraction = 0.0; ///< 1 + Re(û)/V, û the first harmonic of the relative velocity
};
/// The simulation of one stroke ξ in (0, 1/√(π²+4)] (std::invalid_argument otherwise).
ImpactMapPoint simulate_impact_map(double stroke_over_clearance, int warm_cycles = kImpactMapWarmCycles,
                                   int cycles = kImpactMapCycles);
/// The smoothed table's η* of the block at ξ = cX/h (linear interpolation; below the first
/// point linear to 0 at ξ = 0, the block's small-stroke limit; above ξ_on the last value).
/// Thread-safe; about 20 ns after the first call.
double impact_map_reduced_loss_factor(double stroke_over_effective_clearance);
/// dη*/dξ of that interpolant (of the piece ξ lies on; 0 above ξ_on).
double impact_map_reduced_loss_factor_slope(double stroke_over_effective_clearance);
/// The table itself: ξ_i, the raw η*_i and the smoothed η*_i.
struct ImpactMapTable {
  std::vector<double> stroke_over_clearance;
  std::vector<double> eta_star_raw;
  std::vector<double> eta_star;
};
const ImpactMapTable& impact_map_table();

// ---- Nested beds: the Coulomb block (docs/theory.md §3.3) --------------------------------
/// A block on its base with Coulomb friction μ in a container x_c = X sin φ with walls h apart,
/// r = μ/Γ. Stuck for r >= 1 (η* = 0, m_app = m_bed). Above: released at sin φ_d = r, it slides
/// with u/V = cos φ_d − cos φ − r(φ − φ_d) until it sticks again (stick-slip, r > r_c =
/// 1/√(1+π²/4) = 0.537: slide X·D(r) per half cycle, η* = (2/π) r D(r)) or, for r <= r_c,
/// slides without sticking (Den Hartog: cos φ_1 = πr/2, η* = (4/π) r sin φ_1); where the
/// slide from the wall reaches the far wall first it hits it (plastic) and is held there:
/// η* = (2/π) r h/X + (u_h/V)²/π. m_app from the first harmonic of its velocity (§1).
struct CoulombBlock {
  MotionRegime regime = MotionRegime::kStuck;  ///< kStuck or kSliding
  double eta_star = 0.0;
  double apparent_mass_fraction = 1.0;
  double slide_over_stroke = 0.0;  ///< relative travel per half cycle / X
  bool wall_to_wall = false;       ///< the slide reaches the far wall
  /// r <= r_c with a slide between h and the wall-to-wall one: the block's orbit is neither
  /// of the three above; the stick-free one is returned (reduced_loss_factor warns).
  bool outside_domain = false;
};
/// μ >= 0, Γ > 0, h/X > 0, all finite (std::invalid_argument otherwise).
CoulombBlock coulomb_block(double friction, double intensity, double clearance_over_stroke);
/// The block's periodic slide far from both walls: the orbit of a block that has left them
/// with no drift, stuck (r >= 1), stick-slip (r > r_c) or Den Hartog's (r <= r_c), never
/// wall to wall. Same ranges as coulomb_block.
CoulombBlock coulomb_slide_without_walls(double friction, double intensity);

// ---- Below the onset after collect-and-collide: the rolling tail (docs/theory.md §3.4) ----
/// A rolling bed (κ > 0) that has left the walls rolls about its mean position. Its
/// relative motion u obeys (1+κ)u̇ = −a_c − μ_r g sgn u (a resisting torque μ_r r m g at the
/// base), the Coulomb block of friction μ_r in U = (1+κ)u, so
///   η* = η*_block/(1+κ),   m_app/m_bed = (κ + m_block/m)/(1+κ),
/// the block's wall-free slide at r = μ_r/Γ; μ_r = 0: η* = 0, m_app/m_bed = κ/(1+κ) (2/7 for
/// solid spheres). kRollingTail, or kStuck for μ_r >= Γ (carried by the base).
struct RollingTail {
  MotionRegime regime = MotionRegime::kRollingTail;
  double eta_star = 0.0;
  double apparent_mass_fraction = 0.0;
};
/// κ in (0, 1], μ_r >= 0, Γ > 0, all finite (std::invalid_argument otherwise).
RollingTail rolling_tail(double inertia_factor, double rolling_resistance, double intensity);

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

/// Energy measures from η* (docs/theory.md §1): E_diss = η*·½ m_bed |V*|² = Re(P)/Ω, J.
/// η* >= 0, m_bed > 0, |V*| >= 0, all finite (std::invalid_argument otherwise).
double dissipated_energy_measure(double eta_star, double bed_mass_kg, double velocity_amplitude_m_s);
/// Energy dissipated per cycle, 2π·E_diss, J; e_diss_j >= 0 and finite.
double energy_per_cycle(double e_diss_j);

}  // namespace pdamp::formulas
