// Scattered-state law: samples below the onset, weighted least squares (NLopt), coefficient file.
#include "pdamp/surrogate/scattered_fit.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlopt.hpp>
#include <stdexcept>

#include "file_io.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/strict_object.hpp"
#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;
using nlohmann::json;

namespace {

constexpr std::string_view kFormat = "pdamp.scattered_fit";
constexpr int kFormatVersion = 1;
/// Parameter box of formulas::ScatteredFit (its validate() rules).
constexpr double kJumpMax = formulas::kMaxJumpFraction;
constexpr double kExponentMax = 10.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// χ²(J, p) and its gradient for NLopt (no exception can be thrown in here).
struct Objective {
  std::span<const ScatteredSample> samples;

  double operator()(double jump, double exponent, double* gradient) const {
    double chi2 = 0.0;
    double d_jump = 0.0;
    double d_exponent = 0.0;
    for (const auto& x : samples) {
      const double w = 1.0 / (x.eta_star_stderr * x.eta_star_stderr);
      const double shape = x.eta_star_onset * std::pow(x.s, exponent);  // ∂model/∂J
      const double residual = x.eta_star - jump * shape;
      chi2 += w * residual * residual;
      d_jump -= 2.0 * w * residual * shape;
      d_exponent -= 2.0 * w * residual * jump * shape * std::log(x.s);
    }
    if (gradient != nullptr) {
      gradient[0] = d_jump;
      gradient[1] = d_exponent;
    }
    return chi2;
  }
};

double nlopt_objective(const std::vector<double>& x, std::vector<double>& gradient, void* data) {
  const auto& objective = *static_cast<Objective*>(data);
  return objective(x[0], x[1], gradient.empty() ? nullptr : gradient.data());
}

/// Start: weighted regression of ln(η*/η*_onset) = ln J + p ln s over the samples with
/// η* > 0 (weights (η*/σ)², since σ(ln η*) ≈ σ/η*), then clipped into the box.
std::pair<double, double> initial_guess(std::span<const ScatteredSample> samples) {
  double sw = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (const auto& x : samples) {
    if (!(x.eta_star > 0.0)) continue;
    const double w = (x.eta_star / x.eta_star_stderr) * (x.eta_star / x.eta_star_stderr);
    const double u = std::log(x.s);
    const double v = std::log(x.eta_star / x.eta_star_onset);
    sw += w;
    sx += w * u;
    sy += w * v;
    sxx += w * u * u;
    sxy += w * u * v;
  }
  const double det = sw * sxx - sx * sx;
  double exponent = 2.0;  // formulas' provisional default when the regression is degenerate
  double log_jump = std::log(0.5);
  if (sw > 0.0 && det > 1e-12 * sw * sxx) {
    exponent = (sw * sxy - sx * sy) / det;
    log_jump = (sy - exponent * sx) / sw;
  }
  return {std::clamp(std::exp(log_jump), 0.0, kJumpMax), std::clamp(exponent, 0.0, kExponentMax)};
}

void check_samples(std::span<const ScatteredSample> samples) {
  if (samples.size() < 3) {
    throw std::invalid_argument("scattered fit: " + std::to_string(samples.size()) +
                                " samples below the onset; need at least 3 (2 coefficients and 1 degree of freedom)");
  }
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const auto& x = samples[k];
    const std::string at = "scattered fit: sample " + std::to_string(k);
    if (!(x.s > 0.0 && x.s < 1.0))
      throw std::invalid_argument(at + ": s = " + format_number(x.s, 12) + ": must be in (0, 1)");
    if (!std::isfinite(x.eta_star))
      throw std::invalid_argument(at + ": eta_star = " + format_number(x.eta_star, 12) + ": must be finite");
    if (!positive_finite(x.eta_star_stderr)) {
      throw std::invalid_argument(at + " (s = " + format_number(x.s, 12) +
                                  "): eta_star_stderr = " + format_number(x.eta_star_stderr, 12) +
                                  ": must be > 0 and finite (the fit weights by 1/stderr^2)");
    }
    if (!positive_finite(x.eta_star_onset)) {
      throw std::invalid_argument(at + ": eta_star_onset = " + format_number(x.eta_star_onset, 12) +
                                  ": must be > 0 and finite");
    }
  }
}

