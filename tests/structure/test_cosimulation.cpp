// Tests of the co-simulation (modal model + DEM beds in the loop): exact 1-DOF responses
// without contacts, added mass of a bed that cannot move, energy closure with impacts,
// rotation kinematics and the returned moment, no allocation in the step loop.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <new>

#include "pdamp/structure/cosimulation.hpp"
#include "structure/cosimulation_support.hpp"

// Allocation counter for the "no allocation in the step loop" test: the global operator
// new/delete are replaced by malloc/free. GCC pairs the standard allocation functions it
// inlines with this file's free() and warns of a mismatch that the replacement rules out.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {
std::atomic<long long> g_allocations{0};
}
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace pdamp::structure;
using pdamp::test::bed;
using pdamp::test::tip_damper;
namespace dem = pdamp::dem_reference;
using cd = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

/// One mode: f (Hz), ζ, modal mass m (kg); point "tip" with translation (0, φ) and rotation θ.
ModalModel one_dof(double f_hz, double zeta, double mass_kg, double phi = 1.0, double theta = 0.0,
                   double base_participation_kg = 0.0) {
  ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, f_hz);
  m.damping_ratios = Eigen::VectorXd::Constant(1, zeta);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, mass_kg);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, phi;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Constant(1, theta)}};
  m.base_participation = Eigen::MatrixXd(1, 2);
  m.base_participation << 0.0, base_participation_kg;
  return m;
}

/// A single sphere floating in the middle of a long box without gravity: it never touches.
dem::WorldOptions lone_sphere() { return pdamp::test::lone_sphere(0.12); }

/// Mean period from the up-crossings of y − mean(y) (linear interpolation), s.
double mean_period_s(const std::vector<double>& t, const Eigen::VectorXd& y) {
  const double mean = y.mean();
  std::vector<double> crossings;
  for (Eigen::Index i = 1; i < y.size(); ++i) {
    const double a = y[i - 1] - mean, b = y[i] - mean;
    if (a < 0.0 && b >= 0.0) {
      const auto k = static_cast<std::size_t>(i);
      crossings.push_back(t[k - 1] + (t[k] - t[k - 1]) * (-a) / (b - a));
    }
  }
  REQUIRE(crossings.size() >= 3);
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

}  // namespace

// Reference: the exact 1-DOF of the bare structure with the container mass, M = m + m_c φ².
// The lone sphere never touches a wall (checked: no container work), so the modes see no bed
// force and the scheme is plain velocity Verlet with trapezoidal damping. Its error: a phase
// drift ω t (ωdt)²/24 (ω dt ≈ 1e-3 here: 4e-8 rad per period, 3e-6 after 1 s) and an O((ωdt)²)
// amplitude error; 1e-4 of the amplitude leaves a margin of > 30 on both.
TEST_CASE("without bed contact a free decay is the exact damped 1-DOF with the container mass", "[cosimulation]") {
  const double f = 10.0, zeta = 0.02, m = 1.0, mc = 0.25, q0 = 1e-3;
  const ModalModel model = one_dof(f, zeta, m);
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, q0);
  o.duration_s = 1.0;
  const CosimulationResult r = cosimulate(model, {tip_damper(lone_sphere(), mc)}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  CHECK(r.energy.container_work_j == 0.0);
  const double k = m * std::pow(2 * kPi * f, 2), c = 2 * zeta * 2 * kPi * f * m, M = m + mc;
  const double wn = std::sqrt(k / M), z = c / (2 * M * wn), wd = wn * std::sqrt(1 - z * z);
  CHECK(r.frequencies_with_containers_hz[0] == Approx(wn / (2 * kPi)).epsilon(1e-12));
  double max_error = 0.0;
  for (std::size_t s = 0; s < r.history.time_s.size(); ++s) {
    const double t = r.history.time_s[s];
    const double exact = std::exp(-z * wn * t) * q0 * (std::cos(wd * t) + z * wn / wd * std::sin(wd * t));
    max_error = std::max(max_error, std::abs(r.history.modal_displacements(static_cast<Eigen::Index>(s), 0) - exact));
  }
  INFO("dt = " << r.time_step_s << " s, max error / q0 = " << max_error / q0);
  CHECK(max_error < 1e-4 * q0);
  // Free decay: the structural damping takes all the energy (ledger closes to the scheme's
  // O((ωdt)²) ≈ 1e-6; 1e-4 bounds it).
  CHECK(r.energy.relative_error < 1e-4);
}

