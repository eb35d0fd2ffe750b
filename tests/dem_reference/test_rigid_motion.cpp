// Prescribed rigid-body motion of the container with rotation (World::step(ContainerState)):
// the returned force and moment against rigid-body mechanics and statics.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using dem_test::kPi;

constexpr double kRadius = 0.005;
constexpr double kGravity = 9.80665;

dr::Vec3 add(const dr::Vec3& a, const dr::Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
dr::Vec3 sub(const dr::Vec3& a, const dr::Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
dr::Vec3 scale(double s, const dr::Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
dr::Vec3 cross(const dr::Vec3& a, const dr::Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const dr::Vec3& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

/// Rotation by angle a about the unit axis u (Rodrigues), body → world, row-major.
dr::Matrix3 rotation(const dr::Vec3& u, double a) {
  const double c = std::cos(a), s = std::sin(a), k = 1.0 - c;
  return {c + u[0] * u[0] * k,        u[0] * u[1] * k - u[2] * s, u[0] * u[2] * k + u[1] * s,
          u[1] * u[0] * k + u[2] * s, c + u[1] * u[1] * k,        u[1] * u[2] * k - u[0] * s,
          u[2] * u[0] * k - u[1] * s, u[2] * u[1] * k + u[0] * s, c + u[2] * u[2] * k};
}
dr::Vec3 rotate_vector(const dr::Matrix3& r, const dr::Vec3& b) {
  return {r[0] * b[0] + r[1] * b[1] + r[2] * b[2], r[3] * b[0] + r[4] * b[1] + r[5] * b[2],
          r[6] * b[0] + r[7] * b[1] + r[8] * b[2]};
}
/// Body-frame coordinates of the world point x for the container state s.
dr::Vec3 to_body(const dr::ContainerState& s, const dr::Vec3& x) {
  const auto d = sub(x, s.position_m);
  const auto& r = s.orientation;
  return {r[0] * d[0] + r[3] * d[1] + r[6] * d[2], r[1] * d[0] + r[4] * d[1] + r[7] * d[2],
          r[2] * d[0] + r[5] * d[1] + r[8] * d[2]};
}

// The turntable: the body spins at ω about the world z axis through its origin, which
// sits at kPivot (not the world origin, so that the moment's reference point matters).
constexpr double kOmega = 8.0;  // rad/s
const dr::Vec3 kPivot{0.3, -0.2, 0.1};
const dr::Vec3 kAxis{0.0, 0.0, 1.0};

dr::ContainerState turntable(double t) {
  dr::ContainerState s;
  s.position_m = kPivot;
  s.orientation = rotation(kAxis, kOmega * t);
  s.angular_velocity_rad_s = scale(kOmega, kAxis);
  return s;
}

}  // namespace

// Reference: rigid-body mechanics. A sphere co-rotating with a container that spins at
// ω about a fixed axis moves on a circle of radius r_c; the only force on it is the
// wall's, which must be the centripetal m ω² r_c towards the axis; its moment about the
// body origin is (contact point − origin) × F. The container is a cylinder parallel to
// the spin axis but 3 cm off it, and the sphere touches its mantle at the point farthest
// from the spin axis, 2 cm above the origin: there the centrifugal potential along the
// wall is least, so the sphere stays put (against a flat wall it would sit on a
// potential ridge and roll off, as the DEM rightly shows). Tolerances: 1% on the force
// (the start's Hertz oscillation decays within a few ms, read after 50 ms);
// rounding on the moment, which is the same force at the contact point; 0.1 µm on the
// position in the container: the static Hertz overlap (~20 nm) and the slow rocking
// about the equilibrium that the start leaves.
TEST_CASE("a sphere in a spinning container is held on its circle by the centripetal wall force", "[dem_reference]") {
  dr::WorldOptions o = dem_test::box_world(1, kRadius, 0.7, 0.3);
  auto& c = o.compartments.front();
  c.container.shape = pdamp::formulas::ContainerShape::kCylinder;
  c.container.cylinder_axis = 2;
  c.container.cylinder_inner_radius_m = 0.07;
  c.container.cylinder_inner_length_m = 0.06;
  c.offset_m = {0.03, 0.0, 0.02};
  c.collect_axis = 2;  // the initial lattice (replaced below) is built along the cylinder
  const dr::ContainerState start = turntable(0.0);
  dr::World world(o, start);
  const dr::Vec3 body{0.1 - kRadius, 0.0, 0.02};
  const dr::Vec3 at = add(kPivot, rotate_vector(start.orientation, body));
  // Co-rotating: velocity ω × (x − pivot), spin ω (at rest in the container).
  world.set_particle_state(0, at, cross(start.angular_velocity_rad_s, sub(at, kPivot)), start.angular_velocity_rad_s);
  const double m = world.mass(0);

  double worst_force = 0.0, worst_moment = 0.0, worst_drift = 0.0;
  int samples = 0;
  while (world.time_s() < 0.3) {
    const auto& load = world.step(turntable(world.time_s() + world.time_step_s()));
    if (world.time_s() < 0.05) continue;
    const auto p = world.position(0);
    const auto state = turntable(world.time_s());
    // Radial vector from the spin axis to the centre, and the expected centripetal force.
    const dr::Vec3 radial{p[0] - kPivot[0], p[1] - kPivot[1], 0.0};
    const dr::Vec3 expected = scale(-m * kOmega * kOmega, radial);
    worst_force = std::max(worst_force, norm(sub(load.force_n, expected)) / norm(expected));
    // Contact point: one radius from the centre, away from the cylinder's axis.
    const dr::Vec3 axis_point = add(kPivot, rotate_vector(state.orientation, c.offset_m));
    const dr::Vec3 outward{p[0] - axis_point[0], p[1] - axis_point[1], 0.0};
    const dr::Vec3 contact = add(p, scale(kRadius / norm(outward), outward));
    const dr::Vec3 moment = cross(sub(contact, kPivot), load.force_n);
    worst_moment = std::max(worst_moment, norm(sub(load.moment_nm, moment)) / norm(moment));
    worst_drift = std::max(worst_drift, norm(sub(to_body(state, p), body)));
    ++samples;
  }
  INFO("samples " << samples << ": force error " << worst_force << " of m w^2 r_c = "
                  << m * kOmega * kOmega * (0.1 - kRadius) << " N, moment error " << worst_moment
                  << ", drift in the container " << worst_drift << " m");
  CHECK(samples > 1000);
  CHECK(worst_force < 0.01);
  CHECK(worst_moment < 1e-9);
  CHECK(worst_drift < 1e-7);
}

// Reference: Newton's first law. A sphere touching nothing moves in a straight line
// whatever the container does, and the container exerts no force or moment: both are
// exactly zero, and the path is straight to rounding. (A world always holds particles:
// a compartment without particles is refused, checked at the end.)
TEST_CASE("a container translating and rotating around a free sphere returns zero load", "[dem_reference]") {
  dr::WorldOptions o = dem_test::box_world(1, kRadius, 0.7, 0.3);
  o.gravity_m_s2 = {0.0, 0.0, 0.0};
  const dr::Vec3 axis{1.0 / std::sqrt(14.0), 2.0 / std::sqrt(14.0), 3.0 / std::sqrt(14.0)};
  const double omega = 2.0 * kPi * 5.0;
  const auto shaken = [&](double t) {
    dr::ContainerState s;
    s.position_m = {0.004 * std::sin(omega * t), -0.003 * std::sin(omega * t), 0.002 * std::cos(omega * t)};
    s.velocity_m_s = {0.004 * omega * std::cos(omega * t), -0.003 * omega * std::cos(omega * t),
                      -0.002 * omega * std::sin(omega * t)};
    s.orientation = rotation(axis, 0.4 * std::sin(omega * t));
    s.angular_velocity_rad_s = scale(0.4 * omega * std::cos(omega * t), axis);
    return s;
  };
  dr::World world(o, shaken(0.0));
  const dr::Vec3 p0{0.001, 0.002, -0.001}, v0{0.01, -0.005, 0.008};
  world.set_particle_state(0, p0, v0, {0.0, 0.0, 0.0});
  bool zero = true;
  while (world.time_s() < 0.5) {
    const auto& load = world.step(shaken(world.time_s() + world.time_step_s()));
    for (int a = 0; a < 3; ++a) zero &= load.force_n[a] == 0.0 && load.moment_nm[a] == 0.0;
  }
  CHECK(zero);
  const auto p = world.position(0);
  CHECK(norm(sub(p, add(p0, scale(world.time_s(), v0)))) < 1e-12);
  CHECK(world.energy().container_work_j == 0.0);

  o.compartments.front().particles.front().count = 0;
  CHECK_THROWS_AS(dr::World(o), std::invalid_argument);
}

// Reference: statics. A bed at rest in a static container under gravity is held by the
// walls alone (particle–particle forces cancel in pairs), so the container's force on
// the particles is −Σ m_i g and its moment about the body origin o is −Σ (x_i − o) × m_i g.
// The container is turned by a general rotation and its origin sits away from the bed,
// so all three components count. 0.1%: after 0.1 s the damped bed's residual
// accelerations are far below that.
TEST_CASE("a settled bed in a static turned container loads it with its weight", "[dem_reference]") {
  dr::WorldOptions o;
  auto& c = o.compartments.front();
  c.container.box_inner_size_m = {0.06, 0.04, 0.05};
  c.offset_m = {0.03, 0.01, -0.02};
  c.particles = {dr::ParticleGroupOptions{18, kRadius, 0.0, 0}};
  c.particles.front().lot_diameter_variation_m = 0.0;  // identical spheres (perfect lattice)
  o.default_pair.restitution.constant = 0.5;
  o.default_pair.friction = 0.4;
  o.default_pair.rolling_friction = 0.1;
  dr::ContainerState tilted;
  tilted.position_m = {0.1, 0.2, -0.3};
  tilted.orientation = rotation({0.6, 0.0, 0.8}, 0.08);
  dr::World world(o, tilted);
  while (world.time_s() < 0.1) world.step(tilted);
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);

  const dr::Vec3 g = o.gravity_m_s2;
  dr::Vec3 weight{0.0, 0.0, 0.0}, weight_moment{0.0, 0.0, 0.0};
  for (int i = 0; i < world.particle_count(); ++i) {
    const auto w = scale(world.mass(i), g);
    weight = add(weight, w);
    weight_moment = add(weight_moment, cross(sub(world.position(i), tilted.position_m), w));
  }
  const auto& load = world.load();
  const double force_error = norm(add(load.force_n, weight)) / norm(weight);
  const double moment_error = norm(add(load.moment_nm, weight_moment)) / norm(weight_moment);
  INFO("force " << load.force_n[0] << ", " << load.force_n[1] << ", " << load.force_n[2] << " N vs weight "
                << norm(weight) << " N: error " << force_error << "; moment error " << moment_error
                << " of " << norm(weight_moment) << " N m");
  CHECK(force_error < 1e-3);
  CHECK(moment_error < 1e-3);
  CHECK(norm(weight) == Approx(world.bed_mass_kg() * kGravity).epsilon(1e-12));
}
