// Tests of optimizer::solve on an analytic cliff problem (both back ends), of the
// exception, budget and infeasibility paths, and of the problem and option checks.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "optimizer/cliff_problem.hpp"
#include "pdamp/optimizer/solve.hpp"

namespace {

namespace opt = pdamp::optimizer;
using opt::test::cliff_problem;

opt::Options options_for(opt::Backend backend) {
  opt::Options options;
  options.backend = backend;
  return options;
}

bool message_has(const std::invalid_argument& error, const std::string& text) {
  return std::string(error.what()).find(text) != std::string::npos;
}

}  // namespace

// Reference: the optimum (1.15, 0.65), f* = 0.245, is the projection of the bowl centre
// onto the constraint (closed form). Tolerance 1e-6 on x: the local stages stop at
// relative_tolerance = 1e-8 on a problem of curvature 2, and forward-difference slopes
// (error ~√ε) move the KKT point by far less than 1e-6.
TEST_CASE("both back ends find the cliff problem's optimum on the good side of the cliff", "[optimizer]") {
  const auto backend = GENERATE(opt::Backend::kNlopt, opt::Backend::kIpopt);
  const bool with_gradients = GENERATE(true, false);
  CAPTURE(opt::to_string(backend), with_gradients);
  const opt::Summary summary = opt::solve(cliff_problem(with_gradients), options_for(backend));
  INFO(summary.full_report());
  CHECK(summary.outcome == opt::Outcome::kConverged);
  REQUIRE(summary.x.size() == 2);
  CHECK(summary.x[0] > opt::test::kCliffX);
  CHECK(summary.x[0] == Approx(opt::test::kOptimumX).margin(1e-6));
  CHECK(summary.x[1] == Approx(opt::test::kOptimumY).margin(1e-6));
  CHECK(summary.objective == Approx(opt::test::kOptimumObjective).margin(1e-6));
  CHECK(summary.max_constraint_violation <= 1e-8);
  CHECK(summary.global_evaluations == 2000);
  CHECK(summary.evaluations > summary.global_evaluations);
  CHECK(summary.iterations > 0);
}

// Reference: the closed-form optimum again; COBYLA's linear models converge linearly,
// so the tolerance is looser (1e-5).
TEST_CASE("NLopt's derivative-free COBYLA refinement finds the cliff problem's optimum", "[optimizer]") {
  opt::Options options;
  options.nlopt_local_algorithm = opt::NloptLocalAlgorithm::kCobyla;
  const opt::Summary summary = opt::solve(cliff_problem(false), options);
  INFO(summary.full_report());
  CHECK(summary.outcome == opt::Outcome::kConverged);
  CHECK(summary.x[0] == Approx(opt::test::kOptimumX).margin(1e-5));
  CHECK(summary.x[1] == Approx(opt::test::kOptimumY).margin(1e-5));
}

// Why the global stage exists: the plateau has zero slope, so a local method started
// on it stops at once, on the wrong side of the cliff.
TEST_CASE("without the global stage a local start on the plateau stays on the wrong side of the cliff",
          "[optimizer]") {
  opt::Options options;
  options.global_stage = false;
  const opt::Summary summary = opt::solve(cliff_problem(true), options);
  INFO(summary.full_report());
  CHECK(summary.x[0] < opt::test::kCliffX);
  CHECK(summary.objective == opt::test::kPlateauValue);
  CHECK(summary.global_evaluations == 0);
}

// Ipopt alone is a local method: from a start on the good side it needs no global stage.
TEST_CASE("Ipopt alone converges from a start on the good side of the cliff", "[optimizer]") {
  opt::Problem problem = cliff_problem(true);
  problem.variables[0].initial = 2.5;
  opt::Options options = options_for(opt::Backend::kIpopt);
  options.global_stage = false;
  const opt::Summary summary = opt::solve(problem, options);
  INFO(summary.full_report());
  CHECK(summary.outcome == opt::Outcome::kConverged);
  CHECK(summary.x[0] == Approx(opt::test::kOptimumX).margin(1e-6));
  CHECK(summary.x[1] == Approx(opt::test::kOptimumY).margin(1e-6));
}

