// Closed-form collect-and-collide models: ideal orbits, optimum strokes, η* with validity warnings.
#include "pdamp/formulas/collect_and_collide.hpp"

#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace pdamp::formulas {

const base::Fields<OptimumStroke>& OptimumStroke::fields() {
  using O = OptimumStroke;
  static const auto f =
      base::Fields<O>()
          .field("model", &O::model, "", "rolling or bouncing")
          .field("clearance_m", &O::clearance_m, "m", "the clearance h")
          .field("x_opt_m", &O::x_opt_m, "m", "the design stroke, calibration_factor times the ideal peak")
          .field("x_opt_ideal_m", &O::x_opt_ideal_m, "m", "the ideal peak (1 + kappa) h / pi")
          .field("x_onset_m", &O::x_onset_m, "m", "the onset of collect-and-collide, the cliff")
          .field("calibration_factor", &O::calibration_factor, "1", "the design stroke over the ideal peak")
          .field("eta_star_peak", &O::eta_star_peak, "1", "eta* at the ideal peak")
          .field("eta_star_onset", &O::eta_star_onset, "1", "eta* at the onset");
  return f;
}
namespace {

/// Above this multiple of μ the friction takes less than 5% of the drive's acceleration
/// and the sliding bed is a free-flying block within the models' accuracy (no warning).
constexpr double kFreeFlightFrictionRatio = 20.0;


/// R = √(π²+4): π cos ψ + 2 sin ψ = R cos(ψ − α), so the sub-peak orbit exists for
/// h_eff/X <= R and the onset stroke is h_eff/R.
constexpr double kOnsetRadius = 3.724191778237173;
/// α = atan(2/π): ψ at the onset, where the sub-peak branch ends (saddle-node).
constexpr double kOnsetAngle = 0.5669115049410094;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Above this X/h the bed hits the far wall within a small fraction of the cycle
/// after detachment: η* is tiny and set by details the one-block model leaves out.
constexpr double kMaxStrokeOverClearance = 10.0;
/// Safeguarded Newton needs 1-3 steps; the cap only bounds the bisection fallback,
/// which alone reaches full precision on [0, π] in about 55 halvings.
constexpr int kMaxPhaseIterations = 100;
/// impact_phase starts from the series at 0 up to this r and from the series at π above.
constexpr double kStartSwitch = 1.3;
/// impact_phase stops after a Newton step smaller than this fraction of φ.
constexpr double kLastStep = 1e-8;
/// Below this φ the series replaces φ − sin φ (which cancels: at φ = 1 the direct
/// difference already loses about 3 bits).
constexpr double kSeriesLimit = 1.0;

using base::format_number;
using base::require_non_negative;
using base::require_positive;

void require_valid(const ModelOptions& options) {
  const std::vector<std::string> problems = options.validate();
  if (problems.empty()) return;
  std::string message = "invalid model options: ";
  for (std::size_t i = 0; i < problems.size(); ++i) {
    if (i > 0) message += "; ";
    message += problems[i];
  }
  throw std::invalid_argument(message);
}

/// φ − sin φ for φ >= 0 with a relative error of a few ulp. Below kSeriesLimit the
/// Taylor series Σ (−1)^k φ^{2k+3}/(2k+3)! to k = 9 (first omitted term relative to
/// the sum: 6φ^20/23! < 3e-22); above it the direct difference, whose relative error
/// ε·φ/(φ − sin φ) is at most ε/(1 − sin 1) ≈ 6ε.
double phi_minus_sin(double phi) {
  if (phi >= kSeriesLimit) return phi - std::sin(phi);
  constexpr double kCoefficients[] = {
      1.0 / 6.0,                      // 1/3!
      -1.0 / 120.0,                   // 1/5!
      1.0 / 5040.0,                   // 1/7!
      -1.0 / 362880.0,                // 1/9!
      1.0 / 39916800.0,               // 1/11!
      -1.0 / 6227020800.0,            // 1/13!
      1.0 / 1307674368000.0,          // 1/15!
      -1.0 / 355687428096000.0,       // 1/17!
      1.0 / 121645100408832000.0,     // 1/19!
      -1.0 / 51090942171709440000.0,  // 1/21!
  };
  const double phi2 = phi * phi;
  double sum = 0.0;
  for (int k = 9; k >= 0; --k) sum = sum * phi2 + kCoefficients[k];
  return sum * phi2 * phi;
}

/// 1 − cos φ without cancellation.
double one_minus_cos(double phi) {
  const double half_sin = std::sin(0.5 * phi);
  return 2.0 * half_sin * half_sin;
}

double inertia_factor_of(DamperModel family, const ModelOptions& options) {
  return family == DamperModel::kRolling ? options.rolling_inertia_factor : 0.0;
}

double calibration_of(DamperModel family, const ModelOptions& options) {
  return family == DamperModel::kRolling ? options.rolling_calibration
                                         : options.bouncing_calibration;
}

void require_family(DamperModel model, const char* function) {
  if (model != DamperModel::kRolling && model != DamperModel::kBouncing) {
    throw std::invalid_argument(std::string(function) + ": model = " +
                                std::string(to_string(model)) + ": must be rolling or bouncing");
  }
}

/// Onset stroke h_eff/R; computed in one place so that X = x_onset_m from
/// optimum_stroke is classified as on the orbit (same rounding).
double onset_stroke(double effective_clearance_m) { return effective_clearance_m / kOnsetRadius; }
double peak_stroke(double effective_clearance_m) { return effective_clearance_m / kPi; }
double onset_eta_star(double inertia_factor) {
  return 4.0 * kPi / ((kPi * kPi + 4.0) * (1.0 + inertia_factor));
}

/// ideal_orbit without input checks (inputs already validated by the caller).
IdealOrbit orbit_of(double inertia_factor, double clearance_m, double stroke_m) {
  const double scale = 1.0 + inertia_factor;
  const double effective_clearance_m = scale * clearance_m;
  IdealOrbit orbit;
  if (stroke_m >= peak_stroke(effective_clearance_m)) {
    // Rounding can put h_eff/X a hair above π exactly at the peak stroke.
    const double phase = impact_phase(std::min(effective_clearance_m / stroke_m, kPi));
    const double jump = one_minus_cos(phase);
    orbit.regime = MotionRegime::kCollectAndCollide;
    orbit.eta_star = jump * jump / (kPi * scale);
    orbit.impact_phase_rad = phase;
  } else if (stroke_m >= onset_stroke(effective_clearance_m)) {
    // π cos ψ + 2 sin ψ = R cos(ψ − α) = h_eff/X; the branch joined to the peak
    // (ψ = 0 at h_eff/X = π) is ψ = α − acos(h_eff/(X R)), ψ in [0, α].
    const double ratio = std::min(effective_clearance_m / (stroke_m * kOnsetRadius), 1.0);
    const double psi = std::clamp(kOnsetAngle - std::acos(ratio), 0.0, kOnsetAngle);
    const double cos_psi = std::cos(psi);
    orbit.regime = MotionRegime::kSubPeak;
    orbit.eta_star = 4.0 * cos_psi * cos_psi / (kPi * scale);
    orbit.impact_phase_rad = kPi + psi;
  } else {
    orbit.regime = MotionRegime::kScattered;
    orbit.eta_star = kNaN;
    orbit.impact_phase_rad = kNaN;
  }
  return orbit;
}

void append_range_rule(std::vector<std::string>& problems, const std::string& name, double value,
                       bool ok, const char* rule) {
  if (!ok) problems.push_back(base::violation(name, value, rule));
}

}  // namespace

