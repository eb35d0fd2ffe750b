// The design studies as library calls, without the binary: the filling ratios of the shipped
// optimisation (the closed forms only) and the placement of the shipped beam case.
#include <catch2/catch.hpp>

#include <cmath>

#include "cli/cli_support.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/placement.hpp"

using namespace pdamp;
using test::case_path;

// Reference: the optimiser's own scoring (evaluate_filling_design) of the chosen slabs, and
// the budget. The comparison decay of the chosen design is the same free decay sampled more
// densely: its settling time is the design's (the settling instant is found by bisection,
// not on the samples), to the bisection's tolerance.
TEST_CASE("filling ratios: the chosen design is within the budget and its decay is the optimiser's", "[tasks]") {
  const auto c = case_file::load_case(case_path("manipulator_link_optimize.json"));
  tasks::FillingRatiosOptions options;
  options.skip_verify = true;
  const auto r = tasks::run_filling_ratios(c, options, tasks::silent_hooks(), tasks::local_executor());
  CHECK_FALSE(r.verification.has_value());
  const auto& chosen = r.optimum.chosen;
  CHECK(chosen.total_mass_kg <= r.mass_budget_kg * (1.0 + 1e-9));
  for (const auto& l : chosen.layers) CHECK(l.slabs == std::round(l.slabs));
  const auto again = optimizer::evaluate_filling_design(r.problem.modal, r.problem.options, tasks::slabs_of(chosen));
  CHECK(again.objective == chosen.objective);
  REQUIRE(r.comparison.decays.size() == 3);
  CHECK(r.comparison.decays[0].settling_time_s == Approx(chosen.settling_time_s).epsilon(1e-6));
  CHECK(r.comparison.decays[1].settling_time_s == Approx(r.optimum.baseline.settling_time_s).epsilon(1e-6));
  // The references: without particles only the structure damps (its decay is slower than
  // any design's); the same mass in one compartment is scored at its own best clearance.
  CHECK(r.optimum.bare.total_mass_kg == 0.0);
  CHECK(r.optimum.bare.objective > chosen.objective);
  CHECK(r.optimum.bare.objective > r.optimum.baseline.objective);
  CHECK(r.optimum.same_mass.total_mass_kg == chosen.total_mass_kg);
  // Its clearance is searched from one sphere diameter of travel (the candidates' smallest)
  // up: nearby clearances inside that range are no better.
  const double h = r.optimum.same_mass.layers.front().clearance_m;
  double smallest = INFINITY;
  for (const auto& l : r.problem.options.layers) smallest = std::min(smallest, l.slab_length_m);
  CHECK(h >= smallest * (1.0 - 1e-12));
  for (const double factor : {0.95, 1.05}) {
    if (h * factor < smallest) continue;
    double particles = 0.0;
    for (const auto& l : chosen.layers) particles += l.particles;
    const auto nearby = optimizer::evaluate_single_compartment(r.problem.modal, r.problem.options, chosen.total_mass_kg,
                                                               particles, h * factor);
    CHECK(nearby.objective >= r.optimum.same_mass.objective);
  }
  const auto j = tasks::to_json(r);
  CHECK(j["verification"].is_null());
  CHECK(j["designs"]["same_mass"]["layers"][0]["slabs"].is_null());
  CHECK(j["design"]["total_mass_kg"] == chosen.total_mass_kg);
}

// Reference: the scan evaluates sites and the refinement only improves on the best of them;
// the case's own site is one of the candidates the search may choose.
TEST_CASE("placement: the chosen site damps at least as much as every scanned site and the case's own", "[tasks]") {
  const auto c = case_file::load_case(case_path("free_free_beam_placement.json"));
  const auto s = tasks::run_placement(c, {});
  const auto& r = s.result;
  for (const auto& p : r.scan) CHECK(r.best.objective >= p.objective);
  REQUIRE(r.current.has_value());
  CHECK(r.best.objective >= r.current->objective);
  CHECK(tasks::to_json(s)["design"]["objective"] == r.best.objective);
}
