// Several compartments moving as one damper body (multi-layer dampers): the body load
// is the sum of the compartments' loads, each compartment reports its own clearance.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;
using dem_test::kPi;

constexpr double kFrequency = 10.0;   // Hz
constexpr double kStroke = 0.005;     // m, Γ ≈ 2
constexpr double kTilt = 0.05;        // rad, rocking amplitude about y
constexpr double kDuration = 0.2;     // s, two periods

/// Compartment A: a box with a 2×2×2 lattice of 5 mm spheres against its −x wall.
dr::CompartmentOptions compartment_a() {
  dr::CompartmentOptions c;
  c.container.shape = pdamp::formulas::ContainerShape::kBox;
  c.container.box_inner_size_m = {0.06, 0.03, 0.03};
  c.offset_m = {0.0, 0.0, 0.0};
  c.particles = {dr::ParticleGroupOptions{8, 0.005, 0.0, 0}};
  // Identical spheres: with the ball-lot tolerance a compartment's radii would depend on
  // the draws of the compartments before it, and superposition would not be exact.
  c.particles.front().lot_diameter_variation_m = 0.0;
  c.lattice_counts = {2, 2, 2};
  return c;
}

/// Compartment B: a cylinder along x with a 3×2×1 lattice of 4 mm spheres. Its volume
/// overlaps A's on purpose: were particles of different compartments to interact, the
/// two beds would collide.
dr::CompartmentOptions compartment_b() {
  dr::CompartmentOptions c;
  c.container.shape = pdamp::formulas::ContainerShape::kCylinder;
  c.container.cylinder_axis = 0;
  c.container.cylinder_inner_radius_m = 0.012;
  c.container.cylinder_inner_length_m = 0.08;
  c.offset_m = {0.01, 0.004, 0.006};
  c.particles = {dr::ParticleGroupOptions{6, 0.004, 0.0, 0}};
  // Identical spheres: with the ball-lot tolerance a compartment's radii would depend on
  // the draws of the compartments before it, and superposition would not be exact.
  c.particles.front().lot_diameter_variation_m = 0.0;
  c.lattice_counts = {3, 2, 1};
  return c;
}

dr::WorldOptions body_with(const std::vector<dr::CompartmentOptions>& compartments, double time_step_s) {
  dr::WorldOptions o;
  o.compartments = compartments;
  o.default_pair.restitution.constant = 0.6;
  o.default_pair.friction = 0.3;
  o.default_pair.rolling_friction = 0.01;
  o.integration.time_step_s = time_step_s;
  return o;
}

/// Body → world rotation by angle a about y.
dr::Matrix3 rotation_y(double a) {
  const double c = std::cos(a), s = std::sin(a);
  return {c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c};
}

/// The damper body shaken along x and rocked about y at the same frequency.
dr::ContainerState body_state(double t) {
  const double omega = 2.0 * kPi * kFrequency;
  dr::ContainerState s;
  s.position_m = {kStroke * std::sin(omega * t), 0.0, 0.0};
  s.velocity_m_s = {kStroke * omega * std::cos(omega * t), 0.0, 0.0};
  s.orientation = rotation_y(kTilt * std::sin(omega * t + 0.5));
  s.angular_velocity_rad_s = {0.0, kTilt * omega * std::cos(omega * t + 0.5), 0.0};
  return s;
}

/// Load history (force and moment, 6 values per step) and final positions of one run.
struct Run {
  std::vector<double> load;
  std::vector<dr::Vec3> positions;
  std::vector<double> clearances;
};

Run run(const dr::WorldOptions& options) {
  dr::World world(options, body_state(0.0));
  Run out;
  while (world.time_s() < kDuration) {
    const auto& load = world.step(body_state(world.time_s() + world.time_step_s()));
    out.load.insert(out.load.end(), load.force_n.begin(), load.force_n.end());
    out.load.insert(out.load.end(), load.moment_nm.begin(), load.moment_nm.end());
  }
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);
  for (int i = 0; i < world.particle_count(); ++i) out.positions.push_back(world.position(i));
  for (int c = 0; c < world.compartment_count(); ++c) out.clearances.push_back(world.clearance_m(c));
  return out;
}

}  // namespace

