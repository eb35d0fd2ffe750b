// Robust clearance sizing: the sampled operating range, the sizing problem and its result.
#include "pdamp/optimizer/robust_sizing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "pdamp/optimizer/solve.hpp"
#include "pdamp/base/number_text.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {
namespace {

namespace fm = formulas;

/// n geometric samples of [low, high], ends included; one when the range is a point.
std::vector<double> geometric_samples(double low, double high, int n) {
  if (low == high) return {low};
  std::vector<double> samples(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) samples[k] = low * std::pow(high / low, static_cast<double>(k) / (n - 1));
  samples.back() = high;
  return samples;
}

struct OperatingPoint {
  double stroke_m = 0.0;
  double frequency_hz = 0.0;
  /// κ of the family the closed form uses there: it depends on X and f (through Γ in
  /// kAuto) but not on h, so the onset X_onset = (1+κ)h/√(π²+4) is linear in h.
  double inertia_factor = 0.0;
};

/// Everything the problem functions share (held by shared_ptr: Functions are copied).
struct SizingModel {
  const RobustSizingOptions options;
  std::vector<OperatingPoint> points;

  double eta_star(const OperatingPoint& point, double clearance_m) const {
    return fm::reduced_loss_factor(options.model, clearance_m, point.stroke_m, point.frequency_hz,
                                   options.model_options)
        .eta_star;
  }
  double stroke_over_onset(const OperatingPoint& point, double clearance_m) const {
    return point.stroke_m / fm::onset_stroke_m(point.inertia_factor, clearance_m);
  }
  /// The sample nearest its onset for every h: largest (1+κ)/X.
  const OperatingPoint& nearest_onset() const {
    return *std::min_element(points.begin(), points.end(), [&](const OperatingPoint& a, const OperatingPoint& b) {
      return stroke_over_onset(a, 1.0) < stroke_over_onset(b, 1.0);
    });
  }
};

std::shared_ptr<const SizingModel> make_model(const RobustSizingOptions& options, double clearance_m) {
  auto model = std::make_shared<SizingModel>(SizingModel{options, {}});
  for (double stroke_m : geometric_samples(options.stroke_min_m, options.stroke_max_m, options.stroke_samples)) {
    for (double frequency_hz :
         geometric_samples(options.frequency_min_hz, options.frequency_max_hz, options.frequency_samples)) {
      const double inertia_factor =
          fm::reduced_loss_factor(options.model, clearance_m, stroke_m, frequency_hz, options.model_options)
              .inertia_factor;
      model->points.push_back({stroke_m, frequency_hz, inertia_factor});
    }
  }
  return model;
}

std::string sample_name(const OperatingPoint& point) {
  std::ostringstream name;
  name.precision(6);
  name << "eta_star(X = " << point.stroke_m << " m, f = " << point.frequency_hz << " Hz)";
  return name.str();
}

Problem sizing_problem(const std::shared_ptr<const SizingModel>& model, double clearance_min_m,
                       double clearance_max_m) {
  Problem problem;
  problem.variables.push_back(
      {"clearance_m", "m", clearance_min_m, clearance_max_m, std::sqrt(clearance_min_m * clearance_max_m)});
  // (1 + m)·X_onset(h)/X − 1 <= 0 at the sample nearest its onset; exact slope (linear in h).
  const OperatingPoint binding = model->nearest_onset();
  const double factor = (1.0 + model->options.onset_margin) / model->stroke_over_onset(binding, 1.0);
  problem.constraints.push_back({"onset_margin", [factor](std::span<const double> x) { return factor * x[0] - 1.0; },
                                 [factor](std::span<const double>, std::span<double> gradient) {
                                   gradient[0] = factor;
                                   std::fill(gradient.begin() + 1, gradient.end(), 0.0);
                                 }});
  if (model->options.criterion == RobustCriterion::kMean) {
    problem.objective = {"minus_mean_eta_star",
                         [model](std::span<const double> x) {
                           double sum = 0.0;
                           for (const OperatingPoint& point : model->points) sum += model->eta_star(point, x[0]);
                           return -sum / static_cast<double>(model->points.size());
                         },
                         nullptr};
    return problem;
  }
  // Epigraph of the worst case: t is bounded by the largest η* of any state, twice the
  // onset value (formulas::kMaxJumpFraction) being above the peak 4/π of κ = 0.
  problem.variables.push_back({"worst_eta_star", "", 0.0, 2.0, 0.0});
  problem.objective = {"minus_worst_eta_star", [](std::span<const double> x) { return -x[1]; },
                       [](std::span<const double>, std::span<double> gradient) {
                         gradient[0] = 0.0;
                         gradient[1] = -1.0;
                       }};
  for (const OperatingPoint& point : model->points) {
    problem.constraints.push_back(
        {sample_name(point),
         [model, point](std::span<const double> x) { return x[1] - model->eta_star(point, x[0]); }, nullptr});
  }
  return problem;
}

}  // namespace

