// Private: point evaluation, forward differences and the incumbent for the back ends.
#include "evaluator.hpp"

#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pdamp::optimizer::detail {
namespace {

bool same_point(const std::vector<double>& cached, std::span<const double> x) {
  return cached.size() == x.size() && std::equal(x.begin(), x.end(), cached.begin());
}

double checked(double value, const std::string& what, std::span<const double> x) {
  if (!std::isfinite(value)) {
    std::ostringstream message;
    message << what << " returned " << value << " at x = " << format_point(x)
            << ": problem functions must be finite inside the bounds";
    throw std::domain_error(message.str());
  }
  return value;
}

}  // namespace

std::string format_point(std::span<const double> x) {
  std::string text = "(";
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (j) text += ", ";
    text += base::format_number(x[j], 10);
  }
  text += ')';
  return text;
}

Evaluator::Evaluator(const Problem& problem, double constraint_tolerance)
    : problem_(problem), constraint_tolerance_(constraint_tolerance) {}

void Evaluator::evaluate_point(std::span<const double> x, PointValues& out) {
  ++evaluations_;
  out.objective = checked(problem_.objective.value(x), "objective '" + problem_.objective.name + "'", x);
  out.constraints.resize(constraint_count());
  out.max_violation = 0.0;
  for (std::size_t i = 0; i < constraint_count(); ++i) {
    const Function& constraint = problem_.constraints[i];
    out.constraints[i] = checked(constraint.value(x), "constraint '" + constraint.name + "'", x);
    out.max_violation = std::max(out.max_violation, out.constraints[i]);
  }
  update_incumbent(x, out);
}

void Evaluator::update_incumbent(std::span<const double> x, const PointValues& values) {
  const bool feasible = is_feasible(values);
  const bool better =
      incumbent_.x.empty() ||
      (feasible && (!incumbent_.feasible || values.objective < incumbent_.values.objective)) ||
      (!feasible && !incumbent_.feasible && values.max_violation < incumbent_.values.max_violation);
  if (!better) return;
  incumbent_.x.assign(x.begin(), x.end());
  incumbent_.values = values;
  incumbent_.feasible = feasible;
}

const PointValues& Evaluator::values(std::span<const double> x) {
  if (!same_point(cached_x_, x)) {
    cached_x_.clear();  // stays empty if evaluate_point throws
    evaluate_point(x, cached_values_);
    cached_x_.assign(x.begin(), x.end());
  }
  return cached_values_;
}

void Evaluator::gradients(std::span<const double> x, std::span<double> objective_gradient,
                          std::span<double> constraint_jacobian) {
  const std::size_t n = variable_count();
  const std::size_t m = constraint_count();
  if (!same_point(cached_gradient_x_, x)) {
    cached_gradient_x_.clear();
    ++gradient_evaluations_;
    const PointValues base = values(x);
    cached_objective_gradient_.assign(n, 0.0);
    cached_jacobian_.assign(m * n, 0.0);
    std::vector<bool> by_differences(m + 1);  // [0]: objective, [1 + i]: constraint i
    const auto analytic = [&](const Function& function, std::span<double> gradient) {
      if (!function.gradient) return false;
      function.gradient(x, gradient);
      for (double slope : gradient) checked(slope, "gradient of '" + function.name + "'", x);
      return true;
    };
    by_differences[0] = !analytic(problem_.objective, cached_objective_gradient_);
    for (std::size_t i = 0; i < m; ++i) {
      by_differences[1 + i] =
          !analytic(problem_.constraints[i], std::span(cached_jacobian_).subspan(i * n, n));
    }
    if (std::find(by_differences.begin(), by_differences.end(), true) != by_differences.end()) {
      perturbed_x_.assign(x.begin(), x.end());
      for (std::size_t j = 0; j < n; ++j) {
        const double step = finite_difference_step(problem_.variables[j], x[j]);
        if (step == 0.0) continue;  // fixed variable: slope 0
        perturbed_x_[j] = x[j] + step;
        evaluate_point(perturbed_x_, perturbed_values_);
        perturbed_x_[j] = x[j];
        if (by_differences[0]) {
          cached_objective_gradient_[j] = (perturbed_values_.objective - base.objective) / step;
        }
        for (std::size_t i = 0; i < m; ++i) {
          if (by_differences[1 + i]) {
            cached_jacobian_[i * n + j] = (perturbed_values_.constraints[i] - base.constraints[i]) / step;
          }
        }
      }
    }
    cached_gradient_x_.assign(x.begin(), x.end());
  }
  std::copy(cached_objective_gradient_.begin(), cached_objective_gradient_.end(), objective_gradient.begin());
  std::copy(cached_jacobian_.begin(), cached_jacobian_.end(), constraint_jacobian.begin());
}

}  // namespace pdamp::optimizer::detail