// Reference: superposition. Particles of different compartments never interact, so the
// body's load is the sum of the loads each compartment produces alone under the same
// motion and step. Each particle's forces are summed over its own contacts in list
// order, so the trajectories must agree bit for bit; only the body's load sums the two
// compartments in another order: 1e-12 of the peak (rounding of a sum of ~20 terms).
// The motion shakes and rocks the body so that moments and the rotated walls count.
TEST_CASE("the load of two compartments is the sum of their loads alone", "[dem_reference]") {
  const auto a = compartment_a();
  const auto b = compartment_b();
  // One step for the three runs: the combined body's automatic bound (B's smaller spheres).
  const double dt = dr::time_step_bound(body_with({a, b}, 0.0)).max_time_step_s;
  const Run both = run(body_with({a, b}, dt));
  const Run alone_a = run(body_with({a}, dt));
  const Run alone_b = run(body_with({b}, dt));
  REQUIRE(both.load.size() == alone_a.load.size());
  REQUIRE(both.load.size() == alone_b.load.size());

  double peak = 0.0, worst = 0.0;
  for (std::size_t k = 0; k < both.load.size(); ++k) {
    peak = std::max(peak, std::abs(both.load[k]));
    worst = std::max(worst, std::abs(both.load[k] - (alone_a.load[k] + alone_b.load[k])));
  }
  INFO("steps " << both.load.size() / 6 << ", peak load component " << peak << ", largest difference " << worst);
  CHECK(peak > 0.1);  // the beds do hit the walls (bed weight ~0.4 N)
  CHECK(worst <= 1e-12 * peak);

  REQUIRE(both.positions.size() == alone_a.positions.size() + alone_b.positions.size());
  bool identical = true;
  for (std::size_t i = 0; i < alone_a.positions.size(); ++i) identical &= both.positions[i] == alone_a.positions[i];
  for (std::size_t i = 0; i < alone_b.positions.size(); ++i) {
    identical &= both.positions[alone_a.positions.size() + i] == alone_b.positions[i];
  }
  CHECK(identical);
}

// Reference: geometry. The clearance of a collected bed is the container's inner length
// along the collect axis less the settled bed's extent (docs/theory.md §9, "Clearance of a
// real bed", formulas::LatticeBed::settled_clearance_m): A's 2 × 2 × 2 lattice is two high
// across gravity, so each lane's 4 spheres settle onto the base, 0.06 − 4·0.01 = 0.02 m
// (its lattice would leave 0.04 m); B is a cylinder, 0.08 − 3·0.008 = 0.056 m; whether
// the compartment is alone or not.
TEST_CASE("each compartment reports the clearance of its own bed", "[dem_reference]") {
  const auto a = compartment_a();
  const auto b = compartment_b();
  dr::World world(body_with({a, b}, 0.0));
  REQUIRE(world.compartment_count() == 2);
  CHECK(world.clearance_m(0) == Approx(0.06 - 4.0 * 0.01).epsilon(1e-12));
  CHECK(world.clearance_m(1) == Approx(0.08 - 3.0 * 0.008).epsilon(1e-12));
  CHECK(dr::World(body_with({b}, 0.0)).clearance_m(0) == world.clearance_m(1));
  // Particles are numbered compartment by compartment and carry their compartment.
  for (int i = 0; i < world.particle_count(); ++i) CHECK(world.compartment(i) == (i < 8 ? 0 : 1));
  // Each bed starts against its own −x wall: A's at −0.03 m, B's at 0.01 − 0.04 m.
  double lowest[2] = {1.0, 1.0};
  for (int i = 0; i < world.particle_count(); ++i) {
    double& left = lowest[world.compartment(i)];
    left = std::min(left, world.position(i)[0] - world.radius(i));
  }
  CHECK(lowest[0] == Approx(-0.03).margin(1e-12));
  CHECK(lowest[1] == Approx(0.01 - 0.04).margin(1e-12));
  CHECK(world.bed_mass_kg() == Approx(8.0 * 7850.0 * 4.0 / 3.0 * kPi * 0.005 * 0.005 * 0.005 +
                                      6.0 * 7850.0 * 4.0 / 3.0 * kPi * 0.004 * 0.004 * 0.004)
                                   .epsilon(1e-12));
}
