// Tests of damper placement (docs/optimizer.md, "Placement") against analytic beam modes: the sine modes of
// a pinned-pinned beam, the tip slope of a cantilever, and a brute-force scan of the closed
// forms on those analytic shapes.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/optimizer/placement.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace {

using namespace pdamp::optimizer;
namespace st = pdamp::structure;
namespace sg = pdamp::surrogate;
namespace fm = pdamp::formulas;
constexpr double kPi = 3.14159265358979323846;

/// Constant η* and apparent mass: ζ_add then follows the mode shape alone.
class ConstantLoss final : public sg::LossModel {
 public:
  explicit ConstantLoss(double eta) : eta_(eta) {}
  sg::DamperResponse evaluate(double, double) const override {
    sg::DamperResponse r;
    r.eta_star = eta_;
    r.apparent_mass_fraction = 1.0;
    return r;
  }
  sg::StrokeRange stroke_range_m(double) const override { return {1e-9, 1.0}; }

 private:
  double eta_;
};

constexpr double kLength = 2.0;         // m
constexpr double kWidth = 0.04;         // m, out of plane
constexpr double kDepth = 0.01;         // m, in plane
constexpr double kDensity = 7850.0;     // kg/m³
constexpr double kModulus = 206e9;      // Pa
constexpr double kBedMass = 1e-3;       // kg: μ ~ 3e-4, so ζ_add = ½η*μ to that order

st::BeamModel steel_beam(double length, int elements) {
  st::BeamModel beam;
  st::BeamSegment segment;
  segment.length_m = length;
  segment.section.shape = st::SectionShape::kSolidRectangle;
  segment.section.width_m = kWidth;
  segment.section.depth_m = kDepth;
  segment.material = {kModulus, kDensity};
  segment.elements = elements;
  beam.segments.push_back(segment);
  return beam;
}

/// Pinned at both ends, points at L/2 and L/4 (the antinodes of modes 1 and 2).
BeamPlacement pinned_beam() {
  BeamPlacement p;
  p.beam = steel_beam(kLength, 40);
  p.beam.supports.push_back({st::Support::Kind::kPinned, 0.0, 0.0, 0.0, 0.0});
  p.beam.supports.push_back({st::Support::Kind::kPinned, kLength, 0.0, 0.0, 0.0});
  p.beam.points.push_back({"middle", 0.5 * kLength});
  p.beam.points.push_back({"quarter", 0.25 * kLength});
  p.mode_count = 2;
  p.damping.ratios = {0.001};
  p.min_position_m = 0.0;
  p.max_position_m = 0.5 * kLength;  // the modes are symmetric: the twin optimum is L − x
  return p;
}

PlacementOptions placement(std::shared_ptr<const sg::LossModel> loss, double a1, double a2) {
  PlacementOptions o;
  o.damper.name = std::string_view("placed");  // GCC 12 warns falsely (-Wrestrict) on = "literal" here
  o.damper.drive_direction = {0.0, 1.0};
  o.damper.layers.push_back({"bed", kBedMass, std::move(loss)});
  o.targets.push_back({0, 1.0, "middle", a1});
  o.targets.push_back({1, 1.0, "quarter", a2});
  return o;
}

/// Mass-normalised sine mode j (1-based) of the pinned-pinned beam: √(2/(ρAL)) sin(jπx/L).
double sine_mode(int j, double x) {
  return std::sqrt(2.0 / (kDensity * kWidth * kDepth * kLength)) * std::sin(j * kPi * x / kLength);
}

}  // namespace