// Reference: the container's rotary inertia. A site that rotates by θ = 2 rad per unit q
// adds J θ² to the modal mass (kinetic energy ½J θ̇²): f = f₀·√(m/(m + m_c φ² + J θ²)),
// exact in couple() (1e-12) and in the co-simulated free decay to the period measurement's
// 1e-3 (up-crossings of a 1 s record; ζ = 0.02 shifts the damped period by 1e-4); the
// ledger includes ½J θ̇² (scheme bound 1e-4).
TEST_CASE("the container's rotary inertia at a rotating site lowers the frequency as J theta^2", "[cosimulation]") {
  const double f = 10.0, m = 1.0, mc = 0.25, J = 0.05, theta = 2.0;
  const ModalModel model = one_dof(f, 0.02, m, 1.0, theta);  // damped: the ledger has work to close
  CosimulationDamper damper = tip_damper(lone_sphere(), mc);
  damper.container_rotary_inertia_kg_m2 = J;
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, 1e-3);
  o.duration_s = 1.0;
  const CosimulationResult r = cosimulate(model, {damper}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  const double expected = f * std::sqrt(m / (m + mc + J * theta * theta));
  CHECK(r.frequencies_with_containers_hz[0] == Approx(expected).epsilon(1e-12));
  const double period = mean_period_s(r.history.time_s, r.history.site_displacement_m.col(0));
  CHECK(1.0 / period == Approx(expected).epsilon(1e-3));
  CHECK(r.energy.relative_error < 1e-4);
  damper.container_rotary_inertia_kg_m2 = -1.0;
  CHECK_THROWS_AS(cosimulate(model, {damper}, o), std::invalid_argument);
}

// Reference: two dampers on two modes. M = diag(m_j) + Σ_d m_c,d Φ_dᵀΦ_d couples the modes; the
// natural frequencies are those of the generalised eigenproblem K x = ω² M x solved here
// independently (1e-12). Each site's history is its own Φ_d q (1e-12 of the amplitude), and
// with both beds impacting under base motion the ledger closes within 1% (the 1-damper
// bound, docs/cosimulation.md §4) and each bed's in-loop η* is positive (it dissipates).
TEST_CASE("two dampers on two modes: coupled frequencies, per-site kinematics and the energy ledger", "[cosimulation]") {
  ModalModel model;
  model.natural_frequencies_hz = Eigen::Vector2d(10.0, 27.0);
  model.damping_ratios = Eigen::Vector2d(0.02, 0.02);
  model.modal_masses_kg = Eigen::Vector2d(1.0, 0.5);
  Eigen::MatrixXd a(2, 2), b(2, 2);
  a << 0.0, 0.0, 1.0, 0.6;
  b << 0.0, 0.0, -0.7, 0.9;
  model.points = {{"a", a, Eigen::RowVectorXd::Zero(2)}, {"b", b, Eigen::RowVectorXd::Zero(2)}};
  model.base_participation = Eigen::MatrixXd(2, 2);
  model.base_participation << 0.0, 0.4, 0.0, -0.2;
  const double mc_a = 0.2, mc_b = 0.1;
  // Names moved in (GCC 12 flags assigning a literal here with a false -Wrestrict).
  const auto at = [](CosimulationDamper d, std::string name, std::string point) {
    d.name = std::move(name);
    d.point = std::move(point);
    return d;
  };
  CosimulationDamper at_a = at(tip_damper(lone_sphere(), mc_a), "at_a", "a");
  CosimulationDamper at_b = at(tip_damper(lone_sphere(), mc_b), "at_b", "b");

  SECTION("no contact: the coupled 2-DOF") {
    DecayRun o;
    o.initial_modal_displacements = Eigen::Vector2d(1e-3, 5e-4);
    o.duration_s = 0.5;
    const CosimulationResult r = cosimulate(model, {at_a, at_b}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    Eigen::MatrixXd M = model.modal_masses_kg.asDiagonal();
    M += mc_a * a.transpose() * a + mc_b * b.transpose() * b;
    const Eigen::Vector2d w = 2 * kPi * model.natural_frequencies_hz;
    const Eigen::MatrixXd K = model.modal_masses_kg.cwiseProduct(w.cwiseAbs2()).asDiagonal();
    const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M, Eigen::EigenvaluesOnly);
    for (int j = 0; j < 2; ++j)
      CHECK(r.frequencies_with_containers_hz[j] == Approx(std::sqrt(eig.eigenvalues()[j]) / (2 * kPi)).epsilon(1e-12));
    REQUIRE(r.history.site_displacement_m.cols() == 2);
    double worst = 0.0;
    for (Eigen::Index s = 0; s < r.history.modal_displacements.rows(); ++s) {
      const Eigen::Vector2d q = r.history.modal_displacements.row(s).transpose();
      worst = std::max(worst, std::abs(r.history.site_displacement_m(s, 0) - a.row(1).dot(q)));
      worst = std::max(worst, std::abs(r.history.site_displacement_m(s, 1) - b.row(1).dot(q)));
    }
    CHECK(worst < 1e-12 * 1e-3);
    CHECK(r.energy.relative_error < 1e-4);
  }
  SECTION("both beds impacting under base motion") {
    const dem::WorldOptions impacting = bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                                            dem::InitialPlacement::kCollectedLattice);
    at_a.world = impacting;
    at_b.world = impacting;
    SteadyStateRun o;
    o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
    o.excitation.direction = {0.0, 1.0};
    o.excitation.amplitude = 1e-3;
    o.excitation.frequency_hz = 9.0;
    o.transient_periods = 3;
    o.analysed_periods = 2;
    const CosimulationResult r = cosimulate(model, {at_a, at_b}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    const auto& e = r.energy;
    INFO("W " << e.excitation_work_j << " J, D_s " << e.structural_damping_j << " J, D_dem " << e.dem_dissipated_j()
              << " J, error " << e.relative_error);
    CHECK(e.dem_dissipated_j() > 0.1 * e.structural_damping_j);
    CHECK(e.relative_error < 0.01);
    REQUIRE(r.steady_state.bed_reduced_loss_factor.size() == 2);
    CHECK(r.steady_state.bed_reduced_loss_factor[0] > 0.0);
    CHECK(r.steady_state.bed_reduced_loss_factor[1] > 0.0);
  }
}