/// √diag of the inverse Gauss-Newton matrix Σ w g gᵀ, g = ∂model/∂(J, p).
std::pair<double, double> coefficient_errors(std::span<const ScatteredSample> samples, double jump, double exponent) {
  double a = 0.0, b = 0.0, c = 0.0;  // [[a, b], [b, c]]
  for (const auto& x : samples) {
    const double w = 1.0 / (x.eta_star_stderr * x.eta_star_stderr);
    const double g_jump = x.eta_star_onset * std::pow(x.s, exponent);
    const double g_exponent = jump * g_jump * std::log(x.s);
    a += w * g_jump * g_jump;
    b += w * g_jump * g_exponent;
    c += w * g_exponent * g_exponent;
  }
  const double det = a * c - b * b;
  // A singular matrix (J = 0 leaves p free) has no finite error bars.
  if (!(det > 1e-14 * a * c)) return {kNaN, kNaN};
  return {std::sqrt(c / det), std::sqrt(a / det)};
}

json nullable(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

}  // namespace

std::vector<ScatteredSample> scattered_samples(const EffectiveField& field, formulas::DamperModel model,
                                               const formulas::ModelOptions& options) {
  detail::throw_if_any(field.validate(), "effective field");
  detail::throw_if_any(options.validate(), "model options");
  const bool fixed = model == formulas::DamperModel::kRolling || model == formulas::DamperModel::kBouncing;
  std::vector<ScatteredSample> samples;
  for (std::size_t k = 0; k < field.points.size(); ++k) {
    const FieldPoint& p = field.points[k];
    if (p.status != PointStatus::kOk) continue;
    const DrivePoint drive = drive_point(field.grid, k, field.clearance_m);
    const double omega = 2.0 * formulas::kPi * drive.frequency_hz;
    const double intensity = drive.amplitude_m * omega * omega / formulas::kStandardGravity;
    // The block the closed forms use at this point (auto: formulas::auto_inertia_factor),
    // so that s and η*_onset are those reduced_loss_factor evaluates the fit with.
    const double kappa = !fixed ? formulas::auto_inertia_factor(intensity, options)
                         : model == formulas::DamperModel::kRolling ? options.rolling_inertia_factor
                                                                     : 0.0;
    const double s = drive.amplitude_m / formulas::onset_stroke_m(kappa, field.clearance_m);
    if (s < 1.0) samples.push_back({s, p.eta_star, p.eta_star_stderr, formulas::onset_reduced_loss_factor(kappa)});
  }
  return samples;
}

ScatteredFitResult fit_scattered_law(std::span<const ScatteredSample> samples, std::string source) {
  check_samples(samples);
  Objective objective{samples};
  nlopt::opt optimizer(nlopt::LD_LBFGS, 2);
  optimizer.set_lower_bounds({0.0, 0.0});
  optimizer.set_upper_bounds({kJumpMax, kExponentMax});
  optimizer.set_min_objective(nlopt_objective, &objective);
  optimizer.set_xtol_rel(1e-12);
  optimizer.set_ftol_rel(1e-15);
  optimizer.set_maxeval(2000);
  const auto [jump0, exponent0] = initial_guess(samples);
  std::vector<double> x = {jump0, exponent0};
  double chi2 = 0.0;
  try {
    optimizer.optimize(x, chi2);
  } catch (const nlopt::roundoff_limited&) {
    // The optimum is resolved to rounding: x holds the best point found, which is the answer.
    chi2 = objective(x[0], x[1], nullptr);
  } catch (const std::exception& e) {
    throw base::NumericalError(std::string("scattered fit: NLopt failed (") + e.what() + ")");
  }
  ScatteredFitResult result;
  result.fit.jump_fraction = x[0];
  result.fit.exponent = x[1];
  result.fit.provisional = false;
  result.fit.source = std::move(source);
  const auto [s_min, s_max] =
      std::minmax_element(samples.begin(), samples.end(), [](const auto& a, const auto& b) { return a.s < b.s; });
  result.fit.s_min = s_min->s;
  result.fit.s_max = s_max->s;
  result.fit.reduced_chi_squared = chi2 / static_cast<double>(samples.size() - 2);
  std::tie(result.fit.jump_fraction_stderr, result.fit.exponent_stderr) = coefficient_errors(samples, x[0], x[1]);
  result.fit.points = samples.size();
  return result;
}

