// Inner structures of a compartment (plates and pins) against independent references:
// Hertz statics, the pair's restitution, energy conservation and the reflection law.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using dem_test::box_world;
using dem_test::kPi;

constexpr double kRadius = 0.005;
constexpr double kGravity = 9.80665;
// Steel (the default material 0) and aluminium (material 1, used by the structures so
// that a wrong material choice shows).
constexpr double kSteelE = 210e9, kSteelNu = 0.3, kSteelRho = 7850.0;
constexpr double kAluE = 70e9, kAluNu = 0.33, kAluRho = 2700.0;

/// 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂ (docs/theory.md §5), written out here rather than taken
/// from formulas/ so that the reference does not share code with the DEM.
double effective_modulus(double e1, double nu1, double e2, double nu2) {
  return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
}

double steel_sphere_mass() { return kSteelRho * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius; }

/// Box world of one steel sphere (0.1 m cube) with aluminium as material 1; the pair
/// steel–aluminium gets its own restitution so that it differs from the default pair.
dr::WorldOptions structure_world(double steel_steel_eps, double steel_alu_eps, double friction) {
  dr::WorldOptions o = box_world(1, kRadius, steel_steel_eps, friction);
  o.compartments.front().container.box_inner_size_m = {0.1, 0.1, 0.1};
  o.materials.push_back(dr::MaterialOptions{"aluminium", {kAluRho, kAluE, kAluNu}});
  dr::ContactPairOptions pair;
  pair.material_a = 0;
  pair.material_b = 1;
  pair.restitution.constant = steel_alu_eps;
  pair.friction = friction;
  o.pairs.push_back(pair);
  return o;
}

double norm(const dr::Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/// Kinetic energy of particle 0 (translation and rotation), J.
double kinetic(const dr::World& world) {
  const auto v = world.velocity(0);
  const auto w = world.angular_velocity(0);
  const double m = world.mass(0);
  const double inertia = 0.4 * m * world.radius(0) * world.radius(0);
  return 0.5 * m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5 * inertia * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
}

/// Gap between a sphere (centre p, radius r) and an axis-aligned box, computed
/// independently of the DEM's wall code (closest point by clamping), m.
double box_gap(const dr::Vec3& p, double r, const dr::Vec3& centre, const dr::Vec3& size) {
  double d2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    const double excess = std::abs(p[a] - centre[a]) - 0.5 * size[a];
    if (excess > 0.0) d2 += excess * excess;
  }
  return std::sqrt(d2) - r;
}

/// Gap between a sphere and a finite solid cylinder of axis z, m (independent code).
double pin_gap(const dr::Vec3& p, double r, const dr::Vec3& centre, double radius, double length) {
  const double rho = std::hypot(p[0] - centre[0], p[1] - centre[1]);
  const double radial = std::max(rho - radius, 0.0);
  const double axial = std::max(std::abs(p[2] - centre[2]) - 0.5 * length, 0.0);
  return std::hypot(radial, axial) - r;
}

/// Velocity of a frictionless impact on a fixed surface of unit normal n (pointing to
/// the sphere): the normal component is reversed and scaled by ε, the tangential one
/// kept (the rigid-body impact law; ε = 1 is a mirror reflection).
dr::Vec3 frictionless_rebound(const dr::Vec3& v, const dr::Vec3& n, double eps) {
  const double vn = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
  return {v[0] - (1.0 + eps) * vn * n[0], v[1] - (1.0 + eps) * vn * n[1], v[2] - (1.0 + eps) * vn * n[2]};
}

/// Angle between two vectors, degrees.
double angle_deg(const dr::Vec3& a, const dr::Vec3& b) {
  const double c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (norm(a) * norm(b));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
}

/// The pin of the pin tests: aluminium, axis z through the box centre.
constexpr double kPinRadius = 0.004;
constexpr double kPinLength = 0.06;

dr::WorldOptions pin_world(double eps, double friction) {
  dr::WorldOptions o = structure_world(0.9, eps, friction);
  dr::PinOptions pin;
  pin.centre_m = {0.0, 0.0, 0.0};
  pin.axis = 2;
  pin.radius_m = kPinRadius;
  pin.length_m = kPinLength;
  pin.material = 1;
  o.compartments.front().pins.push_back(pin);
  return o;
}