// Reference: |H(Ω)| of the same 1-DOF. Started on the exact steady state (q(0) = Im q̂,
// q̇(0) = Ω Re q̂) so no transient has to decay; the Verlet solution then differs by the
// O((ωdt)²) ≈ 1e-6 frequency error amplified by at most Q = 1/(2ζ) = 25 near Ω: 1e-4.
TEST_CASE("without bed contact forced steady states equal the exact receptance and transmissibility", "[cosimulation]") {
  const double f = 10.0, zeta = 0.02, m = 1.0, mc = 0.25, fd = 8.5;
  const double W = 2 * kPi * fd, k = m * std::pow(2 * kPi * f, 2), c = 2 * zeta * 2 * kPi * f * m;
  const cd D = k - W * W * (m + mc) + cd(0, 1) * W * c;
  SECTION("point force") {
    const ModalModel model = one_dof(f, zeta, m);
    const double F = 0.5;
    const cd qhat = F / D;
    SteadyStateRun o;
    o.excitation.kind = CosimulationExcitationKind::kPointForce;
    o.excitation.point = "tip";
    o.excitation.direction = {0.0, 1.0};
    o.excitation.amplitude = F;
    o.excitation.frequency_hz = fd;
    o.initial_modal_displacements = Eigen::VectorXd::Constant(1, qhat.imag());
    o.initial_modal_velocities = Eigen::VectorXd::Constant(1, W * qhat.real());
    o.transient_periods = 1;
    o.analysed_periods = 4;
    const CosimulationResult r = cosimulate(model, {tip_damper(lone_sphere(), mc)}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    CHECK(r.energy.container_work_j == 0.0);
    INFO("steps per period " << r.steps_per_period);
    CHECK(std::abs(r.steady_state.site_amplitudes_m[0] - qhat) < 1e-4 * std::abs(qhat));
    CHECK(r.steady_state.site_amplitude_per_excitation[0] == Approx(std::abs(qhat) / F).epsilon(1e-4));
    // Work of the force = structural damping + change of energy (to the scheme's O((ωdt)²)).
    CHECK(r.energy.relative_error < 1e-4);
  }
  SECTION("base translation") {
    const double gamma = 0.8, U = 1e-4;
    const ModalModel model = one_dof(f, zeta, m, 1.0, 0.0, gamma);
    const cd qhat = W * W * (gamma + mc) * U / D;  // relative; absolute site = U + q̂
    SteadyStateRun o;
    o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
    o.excitation.direction = {0.0, 1.0};
    o.excitation.amplitude = U;
    o.excitation.frequency_hz = fd;
    o.initial_modal_displacements = Eigen::VectorXd::Constant(1, qhat.imag());
    o.initial_modal_velocities = Eigen::VectorXd::Constant(1, W * qhat.real());
    o.transient_periods = 1;
    o.analysed_periods = 4;
    const CosimulationResult r = cosimulate(model, {tip_damper(lone_sphere(), mc)}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    CHECK(r.energy.container_work_j == 0.0);
    CHECK(std::abs(r.steady_state.site_amplitudes_m[0] - (U + qhat)) < 1e-4 * std::abs(U + qhat));
    CHECK(std::abs(r.steady_state.modal_amplitudes[0] - qhat) < 1e-4 * std::abs(qhat));
    // The base reaction's work in the inertial frame closes the ledger (same scheme bound).
    CHECK(r.energy.relative_error < 1e-4);
  }
}

// Reference: added mass. Gravity along −drive presses 4 spheres (0.132 kg) onto the wall;
// the container's acceleration (ω²X ≈ 0.8 m/s²) stays below g, so they never leave it and
// move with the container: f = √(k/(m + m_c + m_bed))/2π. Deviations: the Hertz contact's
// compliance (contact frequency ≈ 220 Hz against 8 Hz: (f/f_c)² ≈ 0.13% in mass) and the
// period measurement from up-crossings (sampling dt-exact, < 0.05%): 1% bounds both, and is
// a tenth of the shift being tested (15%).
TEST_CASE("a bed that cannot move relative to the container shifts the frequency as its added mass", "[cosimulation]") {
  const double f = 10.0, m = 0.3, mc = 0.05;
  const ModalModel model = one_dof(f, 0.0, m);
  const dem::WorldOptions world = bed(0.01, {0.03, 0.0401, 0.0401}, {1, 2, 2}, 2e8, {-9.80665, 0.0, 0.0},
                                      dem::InitialPlacement::kCollectedLattice);
  CosimulationDamper damper = tip_damper(world, mc);
  const double k = m * std::pow(2 * kPi * f, 2);
  const double bed_mass = 4 * 7850.0 * 4.0 / 3.0 * kPi * std::pow(0.01, 3);
  const double q_static = -bed_mass * 9.80665 / k;  // the bed's weight on the container
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, q_static + 3e-4);
  o.duration_s = 1.0;
  const CosimulationResult r = cosimulate(model, {damper}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  const double period = mean_period_s(r.history.time_s, r.history.site_displacement_m.col(0));
  const double expected = std::sqrt(k / (m + mc + bed_mass)) / (2 * kPi);
  INFO("measured " << 1.0 / period << " Hz, added-mass prediction " << expected << " Hz, without bed "
                   << r.frequencies_with_containers_hz[0] << " Hz");
  CHECK(1.0 / period == Approx(expected).epsilon(0.01));
  CHECK(std::abs(1.0 / period - r.frequencies_with_containers_hz[0]) > 0.1 * expected);
}

// Reference: the bed's complex power in the loop. The same held bed (gravity along −drive
// keeps the 4 spheres on the wall: the container's acceleration ω²X stays below g) under a
// harmonic force moves as a rigid mass: F = m_bed·a, so m_app/m_bed = 1 and η* = 0, up to
// the contact's compliance ((f/f_c)² ≈ 0.2% at 9 Hz against 220 Hz) and the one-step lag
// between force and site (Ωdt ≈ 1e-4): 1% and 0.01 bound them.
TEST_CASE("a held bed's in-loop complex power gives its mass and no dissipation", "[cosimulation]") {
  const double f = 10.0, m = 0.3, mc = 0.05;
  const ModalModel model = one_dof(f, 0.02, m);
  const dem::WorldOptions world = bed(0.01, {0.03, 0.0401, 0.0401}, {1, 2, 2}, 2e8, {-9.80665, 0.0, 0.0},
                                      dem::InitialPlacement::kCollectedLattice);
  // Started on the rigid-mass steady state (plus the bed's static weight on the spring), so
  // no free transient leaks into the analysed periods' bin at Ω.
  const double fd = 9.0, F = 0.3, W = 2 * kPi * fd, k = m * std::pow(2 * kPi * f, 2), c = 2 * 0.02 * 2 * kPi * f * m;
  const double bed_mass = 4 * 7850.0 * 4.0 / 3.0 * kPi * std::pow(0.01, 3);
  const cd qhat = F / (k - W * W * (m + mc + bed_mass) + cd(0, 1) * W * c);
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kPointForce;
  o.excitation.point = "tip";
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = F;
  o.excitation.frequency_hz = fd;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, -bed_mass * 9.80665 / k + qhat.imag());
  o.initial_modal_velocities = Eigen::VectorXd::Constant(1, W * qhat.real());
  o.transient_periods = 2;
  o.analysed_periods = 4;
  const CosimulationResult r = cosimulate(model, {tip_damper(world, mc)}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  const auto& ss = r.steady_state;
  REQUIRE(ss.bed_apparent_mass_fraction.size() == 1);
  INFO("m_app/m_bed " << ss.bed_apparent_mass_fraction[0] << ", eta* " << ss.bed_reduced_loss_factor[0] << ", |y| "
                      << std::abs(ss.site_amplitudes_m[0]) << " m");
  CHECK(std::abs(ss.site_amplitudes_m[0]) * W * W < 9.80665);
  CHECK(ss.bed_apparent_mass_fraction[0] == Approx(1.0).epsilon(0.01));
  CHECK(std::abs(ss.bed_reduced_loss_factor[0]) < 0.01);
}

// Reference: the site's motion across the drive. A mode that moves the site only across the
// drive (shape (φ, 0), drive along y) with gravity pressing the 4 spheres on the container
// wall that faces that motion (container −y ↔ structure +x: c = k × a follows t = z × n):
// the bed moves with the container across the drive, so f = √(k/(m + m_c + m_bed))/2π
// (1%, as the added-mass test along the drive); a bed that did not see the motion would
// leave √(k/(m + m_c)), 15% higher.
TEST_CASE("the site's motion across the drive reaches the bed and its load returns", "[cosimulation]") {
  const double f = 10.0, m = 0.3, mc = 0.05;
  ModalModel model = one_dof(f, 0.0, m);
  model.points[0].translation << 1.0, 0.0;  // along x only; the damper drives along y
  const dem::WorldOptions world = bed(0.01, {0.0401, 0.03, 0.0401}, {2, 1, 2}, 2e8, {0.0, -9.80665, 0.0},
                                      dem::InitialPlacement::kCollectedLattice);
  const CosimulationDamper damper = tip_damper(world, mc);
  const double k = m * std::pow(2 * kPi * f, 2);
  const double bed_mass = 4 * 7850.0 * 4.0 / 3.0 * kPi * std::pow(0.01, 3);
  // The bed's weight along container −y is along structure +x (t = z × n = −x, c = +y ↔ t).
  const double q_static = bed_mass * 9.80665 / k;
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, q_static + 3e-4);
  o.duration_s = 1.0;
  const CosimulationResult r = cosimulate(model, {damper}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  const double period = mean_period_s(r.history.time_s, r.history.modal_displacements.col(0));
  const double expected = std::sqrt(k / (m + mc + bed_mass)) / (2 * kPi);
  INFO("measured " << 1.0 / period << " Hz, added-mass prediction " << expected << " Hz, without bed "
                   << r.frequencies_with_containers_hz[0] << " Hz");
  CHECK(1.0 / period == Approx(expected).epsilon(0.01));
  CHECK(r.energy.relative_error < 0.01);
}

// Reference: conservation of energy. The DEM's own ledger closes to 2e-4..1e-3 at 50 steps per
// contact (docs/dem.md); the structure's Verlet adds O((ωdt)²) ≈ 1e-6, and the impulsive bed
// force over a contact adds the trapezoid's O((dt/t_c)²) ≈ 4e-4 on the exchanged work: 1% holds
// with a margin of ~5.
TEST_CASE("the energy ledger closes within 1% with impacting spheres, free and forced", "[cosimulation]") {
  const dem::WorldOptions world = bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                                      dem::InitialPlacement::kCollectedLattice);
  SECTION("free decay") {
    const ModalModel model = one_dof(10.0, 0.01, 0.1);
    DecayRun o;
    o.initial_modal_displacements = Eigen::VectorXd::Constant(1, 0.01);
    o.duration_s = 0.5;
    const CosimulationResult r = cosimulate(model, {tip_damper(world, 0.02)}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    const auto& e = r.energy;
    INFO("D_s " << e.structural_damping_j << " J, D_dem " << e.dem_dissipated_j() << " J, ΔE_s "
                << e.delta_structure_kinetic_j + e.delta_structure_potential_j << " J, error " << e.relative_error);
    CHECK(e.dem_dissipated_j() > 0.1 * e.structural_damping_j);  // real impacts
    CHECK(e.relative_error < 0.01);
  }
  SECTION("base excitation") {
    const ModalModel model = one_dof(10.0, 0.01, 0.1, 1.0, 0.0, 0.08);
    SteadyStateRun o;
    o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
    o.excitation.direction = {0.0, 1.0};
    o.excitation.amplitude = 1e-3;
    o.excitation.frequency_hz = 9.0;
    o.transient_periods = 3;
    o.analysed_periods = 2;
    const CosimulationResult r = cosimulate(model, {tip_damper(world, 0.02)}, o);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    const auto& e = r.energy;
    INFO("W " << e.excitation_work_j << " J, D_s " << e.structural_damping_j << " J, D_dem " << e.dem_dissipated_j()
              << " J, error " << e.relative_error << ", |y/U| " << r.steady_state.site_amplitude_per_excitation[0]);
    CHECK(e.dem_dissipated_j() > 0.1 * e.structural_damping_j);
    CHECK(e.relative_error < 0.01);
  }
}

// Kinematics: the container's orientation is the rotation about the mapped axis by the site's
// θ = φ_θ q (to round-off). Moment: a sphere resting on the −y wall of a compartment at
// d = 0.1 m along the drive (0.1 mm of play in x, so it cannot roll away along the tilted
// wall and change d) must follow the wall when the container turns (dθ̈ ≈ 1 m/s² < g),
// so a mode that only rotates the site gains the rotary inertia φ_θ² m d² (0.21 of its
// modal mass): f = f_0/√(1 + φ_θ² m d²/m_j) = 0.911 f_0. Without the moment's return the
// frequency would stay f_0. The sphere's own spin, if the wall turns it too, adds
// (2/5)r²/d² = 0.4% of that inertia (0.07% in f), the contact compliance ~0.1%: 1%.
TEST_CASE("a rotating site turns the container and the bed's moment returns to the mode", "[cosimulation]") {
  const double f0 = 10.0, phi_theta = 25.0, d = 0.1;
  const ModalModel model = one_dof(f0, 0.0, 1.0, 0.0, phi_theta);
  dem::WorldOptions world = bed(0.01, {0.0202, 0.0202, 0.0202}, {1, 1, 1}, 2e8, {0.0, -9.80665, 0.0},
                                dem::InitialPlacement::kCentredLattice);
  world.compartments[0].offset_m = {d, 0.0, 0.0};
  world.compartments[0].collect_axis = 1;  // the sphere starts on the −y wall
  CosimulationDamper damper = tip_damper(world, 0.0);
  damper.drive_direction = {1.0, 0.0};
  const double sphere = 7850.0 * 4.0 / 3.0 * kPi * std::pow(0.01, 3);
  const double k = std::pow(2 * kPi * f0, 2);
  const double q_static = -phi_theta * sphere * 9.80665 * d / k;
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, q_static + 1e-4);
  o.duration_s = 0.6;
  const CosimulationResult r = cosimulate(model, {damper}, o);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  const Eigen::Index last = r.history.modal_displacements.rows() - 1;
  CHECK(r.history.site_rotation_rad(last, 0) ==
        Approx(phi_theta * r.history.modal_displacements(last, 0)).epsilon(1e-12));
  const double theta = phi_theta * r.final_modal_displacements[0];
  const dem::Matrix3 expected = rotation_about({0.0, 0.0, 1.0}, theta);
  for (std::size_t i = 0; i < 9; ++i) CHECK(r.final_container_states[0].orientation[i] == Approx(expected[i]).margin(1e-14));
  const double period = mean_period_s(r.history.time_s, r.history.site_rotation_rad.col(0));
  const double predicted = f0 / std::sqrt(1.0 + phi_theta * phi_theta * sphere * d * d);
  INFO("measured " << 1.0 / period << " Hz, rotary-inertia prediction " << predicted << " Hz");
  CHECK(1.0 / period == Approx(predicted).epsilon(0.01));
  CHECK(r.energy.relative_error < 0.01);
}

// The step loop allocates nothing: allocations are counted between progress calls (every 256
// steps with a tiny interval), after the loop has started. The bed is the lone sphere, which
// moves relative to its container (Verlet rebuilds) but never outgrows the world's reserved
// lists: World::step itself may allocate when a rebuild of a colliding bed outgrows them
// (its documented exception, seen as 2 allocations in 0.2 s of the impact case above).
TEST_CASE("the co-simulation step loop does not allocate", "[cosimulation]") {
  const ModalModel model = one_dof(10.0, 0.01, 0.1, 1.0, 0.0, 0.05);
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = 1e-4;
  o.excitation.frequency_hz = 9.0;
  o.transient_periods = 1;
  o.analysed_periods = 1;
  o.sample_interval_s = 1e-4;
  const dem::WorldOptions world = lone_sphere();
  o.progress_interval_s = 1e-9;
  struct AllocationProbe : pdamp::base::RunHooks {
    long long previous = -1, worst = 0;
    int calls = 0;
    void progress(const pdamp::base::Progress& p) override {
      const long long now = g_allocations.load();
      if (p.stage != "settling" && previous >= 0) {
        worst = std::max(worst, now - previous);
        ++calls;
      }
      previous = p.stage != "settling" ? now : -1;
    }
  } probe;
  const CosimulationResult r = cosimulate(model, {tip_damper(world, 0.02)}, o, probe);
  REQUIRE(r.outcome == dem::Outcome::kCompleted);
  CHECK(probe.calls > 10);
  CHECK(probe.worst == 0);
}

TEST_CASE("invalid co-simulation inputs are refused naming field and rule", "[cosimulation]") {
  const ModalModel model = one_dof(10.0, 0.01, 1.0);
  CosimulationDamper damper = tip_damper(lone_sphere(), 0.1);
  damper.point = "nowhere";
  damper.container_rotation_axis = {1.0, 0.0, 0.0};
  DecayRun o;  // free decay without a start
  o.duration_s = -1.0;
  try {
    cosimulate(model, {damper}, o);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::Contains("dampers[0].point = \"nowhere\""));
    CHECK_THAT(what, Catch::Contains("perpendicular to container_drive_axis"));
    CHECK_THAT(what, Catch::Contains("cosimulation.duration_s = -1"));
    CHECK_THAT(what, Catch::Contains("a free decay needs a non-zero start"));
  }
}

