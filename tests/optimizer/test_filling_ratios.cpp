// Tests of the filling-ratio optimisation of a multi-layer damper (docs/optimizer.md): the
// relaxed solve plus rounded neighbours against an exhaustive integer enumeration, both
// back ends, the single-layer baseline and the validation of the options.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <vector>

#include "pdamp/optimizer/filling_ratios.hpp"

namespace {

namespace opt = pdamp::optimizer;
namespace st = pdamp::structure;
constexpr double kPi = 3.14159265358979323846;

/// One bending mode at 3.6 Hz, ζ = 0.3 %, modal mass 0.9 kg at the tip (about the
/// manipulator link of cases/manipulator_link_decay.json with its end effector).
st::ModalModel one_mode() {
  st::ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 3.6);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.003);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, 0.9);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(1)}};
  return m;
}

/// Steel spheres of 5 mm radius, 4 to a slab, in boxes of the given inner lengths.
opt::FillingRatioOptions layered(const std::vector<double>& lengths_m, double budget_slabs) {
  opt::FillingRatioOptions o;
  const double r = 0.005;
  const double sphere_mass = 7850.0 * 4.0 / 3.0 * kPi * r * r * r;
  for (std::size_t k = 0; k < lengths_m.size(); ++k) {
    opt::LayerCandidate l;
    l.name = "layer_" + std::to_string(k + 1);
    l.inner_length_m = lengths_m[k];
    l.slab_length_m = 2.0 * r;
    l.spheres_per_slab = 4;
    l.sphere_mass_kg = sphere_mass;
    l.cross_section_m2 = 0.041 * 0.012;
    l.sphere_volume_m3 = 4.0 / 3.0 * kPi * r * r * r;
    l.initial_slabs = 1;
    o.layers.push_back(l);
  }
  o.damper.name = "damper";
  o.damper.point = "tip";
  o.damper.drive_direction = {0.0, 1.0};
  o.damper.container_mass_kg = 0.25;
  o.model = pdamp::formulas::DamperModel::kRolling;
  o.decay.initial_modal_amplitudes = Eigen::VectorXd::Constant(1, 0.025);
  o.decay.duration_s = 40.0;
  o.decay.threshold_fraction = 0.05;
  o.mass_budget_kg = budget_slabs * 4 * sphere_mass;
  return o;
}

/// Every integer design within the bounds and the budget, the best by objective.
struct Enumerated {
  std::vector<double> slabs;
  double objective = std::numeric_limits<double>::infinity();
  int points = 0;
};
Enumerated enumerate(const st::ModalModel& model, const opt::FillingRatioOptions& o) {
  Enumerated best;
  std::vector<double> n(o.layers.size(), 0.0);
  const auto next = [&] {
    for (std::size_t k = 0; k < n.size(); ++k) {
      if (n[k] < o.layers[k].max_slabs()) {
        n[k] += 1.0;
        return true;
      }
      n[k] = 0.0;
    }
    return false;
  };
  do {
    double mass = 0.0;
    for (std::size_t k = 0; k < n.size(); ++k) mass += n[k] * o.layers[k].slab_mass_kg();
    if (mass > o.mass_budget_kg * (1.0 + 1e-9)) continue;
    ++best.points;
    const auto d = opt::evaluate_filling_design(model, o, n);
    if (d.objective < best.objective) best.objective = d.objective, best.slabs = n;
  } while (next());
  return best;
}


}  // namespace

TEST_CASE("a layer's bounds keep one slab of travel and its mass and clearance are linear in the slabs", "[optimizer]") {
  // L = 0.07 m, 2r = 0.01 m: 7 slabs fit, at most 6 leave h >= 2r; h(n) = L − 2r n, φ = 2r n/L.
  auto o = layered({0.07, 0.028}, 6.0);
  CHECK(o.layers[0].max_slabs() == 6);
  CHECK(o.layers[1].max_slabs() == 1);
  const std::vector<double> n = {2.5, 1.0};
  const auto damper = opt::filling_damper(o, n);
  REQUIRE(damper.layers.size() == 2);
  CHECK(damper.layers[0].bed_mass_kg == Approx(2.5 * o.layers[0].slab_mass_kg()).epsilon(1e-14));
  const auto d = opt::evaluate_filling_design(one_mode(), o, n);
  CHECK(d.layers[0].clearance_m == Approx(0.045).epsilon(1e-14));
  CHECK(d.layers[0].filling_ratio == Approx(0.025 / 0.07).epsilon(1e-14));
  // An empty layer is left out of the damper (its bed mass would be 0).
  CHECK(opt::filling_damper(o, std::vector<double>{0.0, 1.0}).layers.size() == 1);
}