TEST_CASE("equal seeds give equal results", "[optimizer]") {
  opt::Options options;
  const opt::Summary first = opt::solve(cliff_problem(true), options);
  const opt::Summary second = opt::solve(cliff_problem(true), options);
  CHECK(first.x == second.x);
  CHECK(first.evaluations == second.evaluations);
}

TEST_CASE("an exception thrown by the objective stops the solver and leaves solve unchanged", "[optimizer]") {
  struct ModelBroke : std::runtime_error {
    using std::runtime_error::runtime_error;
  };
  const auto backend = GENERATE(opt::Backend::kNlopt, opt::Backend::kIpopt);
  const bool in_global_stage = GENERATE(true, false);
  CAPTURE(opt::to_string(backend), in_global_stage);
  opt::Problem problem = cliff_problem(true);
  int calls = 0;
  int calls_after_throw = 0;
  const int throw_at = in_global_stage ? 10 : 2005;
  const opt::ScalarFunction bowl = problem.objective.value;
  problem.objective.value = [&](std::span<const double> x) {
    ++calls;
    if (calls > throw_at) ++calls_after_throw;
    if (calls == throw_at) throw ModelBroke("model broke at call " + std::to_string(calls));
    return bowl(x);
  };
  CHECK_THROWS_AS(opt::solve(problem, options_for(backend)), ModelBroke);
  CHECK(calls_after_throw == 0);
}

TEST_CASE("a NaN from a problem function is reported as std::domain_error naming it", "[optimizer]") {
  opt::Problem problem = cliff_problem(true);
  problem.constraints[0].value = [](std::span<const double>) { return std::nan(""); };
  try {
    opt::solve(problem);
    FAIL("no exception");
  } catch (const std::domain_error& error) {
    CHECK(std::string(error.what()).find("constraint 'cut' returned nan") != std::string::npos);
  }
}

TEST_CASE("a spent evaluation budget is reported as max evaluations", "[optimizer]") {
  const auto backend = GENERATE(opt::Backend::kNlopt, opt::Backend::kIpopt);
  CAPTURE(opt::to_string(backend));
  opt::Options options = options_for(backend);
  options.global_evaluations = 100;
  options.max_evaluations = 106;  // two gradients (3 points each) after the global stage
  const opt::Summary summary = opt::solve(cliff_problem(false), options);
  INFO(summary.full_report());
  CHECK(summary.outcome == opt::Outcome::kMaxEvaluations);
  // Ipopt checks the budget once per iteration: one line search may overshoot it.
  CHECK(summary.evaluations <= options.max_evaluations + 20);
}

TEST_CASE("bounds with lower > upper or NaN are invalid arguments naming the variable", "[optimizer]") {
  opt::Problem problem = cliff_problem(true);
  problem.variables[0].lower = 4.0;
  problem.variables[1].upper = std::numeric_limits<double>::quiet_NaN();
  try {
    opt::solve(problem);
    FAIL("no exception");
  } catch (const std::invalid_argument& error) {
    CHECK(message_has(error, "variable 'x': lower = 4 > upper = 3: must have lower <= upper"));
    CHECK(message_has(error, "variable 'y': upper = nan: must be a number"));
  }
}

TEST_CASE("an initial value outside the bounds and duplicate names are reported", "[optimizer]") {
  opt::Problem problem = cliff_problem(true);
  problem.variables[1].initial = 5.0;
  problem.constraints.push_back(problem.constraints[0]);
  const std::vector<std::string> violations = problem.validate();
  REQUIRE(violations.size() == 2);
  CHECK(violations[0] == "variable 'y': initial = 5: must be finite and in [lower, upper] = [-2, 2]");
  CHECK(violations[1] == "constraint 'cut': name used twice: must be unique");
}

TEST_CASE("the global stage needs finite bounds", "[optimizer]") {
  opt::Problem problem = cliff_problem(true);
  problem.variables[1].upper = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(opt::solve(problem), Catch::Contains("variable 'y': bounds [-2, inf]: must be finite"));
  opt::Options local_only;
  local_only.global_stage = false;
  problem.variables[0].initial = 2.5;
  CHECK(opt::solve(problem, local_only).x[0] == Approx(opt::test::kOptimumX).margin(1e-6));
}