// Continuation (CosimulationState): the state carries the worlds (particles, contacts, step),
// q, q̇, the time and the drive's phase, so two runs at one frequency continued from the state
// are one run of the combined length. The loop does the same arithmetic on the same numbers in
// the same order (the drive's tables are indexed by step modulo the period, the runs end on
// whole periods, the opening acceleration is recomputed from the same q, q̇ and bed load), so
// the end states are bit-identical; the ledgers are sums over the two runs, equal to round-off.
// Impacting spheres, so a bed that was re-settled would differ at once.
TEST_CASE("two continued runs equal one run of the combined length and the ledger closes across the junction",
          "[cosimulation]") {
  const dem::WorldOptions world = bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                                      dem::InitialPlacement::kCollectedLattice);
  const ModalModel model = one_dof(10.0, 0.01, 0.1, 1.0, 0.0, 0.08);
  const std::vector<CosimulationDamper> dampers{tip_damper(world, 0.02)};
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = 1e-3;
  o.excitation.frequency_hz = 9.0;
  for (const double phase : {0.0, kPi / 2}) {
    INFO("start phase " << phase);
    o.excitation_phase_rad = phase;
    SteadyStateRun whole = o;
    whole.transient_periods = 2;
    whole.analysed_periods = 3;
    CosimulationState one;
    const CosimulationResult r = cosimulate(model, dampers, whole, one);
    REQUIRE(r.outcome == dem::Outcome::kCompleted);
    CHECK(!r.continued);
    SteadyStateRun first = o, second = o;
    first.analysed_periods = 2;
    second.analysed_periods = 3;
    CosimulationState state;
    const CosimulationResult a = cosimulate(model, dampers, first, state);
    REQUIRE(a.outcome == dem::Outcome::kCompleted);
    REQUIRE(state.started());
    CHECK(state.excitation_phase_rad == phase);
    CHECK(state.steps == a.steps);
    second.excitation_phase_rad = 1.0;  // ignored: the continuation starts at the state's phase
    const CosimulationResult b = cosimulate(model, dampers, second, state);
    REQUIRE(b.outcome == dem::Outcome::kCompleted);
    CHECK(b.continued);
    CHECK(b.settling_steps == 0);
    CHECK(b.time_step_s == a.time_step_s);
    CHECK(b.start_time_s == Approx(a.simulated_time_s).epsilon(1e-14));
    CHECK(b.history.time_s.front() == Approx(a.simulated_time_s).epsilon(1e-14));
    // Bit-identical end state: modes, every particle, the container.
    CHECK(a.steps + b.steps == r.steps);
    CHECK(state.modal_displacements[0] == one.modal_displacements[0]);
    CHECK(state.modal_velocities[0] == one.modal_velocities[0]);
    CHECK(state.worlds[0].state_hash() == one.worlds[0].state_hash());
    CHECK(b.steady_state.site_amplitudes_m[0] == r.steady_state.site_amplitudes_m[0]);
    // The ledger: each run's closes, and the sum of the two is the combined run's (round-off).
    const auto& ea = a.energy;
    const auto& eb = b.energy;
    const auto& e = r.energy;
    const double w = ea.excitation_work_j + eb.excitation_work_j;
    const double dissipated = ea.structural_damping_j + eb.structural_damping_j + ea.dem_dissipated_j() +
                              eb.dem_dissipated_j();
    const double delta = ea.delta_structure_kinetic_j + eb.delta_structure_kinetic_j + ea.delta_structure_potential_j +
                         eb.delta_structure_potential_j + ea.delta_bed_kinetic_j + eb.delta_bed_kinetic_j +
                         ea.delta_bed_potential_j + eb.delta_bed_potential_j + ea.delta_bed_elastic_j +
                         eb.delta_bed_elastic_j;
    INFO("W " << w << " J, D " << dissipated << " J, ΔE " << delta << " J; combined error " << e.relative_error);
    CHECK(e.dem_dissipated_j() > 0.1 * e.structural_damping_j);  // real impacts
    CHECK(w == Approx(e.excitation_work_j).epsilon(1e-12));
    CHECK(dissipated == Approx(e.structural_damping_j + e.dem_dissipated_j()).epsilon(1e-12));
    CHECK(std::abs(w - dissipated - delta) / std::max(std::abs(w), dissipated) < 0.01);
    CHECK(std::abs((w - dissipated - delta) - e.excitation_work_j + e.structural_damping_j + e.dem_dissipated_j() +
                   e.delta_structure_kinetic_j + e.delta_structure_potential_j + e.delta_bed_kinetic_j +
                   e.delta_bed_potential_j + e.delta_bed_elastic_j) < 1e-12 * std::abs(w));
  }
}