std::string_view to_string(DamperModel model) {
  switch (model) {
    case DamperModel::kRolling: return "rolling";
    case DamperModel::kBouncing: return "bouncing";
    case DamperModel::kScattered: return "scattered";
    case DamperModel::kAuto: return "auto";
    case DamperModel::kCoulombBlock: return "coulomb_block";
  }
  return "unknown";
}

std::optional<DamperModel> damper_model_from_string(std::string_view name) {
  if (name == "rolling") return DamperModel::kRolling;
  if (name == "bouncing") return DamperModel::kBouncing;
  if (name == "scattered") return DamperModel::kScattered;
  if (name == "auto") return DamperModel::kAuto;
  if (name == "coulomb_block") return DamperModel::kCoulombBlock;
  return std::nullopt;
}

std::string_view to_string(MotionRegime regime) {
  switch (regime) {
    case MotionRegime::kCollectAndCollide: return "collect_and_collide";
    case MotionRegime::kSubPeak: return "sub_peak";
    case MotionRegime::kScattered: return "scattered";
    case MotionRegime::kStuck: return "stuck";
    case MotionRegime::kSliding: return "sliding";
    case MotionRegime::kRollingTail: return "rolling_tail";
  }
  return "unknown";
}

std::string_view to_string(BelowOnsetModel model) {
  switch (model) {
    case BelowOnsetModel::kScatteredFit: return "scattered_fit";
    case BelowOnsetModel::kImpactMap: return "impact_map";
    case BelowOnsetModel::kRollingTail: return "rolling_tail";
  }
  return "unknown";
}