TEST_CASE("the chosen integer design of two and three layers is the best of an exhaustive enumeration",
          "[optimizer]") {
  // Independent reference: every integer point in the box under the budget (56 and 28
  // points), evaluated by the same free decay. Equal designs, and equal objective to
  // round-off (the same evaluation).
  const auto model = one_mode();
  for (const auto& lengths : std::vector<std::vector<double>>{{0.07, 0.04, 0.028}, {0.06, 0.03}}) {
    const auto o = layered(lengths, 5.0);
    opt::Options solver;
    solver.global_evaluations = 300;
    solver.max_evaluations = 1000;
    const auto result = opt::optimize_filling_ratios(model, o, solver);
    const auto reference = enumerate(model, o);
    INFO("layers " << lengths.size() << ", enumeration of " << reference.points << " points, relaxed objective "
                   << result.relaxed.objective << ", chosen " << result.chosen.objective);
    CHECK(result.chosen.slabs() == reference.slabs);
    CHECK(result.chosen.objective == Approx(reference.objective).epsilon(1e-12));
    CHECK(result.neighbours_feasible >= 1);
    CHECK(result.neighbours_feasible <= result.neighbours_total);
    CHECK(result.chosen.total_mass_kg <= o.mass_budget_kg * (1.0 + 1e-9));
    // The single-layer baseline is one of the enumerated points: never better.
    CHECK(result.baseline.objective >= reference.objective);
  }
}

TEST_CASE("above the enumeration limit the chosen design is the best rounded neighbour of the relaxed optimum",
          "[optimizer]") {
  // The same three layers with max_enumerated_designs = 0: only the floors and ceilings of
  // the relaxed optimum are evaluated (2^F for F fractional counts), the best of them chosen;
  // it is never better than the exhaustive enumeration's best, and the result says which rule
  // chose it.
  const auto model = one_mode();
  auto o = layered({0.07, 0.04, 0.028}, 5.0);
  o.max_enumerated_designs = 0;
  opt::Options solver;
  solver.global_evaluations = 300;
  solver.max_evaluations = 1000;
  const auto result = opt::optimize_filling_ratios(model, o, solver);
  CHECK_FALSE(result.enumerated);
  int fractional = 0;
  for (std::size_t k = 0; k < o.layers.size(); ++k) {
    const double x = result.relaxed.layers[k].slabs;
    if (std::abs(x - std::round(x)) > 1e-6) ++fractional;
    CHECK(std::abs(result.chosen.layers[k].slabs - x) < 1.0);
  }
  CHECK(result.neighbours_total == (1 << fractional));
  for (const auto& n : result.neighbours) CHECK(result.chosen.objective <= n.objective);
  CHECK(result.chosen.objective >= enumerate(model, o).objective);
  o.max_enumerated_designs = opt::FillingRatioOptions::kMaxEnumeratedDesigns + 1;
  CHECK_FALSE(o.validate().empty());
}

TEST_CASE("NLopt and the Ipopt hybrid choose the same integer design", "[optimizer]") {
  const auto model = one_mode();
  const auto o = layered({0.07, 0.04, 0.028}, 5.0);
  opt::Options nlopt;
  nlopt.global_evaluations = 300;
  nlopt.max_evaluations = 1000;
  opt::Options ipopt = nlopt;
  ipopt.backend = opt::Backend::kIpopt;
  const auto a = opt::optimize_filling_ratios(model, o, nlopt);
  const auto b = opt::optimize_filling_ratios(model, o, ipopt);
  INFO("nlopt: " << a.summary.brief_report() << "\nipopt: " << b.summary.brief_report());
  CHECK(a.chosen.slabs() == b.chosen.slabs());
  CHECK(a.summary.backend == opt::Backend::kNlopt);
  CHECK(b.summary.backend == opt::Backend::kIpopt);
}

