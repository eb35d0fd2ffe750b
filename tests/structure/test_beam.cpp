// Tests of the planar Euler-Bernoulli beam model: eigenfrequencies against closed forms,
// mass normalisation, base participation, static deflection, gravity's geometric stiffness.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/damper_coupling.hpp"

namespace {

using namespace pdamp::structure;

constexpr double kPi = 3.14159265358979323846;
constexpr double kYoungsModulusPa = 210e9;
constexpr double kDensityKgM3 = 7800.0;
constexpr double kLengthM = 1.0;

/// A slender steel strip, 20 mm wide and 5 mm deep (in plane): its bending modes lie far
/// below its axial ones (4.2 Hz vs 1.3 kHz for a cantilever).
Section strip() {
  Section s;
  s.width_m = 0.02;
  s.depth_m = 0.005;
  return s;
}

BeamModel uniform_beam(int elements, std::vector<Support> supports, Section section = strip(),
                       double density_kg_m3 = kDensityKgM3) {
  BeamModel beam;
  BeamSegment segment;
  segment.length_m = kLengthM;
  segment.section = section;
  segment.material.youngs_modulus_pa = kYoungsModulusPa;
  segment.material.density_kg_m3 = density_kg_m3;
  segment.elements = elements;
  beam.segments = {segment};
  beam.supports = std::move(supports);
  beam.points = {{"tip", kLengthM}};
  return beam;
}

Support support(Support::Kind kind, double position_m) {
  Support s;
  s.kind = kind;
  s.position_m = position_m;
  return s;
}

Support spring(double position_m, double axial_n_m, double transverse_n_m, double rotational_n_m_rad) {
  Support s = support(Support::Kind::kSpring, position_m);
  s.axial_stiffness_n_m = axial_n_m;
  s.transverse_stiffness_n_m = transverse_n_m;
  s.rotational_stiffness_n_m_rad = rotational_n_m_rad;
  return s;
}

double bending_rigidity(const Section& s = strip()) { return kYoungsModulusPa * s.second_moment_m4(); }
double mass_per_length(const Section& s = strip(), double density = kDensityKgM3) { return density * s.area_m2(); }

/// Euler-Bernoulli bending frequency f = (βL)²/(2π L²) √(EI/ρA).
double bending_frequency_hz(double beta_l) {
  return beta_l * beta_l / (2.0 * kPi * kLengthM * kLengthM) * std::sqrt(bending_rigidity() / mass_per_length());
}

/// Root of f in [low, high] by bisection (f changes sign there), independent of the FE code.
double bisect(const std::function<double(double)>& f, double low, double high) {
  REQUIRE(f(low) * f(high) < 0.0);
  for (int i = 0; i < 200 && high - low > 1e-14 * high; ++i) {
    const double middle = 0.5 * (low + high);
    (f(low) * f(middle) <= 0.0 ? high : low) = middle;
  }
  return 0.5 * (low + high);
}

ModalDamping no_damping() { return ModalDamping{}; }

}  // namespace

TEST_CASE("section areas and second moments match their closed forms", "[structure]") {
  Section hollow_rectangle;
  hollow_rectangle.shape = SectionShape::kHollowRectangle;
  hollow_rectangle.width_m = 0.04;
  hollow_rectangle.depth_m = 0.06;
  hollow_rectangle.wall_thickness_m = 0.005;
  // Outer 40 x 60 mm minus inner 30 x 50 mm.
  CHECK(hollow_rectangle.area_m2() == Approx(0.04 * 0.06 - 0.03 * 0.05).epsilon(1e-14));
  CHECK(hollow_rectangle.second_moment_m4() ==
        Approx((0.04 * std::pow(0.06, 3) - 0.03 * std::pow(0.05, 3)) / 12.0).epsilon(1e-14));

  Section tube;
  tube.shape = SectionShape::kHollowCircle;
  tube.diameter_m = 0.05;
  tube.wall_thickness_m = 0.002;
  CHECK(tube.area_m2() == Approx(kPi / 4.0 * (0.05 * 0.05 - 0.046 * 0.046)).epsilon(1e-14));
  CHECK(tube.second_moment_m4() == Approx(kPi / 64.0 * (std::pow(0.05, 4) - std::pow(0.046, 4))).epsilon(1e-14));

  Section rod;
  rod.shape = SectionShape::kSolidCircle;
  rod.diameter_m = 0.01;
  CHECK(rod.second_moment_m4() == Approx(kPi * 1e-8 / 64.0).epsilon(1e-14));
  CHECK(strip().second_moment_m4() == Approx(0.02 * std::pow(0.005, 3) / 12.0).epsilon(1e-14));
}