void write_scattered_fit(const ScatteredFitResult& result, const std::filesystem::path& path) {
  detail::throw_if_any(result.fit.validate(), "scattered fit");
  nlohmann::ordered_json doc;
  doc["format"] = kFormat;
  doc["format_version"] = kFormatVersion;
  doc["jump_fraction"] = result.fit.jump_fraction;
  doc["exponent"] = result.fit.exponent;
  doc["s_min"] = result.fit.s_min;
  doc["s_max"] = result.fit.s_max;
  doc["source"] = result.fit.source;
  doc["residual"] = result.fit.reduced_chi_squared;
  doc["points"] = result.fit.points;
  doc["jump_fraction_stderr"] = nullable(result.fit.jump_fraction_stderr);
  doc["exponent_stderr"] = nullable(result.fit.exponent_stderr);
  detail::write_file_atomically(path, doc.dump(2) + "\n");
}

ScatteredFitResult read_scattered_fit(const std::filesystem::path& path) {
  const std::string file = detail::file_label(path);
  // read_json_file refuses directories, FIFOs and duplicate keys ("<path>: ...").
  const json doc = detail::read_json_file(path);
  base::StrictObject root(doc, "", file);
  if (root.optional("format") != nullptr) root.expect_string("format", kFormat);
  if (root.optional("format_version") != nullptr) root.integer("format_version", kFormatVersion, kFormatVersion);
  ScatteredFitResult result;
  result.fit.jump_fraction = root.number("jump_fraction", false);
  result.fit.exponent = root.number("exponent", false);
  result.fit.s_min = root.number("s_min", false);
  result.fit.s_max = root.number("s_max", false);
  result.fit.source = root.string("source");
  if (detail::has_control_byte(result.fit.source)) {
    root.fail("source", "\"" + base::printable(result.fit.source) +
                            "\" holds control characters (must be printable text: it is printed in reports)");
  }
  result.fit.provisional = false;
  result.fit.reduced_chi_squared = root.number("residual", false);
  if (root.optional("points") != nullptr) {
    // fit_scattered_law needs 3 samples (2 coefficients and 1 degree of freedom): fewer is no fit.
    result.fit.points = static_cast<std::size_t>(root.integer("points", 3, std::numeric_limits<int>::max()));
  }
  auto optional_stderr = [&](std::string_view key) {
    const json* value = root.optional(key);
    if (value == nullptr || value->is_null()) return kNaN;
    const double x = root.number_value(*value, root.pointer(key), false);
    if (x < 0.0) root.fail(key, format_number(x, 12) + ": must be >= 0 or null");
    return x;
  };
  result.fit.jump_fraction_stderr = optional_stderr("jump_fraction_stderr");
  result.fit.exponent_stderr = optional_stderr("exponent_stderr");
  root.finish();
  if (!(result.fit.s_max >= result.fit.s_min && result.fit.s_max <= 1.0)) {
    root.fail("s_max", format_number(result.fit.s_max, 12) + ": must be in [s_min, 1] = [" +
                           format_number(result.fit.s_min, 12) + ", 1]");
  }
  // Range rules, each reported at its key.
  const std::vector<std::string> problems = result.fit.validate();
  if (!problems.empty()) {
    const std::string& line = problems.front();
    const std::string key = line.substr(0, line.find_first_of(" ="));
    root.fail(key, line);
  }
  if (result.fit.reduced_chi_squared < 0.0)
    root.fail("residual", format_number(result.fit.reduced_chi_squared, 12) + ": must be >= 0");
  return result;
}

}  // namespace pdamp::surrogate
