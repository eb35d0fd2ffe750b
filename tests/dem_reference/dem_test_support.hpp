// Shared set-ups of the DEM tests: worlds of a few spheres in a large static box.
#pragma once

#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace dem_test {

namespace dr = pdamp::dem_reference;

inline constexpr double kPi = 3.14159265358979323846;

/// The damper of cases/low_intensity_36_spheres.json (docs/theory.md §8): 36 steel spheres
/// r = 5 mm, 6 × 6 × 1 lattice collected against −x in a 160 × 61 × 40 mm box (h_roll =
/// 0.1 m), 2 Hz along x, gravity −z, stroke X = x_over_h·h_roll; restitution, friction,
/// rolling friction as given and Young's modulus 210 GPa / softening. Periods and samples
/// are the defaults: each test sets its own.
inline dr::DamperSimulationOptions shipped_layer(double x_over_h, double restitution, double friction,
                                                 double rolling_friction, double softening) {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.container.box_inner_size_m = {0.160, 0.061, 0.040};
  c.particles = {dr::ParticleGroupOptions{36, 0.005, 0.0, 0}};
  c.lattice_counts = {6, 6, 1};
  o.world.materials.front().material.youngs_modulus_pa = 210e9 / softening;
  o.world.default_pair.restitution.constant = restitution;
  o.world.default_pair.friction = friction;
  o.world.default_pair.rolling_friction = rolling_friction;
  o.frequency_hz = 2.0;
  o.amplitude_m = x_over_h * 0.1;
  return o;
}

/// `count` identical steel spheres of radius r (no ball-lot tolerance) in a static 0.2 m
/// cubic box, no gravity.
inline dr::WorldOptions box_world(int count, double radius_m, double restitution, double friction) {
  dr::WorldOptions o;
  o.gravity_m_s2 = {0.0, 0.0, 0.0};
  auto& c = o.compartments.front();
  c.container.shape = pdamp::formulas::ContainerShape::kBox;
  c.container.box_inner_size_m = {0.2, 0.2, 0.2};
  c.particles = {dr::ParticleGroupOptions{count, radius_m, 0.0, 0}};
  // Identical spheres: the tests compare with closed forms at the nominal radius.
  c.particles.front().lot_diameter_variation_m = 0.0;
  c.lattice_counts.clear();
  o.default_pair.restitution.constant = restitution;
  o.default_pair.friction = friction;
  o.default_pair.rolling_friction = 0.0;
  return o;
}

/// Steps with the container at rest until particle `watch` has touched something and
/// let go again (or max_steps pass); returns the steps taken.
inline long run_one_impact(dr::World& world, long max_steps) {
  const dr::ContainerState rest;
  bool touched = false;
  for (long k = 0; k < max_steps; ++k) {
    world.step(rest);
    const auto census = world.contact_census({0.0, 0.0, 0.0});
    const bool touching = census.airborne < world.particle_count();
    if (touching) touched = true;
    if (touched && !touching) return k + 1;
  }
  return max_steps;
}

}  // namespace dem_test