TEST_CASE("beam validation names the field, the value and the rule", "[structure]") {
  BeamModel beam = uniform_beam(10, {support(Support::Kind::kClamped, 0.0)});
  REQUIRE(beam.validate().empty());

  SECTION("a hollow wall must be thinner than half the smallest outer size") {
    Section tube;
    tube.shape = SectionShape::kHollowCircle;
    tube.diameter_m = 0.02;
    tube.wall_thickness_m = 0.01;
    beam.segments[0].section = tube;
    const auto problems = beam.validate();
    REQUIRE(problems.size() == 1);
    CHECK(problems[0] == "segments/0/section/wall_thickness_m = 0.01: must be in [1e-05, 0.01) m (half the smallest outer size)");
  }
  SECTION("lengths, element counts, positions, stiffnesses and names") {
    beam.segments.push_back(beam.segments[0]);
    beam.segments[1].length_m = -0.5;
    beam.segments[1].elements = 0;
    beam.supports.push_back(spring(0.25, -1.0, 0.0, 0.0));
    beam.supports.push_back(support(Support::Kind::kPinned, 0.5));
    beam.supports.back().transverse_stiffness_n_m = 1.0;
    beam.point_masses.push_back({"tip", 0.75, 1.0, 0.0});
    const auto problems = beam.validate();
    const auto has = [&](const std::string& text) {
      return std::any_of(problems.begin(), problems.end(), [&](const std::string& p) { return p == text; });
    };
    CHECK(has("segments/1/length_m = -0.5: must be in [0.0001, 10000] m"));
    CHECK(has("segments/1/elements = 0: must be in [1, 500]"));
    CHECK(has("supports/1/axial_stiffness_n_m = -1: must be in [0, 1e+15] "));
    CHECK(has("supports/2/transverse_stiffness_n_m = 1: only spring supports take stiffnesses, must be 0"));
    CHECK(has("points/0/name = \"tip\": must be unique among point masses and named points"));
    // The total length is now 0.5 m: the named point at 1 m is off the beam.
    CHECK(has("points/0/position_m = 1: must be in [0, 0.5] m (on the beam)"));
    CHECK(has("point_masses/0/position_m = 0.75: must be in [0, 0.5] m (on the beam)"));
    CHECK(problems.size() == 7);
  }
  SECTION("an invalid beam is refused by the modal reduction") {
    beam.segments[0].material.density_kg_m3 = std::nan("");
    CHECK_THROWS_WITH(beam_modal_model(beam, 1, no_damping()),
                      Catch::StartsWith("beam model: segments/0/material/density_kg_m3 = nan: must be > 0"));
  }
}

// Reference: Euler-Bernoulli cantilever, β_nL = 1.875104, 4.694091, 7.854757 (Blevins,
// Formulas for Natural Frequency and Mode Shape, table 8-1). Hermite elements converge as
// h⁴ in ω: with 20 elements the third mode is within ~1e-5, so 0.1% is a wide margin.
TEST_CASE("cantilever bending frequencies are within 0.1% of beta_n L = 1.875, 4.694, 7.855", "[structure]") {
  const auto result = beam_modal_model(uniform_beam(20, {support(Support::Kind::kClamped, 0.0)}), 3, no_damping());
  CHECK(result.rigid_modes_dropped == 0);
  const double beta_l[] = {1.875104, 4.694091, 7.854757};
  for (int j = 0; j < 3; ++j) {
    INFO("mode " << j);
    CHECK(result.modal.natural_frequencies_hz[j] == Approx(bending_frequency_hz(beta_l[j])).epsilon(1e-3));
  }
  CHECK(result.modal.validate().empty());
  // Sign rule: the largest translation of each mode (here the tip's y) is positive.
  for (int j = 0; j < 3; ++j) CHECK(result.modal.point("tip").translation(1, j) > 0.0);
}

// Reference: free-free beam β_nL = 4.730041, 7.853205 (Blevins table 8-1). The plane has
// three rigid-body modes (axial translation, transverse translation, rotation).
TEST_CASE("a free-free beam drops three rigid modes and bends at beta_n L = 4.730, 7.853", "[structure]") {
  const auto result = beam_modal_model(uniform_beam(20, {}), 2, no_damping());
  CHECK(result.rigid_modes_dropped == 3);
  CHECK(result.modal.natural_frequencies_hz[0] == Approx(bending_frequency_hz(4.730041)).epsilon(1e-3));
  CHECK(result.modal.natural_frequencies_hz[1] == Approx(bending_frequency_hz(7.853205)).epsilon(1e-3));
}

