// Closed-form implementation of the LossModel lookup interface: η* from formulas/, the
// apparent mass and the stroke derivatives from the same ideal orbits.
#include "pdamp/surrogate/loss_model.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace pdamp::surrogate {

namespace {

constexpr double kPi = formulas::kPi;
/// Scan range of the closed forms relative to the clearance: above 10 h they warn (X/h > 10).
constexpr double kMinStrokeOverClearance = 1e-3;
constexpr double kMaxStrokeOverClearance = 10.0;

bool uses_auto_block(formulas::DamperModel model) {
  return model == formulas::DamperModel::kAuto || model == formulas::DamperModel::kScattered;
}

/// dκ/dX of the block that answers: nonzero only for auto's friction-limited sliding,
/// κ_eff = μ/(Γ − μ) above Γ_slip, with Γ = XΩ²/g so dΓ/dX = Γ/X.
double d_inertia_factor_d_stroke(formulas::DamperModel model, const formulas::ModelOptions& options,
                                 double intensity, double stroke_m) {
  if (!uses_auto_block(model) || !options.gravity_across_drive) return 0.0;
  if (intensity <= formulas::slip_intensity(options)) return 0.0;
  const double mu = options.base_friction;
  return -mu / ((intensity - mu) * (intensity - mu)) * intensity / stroke_m;
}

/// The free block's η*, m_app/m and their derivatives with respect to r = h_eff/X on one
/// orbit branch (docs/collect_and_collide.md §2-3, docs/structure_coupling.md §2).
struct BlockSlopes {
  double apparent_mass_fraction;
  double d_eta_d_r;       ///< of the block's η*, before the 1/(1+κ) factor
  double d_apparent_d_r;  ///< of the block's m_app/m
};

BlockSlopes block_slopes(formulas::MotionRegime regime, double impact_phase_rad) {
  if (regime == formulas::MotionRegime::kCollectAndCollide) {
    // φ* − sin φ* = r ⇒ dφ*/dr = 1/(1 − cos φ*); η_b = (1 − cos φ*)²/π ⇒ dη_b/dr = 2 sin φ*/π;
    // m_b = (π − φ* + 2 sin φ* − sin φ* cos φ*)/π ⇒ dm_b/dφ* = 2 cos φ*(1 − cos φ*)/π.
    const double phi = impact_phase_rad;
    const double s = std::sin(phi), c = std::cos(phi);
    return {(kPi - phi + 2.0 * s - s * c) / kPi, 2.0 * s / kPi, 2.0 * c / kPi};
  }
  // Sub-peak: π cos ψ + 2 sin ψ = r ⇒ dψ/dr = 1/(2 cos ψ − π sin ψ) (infinite at the onset);
  // η_b = 4 cos²ψ/π ⇒ dη_b/dψ = −4 sin 2ψ/π;  m_b = −2 sin 2ψ/π ⇒ dm_b/dψ = −4 cos 2ψ/π.
  const double psi = impact_phase_rad - kPi;
  const double d_psi_d_r = 1.0 / (2.0 * std::cos(psi) - kPi * std::sin(psi));
  return {-2.0 * std::sin(2.0 * psi) / kPi, -4.0 * std::sin(2.0 * psi) / kPi * d_psi_d_r,
          -4.0 * std::cos(2.0 * psi) / kPi * d_psi_d_r};
}

/// The rebounding block's η*, m_app/m and their derivatives with respect to r = h_eff/X on
/// its orbit (ψ from the departure phase), K = (1+e_b)/(1−e_b) (docs/theory.md §3.1):
/// r = πK cos ψ + 2 sin ψ ⇒ dψ/dr = 1/(2 cos ψ − πK sin ψ); η_b = (4/π)K cos²ψ,
/// m_b = −(2/π)K sin 2ψ.
BlockSlopes rebounding_slopes(double psi, double k) {
  const double d_psi_d_r = 1.0 / (2.0 * std::cos(psi) - kPi * k * std::sin(psi));
  return {-2.0 * k * std::sin(2.0 * psi) / kPi, -4.0 * k * std::sin(2.0 * psi) / kPi * d_psi_d_r,
          -4.0 * k * std::cos(2.0 * psi) / kPi * d_psi_d_r};
}

/// A friction-limited bed's response (the nested bed's Coulomb block, the rolling tail with
/// rolling resistance): η* from `loss`, m_app/m_bed from `at(X)`, and where the bed `moves`
/// both stroke derivatives by central differences (η* and m_app are smooth in X inside each
/// regime; 1e-6 X keeps the truncation error near 1e-12 and the rounding error near 1e-10
/// relative).
template <class At>
DamperResponse friction_response(const formulas::LossResult& loss, double stroke_m, bool moves, const At& at) {
  DamperResponse response;
  response.eta_star = loss.eta_star;
  response.regime = formulas::to_string(loss.regime);
  response.apparent_mass_fraction = at(stroke_m).apparent_mass_fraction;
  if (moves) {
    const double step = 1e-6 * stroke_m;
    const auto up = at(stroke_m + step);
    const auto down = at(stroke_m - step);
    response.d_eta_star_d_stroke_1_m = (up.eta_star - down.eta_star) / (2.0 * step);
    response.d_apparent_mass_fraction_d_stroke_1_m =
        (up.apparent_mass_fraction - down.apparent_mass_fraction) / (2.0 * step);
  }
  if (loss.warning_count > 0) response.warnings |= kLossOutsideClosedForm;
  return response;
}

}  // namespace