// A stepped sine: the next frequency continues the state at the phase where the last ended;
// with a carried step that does not divide the new period the frequency is the nearest whole
// number of steps (a warning), and a state that does not fit is refused naming the field.
TEST_CASE("a continuation at a new frequency keeps the step, the phase and the bed, and checks its inputs",
          "[cosimulation]") {
  const ModalModel model = one_dof(10.0, 0.02, 1.0, 1.0, 0.0, 0.8);
  const std::vector<CosimulationDamper> dampers{tip_damper(lone_sphere(), 0.25)};
  SteadyStateRun o;
  o.excitation.kind = CosimulationExcitationKind::kBaseTranslation;
  o.excitation.direction = {0.0, 1.0};
  o.excitation.amplitude = 1e-4;
  o.excitation.frequency_hz = 8.0;
  o.excitation_phase_rad = kPi / 2;
  o.analysed_periods = 2;
  CosimulationState state;
  const CosimulationResult a = cosimulate(model, dampers, o, state);
  REQUIRE(a.outcome == dem::Outcome::kCompleted);
  o.excitation.frequency_hz = 8.37;
  const CosimulationResult b = cosimulate(model, dampers, o, state);
  REQUIRE(b.outcome == dem::Outcome::kCompleted);
  CHECK(b.time_step_s == a.time_step_s);
  const double N = std::round(1.0 / (8.37 * a.time_step_s));
  CHECK(b.steady_state.frequency_hz == Approx(1.0 / (N * a.time_step_s)).epsilon(1e-12));
  CHECK(std::abs(b.steady_state.frequency_hz - 8.37) <= 8.37 / (2 * N) * (1 + 1e-9));
  CHECK(state.excitation_phase_rad == Approx(kPi / 2).epsilon(1e-12));
  // The junction at ψ = π/2: the base at U with velocity 0 on both sides, so b's first site
  // position is a's last, y = b q + U (b = 1), and the container did not jump.
  CHECK(b.history.site_displacement_m(0, 0) == Approx(a.final_modal_displacements[0] + 1e-4).epsilon(1e-12));
  CHECK(a.final_container_states[0].position_m[0] == Approx(a.final_modal_displacements[0] + 1e-4).epsilon(1e-12));
  // Misfits: another amplitude, initial values, a state for other dampers.
  SteadyStateRun bad = o;
  bad.excitation.amplitude = 2e-4;
  bad.initial_modal_displacements = Eigen::VectorXd::Constant(1, 0.0);
  try {
    cosimulate(model, dampers, bad, state);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::Contains("cosimulation.excitation.amplitude = 0.0002: must be the state's"));
    CHECK_THAT(what, Catch::Contains("must be empty when continuing"));
  }
  CHECK_THROWS_WITH(cosimulate(model, {dampers[0], dampers[0]}, o, state), Catch::Contains("holds 1 world(s) for 2"));
}