// Reference: pinned-pinned beam β_nL = nπ. Same mesh argument as the cantilever.
TEST_CASE("pinned-pinned bending frequencies are within 0.1% of beta_n L = n pi", "[structure]") {
  const auto result = beam_modal_model(
      uniform_beam(20, {support(Support::Kind::kPinned, 0.0), support(Support::Kind::kPinned, kLengthM)}), 3,
      no_damping());
  CHECK(result.rigid_modes_dropped == 0);
  for (int n = 1; n <= 3; ++n) {
    CHECK(result.modal.natural_frequencies_hz[n - 1] == Approx(bending_frequency_hz(n * kPi)).epsilon(1e-3));
  }
}

// Reference: the clamped-free frequency equation with a tip mass M and rotary inertia J
// (Laura, Pombo & Susemihl 1974, J. Sound Vib. 37:161), α = M/(ρAL), κ = J/(ρAL³):
// 1 + cos λ cosh λ + αλ(cos λ sinh λ − sin λ cosh λ) − κλ³(cosh λ sin λ + sinh λ cos λ)
//   + ακλ⁴(1 − cos λ cosh λ) = 0,
// solved here by bisection. 20 elements: FE error ~1e-5, tolerance 0.1%.
TEST_CASE("a cantilever with a tip mass and rotary inertia matches its frequency equation", "[structure]") {
  const double beam_mass = mass_per_length() * kLengthM;
  const auto frequency_equation = [](double mass_ratio, double inertia_ratio) {
    return [=](double x) {
      const double c = std::cos(x), s = std::sin(x), ch = std::cosh(x), sh = std::sinh(x);
      return 1.0 + c * ch + mass_ratio * x * (c * sh - s * ch) - inertia_ratio * x * x * x * (ch * s + sh * c) +
             mass_ratio * inertia_ratio * std::pow(x, 4) * (1.0 - c * ch);
    };
  };
  const auto fe_frequency = [&](double mass_kg, double inertia_kg_m2) {
    BeamModel beam = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)});
    beam.points.clear();
    beam.point_masses = {{"container", kLengthM, mass_kg, inertia_kg_m2}};
    return beam_modal_model(beam, 1, no_damping()).modal.natural_frequencies_hz[0];
  };

  const double mass_ratio = 0.5;
  const double point_mass_only = bisect(frequency_equation(mass_ratio, 0.0), 0.5, 1.875);
  const double f_point_mass = fe_frequency(mass_ratio * beam_mass, 0.0);
  CHECK(f_point_mass == Approx(bending_frequency_hz(point_mass_only)).epsilon(1e-3));

  // A container of 10% of the beam length radius of gyration: κ = α·0.1².
  const double inertia_ratio = mass_ratio * 0.01;
  const double with_inertia = bisect(frequency_equation(mass_ratio, inertia_ratio), 0.5, point_mass_only);
  const double f_with_inertia = fe_frequency(mass_ratio * beam_mass, inertia_ratio * beam_mass * kLengthM * kLengthM);
  CHECK(f_with_inertia == Approx(bending_frequency_hz(with_inertia)).epsilon(1e-3));
  // The rotary inertia lowers the frequency (by 0.7%, seven times the tolerance above).
  CHECK(f_with_inertia < 0.995 * f_point_mass);
}

// Very stiff springs approach the ideal supports. A spring k = 1e6·EI/L³ (EI/L for
// rotation) leaves a relative flexibility of 1e-6, amplified by the mode's curvature at
// the support, ~(β_nL)⁴/2: at most ~1e-4 for the second mode (measured 7e-5), within 0.1%.
TEST_CASE("very stiff spring supports reproduce clamped and pinned frequencies", "[structure]") {
  const double ei = bending_rigidity();
  const double stiff = 1e6;
  SECTION("clamped") {
    const auto result = beam_modal_model(
        uniform_beam(20, {spring(0.0, stiff * ei / kLengthM / kLengthM, stiff * ei / std::pow(kLengthM, 3), stiff * ei / kLengthM)}),
        2, no_damping());
    CHECK(result.rigid_modes_dropped == 0);
    CHECK(result.modal.natural_frequencies_hz[0] == Approx(bending_frequency_hz(1.875104)).epsilon(1e-3));
    CHECK(result.modal.natural_frequencies_hz[1] == Approx(bending_frequency_hz(4.694091)).epsilon(1e-3));
  }
  SECTION("pinned") {
    const double k = stiff * ei / std::pow(kLengthM, 3);
    const auto result = beam_modal_model(uniform_beam(20, {spring(0.0, k, k, 0.0), spring(kLengthM, 0.0, k, 0.0)}), 2,
                                         no_damping());
    CHECK(result.modal.natural_frequencies_hz[0] == Approx(bending_frequency_hz(kPi)).epsilon(1e-3));
    CHECK(result.modal.natural_frequencies_hz[1] == Approx(bending_frequency_hz(2.0 * kPi)).epsilon(1e-3));
  }
}