std::vector<double> LossModel::discontinuities_stroke_m(double /*frequency_hz*/) const { return {}; }

DamperResponse LossModel::evaluate_from_above(double frequency_hz, double stroke_m) const {
  return evaluate(frequency_hz, stroke_m);
}

std::vector<std::string> LossModel::warning_messages(double frequency_hz, double stroke_m) const {
  return describe_loss_warnings(evaluate(frequency_hz, stroke_m).warnings);
}

std::vector<std::string> describe_loss_warnings(std::uint32_t warnings) {
  static constexpr std::pair<LossWarning, const char*> kSentences[] = {
      {kLossOutsideFieldGrid, "effective field queried outside its grid: the edge value is used, its slope is 0"},
      {kLossRescaledClearance, "effective field made for another clearance, reused at equal intensity and X/h"},
      {kLossOutsideClosedForm, "a validity rule of the closed-form model is violated (see its warning)"},
      {kLossScatteredState, "below the collect-and-collide onset: eta* from the empirical scattered-state fit"},
      {kLossApparentMassMissing, "the loss model gives no apparent mass"},
      {kLossApparentMassAssumed, "apparent mass from an assumption (no-impact limit below the onset)"},
  };
  std::vector<std::string> sentences;
  for (const auto& [bit, sentence] : kSentences)
    if (warnings & bit) sentences.emplace_back(sentence);
  return sentences;
}

ClosedFormLossModel::ClosedFormLossModel(formulas::DamperModel model, double clearance_m,
                                         formulas::ModelOptions options)
    : model_(model), clearance_m_(clearance_m), options_(std::move(options)), from_above_options_(options_) {
  from_above_options_.below_onset = options_.below_onset_from_above;
  if (!(clearance_m > 0.0 && std::isfinite(clearance_m)))
    throw std::invalid_argument("ClosedFormLossModel: clearance_m = " + std::to_string(clearance_m) +
                                ": must be > 0 and finite");
  if (const auto problems = options_.validate(); !problems.empty())
    throw std::invalid_argument("ClosedFormLossModel: " + problems.front());
}

DamperResponse ClosedFormLossModel::evaluate(double frequency_hz, double stroke_m) const {
  return respond(options_, frequency_hz, stroke_m);
}

DamperResponse ClosedFormLossModel::evaluate_from_above(double frequency_hz, double stroke_m) const {
  return respond(from_above_options_, frequency_hz, stroke_m);
}