/// Velocity after one sphere travelling along +x at speed v with impact parameter b
/// (offset along y) has hit the pin.
dr::Vec3 pin_rebound(double eps, double b, double v) {
  dr::World world(pin_world(eps, 0.0));
  const double gap = 20.0 * v * world.time_step_s();
  const double reach = kRadius + kPinRadius;
  const double x0 = -std::sqrt(reach * reach - b * b) - gap;
  world.set_particle_state(0, {x0, b, 0.0}, {v, 0.0, 0.0}, {0.0, 0.0, 0.0});
  dem_test::run_one_impact(world, 1'000'000);
  return world.velocity(0);
}

struct BouncingRun {
  int impacts = 0;
  int plate_hits = 0;
  int pin_hits = 0;
  double drift = 0.0;             ///< relative change of the energy over the run
  double worst_impact = 0.0;      ///< largest relative change over one impact
  double dissipated_j = 0.0;
};

/// One elastic frictionless sphere bouncing for 1.5 s in a box with an aluminium plate
/// and a steel pin, no gravity; the energy is read between contacts.
BouncingRun elastic_bouncing(int steps_per_contact) {
  dr::WorldOptions o = structure_world(1.0, 1.0, 0.0);
  dr::PlateOptions plate;
  plate.centre_m = {0.015, -0.01, 0.0};
  plate.size_m = {0.004, 0.05, 0.07};
  plate.material = 1;
  o.compartments.front().plates.push_back(plate);
  dr::PinOptions pin;
  pin.centre_m = {-0.02, 0.02, -0.01};
  pin.axis = 2;
  pin.radius_m = 0.01;
  pin.length_m = 0.06;
  o.compartments.front().pins.push_back(pin);
  o.integration.max_impact_speed_m_s = 2.0;
  o.integration.steps_per_contact = steps_per_contact;
  dr::World world(o);
  world.set_particle_state(0, {-0.03, -0.03, 0.03}, {1.1, 0.73, -0.41}, {0.0, 0.0, 0.0});
  const double e0 = kinetic(world);
  double before = e0;
  const dr::ContainerState rest;
  BouncingRun run;
  bool touching = false;
  while (world.time_s() < 1.5 || touching) {
    world.step(rest);
    const bool now = world.contact_census({0.0, 0.0, 0.0}).touching_walls > 0;
    if (now && !touching) {
      ++run.impacts;
      const auto p = world.position(0);
      if (box_gap(p, kRadius, plate.centre_m, plate.size_m) < 1e-6) ++run.plate_hits;
      if (pin_gap(p, kRadius, pin.centre_m, pin.radius_m, pin.length_m) < 1e-6) ++run.pin_hits;
    }
    if (!now && touching) {
      const double after = kinetic(world);
      run.worst_impact = std::max(run.worst_impact, std::abs(after - before) / e0);
      before = after;
    }
    touching = now;
  }
  run.drift = (kinetic(world) - e0) / e0;
  run.dissipated_j = world.energy().dissipated_j();
  return run;
}

}  // namespace

// Reference: Hertz statics. A sphere at rest on a flat surface carries its weight with
// the overlap δ = (3mg/(4E*√R))^{2/3} (docs/theory.md §5 force law set equal to mg), so its
// centre sits at plate top + r − δ. With E* of steel on aluminium, δ ≈ 38 nm. The
// tolerance of 1% of δ (0.4 nm) leaves room for the decaying oscillation at the end of
// the 0.25 s run only: leapfrog's equilibrium is the exact force balance.
TEST_CASE("a sphere dropped on an internal plate rests on its top at the Hertz static overlap", "[dem_reference]") {
  dr::WorldOptions o = structure_world(0.5, 0.5, 0.3);
  o.gravity_m_s2 = {0.0, 0.0, -kGravity};
  dr::PlateOptions plate;
  plate.centre_m = {0.0, 0.0, 0.0};
  plate.size_m = {0.06, 0.06, 0.004};
  plate.material = 1;
  o.compartments.front().plates.push_back(plate);
  dr::World world(o);
  const double top = 0.5 * plate.size_m[2];
  const dr::Vec3 start{0.01, 0.005, top + kRadius + 0.005};
  world.set_particle_state(0, start, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0});
  const dr::ContainerState rest;
  while (world.time_s() < 0.25) world.step(rest);

  const double m = steel_sphere_mass();
  const double e_star = effective_modulus(kSteelE, kSteelNu, kAluE, kAluNu);
  const double delta = std::pow(3.0 * m * kGravity / (4.0 * e_star * std::sqrt(kRadius)), 2.0 / 3.0);
  const auto p = world.position(0);
  const double expected = top + kRadius - delta;
  INFO("centre z " << p[2] << " m, expected " << expected << " m (static overlap " << delta
                   << " m), measured overlap " << top + kRadius - p[2] << " m");
  CHECK(std::abs(p[2] - expected) < 0.01 * delta);
  // A vertical drop stays vertical (no lateral force on a flat top).
  CHECK(std::abs(p[0] - start[0]) < 1e-12);
  CHECK(std::abs(p[1] - start[1]) < 1e-12);
  // The plate carries the whole weight (the container load is on the particles).
  CHECK(world.load().force_n[2] == Approx(m * kGravity).epsilon(1e-6));
  CHECK(norm(world.velocity(0)) < 1e-6);
}