// The forced start (a decay released from steady forced vibration): the beds are driven in
// the start pose's motion (rising to 1.25 times it and easing back) for whole periods before
// the coupling, and the ledger opens after
// it, so the energy account of the coupled run still closes (1 %, as without it) while the
// bed it starts from is another one (impacting spheres: the decay's history differs). The
// forced steps are the periods rounded to whole steps, counted with the settling.
TEST_CASE("a forced start drives the beds before the release and the ledger still closes", "[cosimulation]") {
  const dem::WorldOptions world = bed(0.005, {0.03, 0.0201, 0.0201}, {1, 2, 2}, 2e8, {0.0, 0.0, -9.80665},
                                      dem::InitialPlacement::kCollectedLattice);
  const ModalModel model = one_dof(10.0, 0.01, 0.1);
  DecayRun o;
  o.initial_modal_displacements = Eigen::VectorXd::Constant(1, 0.01);
  o.duration_s = 0.3;
  const CosimulationResult rest = cosimulate(model, {tip_damper(world, 0.02)}, o);
  o.forced_start_periods = 3;
  o.forced_start_frequency_hz = 10.0;
  o.forced_start_peak_factor = 1.25;
  const CosimulationResult forced = cosimulate(model, {tip_damper(world, 0.02)}, o);
  REQUIRE(forced.outcome == dem::Outcome::kCompleted);
  CHECK(forced.settling_steps - rest.settling_steps == std::llround(3 / (10.0 * forced.time_step_s)));
  CHECK(forced.history.modal_displacements(0, 0) == rest.history.modal_displacements(0, 0));  // the same release
  CHECK(forced.history.modal_displacements.col(0) != rest.history.modal_displacements.col(0));
  CHECK(forced.energy.dem_dissipated_j() > 0.1 * forced.energy.structural_damping_j);
  CHECK(forced.energy.relative_error < 0.01);

  o.initial_modal_velocities = Eigen::VectorXd::Constant(1, 0.1);
  o.forced_start_frequency_hz = 0.0;
  o.forced_start_peak_factor = 0.5;
  try {
    cosimulate(model, {tip_damper(world, 0.02)}, o);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    CHECK_THAT(e.what(), Catch::Contains("forced_start_frequency_hz = 0: must be > 0"));
    CHECK_THAT(e.what(), Catch::Contains("the start must be at rest"));
    CHECK_THAT(e.what(), Catch::Contains("forced_start_peak_factor = 0.5: must be in [1, 10]"));
  }
}