DamperResponse ClosedFormLossModel::respond(const formulas::ModelOptions& options, double frequency_hz,
                                            double stroke_m) const {
  // The options were validated by the constructor; only the number of warnings is used here
  // (warning_messages writes the sentences).
  const auto loss = formulas::reduced_loss_factor_counted(model_, clearance_m_, stroke_m, frequency_hz, options);
  DamperResponse response;
  response.eta_star = loss.eta_star;
  response.regime = formulas::to_string(loss.regime);
  const double kappa = loss.inertia_factor;
  const double scale = 1.0 + kappa;
  const double d_kappa = d_inertia_factor_d_stroke(model_, options_, loss.intensity, stroke_m);
  if (loss.model_used == formulas::DamperModel::kCoulombBlock) return coulomb_response(loss, frequency_hz, stroke_m);
  if (loss.regime == formulas::MotionRegime::kRollingTail || loss.regime == formulas::MotionRegime::kStuck)
    return tail_response(loss, frequency_hz, stroke_m);
  const bool scattered = loss.regime == formulas::MotionRegime::kScattered;
  const bool explicit_family =
      model_ == formulas::DamperModel::kRolling || model_ == formulas::DamperModel::kBouncing;
  if (scattered && options.below_onset == formulas::BelowOnsetModel::kImpactMap &&
      model_ != formulas::DamperModel::kScattered) {
    // η* = c·E(ξ), ξ = cX/h, c = 1/(1+κ) (docs/theory.md §4.2); dc/dX = −c² dκ/dX.
    const double c = 1.0 / scale;
    const double dc = -c * c * d_kappa;
    const double xi = c * stroke_m / clearance_m_;
    const double map = formulas::impact_map_reduced_loss_factor(xi);
    const double slope = formulas::impact_map_reduced_loss_factor_slope(xi);
    response.d_eta_star_d_stroke_1_m = dc * map + c * slope * (c + stroke_m * dc) / clearance_m_;
    response.apparent_mass_fraction = kappa / scale;
    response.d_apparent_mass_fraction_d_stroke_1_m = d_kappa / (scale * scale);
    response.warnings |= kLossScatteredState | kLossApparentMassAssumed;
    if (loss.warning_count > (explicit_family ? 1u : 0u)) response.warnings |= kLossOutsideClosedForm;
    return response;
  }
  if (scattered) {
    // η* = j·η*_onset(κ)·(X/X_onset(κ))^p with η*_onset, X_onset ∝ 1/(1+κ), (1+κ):
    // d ln η* = p dX/X − (1+p) dκ/(1+κ). Apparent mass: the no-impact limit κ/(1+κ).
    const double p = options_.scattered.exponent;
    response.d_eta_star_d_stroke_1_m = loss.eta_star * (p / stroke_m - (1.0 + p) * d_kappa / scale);
    response.apparent_mass_fraction = kappa / scale;
    response.d_apparent_mass_fraction_d_stroke_1_m = d_kappa / (scale * scale);
    response.warnings |= kLossScatteredState | kLossApparentMassAssumed;
    // The scattered state's own warnings (provisional or extrapolated fit) are expected
    // there; only the others mean the closed form is outside its validity.
    std::size_t expected = (explicit_family ? 1u : 0u) + (options_.scattered.provisional ? 1u : 0u);
    const double s = loss.stroke_over_onset;
    if (s < options_.scattered.s_min || s > options_.scattered.s_max || s >= 1.0) ++expected;
    if (loss.warning_count > expected) response.warnings |= kLossOutsideClosedForm;
    return response;
  }
  if (options_.bed_restitution > 0.0) return rebounding_response(loss, stroke_m, d_kappa);
  // On an orbit: η* = η_b(r)/(1+κ), m_app/m = (κ + m_b(r))/(1+κ), r = (1+κ)h/X, so
  // dr/dX = −r/X + (h/X)·dκ/dX and ∂/∂κ at fixed r of the two are −η*/(1+κ) and
  // (1 − m_b)/(1+κ)².
  const BlockSlopes block = block_slopes(loss.regime, loss.impact_phase_rad);
  const double r = scale * clearance_m_ / stroke_m;
  const double dr = -r / stroke_m + clearance_m_ / stroke_m * d_kappa;
  response.apparent_mass_fraction = (kappa + block.apparent_mass_fraction) / scale;
  response.d_eta_star_d_stroke_1_m = block.d_eta_d_r * dr / scale - loss.eta_star * d_kappa / scale;
  response.d_apparent_mass_fraction_d_stroke_1_m =
      block.d_apparent_d_r * dr / scale + (1.0 - block.apparent_mass_fraction) * d_kappa / (scale * scale);
  if (loss.warning_count > 0) response.warnings |= kLossOutsideClosedForm;
  return response;
}