// Reference: with a constant η* and a light bed, ζ_add,j = ½ η* m_bed φ_j(x)², so the mean
// of modes 1 and 2 is largest where sin²u + sin²2u is, u = πx/L: sin 2u (1 + 4 cos 2u) = 0,
// cos 2u = −1/4, x/L = arccos(−1/4)/(2π) = 0.29021. Tolerances: the position to 1e-3 L (the
// refinement stops at 1e-4 of a 0.01 L bracket; the 40-element shapes are exact to ~1e-6),
// the value to 1e-3 (the bed's own mass, μ ~ 3e-4, and the FE shapes).
TEST_CASE("placement on a pinned-pinned beam finds the analytic compromise of modes 1 and 2", "[optimizer]") {
  const double eta = 0.5;
  const BeamPlacement beam = pinned_beam();
  const PlacementOptions options = placement(std::make_shared<ConstantLoss>(eta), 0.01, 0.01);
  const double expected = std::acos(-0.25) / (2.0 * kPi) * kLength;
  const double u = kPi * expected / kLength;
  const double expected_value =
      0.5 * eta * kBedMass * 0.5 * (sine_mode(1, expected) * sine_mode(1, expected) + sine_mode(2, expected) * sine_mode(2, expected));
  REQUIRE(std::pow(std::sin(u), 2) + std::pow(std::sin(2 * u), 2) == Approx(1.5625).epsilon(1e-12));

  for (const Backend backend : {Backend::kNlopt, Backend::kIpopt}) {
    Options solver = placement_solver_options();
    solver.backend = backend;
    const PlacementResult r = optimize_placement_on_beam(beam, options, solver, 0.5 * kLength);
    INFO("backend " << to_string(backend) << ", x = " << r.best.position_m);
    CHECK(r.best.position_m == Approx(expected).margin(1e-3 * kLength));
    CHECK(r.best.objective == Approx(expected_value).epsilon(1e-3));
    CHECK(r.refined);
    CHECK(r.scan.size() == 101u);
    // The middle is mode 2's node: half the damping of the compromise there (1 against 1.5625).
    REQUIRE(r.current.has_value());
    CHECK(r.current->modes[1].damper_amplitude_m == Approx(0.0).margin(1e-12));
    CHECK(r.current->objective / r.best.objective == Approx(1.0 / 1.5625).epsilon(1e-3));
  }
}

// Reference: the same modes written analytically, η* from formulas::reduced_loss_factor at
// the strokes X_j(x) = |φ_j(x)|·A_j/|φ_j(ref)|, ζ_add,j = ½η*m_bed φ_j², scanned on 24001
// points of [0, L/2]: an independent brute force of the objective with the cliff of mode 2
// (its stroke falls below the rolling onset near mode 2's node at L/2). Tolerances as above,
// the value to 5e-3 (the optimum sits next to a cliff, where 1e-3 L moves it by that much).
TEST_CASE("placement with the closed forms matches a brute-force scan over the onset cliff", "[optimizer]") {
  const double clearance = 0.01;
  const double a1 = 0.010, a2 = 0.005;  // mode 1 at L/2, mode 2 at L/4: X from 0 to 2.6 h
  const BeamPlacement beam = pinned_beam();
  const PlacementOptions options =
      placement(std::make_shared<sg::ClosedFormLossModel>(fm::DamperModel::kRolling, clearance), a1, a2);

  double best_x = 0.0, best_value = -1.0;
  const int n = 24001;
  for (int i = 0; i < n; ++i) {
    const double x = 0.5 * kLength * i / (n - 1);
    double value = 0.0;
    for (int j = 1; j <= 2; ++j) {
      const double reference = std::abs(sine_mode(j, j == 1 ? 0.5 * kLength : 0.25 * kLength));
      const double stroke = std::abs(sine_mode(j, x)) * (j == 1 ? a1 : a2) / reference;
      if (stroke <= 0.0) continue;
      const double eta = fm::reduced_loss_factor(fm::DamperModel::kRolling, clearance, stroke, 10.0).eta_star;
      value += 0.5 * 0.5 * eta * kBedMass * sine_mode(j, x) * sine_mode(j, x);
    }
    if (value > best_value) best_value = value, best_x = x;
  }
  const PlacementResult r = optimize_placement_on_beam(beam, options, placement_solver_options());
  INFO("brute force x = " << best_x << ", placement x = " << r.best.position_m);
  CHECK(r.best.position_m == Approx(best_x).margin(1e-3 * kLength));
  CHECK(r.best.objective == Approx(best_value).epsilon(5e-3));
  // The brute force's optimum is not mode 1's antinode: the cliff matters.
  CHECK(std::abs(best_x - 0.5 * kLength) > 0.05 * kLength);
}

