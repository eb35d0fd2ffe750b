// Problem validation, the finite-difference step rule and the gradient check.
#include "pdamp/optimizer/problem.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "evaluator.hpp"
#include "pdamp/base/number_text.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {
namespace {

void validate_variable(const Variable& variable, std::size_t index, std::set<std::string>& names,
                       std::vector<std::string>& problems) {
  std::ostringstream prefix;
  prefix << "variable '" << variable.name << "'";
  if (variable.name.empty()) {
    problems.push_back("variables[" + std::to_string(index) + "].name is empty: must name the variable");
  } else if (!names.insert(variable.name).second) {
    problems.push_back(prefix.str() + ": name used twice: must be unique");
  }
  const auto report = [&](const std::string& rule) { problems.push_back(prefix.str() + ": " + rule); };
  if (std::isnan(variable.lower)) report("lower = nan: must be a number");
  if (std::isnan(variable.upper)) report("upper = nan: must be a number");
  if (variable.lower > variable.upper) {
    report("lower = " + base::format_number(variable.lower, 10) +
           " > upper = " + base::format_number(variable.upper, 10) + ": must have lower <= upper");
  }
  if (variable.lower == std::numeric_limits<double>::infinity() ||
      variable.upper == -std::numeric_limits<double>::infinity()) {
    report("bounds [" + base::format_number(variable.lower, 10) + ", " + base::format_number(variable.upper, 10) +
           "]: must contain a finite value");
  }
  if (!std::isfinite(variable.initial) || variable.initial < variable.lower || variable.initial > variable.upper) {
    report("initial = " + base::format_number(variable.initial, 10) + ": must be finite and in [lower, upper] = [" +
           base::format_number(variable.lower, 10) + ", " + base::format_number(variable.upper, 10) + "]");
  }
}

}  // namespace

std::vector<std::string> Problem::validate() const {
  std::vector<std::string> problems;
  if (variables.empty()) problems.emplace_back("variables is empty: a problem needs at least one variable");
  std::set<std::string> variable_names;
  for (std::size_t j = 0; j < variables.size(); ++j) validate_variable(variables[j], j, variable_names, problems);
  if (!objective.value) problems.push_back("objective '" + objective.name + "' has no value function");
  std::set<std::string> constraint_names;
  for (std::size_t i = 0; i < constraints.size(); ++i) {
    const Function& constraint = constraints[i];
    if (constraint.name.empty()) {
      problems.push_back("constraints[" + std::to_string(i) + "].name is empty: must name the constraint");
    } else if (!constraint_names.insert(constraint.name).second) {
      problems.push_back("constraint '" + constraint.name + "': name used twice: must be unique");
    }
    if (!constraint.value) problems.push_back("constraint '" + constraint.name + "' has no value function");
  }
  return problems;
}

double finite_difference_step(const Variable& variable, double x) {
  if (variable.lower == variable.upper) return 0.0;
  const double range = variable.upper - variable.lower;
  double step = std::sqrt(std::numeric_limits<double>::epsilon()) *
                std::max(std::abs(x), std::isfinite(range) ? range : 1.0);
  if (x + step > variable.upper) {
    step = x - step >= variable.lower ? -step
                                      : (variable.upper - x >= x - variable.lower ? variable.upper - x
                                                                                  : variable.lower - x);
  }
  return (x + step) - x;  // the step actually taken in floating point
}

GradientCheck check_gradients(const Problem& problem, std::span<const double> x) {
  detail::throw_if_invalid(problem.validate(), "problem");
  if (x.size() != problem.variables.size()) {
    throw std::invalid_argument("check_gradients: x has " + std::to_string(x.size()) + " values, the problem " +
                                std::to_string(problem.variables.size()) + " variables");
  }
  for (std::size_t j = 0; j < x.size(); ++j) {
    const Variable& variable = problem.variables[j];
    if (!(x[j] >= variable.lower && x[j] <= variable.upper)) {
      throw std::invalid_argument("check_gradients: variable '" + variable.name +
                                  "' = " + base::format_number(x[j], 10) + ": must be in [lower, upper]");
    }
  }
  // Differences of the same problem with its analytic gradients removed.
  Problem by_differences = problem;
  by_differences.objective.gradient = nullptr;
  for (Function& constraint : by_differences.constraints) constraint.gradient = nullptr;
  const std::size_t n = x.size();
  const std::size_t m = problem.constraints.size();
  std::vector<double> analytic_gradient(n), analytic_jacobian(m * n), fd_gradient(n), fd_jacobian(m * n);
  detail::Evaluator analytic(problem, 0.0);
  detail::Evaluator differences(by_differences, 0.0);
  analytic.gradients(x, analytic_gradient, analytic_jacobian);
  differences.gradients(x, fd_gradient, fd_jacobian);

  GradientCheck check;
  const auto compare = [&](const Function& function, const std::string& label, std::span<const double> exact,
                           std::span<const double> approximate) {
    if (!function.gradient) return;
    for (std::size_t j = 0; j < n; ++j) {
      const double error = std::abs(exact[j] - approximate[j]) /
                           std::max({std::abs(exact[j]), std::abs(approximate[j]), 1.0});
      if (error > check.max_error || check.worst.empty()) {
        check.max_error = std::max(check.max_error, error);
        check.worst = label + " '" + function.name + "' d/d(" + problem.variables[j].name + ")";
      }
    }
  };
  compare(problem.objective, "objective", analytic_gradient, fd_gradient);
  for (std::size_t i = 0; i < m; ++i) {
    compare(problem.constraints[i], "constraint", std::span(analytic_jacobian).subspan(i * n, n),
            std::span(fd_jacobian).subspan(i * n, n));
  }
  return check;
}

}  // namespace pdamp::optimizer