std::optional<BelowOnsetModel> below_onset_model_from_string(std::string_view name) {
  if (name == "scattered_fit") return BelowOnsetModel::kScatteredFit;
  if (name == "impact_map") return BelowOnsetModel::kImpactMap;
  if (name == "rolling_tail") return BelowOnsetModel::kRollingTail;
  return std::nullopt;
}

std::vector<std::string> ScatteredFit::validate() const {
  std::vector<std::string> problems;
  append_range_rule(problems, "jump_fraction", jump_fraction,
                    jump_fraction >= 0.0 && jump_fraction <= kMaxJumpFraction, "in [0, 2]");
  append_range_rule(problems, "exponent", exponent, exponent >= 0.0 && exponent <= 10.0,
                    "in [0, 10]");
  append_range_rule(problems, "s_min", s_min, s_min >= 0.0 && s_min < 1.0, "in [0, 1)");
  append_range_rule(problems, "s_max", s_max, s_max >= s_min && s_max <= 1.0, "in [s_min, 1]");
  for (const auto& [name, value] : {std::pair{"reduced_chi_squared", reduced_chi_squared},
                                    std::pair{"jump_fraction_stderr", jump_fraction_stderr},
                                    std::pair{"exponent_stderr", exponent_stderr}})
    append_range_rule(problems, name, value, std::isnan(value) || value >= 0.0, ">= 0 (or NaN: not fitted)");
  return problems;
}

std::vector<std::string> ModelOptions::validate() const {
  std::vector<std::string> problems;
  append_range_rule(problems, "rolling_inertia_factor", rolling_inertia_factor,
                    rolling_inertia_factor > 0.0 && rolling_inertia_factor <= 1.0, "in (0, 1]");
  append_range_rule(problems, "rolling_calibration", rolling_calibration,
                    rolling_calibration > 0.0 && rolling_calibration <= 2.0, "in (0, 2]");
  append_range_rule(problems, "bouncing_calibration", bouncing_calibration,
                    bouncing_calibration > 0.0 && bouncing_calibration <= 2.0, "in (0, 2]");
  append_range_rule(problems, "base_friction", base_friction, base_friction >= 0.0 && base_friction <= 10.0,
                    "in [0, 10]");
  append_range_rule(problems, "rows_along_drive", rows_along_drive,
                    rows_along_drive >= 0.0 && std::isfinite(rows_along_drive), ">= 0 and finite");
  append_range_rule(problems, "rolling_resistance", rolling_resistance,
                    rolling_resistance >= 0.0 && rolling_resistance <= 1.0, "in [0, 1]");
  append_range_rule(problems, "bed_restitution", bed_restitution,
                    bed_restitution >= 0.0 && bed_restitution <= kMaxBedRestitution, "in [0, 0.9]");
  append_range_rule(problems, "particle_restitution", particle_restitution,
                    std::isnan(particle_restitution) || (particle_restitution > 0.0 && particle_restitution <= 1.0),
                    "in (0, 1] (or NaN: unknown)");
  for (const std::string& line : scattered.validate()) problems.push_back("scattered." + line);
  return problems;
}

double impact_phase(double clearance_over_stroke) {
  const double r = clearance_over_stroke;
  if (!(r >= 0.0 && r <= kPi)) {
    throw std::domain_error("impact_phase: clearance_over_stroke = " + format_number(r, 6) +
                            ": must be in [0, pi]");
  }
  if (r == 0.0) return 0.0;
  if (r == kPi) return kPi;
  double phi = 0.0;
  if (r <= kStartSwitch) {
    // Inverse series at 0 of c = (6(φ − sin φ))^{1/3} = φ·exp(−φ²/60 − φ⁴/50400 − ...):
    // φ ≈ c(1 + c²/60 + c⁴/1400); error 3e-3 rad at r = 1, 6e-3 at r = 1.3.
    const double c = std::cbrt(6.0 * r);
    const double c2 = c * c;
    phi = c * (1.0 + c2 * (1.0 / 60.0 + c2 / 1400.0));
  } else {
    // Inverse series at π: φ = π − δ with 2δ − δ³/6 + δ⁵/120 = π − r, so with
    // d = (π − r)/2: δ ≈ d + d³/12 + d⁵/60; error 3e-3 rad at r = 1.3, 1e-4 at r = 2.
    const double d = 0.5 * (kPi - r);
    const double d2 = d * d;
    phi = kPi - d * (1.0 + d2 * (1.0 / 12.0 + d2 / 60.0));
  }
  phi = std::clamp(phi, 0.0, kPi);
  double lo = 0.0;
  double hi = kPi;
  // φ − sin φ is increasing and convex on [0, π]: Newton from the right of the root
  // decreases monotonically onto it; a step from the left overshoots to the right,
  // or out of the bracket, where bisection takes over.
  for (int iteration = 0; iteration < kMaxPhaseIterations; ++iteration) {
    const double residual = phi_minus_sin(phi) - r;
    if (residual == 0.0) return phi;
    if (residual < 0.0) {
      lo = phi;
    } else {
      hi = phi;
    }
    const double slope = one_minus_cos(phi);
    const double next = slope > 0.0 ? phi - residual / slope : 0.5 * (lo + hi);
    // The Newton error after a step is (cot(φ/2)/2)·step² <= step²/φ: a relative step
    // below 1e-8 leaves a relative error below 1e-16, so the step is the last one.
    if (std::abs(next - phi) <= kLastStep * phi) return std::clamp(next, lo, hi);
    phi = (next > lo && next < hi) ? next : 0.5 * (lo + hi);
    if (hi - lo <= 2.0 * kEpsilon * hi) return phi;
  }
  return phi;
}