DamperResponse ClosedFormLossModel::rebounding_response(const formulas::LossResult& loss, double stroke_m,
                                                       double d_kappa) const {
  // η* = η_b/(1+κ) and m_app/m = (κ + m_b)/(1+κ) on the rebounding orbit below the peak; above
  // it η* = 4h/(π²X) (the DEM's tail, docs/theory.md §3.1: independent of κ and e_b) with the
  // apparent mass of the orbit continued (ψ < 0), held at its last value ψ = −acos(1/K) where
  // that orbit ends, and flagged as assumed.
  DamperResponse response;
  response.eta_star = loss.eta_star;
  response.regime = formulas::to_string(loss.regime);
  const double kappa = loss.inertia_factor;
  const double scale = 1.0 + kappa;
  const double k = formulas::rebound_factor(options_.bed_restitution);
  const double r = scale * clearance_m_ / stroke_m;
  const double dr = -r / stroke_m + clearance_m_ / stroke_m * d_kappa;
  const bool tail = loss.regime == formulas::MotionRegime::kCollectAndCollide;
  double psi = loss.impact_phase_rad - kPi;
  bool on_orbit = true;
  if (tail) {
    const auto orbit = formulas::rebounding_orbit(kappa, options_.bed_restitution, clearance_m_, stroke_m);
    on_orbit = orbit.exists;
    psi = orbit.exists ? orbit.psi_rad : -std::acos(1.0 / k);
  }
  const BlockSlopes block = rebounding_slopes(psi, k);
  response.apparent_mass_fraction = (kappa + block.apparent_mass_fraction) / scale;
  response.d_apparent_mass_fraction_d_stroke_1_m =
      (on_orbit ? block.d_apparent_d_r * dr / scale : 0.0) +
      (1.0 - block.apparent_mass_fraction) * d_kappa / (scale * scale);
  response.d_eta_star_d_stroke_1_m =
      tail ? -loss.eta_star / stroke_m : block.d_eta_d_r * dr / scale - loss.eta_star * d_kappa / scale;
  if (tail) response.warnings |= kLossApparentMassAssumed;
  if (loss.warning_count > 0) response.warnings |= kLossOutsideClosedForm;
  return response;
}

DamperResponse ClosedFormLossModel::tail_response(const formulas::LossResult& loss, double frequency_hz,
                                                  double stroke_m) const {
  // The rolling tail (docs/theory.md §3.4): κ is fixed there (the bed rolls, Γ <= Γ_slip), and
  // without rolling resistance η* = 0 and m_app/m_bed = κ/(1+κ) do not depend on X.
  const double kappa = loss.inertia_factor;
  const double mu_r = options_.rolling_resistance;
  const double omega = 2.0 * kPi * frequency_hz;
  return friction_response(loss, stroke_m, mu_r > 0.0 && loss.regime == formulas::MotionRegime::kRollingTail,
                           [&](double x) {
                             return formulas::rolling_tail(kappa, mu_r, x * omega * omega / formulas::kStandardGravity);
                           });
}