// A stiff beam (20 x 50 mm, first free bending mode 270 Hz) on soft springs moves as a
// rigid body: axial √(k_a/m), bounce √(2k/m), pitch √(2k(L/2)²/(mL²/12)) = √(6k/m).
// The beam's flexibility shifts these by ~(ω/ω_bend)² ≈ 1e-5: tolerance 1e-4.
TEST_CASE("a stiff beam on soft springs has the rigid-body frequencies sqrt(k/m)", "[structure]") {
  Section block;
  block.width_m = 0.02;
  block.depth_m = 0.05;
  const double mass = mass_per_length(block) * kLengthM;
  const double k = 100.0;
  const double k_axial = 50.0;
  const auto result = beam_modal_model(uniform_beam(20, {spring(0.0, k_axial, k, 0.0), spring(kLengthM, 0.0, k, 0.0)}, block),
                                       3, no_damping());
  CHECK(result.rigid_modes_dropped == 0);
  const auto& f = result.modal.natural_frequencies_hz;
  CHECK(2.0 * kPi * f[0] == Approx(std::sqrt(k_axial / mass)).epsilon(1e-4));
  CHECK(2.0 * kPi * f[1] == Approx(std::sqrt(2.0 * k / mass)).epsilon(1e-4));
  CHECK(2.0 * kPi * f[2] == Approx(std::sqrt(6.0 * k / mass)).epsilon(1e-4));
  // Mass normalisation seen independently of M: the bounce shape is uniform, 1/√m.
  CHECK(result.modal.point("tip").translation(1, 1) == Approx(1.0 / std::sqrt(mass)).epsilon(1e-4));
}

// Reference: clamped-free bar f_n = (2n − 1) c/(4L), c = √(E/ρ). Linear bar elements with
// consistent mass overestimate ω by ≈ (kh)²/24: 2.6e-4 for the third mode on 100
// elements, inside the 0.1% tolerance. Axial modes are those without any y motion.
TEST_CASE("axial modes of a clamped bar are (2n - 1) c / (4L)", "[structure]") {
  const int elements = 100;
  const auto result = beam_modal_model(uniform_beam(elements, {support(Support::Kind::kClamped, 0.0)}),
                                       3 * elements, no_damping());
  const Eigen::MatrixXd& shapes = result.modal.mode_shapes;
  std::vector<double> axial_hz;
  for (Eigen::Index j = 0; j < shapes.cols(); ++j) {
    double transverse = 0.0, axial = 0.0;
    for (Eigen::Index node = 0; node < shapes.rows() / 3; ++node) {
      axial = std::max(axial, std::abs(shapes(3 * node, j)));
      transverse = std::max(transverse, std::abs(shapes(3 * node + 1, j)));
    }
    if (transverse < 1e-9 * axial) axial_hz.push_back(result.modal.natural_frequencies_hz[j]);
  }
  REQUIRE(axial_hz.size() == static_cast<std::size_t>(elements));
  const double c = std::sqrt(kYoungsModulusPa / kDensityKgM3);
  for (int n = 1; n <= 3; ++n) CHECK(axial_hz[n - 1] == Approx((2 * n - 1) * c / (4.0 * kLengthM)).epsilon(1e-3));
}

// Reference: a massless column with tip mass m under the compressive tip load P = m g
// has the lateral stiffness k(P) = Pα/(tan αL − αL), α = √(P/EI) (Timoshenko & Gere,
// Theory of Elastic Stability, §1.11), so ω²(P)/ω²(0) = k(P)/(3EI/L³); in tension
// k(T) = Tα/(αL − tanh αL). The beam here has 1/100 of steel's density (0.14% of the tip
// mass): its own weight adds ~0.05% to the axial load, which moves the ratio by about as
// much at P = P_cr/2 (measured 4e-4); tolerance 0.1%.
TEST_CASE("gravity's geometric stiffness softens a standing cantilever and stiffens a hanging one",
          "[structure]") {
  const double ei = bending_rigidity();
  const double buckling_load = kPi * kPi * ei / (4.0 * kLengthM * kLengthM);  // P_cr = π²EI/(4L²)
  const double g = 9.81;
  const double load = 0.5 * buckling_load;
  const auto frequency = [&](double axial_gravity, bool geometric) {
    BeamModel beam = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)}, strip(), kDensityKgM3 / 100.0);
    beam.point_masses = {{"container", kLengthM, load / g, 0.0}};
    beam.axial_gravity_m_s2 = axial_gravity;
    beam.geometric_stiffness = geometric;
    return beam_modal_model(beam, 1, no_damping()).modal.natural_frequencies_hz[0];
  };
  const double alpha = std::sqrt(load / ei);
  const double free_stiffness = 3.0 * ei / std::pow(kLengthM, 3);

  const double f0 = frequency(-g, false);
  const double standing = frequency(-g, true);
  const double compressed_stiffness = load * alpha / (std::tan(alpha * kLengthM) - alpha * kLengthM);
  CHECK(standing * standing / (f0 * f0) == Approx(compressed_stiffness / free_stiffness).epsilon(1e-3));
  // The interaction formula f² ≈ f0²(1 − P/P_cr) is itself approximate: at P = P_cr/2 the
  // exact ratio above is 0.514, the formula says 0.5 (3% apart).
  CHECK(standing * standing / (f0 * f0) == Approx(1.0 - load / buckling_load).epsilon(0.03));

  const double hanging = frequency(g, true);
  const double tensioned_stiffness = load * alpha / (alpha * kLengthM - std::tanh(alpha * kLengthM));
  CHECK(hanging * hanging / (f0 * f0) == Approx(tensioned_stiffness / free_stiffness).epsilon(1e-3));

  BeamModel buckled = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)});
  buckled.point_masses = {{"container", kLengthM, 1.2 * buckling_load / g, 0.0}};
  buckled.axial_gravity_m_s2 = -g;
  buckled.geometric_stiffness = true;
  CHECK_THROWS_WITH(beam_modal_model(buckled, 1, no_damping()), Catch::Contains("exceeds the buckling load"));
}