IdealOrbit ideal_orbit(double inertia_factor, double clearance_m, double stroke_m) {
  base::require_in("inertia_factor", inertia_factor, 0.0, 1.0);
  require_positive("clearance_m", clearance_m);
  require_positive("stroke_m", stroke_m);
  return orbit_of(inertia_factor, clearance_m, stroke_m);
}

double rolling_no_slip_friction(double inertia_factor, double intensity) {
  base::require(inertia_factor > 0.0 && inertia_factor <= 1.0, "inertia_factor", inertia_factor, "in (0, 1]");
  require_non_negative("intensity", intensity);
  return inertia_factor * intensity / (1.0 + inertia_factor);
}

OptimumStroke optimum_stroke(DamperModel model, double clearance_m, const ModelOptions& options) {
  require_family(model, "optimum_stroke");
  require_positive("clearance_m", clearance_m);
  require_valid(options);
  const double inertia_factor = inertia_factor_of(model, options);
  const double effective_clearance_m = (1.0 + inertia_factor) * clearance_m;
  OptimumStroke result;
  result.model = model;
  result.clearance_m = clearance_m;
  result.calibration_factor = calibration_of(model, options);
  result.x_opt_ideal_m = peak_stroke(effective_clearance_m);
  result.x_opt_m = result.calibration_factor * result.x_opt_ideal_m;
  result.x_onset_m = onset_stroke(effective_clearance_m);
  result.eta_star_peak = 4.0 / (kPi * (1.0 + inertia_factor));
  result.eta_star_onset = onset_eta_star(inertia_factor);
  const double e_b = options.bed_restitution;
  if (e_b > 0.0) {
    // The rebounding bed (docs/theory.md §3.1): onset and peak move together toward small
    // strokes and closer to each other (X_on/X_pk = πK/√(π²K²+4)). The calibration keeps
    // its meaning, where between the plastic onset and peak the design stroke sits:
    // t = (c − π/R)/(1 − π/R), so x_opt = X_on + t(X_pk − X_on) (c·X_pk for e_b = 0).
    result.x_opt_ideal_m = peak_stroke_m(inertia_factor, clearance_m, e_b);
    result.x_onset_m = onset_stroke_m(inertia_factor, clearance_m, e_b);
    const double plastic_onset_over_peak = kPi / kOnsetRadius;
    const double t = (result.calibration_factor - plastic_onset_over_peak) / (1.0 - plastic_onset_over_peak);
    result.x_opt_m = result.x_onset_m + t * (result.x_opt_ideal_m - result.x_onset_m);
    result.eta_star_peak = peak_reduced_loss_factor(inertia_factor, e_b);
    result.eta_star_onset = onset_reduced_loss_factor(inertia_factor, e_b);
  }
  return result;
}

double clearance_for_stroke(DamperModel model, double stroke_m, const ModelOptions& options) {
  require_family(model, "clearance_for_stroke");
  require_positive("stroke_m", stroke_m);
  require_valid(options);
  // x_opt is proportional to h: with e_b the landmarks of h = 1 m give the factor.
  if (options.bed_restitution > 0.0) return stroke_m / optimum_stroke(model, 1.0, options).x_opt_m;
  // x_opt = c(1+κ)h/π, solved for h.
  return kPi * (stroke_m / calibration_of(model, options)) /
         (1.0 + inertia_factor_of(model, options));
}

double slip_intensity(const ModelOptions& options) {
  const double kappa = options.rolling_inertia_factor;
  return options.base_friction * (1.0 + kappa) / kappa;
}