DamperResponse ClosedFormLossModel::coulomb_response(const formulas::LossResult& loss, double frequency_hz,
                                                     double stroke_m) const {
  // The nested bed as a Coulomb block (docs/theory.md §3.3): η* and m_app from
  // formulas::coulomb_block.
  const double omega = 2.0 * kPi * frequency_hz;
  const double mu = options_.base_friction;
  return friction_response(loss, stroke_m, loss.regime == formulas::MotionRegime::kSliding, [&](double x) {
    return formulas::coulomb_block(mu, x * omega * omega / formulas::kStandardGravity, clearance_m_ / x);
  });
}

std::vector<double> ClosedFormLossModel::discontinuities_stroke_m(double frequency_hz) const {
  if (model_ == formulas::DamperModel::kScattered || model_ == formulas::DamperModel::kCoulombBlock) return {};
  const auto& options = options_;
  // A nested bed under auto is the Coulomb block: continuous in X (η* → 0, m_app → m_bed at Γ = μ).
  if (model_ == formulas::DamperModel::kAuto && options.nested_bed && options.gravity_across_drive) return {};
  const double e_b = options.bed_restitution;
  if (model_ != formulas::DamperModel::kAuto) {
    const double kappa = model_ == formulas::DamperModel::kRolling ? options.rolling_inertia_factor : 0.0;
    if (e_b > 0.0) return {formulas::onset_stroke_m(kappa, clearance_m_, e_b)};
    return {formulas::onset_stroke_m(kappa, clearance_m_)};
  }
  // auto: κ_eff(Γ(X)) does not increase with X, so X − X_onset(κ_eff(Γ(X))) increases
  // monotonically between the free block's onset (κ = 0) and the rolling one: bisection.
  const double omega = 2.0 * kPi * frequency_hz;
  const auto excess = [&](double x) {
    const double kappa = formulas::auto_inertia_factor(x * omega * omega / formulas::kStandardGravity, options);
    return x - (e_b > 0.0 ? formulas::onset_stroke_m(kappa, clearance_m_, e_b)
                          : formulas::onset_stroke_m(kappa, clearance_m_));
  };
  const auto onset = [&](double kappa) {
    return e_b > 0.0 ? formulas::onset_stroke_m(kappa, clearance_m_, e_b) : formulas::onset_stroke_m(kappa, clearance_m_);
  };
  double lo = onset(0.0);
  double hi = onset(options.gravity_across_drive ? options.rolling_inertia_factor : 0.0);
  if (excess(lo) >= 0.0) return {lo};
  for (int iteration = 0; iteration < 200 && hi - lo > 1e-15 * hi; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) >= 0.0 ? hi : lo) = mid;
  }
  return {hi};  // the lowest stroke classified as on the orbit
}

StrokeRange ClosedFormLossModel::stroke_range_m(double /*frequency_hz*/) const {
  return {kMinStrokeOverClearance * clearance_m_, kMaxStrokeOverClearance * clearance_m_};
}

std::vector<std::string> ClosedFormLossModel::warning_messages(double frequency_hz, double stroke_m) const {
  auto sentences = formulas::reduced_loss_factor(model_, clearance_m_, stroke_m, frequency_hz, options_).warnings;
  const DamperResponse response = evaluate(frequency_hz, stroke_m);
  if ((response.warnings & kLossApparentMassAssumed) && response.regime == "collect_and_collide")
    sentences.push_back("apparent mass above the rebounding bed's peak taken from the rebounding block's orbit, " +
                        std::to_string(response.apparent_mass_fraction) +
                        " of the bed mass (the DEM of rebounding layers gives 1.0-1.25 there, docs/theory.md "
                        "section 3.1)");
  else if (response.warnings & kLossApparentMassAssumed)
    sentences.push_back("apparent mass below the onset assumed to be the no-impact limit kappa/(1+kappa) = " +
                        std::to_string(response.apparent_mass_fraction) + " of the bed mass (no closed form there)");
  return sentences;
}

}  // namespace pdamp::surrogate