// Reference: a rigid bar pinned at its top end swings as a compound pendulum,
// ω² = m g (L/2)/(m L²/3) = 3g/(2L); only the geometric stiffness of its own weight holds
// it (without it, the rotation is a rigid mode). The stiff section (first bending mode
// ~1 kHz) couples by ~(ω/ω_bend)² ≈ 1e-7: tolerance 1e-4.
TEST_CASE("a hanging pinned beam swings as a compound pendulum", "[structure]") {
  Section block;
  block.width_m = 0.02;
  block.depth_m = 0.05;
  BeamModel beam = uniform_beam(20, {support(Support::Kind::kPinned, 0.0)}, block);
  beam.axial_gravity_m_s2 = 9.81;
  CHECK(beam_modal_model(beam, 1, no_damping()).rigid_modes_dropped == 1);
  beam.geometric_stiffness = true;
  const auto pendulum = beam_modal_model(beam, 1, no_damping());
  CHECK(pendulum.rigid_modes_dropped == 0);
  CHECK(2.0 * kPi * pendulum.modal.natural_frequencies_hz[0] == Approx(std::sqrt(1.5 * 9.81 / kLengthM)).epsilon(1e-4));
}

// Φᵀ M Φ = I and Γ = Φᵀ M r checked against the assembled matrices (round-off only).
TEST_CASE("modes are mass-normalised and the base participation is Phi^T M r", "[structure]") {
  BeamModel beam = uniform_beam(12, {support(Support::Kind::kClamped, 0.0)});
  beam.point_masses = {{"container", 0.6, 0.3, 1e-4}};
  const auto result = beam_modal_model(beam, 6, no_damping());
  const BeamMatrices matrices = beam_matrices(beam);
  const Eigen::MatrixXd& phi = result.modal.mode_shapes;
  REQUIRE(phi.rows() == matrices.mass_kg.rows());
  const Eigen::MatrixXd orthogonality = phi.transpose() * matrices.mass_kg * phi;
  CHECK((orthogonality - Eigen::MatrixXd::Identity(6, 6)).cwiseAbs().maxCoeff() < 1e-10);
  const Eigen::MatrixXd modal_stiffness = phi.transpose() * matrices.stiffness_n_m * phi;
  const Eigen::VectorXd omega = 2.0 * kPi * result.modal.natural_frequencies_hz;
  CHECK((modal_stiffness - Eigen::MatrixXd(omega.cwiseAbs2().asDiagonal())).cwiseAbs().maxCoeff() <
        1e-8 * omega.cwiseAbs2().maxCoeff());

  Eigen::MatrixXd rigid = Eigen::MatrixXd::Zero(phi.rows(), 2);
  for (Eigen::Index node = 0; node < phi.rows() / 3; ++node) {
    rigid(3 * node, 0) = 1.0;
    rigid(3 * node + 1, 1) = 1.0;
  }
  const Eigen::MatrixXd gamma = phi.transpose() * matrices.mass_kg * rigid;
  CHECK((gamma - result.modal.base_participation).cwiseAbs().maxCoeff() < 1e-12);
  // Shapes at the point mass are the rows of its node (placed at x = 0.6 m).
  const auto& container = result.modal.point("container");
  Eigen::Index node = 0;
  while (std::abs(matrices.node_positions_m[node] - 0.6) > 1e-12) ++node;
  CHECK(container.translation.row(1) == phi.row(3 * node + 1));
  CHECK(container.rotation == phi.row(3 * node + 2));
  // Fixed DOFs (the clamp at node 0) carry no motion.
  CHECK(matrices.fixed_dofs == std::vector<Eigen::Index>{0, 1, 2});
  CHECK(phi.topRows(3).cwiseAbs().maxCoeff() == 0.0);
}