// Reference: the input ε of the steel–aluminium pair (the plate's material), distinct
// from the default pair's 0.9, so that both the impact law on a plate and the plate's
// material choice are checked. 2%: the DEM's tolerance for single impacts.
TEST_CASE("a sphere hitting a vertical plate rebounds with the restitution of the pair", "[dem_reference]") {
  for (const double eps : {0.4, 0.75}) {
    for (const double v : {0.1, 1.0}) {
      dr::WorldOptions o = structure_world(0.9, eps, 0.3);
      dr::PlateOptions plate;
      plate.centre_m = {0.02, 0.0, 0.0};
      plate.size_m = {0.004, 0.06, 0.06};
      plate.material = 1;
      o.compartments.front().plates.push_back(plate);
      dr::World world(o);
      const double face = plate.centre_m[0] - 0.5 * plate.size_m[0];
      const double gap = 20.0 * v * world.time_step_s();
      world.set_particle_state(0, {face - kRadius - gap, 0.003, -0.002}, {v, 0.0, 0.0}, {0.0, 0.0, 0.0});
      dem_test::run_one_impact(world, 1'000'000);
      const auto after = world.velocity(0);
      INFO("epsilon " << eps << ", v " << v << " m/s: rebound " << after[0] / v);
      CHECK(-after[0] / v == Approx(eps).epsilon(0.02));
      CHECK(std::abs(after[1]) < 1e-9 * v);
      CHECK(std::abs(after[2]) < 1e-9 * v);
    }
  }
}

// Reference: conservation of energy. With ε = 1, μ = 0 and no gravity every contact
// (faces, plate faces and edges, pin mantle and rims) is a conservative Hertz spring and
// leapfrog is symplectic: the kinetic energy between contacts must not drift. The
// trajectory is checked to hit both structures repeatedly. Tolerances: a Hertz contact
// begins and ends between steps, which costs each impact a random-signed energy error
// of order (dt/t_c)^{5/2}: measured rms 1.5e-5 per impact at the default 50 steps per
// contact and 5e-7 at 200 (a ratio of 30 ≈ 4^{5/2}; a non-conservative force would
// not shrink so). Hence at 50 steps: each impact within 2e-4, the ~60 impacts together
// within 1e-3 (their random walk is ~1e-4); at 200 steps within 5e-6 and 2e-5.
TEST_CASE("an elastic sphere bouncing between walls plates and pins conserves its energy", "[dem_reference]") {
  for (const auto& [steps, impact_bound, drift_bound] : {std::tuple{50, 2e-4, 1e-3}, std::tuple{200, 5e-6, 2e-5}}) {
    const BouncingRun run = elastic_bouncing(steps);
    INFO(steps << " steps per contact: impacts " << run.impacts << " (plate " << run.plate_hits << ", pin "
               << run.pin_hits << "), relative energy change " << run.drift << ", worst impact "
               << run.worst_impact);
    CHECK(run.plate_hits >= 5);
    CHECK(run.pin_hits >= 5);
    CHECK(run.worst_impact < impact_bound);
    CHECK(std::abs(run.drift) < drift_bound);
    CHECK(run.dissipated_j == 0.0);
  }
}