TEST_CASE("a constraint no point in the bounds can meet is an invalid argument naming it", "[optimizer]") {
  const auto backend = GENERATE(opt::Backend::kNlopt, opt::Backend::kIpopt);
  CAPTURE(opt::to_string(backend));
  opt::Problem problem = cliff_problem(true);
  // x + y <= -5 is out of reach in [0, 3] × [-2, 2] (least value of x + y: -2).
  problem.constraints.push_back({"unreachable", [](std::span<const double> x) { return x[0] + x[1] + 5.0; },
                                 [](std::span<const double>, std::span<double> gradient) {
                                   gradient[0] = 1.0;
                                   gradient[1] = 1.0;
                                 }});
  opt::Options options = options_for(backend);
  options.max_evaluations = 3000;
  CHECK_THROWS_WITH(opt::solve(problem, options),
                    Catch::Contains("constraint 'unreachable' cannot be met within the bounds"));
  options.infeasible_is_error = false;
  const opt::Summary summary = opt::solve(problem, options);
  CHECK(summary.outcome == opt::Outcome::kInfeasible);
  // The least violating point is (0, -2): c = 3.
  CHECK(summary.max_constraint_violation == Approx(3.0).margin(1e-3));
}

TEST_CASE("options validation names the field, the value and the rule", "[optimizer]") {
  opt::Options options;
  options.max_evaluations = 1;
  options.relative_tolerance = 0.0;
  const std::vector<std::string> violations = options.validate();
  REQUIRE(violations.size() == 3);
  CHECK(violations[0] == "max_evaluations = 1: must be >= 2");
  CHECK(violations[1] ==
        "global_evaluations = 2000: must be in [1, max_evaluations) (leave evaluations to the local stage)");
  CHECK(violations[2] == "relative_tolerance = 0: must be in (0, 0.1]");
  CHECK_THROWS_AS(opt::solve(cliff_problem(true), options), std::invalid_argument);
}

TEST_CASE("back ends are selected by name", "[optimizer]") {
  CHECK(opt::backend_from_string("nlopt") == opt::Backend::kNlopt);
  CHECK(opt::backend_from_string("ipopt") == opt::Backend::kIpopt);
  CHECK_FALSE(opt::backend_from_string("Ipopt").has_value());
}

// Reference: the rule h = √ε·max(|x|, upper − lower), backwards at the upper bound.
TEST_CASE("the finite-difference step follows the stated rule and stays inside the bounds", "[optimizer]") {
  const double root_epsilon = std::sqrt(std::numeric_limits<double>::epsilon());
  const opt::Variable clearance{"clearance_m", "m", 0.01, 0.05, 0.02};
  CHECK(opt::finite_difference_step(clearance, 0.02) == Approx(root_epsilon * 0.04).epsilon(1e-6));
  CHECK(opt::finite_difference_step(clearance, 0.05) == Approx(-root_epsilon * 0.05).epsilon(1e-6));
  const opt::Variable fixed{"fixed", "", 1.0, 1.0, 1.0};
  CHECK(opt::finite_difference_step(fixed, 1.0) == 0.0);
  const opt::Variable unbounded{"free", "", -std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::infinity(), 0.0};
  CHECK(opt::finite_difference_step(unbounded, 0.0) == Approx(root_epsilon));
}

// Reference: the analytic gradients of the cliff problem; a wrong one must show.
TEST_CASE("check_gradients accepts correct gradients and names a wrong one", "[optimizer]") {
  const std::vector<double> bowl_point{2.0, -0.5};
  opt::GradientCheck check = opt::check_gradients(cliff_problem(true), bowl_point);
  CHECK(check.max_error < 1e-6);
  opt::Problem wrong = cliff_problem(true);
  wrong.constraints[0].gradient = [](std::span<const double>, std::span<double> gradient) {
    gradient[0] = 1.0;
    gradient[1] = 2.0;
  };
  check = opt::check_gradients(wrong, bowl_point);
  CHECK(check.max_error == Approx(0.5).margin(1e-6));
  CHECK(check.worst == "constraint 'cut' d/d(y)");
}