// Reference: effective modal masses Γ_j²/m_j of a uniform cantilever are 0.6131, 0.1883,
// 0.0647 of ρAL (Blevins; Chopra, Dynamics of Structures, §16.6); FE error ~1e-5.
// Completeness: with every mode of a free beam on springs, Σ Γ_j² = r_yᵀ M r_y, the total
// mass (beam and point masses), to round-off.
TEST_CASE("effective modal masses match the cantilever values and sum to the total mass", "[structure]") {
  const double beam_mass = mass_per_length() * kLengthM;
  const auto cantilever = beam_modal_model(uniform_beam(20, {support(Support::Kind::kClamped, 0.0)}), 3, no_damping());
  const Eigen::VectorXd effective = cantilever.modal.base_participation.col(1).cwiseAbs2();
  CHECK(effective[0] / beam_mass == Approx(0.6131).epsilon(1e-3));
  CHECK(effective[1] / beam_mass == Approx(0.1883).epsilon(1e-3));
  CHECK(effective[2] / beam_mass == Approx(0.0647).epsilon(2e-3));  // 4 digits given: ±0.00005 of 0.0647

  BeamModel floating = uniform_beam(10, {spring(0.0, 5.0, 10.0, 0.0), spring(kLengthM, 0.0, 10.0, 0.0)});
  floating.point_masses = {{"container", kLengthM, 0.2, 1e-4}};
  const auto all = beam_modal_model(floating, 3 * 11, no_damping());
  CHECK(all.rigid_modes_dropped == 0);
  const double total_mass = beam_mass + 0.2;
  CHECK(all.modal.base_participation.col(0).squaredNorm() == Approx(total_mass).epsilon(1e-9));
  CHECK(all.modal.base_participation.col(1).squaredNorm() == Approx(total_mass).epsilon(1e-9));
}

// Reference: cantilever under a tip force P: deflection PL³/(3EI), rotation PL²/(2EI);
// force P at a: tip deflection Pa²(3L − a)/(6EI); tip moment M: rotation ML/EI.
// Hermite elements with consistent loads give exact nodal values, so with every mode the
// reconstruction Σ φ_j q0_j is exact to round-off (1e-9).
TEST_CASE("static deflection modal amplitudes rebuild the cantilever deflection", "[structure]") {
  const BeamModel beam = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)});
  const auto all = beam_modal_model(beam, 3 * 20, no_damping());
  const auto& tip = all.modal.point("tip");
  const double ei = bending_rigidity();
  const double force = 2.0;

  const Eigen::VectorXd q_tip = static_deflection_modal_amplitudes(beam, all.modal, kLengthM, {0.0, force}, 0.0);
  CHECK((tip.translation.row(1) * q_tip)(0) == Approx(force * std::pow(kLengthM, 3) / (3.0 * ei)).epsilon(1e-9));
  CHECK((tip.rotation * q_tip)(0) == Approx(force * kLengthM * kLengthM / (2.0 * ei)).epsilon(1e-9));

  const double a = 0.37;  // between nodes (0.35, 0.40): the consistent load vector
  const Eigen::VectorXd q_inner = static_deflection_modal_amplitudes(beam, all.modal, a, {0.0, force}, 0.0);
  CHECK((tip.translation.row(1) * q_inner)(0) == Approx(force * a * a * (3.0 * kLengthM - a) / (6.0 * ei)).epsilon(1e-9));

  const double moment = 0.5;
  const Eigen::VectorXd q_moment = static_deflection_modal_amplitudes(beam, all.modal, kLengthM, {0.0, 0.0}, moment);
  CHECK((tip.rotation * q_moment)(0) == Approx(moment * kLengthM / ei).epsilon(1e-9));

  // Truncated to 4 modes the tip deflection keeps 99.9% (mode 1 alone carries ~97%): the
  // modal series of a tip load converges as 1/(βL)⁴ per term.
  const auto four = beam_modal_model(beam, 4, no_damping());
  const Eigen::VectorXd q_four = static_deflection_modal_amplitudes(beam, four.modal, kLengthM, {0.0, force}, 0.0);
  CHECK((four.modal.point("tip").translation.row(1) * q_four)(0) ==
        Approx(force * std::pow(kLengthM, 3) / (3.0 * ei)).epsilon(2e-3));

  const BeamModel free_beam = uniform_beam(10, {});
  const auto free_modes = beam_modal_model(free_beam, 2, no_damping());
  CHECK_THROWS_WITH(static_deflection_modal_amplitudes(free_beam, free_modes.modal, kLengthM, {0.0, 1.0}, 0.0),
                    Catch::Contains("mechanism (3 rigid-body modes)"));
  CHECK_THROWS_WITH(static_deflection_modal_amplitudes(free_beam, all.modal, kLengthM, {0.0, 1.0}, 0.0),
                    Catch::Contains("pass the modal model of this beam"));
}