// Reference: a cantilever's mode shape φ = cosh βx − cos βx − σ(sinh βx − sin βx),
// σ = (cosh βL + cos βL)/(sinh βL + sin βL): at the tip the container's ends move by
// |φ'(L)|·L_c/2 against the stroke |φ(L)|. With L_c = L/10 mode 1 stays below 10 % (6.9 %)
// and mode 2 is flagged. Tolerance 1e-4: 40 Hermite elements give the shapes far better.
TEST_CASE("placement flags the rotation at a cantilever's tip as the analytic mode shapes give it", "[optimizer]") {
  const double length = 1.0;
  BeamPlacement beam;
  beam.beam = steel_beam(length, 40);
  beam.beam.supports.push_back({st::Support::Kind::kClamped, 0.0, 0.0, 0.0, 0.0});
  beam.beam.points.push_back({"tip", length});
  beam.mode_count = 2;
  beam.damping.ratios = {0.001};
  PlacementOptions options = placement(std::make_shared<ConstantLoss>(0.5), 0.01, 0.01);
  options.targets[0].reference_point = "tip";
  options.targets[1].reference_point = "tip";
  options.damper.length_along_drive_m = 0.1 * length;
  const PlacementPoint p = evaluate_placement(beam_model_with_site(beam, length, "site"), "site", options);
  for (int j = 0; j < 2; ++j) {
    const double bl = j == 0 ? 1.875104068711961 : 4.694091132974175;
    const double sigma = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
    const double shape = std::cosh(bl) - std::cos(bl) - sigma * (std::sinh(bl) - std::sin(bl));
    const double slope = (bl / length) * (std::sinh(bl) + std::sin(bl) - sigma * (std::cosh(bl) - std::cos(bl)));
    const double expected = std::abs(slope) * 0.05 * length / std::abs(shape);
    CHECK(p.modes[static_cast<std::size_t>(j)].rotation_ratio == Approx(expected).epsilon(1e-4));
  }
  CHECK_FALSE(p.modes[0].rotation_flagged);
  CHECK(p.modes[1].rotation_flagged);

  // The tip is where both modes damp most; the chosen site there carries the warning.
  beam.min_position_m = 0.1 * length;
  beam.max_position_m = length;
  const PlacementResult r = optimize_placement_on_beam(beam, options, placement_solver_options());
  CHECK(r.best.position_m == Approx(length).margin(1e-9));
  REQUIRE(r.warnings.size() == 1u);
  CHECK(r.warnings[0].find("mode 2") != std::string::npos);  // the second mode, counted from 1
  CHECK(r.warnings[0].find("rotates") != std::string::npos);
}