// Reference: the input ε of the steel–aluminium pair; a head-on hit on the pin axis is
// a normal impact whose normal is the line through the pin axis, so the rebound is
// along −x with speed ε v and no sideways component (symmetry). 2% as for walls.
TEST_CASE("a sphere hitting a pin head on rebounds along the normal with the restitution of the pair", "[dem_reference]") {
  for (const double eps : {0.5, 0.9}) {
    const double v = 0.5;
    const auto after = pin_rebound(eps, 0.0, v);
    INFO("epsilon " << eps << ": rebound " << -after[0] / v << ", sideways " << after[1] << " m/s");
    CHECK(-after[0] / v == Approx(eps).epsilon(0.02));
    CHECK(std::abs(after[1]) < 1e-9 * v);
    CHECK(std::abs(after[2]) < 1e-9 * v);
  }
}

// Reference: the frictionless rigid-body impact law. The normal at first touch is the
// line from the pin axis to the sphere centre, at θ = asin(b/(r+ρ)) from −x; the
// tangential velocity is kept and the normal one reversed and scaled by ε (for ε = 1 a
// mirror reflection, deflection π − 2θ). 1°: the normal turns during
// the contact by the tangential travel over r + ρ, about v sinθ·t_c/(r+ρ) ≈ 0.1°.
TEST_CASE("an off-centre hit on a pin deflects the sphere by the reflection about the contact normal", "[dem_reference]") {
  const double v = 0.5;
  const double reach = kRadius + kPinRadius;
  for (const double eps : {1.0, 0.6}) {
    for (const double fraction : {0.25, 0.5, 0.75}) {
      const double b = fraction * reach;
      const double theta = std::asin(fraction);
      const dr::Vec3 normal{-std::cos(theta), std::sin(theta), 0.0};
      const dr::Vec3 expected = frictionless_rebound({v, 0.0, 0.0}, normal, eps);
      const auto after = pin_rebound(eps, b, v);
      const double deflection = std::atan2(after[1], after[0]) * 180.0 / kPi;
      INFO("epsilon " << eps << ", b/(r+rho) " << fraction << ": deflection " << deflection << " deg, expected "
                      << std::atan2(expected[1], expected[0]) * 180.0 / kPi << " deg, speed " << norm(after)
                      << " vs " << norm(expected) << " m/s");
      CHECK(angle_deg(after, expected) < 1.0);
      CHECK(norm(after) == Approx(norm(expected)).epsilon(0.02));
    }
  }
}

// Reference: Hertz's elastic impact on a flat face, contact time
// t_c = 2.868(m²/(R E*² v))^{1/5} with R* = r (docs/theory.md §5). The pin's end face is flat:
// its stiffness must be the flat one, not the mantle's (whose equivalent radius
// √(r·rρ/(r+ρ)) would lengthen the contact by (r/R_eq)^{1/5}, +8% here). 1%: the contact
// is resolved by ~50 steps (one step = 2%, counted from touch to release so the error
// is a fraction of a step).
TEST_CASE("a sphere hitting the flat end of a pin has the flat Hertz contact time", "[dem_reference]") {
  const double v = 0.5;
  dr::World world(pin_world(1.0, 0.0));
  const double gap = 20.0 * v * world.time_step_s();
  world.set_particle_state(0, {0.001, 0.0, 0.5 * kPinLength + kRadius + gap}, {0.0, 0.0, -v}, {0.0, 0.0, 0.0});
  const dr::ContainerState rest;
  long contact_steps = 0;
  for (long k = 0; k < 1'000'000; ++k) {
    world.step(rest);
    const bool touching = world.contact_census({0.0, 0.0, 0.0}).touching_walls > 0;
    if (touching) ++contact_steps;
    if (contact_steps > 0 && !touching) break;
  }
  const double m = steel_sphere_mass();
  const double e_star = effective_modulus(kSteelE, kSteelNu, kAluE, kAluNu);
  const double t_c = 2.868 * std::pow(m * m / (kRadius * e_star * e_star * v), 0.2);
  const double measured = static_cast<double>(contact_steps) * world.time_step_s();
  INFO("contact time " << measured << " s, Hertz (flat) " << t_c << " s");
  CHECK(measured == Approx(t_c).epsilon(0.01 + world.time_step_s() / t_c));
  CHECK(world.velocity(0)[2] == Approx(v).epsilon(1e-3));
}