TEST_CASE("segments of one section and nodes placed at features leave the frequencies unchanged", "[structure]") {
  // Reference: the uniform cantilever above; splitting it and adding nodes only refines
  // the mesh, so the first frequency agrees within the FE error (1e-5).
  BeamModel split = uniform_beam(10, {support(Support::Kind::kClamped, 0.0)});
  split.segments = {split.segments[0], split.segments[0]};
  split.segments[0].length_m = 0.3;
  split.segments[0].elements = 6;
  split.segments[1].length_m = 0.7;
  split.segments[1].elements = 14;
  split.points = {{"tip", kLengthM}, {"near boundary", 0.3 + 1e-12}, {"inside", 0.512}};
  const auto result = beam_modal_model(split, 2, no_damping());
  CHECK(result.modal.natural_frequencies_hz[0] == Approx(bending_frequency_hz(1.875104)).epsilon(1e-4));
  const auto nodes = beam_matrices(split).node_positions_m;
  // "inside" splits the second segment into 4 + 10 elements (its 14 shared by length);
  // "near boundary" is within 1e-9 L of x = 0.3 and shares that node: 20 elements.
  CHECK(nodes.size() == 21);
  CHECK(result.modal.points.size() == 3);
}

// Reference: the uniform cantilever (β₁L = 1.875104, β₂L = 4.694091). A named point 1e-5
// of an element from the tip used to get its own node, a sliver element whose EI/s³ terms
// made the eigensolver return a negative ω²; within 1% of the finest element it now shares
// the tip's node, so the frequencies stay the cantilever's and the point moves as the tip.
TEST_CASE("a point next to another feature shares its node instead of making a sliver element", "[structure]") {
  BeamModel beam = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)});
  const double element = kLengthM / 20;
  beam.points = {{"tip", kLengthM}, {"almost tip", kLengthM - 1e-5 * element}, {"near", 0.5 - 0.005 * element},
                 {"apart", 0.5 + 0.02 * element}};
  const auto result = beam_modal_model(beam, 2, no_damping());
  CHECK(result.modal.natural_frequencies_hz[0] == Approx(bending_frequency_hz(1.875104)).epsilon(1e-4));
  CHECK(result.modal.natural_frequencies_hz[1] == Approx(bending_frequency_hz(4.694091)).epsilon(1e-4));
  CHECK(result.modal.point("almost tip").translation == result.modal.point("tip").translation);
  // "near" (0.5% of an element off) merges with the node at 0.5; "apart" (2%) gets its own.
  CHECK(beam_matrices(beam).node_positions_m.size() == 22);
}

// Reference: at a node the interpolated shape is the node's own (exactly); inside an element
// it is the analytic cantilever mode φ = cosh βx − cos βx − σ(sinh βx − sin βx) scaled to the
// FE tip value, to 1e-5 (20 Hermite elements: the cubic interpolation error of mode 2 is
// O((βh)⁴/384) ~ 1e-6 of its amplitude, the eigenvector error smaller still).
TEST_CASE("a mode shape interpolated between nodes follows the analytic cantilever mode", "[structure]") {
  const BeamModel beam = uniform_beam(20, {support(Support::Kind::kClamped, 0.0)});
  const ModalModel modal = beam_modal_model(beam, 2, no_damping()).modal;
  const PointModeShape tip = beam_point_shape(beam, modal, "tip shape", kLengthM);
  CHECK(tip.translation == modal.point("tip").translation);
  CHECK(tip.rotation == modal.point("tip").rotation);
  for (int j = 0; j < 2; ++j) {
    const double bl = j == 0 ? 1.875104068711961 : 4.694091132974175;
    const double sigma = (std::cosh(bl) + std::cos(bl)) / (std::sinh(bl) + std::sin(bl));
    const auto phi = [&](double x) {
      const double b = bl * x / kLengthM;
      return std::cosh(b) - std::cos(b) - sigma * (std::sinh(b) - std::sin(b));
    };
    const double scale = tip.translation(1, j) / phi(kLengthM);
    for (double x : {0.1234, 0.5555, 0.9876}) {
      const PointModeShape p = beam_point_shape(beam, modal, "p", x);
      INFO("mode " << j << ", x = " << x);
      CHECK(p.translation(1, j) == Approx(scale * phi(x)).margin(1e-5 * std::abs(tip.translation(1, j))));
      CHECK(p.translation(0, j) == Approx(0.0).margin(1e-12));
    }
  }
  CHECK_THROWS_WITH(beam_point_shape(beam, modal, "p", 1.5), Catch::Contains("position_m = 1.5: must be in [0, 1] m"));
}