double auto_inertia_factor(double intensity, const ModelOptions& options) {
  if (!options.gravity_across_drive) return 0.0;
  if (intensity <= slip_intensity(options)) return options.rolling_inertia_factor;
  const double mu = options.base_friction;
  return mu / (intensity - mu);  // intensity > Γ_slip >= μ(1+κ)/κ > μ
}

double onset_stroke_m(double inertia_factor, double clearance_m) {
  return onset_stroke((1.0 + inertia_factor) * clearance_m);
}
double onset_reduced_loss_factor(double inertia_factor) { return onset_eta_star(inertia_factor); }

namespace {

/// The warnings every model shares: gravity along the drive and X/h > 10.
template <class Warn>
void common_warnings(const LossResult& result, double clearance_m, double stroke_m, const ModelOptions& options,
                     const Warn& warn) {
  if (options.gravity_along_drive) {
    warn([&] { return std::string(
        "gravity along the drive is not in the ideal models (docs/theory.md section 2): it moves "
        "the onset and lowers the peak, so eta* = " + format_number(result.eta_star, 6) +
        " is an optimistic estimate"); });
  }
  if (stroke_m > kMaxStrokeOverClearance * clearance_m) {
    warn([&] {
      const std::string impact =
          std::isfinite(result.impact_phase_rad)
              ? " (impact " + format_number(result.impact_phase_rad, 6) + " rad after detachment)"
              : std::string();
      return std::string("stroke/clearance X/h = " + format_number(stroke_m / clearance_m, 6) +
                         " > " + format_number(kMaxStrokeOverClearance, 6) +
                         ": the bed barely separates from the wall" + impact +
                         ", where the one-block model is outside its range");
    });
  }
}

/// Largest X/h at which the rebounding bed's tail η*_pk X_pk/X has been compared with the DEM
/// (docs/theory.md §3.1: the one-high layer of tests/dem_reference/test_bed_models.cpp at
/// X/h = 0.55, 0.7 and 1.0, 10-13 % below the tail).
constexpr double kMaxTailStrokeOverClearance = 1.0;

/// The rebounding bed (e_b > 0) at or above its onset (docs/theory.md §3.1): the orbit
/// below the peak, the DEM's tail η*_pk X_pk/X = 4h/(π²X) above it.
template <class Warn>
void rebounding_loss(LossResult& result, double inertia_factor, double clearance_m, double stroke_m, double e_b,
                     const Warn& warn) {
  const double peak_m = peak_stroke_m(inertia_factor, clearance_m, e_b);
  if (stroke_m < peak_m) {
    const ReboundingOrbit orbit = rebounding_orbit(inertia_factor, e_b, clearance_m, stroke_m);
    result.regime = MotionRegime::kSubPeak;
    result.eta_star = orbit.eta_star;
    result.impact_phase_rad = kPi + std::max(orbit.psi_rad, 0.0);
    return;
  }
  // Above the peak the rebounding block's own orbit (ψ < 0) dissipates 15-40% more than the
  // DEM of the rebounding layers, which follow η*_pk·X_pk/X (an observation, not derived).
  result.regime = MotionRegime::kCollectAndCollide;
  result.eta_star = peak_reduced_loss_factor(inertia_factor, e_b) * peak_m / stroke_m;
  result.impact_phase_rad = kNaN;
  if (stroke_m > kMaxTailStrokeOverClearance * clearance_m) {
    warn([&] { return std::string(
        "rebounding bed (bed_restitution = " + format_number(e_b, 6) + ") at X/h = " + format_number(stroke_m / clearance_m, 6) +
        ": above its peak eta* = eta*_pk X_pk/X = " + format_number(result.eta_star, 6) + " is what the DEM of rebounding "
        "layers shows up to X/h = " + format_number(kMaxTailStrokeOverClearance, 6) + " (docs/theory.md section 3.1); "
        "beyond it is extrapolated"); });
  }
}

/// Largest base friction at which the DEM held a nested bed up to Γ = μ (docs/theory.md §3.3,
/// tests/dem_reference/test_bed_models.cpp: μ = 0.1 and 0.2 held; 0.35 and 0.5 moved below μ).
constexpr double kMaxHeldNestedFriction = 0.2;

/// The nested bed: the Coulomb block on its base (docs/theory.md §3.3).
template <class Warn>
void coulomb_loss(LossResult& result, double clearance_m, double stroke_m, const ModelOptions& options,
                  const Warn& warn) {
  const double mu = options.base_friction;
  result.model_used = DamperModel::kCoulombBlock;
  result.inertia_factor = 0.0;  // the spheres do not rotate
  result.impact_phase_rad = kNaN;
  // The onset of motion: Γ = μ, X_st = μg/Ω², so s = Γ/μ.
  result.stroke_over_onset = mu > 0.0 ? result.intensity / mu : std::numeric_limits<double>::infinity();
  const CoulombBlock block = coulomb_block(mu, result.intensity, clearance_m / stroke_m);
  result.regime = block.regime;
  result.eta_star = block.eta_star;
  if (block.regime == MotionRegime::kSliding) {
    warn([&] { return std::string(
        "nested bed at Gamma = " + format_number(result.intensity, 6) + " > mu = " + format_number(mu, 6) + ": the Coulomb block slides "
        "(eta* = " + format_number(result.eta_star, 6) + "), an estimate: the DEM of a nested bed (docs/theory.md section 3.3) "
        "gives 0.24-0.26 at Gamma = 3 mu where the block gives 0.15-0.31, and is still held at Gamma = 1.5 mu for "
        "mu = 0.1 where the block gives 0.23: check with pdamp dem"); });
  } else if (mu > kMaxHeldNestedFriction) {
    warn([&] { return std::string(
        "nested bed held by its base (eta* = 0) up to Gamma = mu = " + format_number(mu, 6) + ": the DEM holds a nested bed "
        "so only at low friction (mu <= " + format_number(kMaxHeldNestedFriction, 6) + "); at mu = 0.35 and 0.5 it moved from "
        "Gamma = 0.28 and 0.1 with eta* = 0.3-0.75 (docs/theory.md section 3.3), so eta* = 0 at Gamma = " +
        format_number(result.intensity, 6) + " may be far too low: check with pdamp dem"); });
  }
  if (block.outside_domain) {
    warn([&] { return std::string(
        "Coulomb block at Gamma = " + format_number(result.intensity, 6) + ", X/h = " + format_number(stroke_m / clearance_m, 6) +
        ": its slide (" + format_number(block.slide_over_stroke * stroke_m, 6) + " m per half cycle) neither stays inside the "
        "clearance nor runs from wall to wall before the drive reverses; eta* is that of the slide without walls"); });
  }
}

/// reduced_loss_factor's body. kSentences: write the warning sentences (else only count
/// them: no allocation, no formatting). Options are checked by the callers.
template <bool kSentences>
LossResult loss_factor(DamperModel model, double clearance_m, double stroke_m, double frequency_hz,
                       const ModelOptions& options) {
  require_positive("clearance_m", clearance_m);
  require_positive("stroke_m", stroke_m);
  require_positive("frequency_hz", frequency_hz);

  const double omega = kTwoPi * frequency_hz;
  LossResult result;
  const auto warn = [&result](auto&& sentence) {
    ++result.warning_count;
    if constexpr (kSentences) result.warnings.push_back(sentence());
  };
  result.model_requested = model;
  result.velocity_amplitude_m_s = stroke_m * omega;
  result.intensity = result.velocity_amplitude_m_s * omega / kStandardGravity;
  const double slip = slip_intensity(options);
  const bool rolls = options.gravity_across_drive && result.intensity <= slip;
  const bool explicit_family = model == DamperModel::kRolling || model == DamperModel::kBouncing;
  if (model == DamperModel::kCoulombBlock ||
      (model == DamperModel::kAuto && options.nested_bed && options.gravity_across_drive)) {
    coulomb_loss(result, clearance_m, stroke_m, options, warn);
    common_warnings(result, clearance_m, stroke_m, options, warn);
    return result;
  }
  const double inertia_factor = explicit_family ? inertia_factor_of(model, options)
                                                : auto_inertia_factor(result.intensity, options);
  result.inertia_factor = inertia_factor;
  // The nearer family names the answer (in the slip band κ_eff lies between κ and 0).
  result.model_used = explicit_family ? model
                      : 2.0 * inertia_factor >= options.rolling_inertia_factor ? DamperModel::kRolling
                                                                                : DamperModel::kBouncing;
  const bool rolling = result.model_used == DamperModel::kRolling;
  const double e_b = options.bed_restitution;
  const double onset_m = e_b > 0.0 ? onset_stroke_m(inertia_factor, clearance_m, e_b)
                                   : onset_stroke((1.0 + inertia_factor) * clearance_m);
  const double s = stroke_m / onset_m;
  result.stroke_over_onset = s;
  const char* family_name = rolling ? "rolling" : "bouncing";
  const bool impact_map = options.below_onset == BelowOnsetModel::kImpactMap && model != DamperModel::kScattered;

  if (model != DamperModel::kScattered && stroke_m >= onset_m && e_b > 0.0) {
    rebounding_loss(result, inertia_factor, clearance_m, stroke_m, e_b, warn);
  } else if (model != DamperModel::kScattered && stroke_m >= onset_m) {
    const IdealOrbit orbit = orbit_of(inertia_factor, clearance_m, stroke_m);
    result.regime = orbit.regime;
    result.eta_star = orbit.eta_star;
    result.impact_phase_rad = orbit.impact_phase_rad;
  } else if (options.below_onset == BelowOnsetModel::kRollingTail && model != DamperModel::kScattered && rolling &&
             rolls && (options.rows_along_drive == 0.0 || options.rows_along_drive >= kMinRollingTailRows)) {
    // Come down from collect-and-collide, the bed rolls about its mean position: the onset's
    // relative travel 2X/(1+κ) < 0.54 h keeps it off the walls (docs/theory.md §3.4).
    const RollingTail tail = rolling_tail(inertia_factor, options.rolling_resistance, result.intensity);
    result.regime = tail.regime;
    result.eta_star = tail.eta_star;
    result.impact_phase_rad = kNaN;
  } else if (impact_map) {
    // The plastic block's map in ξ = cX/h, c = 1/(1+κ) (docs/theory.md §4.2): η* = c·η*_map(ξ).
    const double c = 1.0 / (1.0 + inertia_factor);
    result.regime = MotionRegime::kScattered;
    result.impact_phase_rad = kNaN;
    result.eta_star = c * impact_map_reduced_loss_factor(c * stroke_m / clearance_m);
    if (explicit_family) {
      warn([&] { return std::string(
          std::string(family_name) + " model at stroke X = " + format_number(stroke_m, 6) +
          " m below its onset X_onset = " + format_number(onset_m, 6) + " m (s = " + format_number(s, 6) +
          "): the collect-and-collide orbit does not exist there, so eta* comes from the plastic block's "
          "impact map"); });
    }
  } else {
    const ScatteredFit& fit = options.scattered;
    result.regime = MotionRegime::kScattered;
    result.impact_phase_rad = kNaN;
    const double eta_onset = e_b > 0.0 ? onset_reduced_loss_factor(inertia_factor, e_b) : onset_eta_star(inertia_factor);
    result.eta_star = fit.jump_fraction * eta_onset * std::pow(s, fit.exponent);
    if (explicit_family) {
      warn([&] { return std::string(
          std::string(family_name) + " model at stroke X = " + format_number(stroke_m, 6) +
          " m below its onset X_onset = " + format_number(onset_m, 6) + " m (s = " + format_number(s, 6) +
          "): the collect-and-collide orbit does not exist there, so eta* comes from the "
          "scattered-state fit"); });
    }
    if (s < fit.s_min || s > fit.s_max || s >= 1.0) {
      // Between s_max and the cliff (s = 1) the law is extrapolated toward the jump,
      // where the DEM shows the largest scatter: say so with the fit's quality.
      warn([&] {
        std::string quality;
        if (fit.points > 0)
          quality = " (fitted on " + std::to_string(fit.points) + " points, reduced chi^2 = " +
                    format_number(fit.reduced_chi_squared, 6) + ", jump_fraction = " + format_number(fit.jump_fraction, 6) + " +- " +
                    format_number(fit.jump_fraction_stderr, 6) + ")";
        return std::string("scattered-state fit evaluated at s = X/X_onset = " + format_number(s, 6) +
                           ", outside the range it was fitted on [" + format_number(fit.s_min, 6) + ", " +
                           format_number(fit.s_max, 6) + "]: extrapolated" + quality);
      });
    }
    if (fit.provisional) {
      warn([&] { return std::string(
          "scattered-state fit is provisional (jump_fraction = " + format_number(fit.jump_fraction, 6) +
          ", exponent = " + format_number(fit.exponent, 6) + ", source: " + fit.source +
          "): the scattered-state eta* = " + format_number(result.eta_star, 6) +
          " is a placeholder until the fit is made on DEM points"); });
    }
  }

  if (model == DamperModel::kRolling && !options.gravity_across_drive) {
    warn([&] { return std::string("rolling model without gravity across the drive: no base carries the spheres, so they "
                              "fly rather than roll (the bouncing model describes that)"); });
  } else if (model == DamperModel::kRolling && !rolls) {
    warn([&] { return std::string(
        "rolling model at intensity Gamma = " + format_number(result.intensity, 6) + ": rolling without slip needs a base "
        "friction mu >= kappa Gamma/(1+kappa) = " + format_number(rolling_no_slip_friction(inertia_factor, result.intensity), 6) +
        ", more than mu = " + format_number(options.base_friction, 6) + ", so the spheres slide (auto then moves toward "
        "free flight)"); });
  }
  if (model == DamperModel::kBouncing && rolls) {
    warn([&] { return std::string(
        "bouncing model at intensity Gamma = " + format_number(result.intensity, 6) + " <= " + format_number(slip, 6) +
        ": the base friction mu = " + format_number(options.base_friction, 6) + " keeps the spheres rolling there, and "
        "the rolling model describes a bed rolling on its base"); });
  }
  if (!explicit_family && options.gravity_across_drive && !rolls &&
      result.intensity < kFreeFlightFrictionRatio * options.base_friction) {
    warn([&] { return std::string(
        "auto at intensity Gamma = " + format_number(result.intensity, 6) + ": the spheres slide on the base (rolling holds up "
        "to Gamma = " + format_number(slip, 6) + " with mu = " + format_number(options.base_friction, 6) + "), and friction still takes " +
        format_number(100.0 * options.base_friction / result.intensity, 6) + "% of the drive's acceleration: eta* = " +
        format_number(result.eta_star, 6) + " uses the relative acceleration 1 - mu/Gamma (kappa_eff = " + format_number(inertia_factor, 6) +
        "), between rolling and free flight, an approximation: check with pdamp dem"); });
  }
  if (result.model_used == DamperModel::kBouncing && options.gravity_across_drive && stroke_m < clearance_m &&
      model != DamperModel::kScattered) {
    // DEM evidence (docs/dem.md, "High intensity with gravity"): the shipped cylinder
    // case with gravity across the drive sits in the decoupled state with eta* ~ 0.02
    // from X = 0.45 h to 0.8 h, where the orbit gives ~1. No closed form says when the
    // bed is thrown off its base instead, so the whole range X < h is flagged.
    warn([&] { return std::string(
        "bouncing model with gravity across the drive at X/h = " + format_number(stroke_m / clearance_m, 6) +
        " < 1: the bed can stay nearly at rest on the base while the container moves around it (the decoupled "
        "state; the shipped cylinder case with gravity gives eta* ~ 0.02 from 0.45 h to 0.8 h), so eta* = " +
        format_number(result.eta_star, 6) + " holds only if the bed is thrown off its base: check with pdamp dem"); });
  }
  if (explicit_family && options.nested_bed && options.gravity_across_drive) {
    warn([&] { return std::string(
        std::string(to_string(model)) + " model for a nested bed (spheres resting on two or more others cannot "
        "rotate, docs/theory.md section 3.3): the bed does not roll but is held by its base up to Gamma = mu = " +
        format_number(options.base_friction, 6) + " (Gamma = " + format_number(result.intensity, 6) +
        " here) and then slides; the auto model takes that Coulomb block"); });
  }
  if (options.bed_restitution > 0.0 && std::isfinite(options.particle_restitution) &&
      options.bed_restitution > bed_restitution_bound(options.particle_restitution, inertia_factor)) {
    warn([&] { return std::string(
        "bed_restitution e_b = " + format_number(options.bed_restitution, 6) + " exceeds what one sphere can give, eps/"
        "(1+kappa) = " + format_number(bed_restitution_bound(options.particle_restitution, inertia_factor), 6) + " for eps = " +
        format_number(options.particle_restitution, 6) + " and kappa = " + format_number(inertia_factor, 6) +
        " (docs/theory.md section 3.1): a bed rebounds less than its front sphere, so the onset and peak are placed "
        "too low"); });
  }
  common_warnings(result, clearance_m, stroke_m, options, warn);
  return result;
}

}  // namespace

LossResult reduced_loss_factor(DamperModel model, double clearance_m, double stroke_m,
                               double frequency_hz, const ModelOptions& options) {
  require_valid(options);
  return loss_factor<true>(model, clearance_m, stroke_m, frequency_hz, options);
}

LossResult reduced_loss_factor_counted(DamperModel model, double clearance_m, double stroke_m,
                                       double frequency_hz, const ModelOptions& validated_options) {
  return loss_factor<false>(model, clearance_m, stroke_m, frequency_hz, validated_options);
}

double dissipated_energy_measure(double eta_star, double bed_mass_kg,
                                 double velocity_amplitude_m_s) {
  require_non_negative("eta_star", eta_star);
  require_positive("bed_mass_kg", bed_mass_kg);
  require_non_negative("velocity_amplitude_m_s", velocity_amplitude_m_s);
  return eta_star * 0.5 * bed_mass_kg * velocity_amplitude_m_s * velocity_amplitude_m_s;
}

double energy_per_cycle(double e_diss_j) {
  require_non_negative("e_diss_j", e_diss_j);
  return kTwoPi * e_diss_j;
}

}  // namespace pdamp::formulas
