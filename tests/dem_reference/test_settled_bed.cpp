// The settled bed (formulas::LatticeBed::settled_clearance_m) against the DEM: a lattice
// stacked two high does not keep its simple cubic order once the container moves; its
// spheres drop onto the base as far as the base holds them.
#include <catch2/catch.hpp>

#include <cmath>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace {

namespace dr = pdamp::dem_reference;

struct Settled {
  int bottom = 0;        ///< spheres resting on the base
  double clearance = 0;  ///< what the world reports, m
};

/// `count` steel spheres (r = 2.5 mm, softened to E/1000: only where the spheres come to
/// rest matters here) in a box `length` × 41 × 12 mm, collected at −x, shaken along x at
/// 3.6 Hz and Γ = 0.3 for two periods, then at rest.
Settled shake_and_settle(double length, int count) {
  dr::WorldOptions o;
  auto& c = o.compartments.front();
  c.container.box_inner_size_m = {length, 0.041, 0.012};
  c.particles = {dr::ParticleGroupOptions{count, 0.0025, 0.0, 0}};
  c.particles.front().lot_diameter_variation_m = 0.0;
  o.materials.front().material.youngs_modulus_pa = 206e9 / 1000.0;
  const double f = 3.6, stroke = 0.3 * 9.80665 / std::pow(2.0 * dem_test::kPi * f, 2);
  const dr::HarmonicMotion motion({1.0, 0.0, 0.0}, stroke, f);
  dr::World world(o, motion.state(0.0));
  const double dt = world.time_step_s();
  for (double t = dt; t <= 2.0 / f; t += dt) world.step(motion.state(t));
  const dr::ContainerState rest = [&] {
    dr::ContainerState s = world.container();
    s.velocity_m_s = {0.0, 0.0, 0.0};
    return s;
  }();
  for (double t = 0.0; t < 0.3; t += dt) world.step(rest);
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);
  Settled out;
  const double base = world.container().position_m[2] - 0.006;
  for (int i = 0; i < world.particle_count(); ++i)
    if (world.position(i)[2] - base < 1.5 * 0.0025) ++out.bottom;  // centre r above the base, not 2.73r
  out.clearance = world.clearance_m(0);
  return out;
}

}  // namespace

// Reference: the settled-bed rule (formulas, tests/formulas/test_bed_packing.cpp): each
// lane's spheres drop onto the base as far as it holds them. 64 spheres of 8 lanes × 2 high
// in 28 mm: 5 of each lane's 8 on the base (40; the simple cubic lattice has 32 there), 3 mm
// of travel instead of 8 mm; 112 in 40 mm: all 8 rows of every lane on the base (64), wall
// to wall, 0 mm instead of 5 mm. Exact counts (a sphere is on the base or a radius above
// it). A softer contact (E/100, the same two periods) left 32 on the base, spread with the
// upper 32 nested between them over 24.3 mm: 3.7 mm of travel, also far from the lattice's 8.
TEST_CASE("a bed stacked two high settles into the bottom rows the settled clearance counts", "[dem_reference]") {
  const Settled narrow = shake_and_settle(0.028, 64);
  CHECK(narrow.clearance == Approx(0.003).margin(1e-12));
  CHECK(narrow.bottom == 40);
  const Settled medium = shake_and_settle(0.040, 112);
  CHECK(medium.clearance == Approx(0.0).margin(1e-12));
  CHECK(medium.bottom == 64);
}