TEST_CASE("damping ratios repeat the last value or follow Rayleigh damping", "[structure]") {
  const BeamModel beam = uniform_beam(10, {support(Support::Kind::kClamped, 0.0)});
  ModalDamping listed;
  listed.ratios = {0.01, 0.02};
  const auto ratios = beam_modal_model(beam, 3, listed).modal.damping_ratios;
  CHECK(ratios == Eigen::Vector3d(0.01, 0.02, 0.02));

  ModalDamping rayleigh;
  rayleigh.rayleigh_alpha_1_s = 0.5;
  rayleigh.rayleigh_beta_s = 1e-4;
  const auto modal = beam_modal_model(beam, 3, rayleigh).modal;
  for (Eigen::Index j = 0; j < 3; ++j) {
    const double omega = 2.0 * kPi * modal.natural_frequencies_hz[j];
    CHECK(modal.damping_ratios[j] == Approx(0.5 / (2.0 * omega) + 1e-4 * omega / 2.0).epsilon(1e-14));
  }

  ModalDamping negative;
  negative.ratios = {0.01, -0.1};
  CHECK_THROWS_WITH(beam_modal_model(beam, 1, negative), "modal damping: ratios/1 = -0.1: must be in [0, 1] (a vibration mode's damping ratio)");
  CHECK_THROWS_WITH(beam_modal_model(beam, 31, listed), Catch::Contains("has only 30 elastic modes"));
}

TEST_CASE("an unknown point name lists the known ones", "[structure]") {
  const auto result = beam_modal_model(uniform_beam(4, {support(Support::Kind::kClamped, 0.0)}), 1, no_damping());
  CHECK_THROWS_AS(result.modal.point("root"), std::invalid_argument);
  CHECK_THROWS_WITH(result.modal.point("root"), "modal model: no point named \"root\" (known: tip)");
}

// Reference: the same standing cantilever with a tip mass M built two ways. (a) M is a
// beam point mass (inertia and weight). (b) M is a damper's container coupled through
// structure::Damper (inertia, exact point-mass update of the modal model) and a carried
// weight of the beam (weight only). Both have the same mass matrix and the same
// geometric stiffness, so the frequencies agree to the modal truncation of (b): the
// container's mass update in 20 modes of a 30-element beam gives the first mode of (a)
// to 1.7e-6 (4.6e-5 with 6 modes); 1e-5 allows for the slow convergence.
TEST_CASE("a carried weight loads the geometric stiffness as the point mass's weight does", "[structure]") {
  const double tip_mass = 0.5;
  BeamModel with_mass = uniform_beam(30, {support(Support::Kind::kClamped, 0.0)});
  with_mass.axial_gravity_m_s2 = -9.80665;
  with_mass.geometric_stiffness = true;
  BeamModel carried = with_mass;
  with_mass.point_masses = {{"tip_mass", kLengthM, tip_mass, 0.0}};
  carried.carried_weights = {{kLengthM, tip_mass}};
  const double f_point = beam_modal_model(with_mass, 1, {}).modal.natural_frequencies_hz[0];
  const ModalModel modal = beam_modal_model(carried, 20, {}).modal;
  Damper container;
  container.name = "container";
  container.point = "tip";
  container.drive_direction = {0.0, 1.0};
  container.container_mass_kg = tip_mass;
  const double f_coupled = natural_frequencies_with_containers_hz(couple(modal, {container}))[0];
  CHECK(f_coupled == Approx(f_point).epsilon(1e-5));
  // Without the carried weight the beam is stiffer (it feels only its own weight).
  BeamModel unloaded = carried;
  unloaded.carried_weights.clear();
  const double f_unloaded =
      natural_frequencies_with_containers_hz(couple(beam_modal_model(unloaded, 6, {}).modal, {container}))[0];
  CHECK(f_unloaded > 1.01 * f_point);
  carried.carried_weights = {{2.0 * kLengthM, -1.0}};
  const auto problems = carried.validate();
  REQUIRE(problems.size() == 2);
  CHECK_THAT(problems[0], Catch::StartsWith("carried_weights/0/position_m"));
  CHECK_THAT(problems[1], Catch::StartsWith("carried_weights/0/mass_kg"));
}