std::vector<std::string> RobustSizingOptions::validate() const {
  std::vector<std::string> problems;
  const auto rule = [&](const char* field, double value, bool holds, const char* text) {
    if (!holds) problems.push_back(std::string(field) + " = " + base::format_number(value, 10) + ": must be " + text);
  };
  if (model == fm::DamperModel::kScattered) {
    problems.emplace_back("model = scattered: must be rolling, bouncing or auto (no orbit to size)");
  }
  for (const std::string& line : model_options.validate()) problems.push_back("model_options." + line);
  rule("stroke_min_m", stroke_min_m, std::isfinite(stroke_min_m) && stroke_min_m > 0.0, "> 0 and finite");
  rule("stroke_max_m", stroke_max_m, std::isfinite(stroke_max_m) && stroke_max_m >= stroke_min_m,
       ">= stroke_min_m and finite");
  rule("frequency_min_hz", frequency_min_hz, std::isfinite(frequency_min_hz) && frequency_min_hz > 0.0,
       "> 0 and finite");
  rule("frequency_max_hz", frequency_max_hz, std::isfinite(frequency_max_hz) && frequency_max_hz >= frequency_min_hz,
       ">= frequency_min_hz and finite");
  rule("stroke_samples", stroke_samples, stroke_samples >= 2 && stroke_samples <= 1000, "in [2, 1000]");
  rule("frequency_samples", frequency_samples, frequency_samples >= 2 && frequency_samples <= 1000, "in [2, 1000]");
  if (clearance_min_m) {
    rule("clearance_min_m", *clearance_min_m, std::isfinite(*clearance_min_m) && *clearance_min_m > 0.0,
         "> 0 and finite");
  }
  if (clearance_max_m) {
    const double lower = clearance_min_m.value_or(stroke_min_m / 10.0);
    rule("clearance_max_m", *clearance_max_m, std::isfinite(*clearance_max_m) && *clearance_max_m > lower,
         "> clearance_min_m (default stroke_min_m/10) and finite");
  }
  rule("onset_margin", onset_margin, onset_margin >= 0.0 && onset_margin <= 1.0, "in [0, 1]");
  return problems;
}

RobustSizing size_clearance_robustly(const RobustSizingOptions& options, const Options& solver_options) {
  detail::throw_if_invalid(options.validate(), "robust sizing options");
  const double clearance_min_m = options.clearance_min_m.value_or(options.stroke_min_m / 10.0);
  const double clearance_max_m = options.clearance_max_m.value_or(10.0 * options.stroke_max_m);
  const std::shared_ptr<const SizingModel> model = make_model(options, clearance_min_m);

  RobustSizing sizing;
  sizing.summary = solve(sizing_problem(model, clearance_min_m, clearance_max_m), solver_options);
  sizing.clearance_m = sizing.summary.x[0];
  sizing.worst_eta_star = std::numeric_limits<double>::infinity();
  sizing.least_stroke_over_onset = std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (const OperatingPoint& point : model->points) {
    const double eta_star = model->eta_star(point, sizing.clearance_m);
    sizing.worst_eta_star = std::min(sizing.worst_eta_star, eta_star);
    sum += eta_star;
    sizing.least_stroke_over_onset =
        std::min(sizing.least_stroke_over_onset, model->stroke_over_onset(point, sizing.clearance_m));
  }
  sizing.mean_eta_star = sum / static_cast<double>(model->points.size());
  return sizing;
}

}  // namespace pdamp::optimizer