TEST_CASE("the integral-square objective is minimised too and is half the envelope's square integral",
          "[optimizer]") {
  // A bare structure (no slabs, no container mass) decays as e0·exp(−ζωt):
  // ½∫e² dt = e0²/(4ζω)(1 − exp(−2ζωT)). Trapezoid over 2000 instants of a smooth
  // exponential: 1e-5 relative.
  const auto model = one_mode();
  auto o = layered({0.07, 0.04}, 4.0);
  o.damper.container_mass_kg = 0.0;
  o.objective = opt::FillingObjective::kIntegralSquare;
  o.integral_samples = 2000;
  const auto bare = opt::evaluate_filling_design(model, o, std::vector<double>{0.0, 0.0});
  const double zw = 0.003 * 2.0 * kPi * 3.6, e0 = 0.025, T = 40.0;
  CHECK(bare.integral_square_m2_s == Approx(e0 * e0 / (4.0 * zw) * (1.0 - std::exp(-2.0 * zw * T))).epsilon(1e-5));
  o.integral_samples = 400;
  opt::Options solver;
  solver.global_evaluations = 200;
  solver.max_evaluations = 600;
  const auto result = opt::optimize_filling_ratios(model, o, solver);
  CHECK(result.chosen.objective < bare.integral_square_m2_s);
  CHECK(std::isfinite(result.chosen.integral_square_m2_s));
}

TEST_CASE("invalid filling-ratio options name the field", "[optimizer]") {
  const auto model = one_mode();
  auto o = layered({0.07, 0.04}, 4.0);
  o.mass_budget_kg = 0.5 * o.layers[0].slab_mass_kg();
  CHECK_THROWS_WITH(opt::optimize_filling_ratios(model, o), Catch::Contains("mass_budget_kg") &&
                                                                 Catch::Contains("lightest slab"));
  o = layered({0.07, 0.015}, 4.0);
  CHECK_THROWS_WITH(opt::optimize_filling_ratios(model, o), Catch::Contains("layers[1].inner_length_m"));
  o = layered({0.07}, 4.0);
  o.layers[0].initial_slabs = 9;
  CHECK_THROWS_WITH(opt::optimize_filling_ratios(model, o), Catch::Contains("layers[0].initial_slabs = 9"));
}

// Reference: the enumeration of the test above with the calibrated beds, and each bed's model
// evaluated directly. Beds whose models are the closed forms of another friction (so that
// the calibrated designs differ from the closed forms' own): the optimiser must choose by
// the given models, over every whole-slab design under the budget.
TEST_CASE("with calibrated beds every whole-slab design is evaluated on its own bed's model", "[optimizer]") {
  const auto model = one_mode();
  auto o = layered({0.07, 0.04, 0.028}, 5.0);
  auto options = o.model_options;
  options.scattered.jump_fraction = 0.0;  // no dissipation below the onset: another bed
  options.scattered.exponent = 2.0;
  options.scattered.provisional = false;
  o.bed_models.resize(o.layers.size());
  for (std::size_t k = 0; k < o.layers.size(); ++k)
    for (int n = 0; n <= o.layers[k].max_slabs(); ++n)
      o.bed_models[k].push_back(n == 0 ? nullptr
                                       : std::make_shared<pdamp::surrogate::ClosedFormLossModel>(
                                             o.model, o.layers[k].clearance_m(n), options));
  const auto result = opt::optimize_filling_ratios(model, o);
  const auto reference = enumerate(model, o);
  CHECK(result.chosen.slabs() == reference.slabs);
  CHECK(result.chosen.objective == reference.objective);
  CHECK(result.neighbours_feasible == reference.points);
  CHECK(result.relaxed.slabs() == reference.slabs);
  // The damper of a design carries the calibrated bed itself.
  const auto damper = opt::filling_damper(o, std::vector<double>{2.0, 0.0, 1.0});
  REQUIRE(damper.layers.size() == 2);
  CHECK(damper.layers[0].loss_model == o.bed_models[0][2]);
  CHECK(damper.layers[1].loss_model == o.bed_models[2][1]);
  // Calibrated beds exist at whole slabs only.
  CHECK_THROWS_WITH(opt::filling_damper(o, std::vector<double>{1.5, 0.0, 0.0}), Catch::Contains("whole slabs only"));
  // A missing bed is refused by name.
  o.bed_models[1].pop_back();
  CHECK_THROWS_WITH(opt::optimize_filling_ratios(model, o), Catch::Contains("bed_models[1]"));
}