// Reference: the backbone's single-mode formula with one point and one layer,
// ζ_add = b²η*m_bed/(2(m_j + m_c b² + m_app b²)), exact (the fixed point converges in one
// step for a frequency-independent loss); the largest |b| wins.
TEST_CASE("placement among named points of modal data takes the largest added damping", "[optimizer]") {
  st::ModalModel m;
  m.natural_frequencies_hz = Eigen::Vector2d(10.0, 30.0);
  m.damping_ratios = Eigen::Vector2d(0.01, 0.01);
  m.modal_masses_kg = Eigen::Vector2d(2.0, 3.0);
  Eigen::MatrixXd a(2, 2), b(2, 2), c(2, 2);
  a << 0.0, 0.0, 0.8, -0.2;   // large in mode 0, small in mode 1
  b << 0.0, 0.0, 0.5, 0.6;    // moderate in both
  c << 0.3, 0.0, 1.0, 0.0;    // reference: moves in mode 0 only along y and x
  m.points = {{"a", a, Eigen::RowVector2d::Zero()}, {"b", b, Eigen::RowVector2d::Zero()},
              {"ref", c, Eigen::RowVector2d::Zero()}};
  PlacementOptions options = placement(std::make_shared<ConstantLoss>(0.8), 0.01, 0.01);
  options.damper.point = "a";
  options.damper.container_mass_kg = 0.1;
  options.targets = {{0, 1.0, "ref", 0.01}};
  const PlacementResult r = optimize_placement_at_points(m, {"a", "b"}, options);
  REQUIRE(r.scan.size() == 2u);
  for (const auto& p : r.scan) {
    const double bj = p.site == "a" ? 0.8 : 0.5;
    const double zeta = bj * bj * 0.8 * kBedMass / (2.0 * (2.0 + 0.1 * bj * bj + kBedMass * bj * bj));
    CHECK(p.modes[0].added_damping_ratio == Approx(zeta).epsilon(1e-12));
    CHECK(p.modes[0].damper_amplitude_m == Approx(bj * 0.01 / std::hypot(0.3, 1.0)).epsilon(1e-12));
  }
  CHECK(r.best.site == "a");
  REQUIRE(r.current.has_value());
  CHECK(r.current->site == "a");

  // Mode 1 as the only target: b moves more there.
  options.targets = {{1, 1.0, "a", 0.01}};
  CHECK(optimize_placement_at_points(m, {"a", "b"}, options).best.site == "b");
  // The worst-mode objective over both modes: a gives mode 1 little, b serves both.
  options.targets = {{0, 1.0, "b", 0.01}, {1, 1.0, "b", 0.01}};
  options.objective = PlacementObjective::kWorstMode;
  CHECK(optimize_placement_at_points(m, {"a", "b"}, options).best.site == "b");
}

TEST_CASE("placement refuses bad targets naming the field and the rule", "[optimizer]") {
  st::ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 10.0);
  m.damping_ratios = Eigen::VectorXd::Constant(1, 0.01);
  m.modal_masses_kg = Eigen::VectorXd::Ones(1);
  Eigen::MatrixXd a(2, 1), z(2, 1);
  a << 0.0, 1.0;
  z << 0.0, 0.0;
  m.points = {{"a", a, Eigen::RowVectorXd::Zero(1)}, {"node", z, Eigen::RowVectorXd::Zero(1)}};
  PlacementOptions options = placement(std::make_shared<ConstantLoss>(0.5), 0.01, 0.01);
  options.targets = {{0, 1.0, "a", 0.01}};

  auto bad = options;
  bad.targets[0].reference_amplitude_m = -1.0;
  CHECK_THROWS_WITH(evaluate_placement(m, "a", bad), Catch::Contains("targets[0].reference_amplitude_m = -1: must be > 0"));
  bad = options;
  bad.targets.push_back(bad.targets[0]);
  CHECK_THROWS_WITH(evaluate_placement(m, "a", bad), Catch::Contains("targets[1].mode = 0: must differ from targets[0].mode"));
  bad = options;
  bad.targets[0].mode = 3;
  CHECK_THROWS_WITH(evaluate_placement(m, "a", bad), Catch::Contains("targets[0].mode = 3: must be < the model's 1 modes"));
  bad = options;
  bad.targets[0].reference_point = "node";
  CHECK_THROWS_WITH(evaluate_placement(m, "a", bad), Catch::Contains("does not move in mode 0"));
  CHECK_THROWS_AS(evaluate_placement(m, "nowhere", options), std::invalid_argument);
  bad = options;
  bad.targets[0].weight = 0.0;
  CHECK_THROWS_WITH(evaluate_placement(m, "a", bad), Catch::Contains("the weights sum to 0"));

  BeamPlacement beam = pinned_beam();
  beam.max_position_m = 3.0 * kLength;
  CHECK_THROWS_WITH(optimize_placement_on_beam(beam, placement(std::make_shared<ConstantLoss>(0.5), 0.01, 0.01),
                                               placement_solver_options()),
                    Catch::Contains("must satisfy 0 <= min < max <= the beam's length 2 m"));
}
