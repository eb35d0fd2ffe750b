// Beds and dampers shared by the co-simulation tests (test_cosimulation*.cpp).
#pragma once

#include <vector>

#include "pdamp/structure/cosimulation.hpp"

namespace pdamp::test {

namespace dem = pdamp::dem_reference;

/// A box compartment with `count` spheres (lattice counts x, y, z), softened steel.
inline dem::WorldOptions bed(double radius_m, const dem::Vec3& box_m, std::vector<int> lattice, double youngs_pa,
                             dem::Vec3 gravity, dem::InitialPlacement placement) {
  dem::WorldOptions w;
  w.materials[0].material.youngs_modulus_pa = youngs_pa;
  w.gravity_m_s2 = gravity;
  auto& c = w.compartments[0];
  c.container.box_inner_size_m = box_m;
  c.placement = placement;
  c.lattice_counts = lattice;
  c.particles[0].radius_m = radius_m;
  c.particles[0].count = lattice[0] * lattice[1] * lattice[2];
  c.particles[0].lot_diameter_variation_m = 0.0;
  return w;
}

/// One mode (f Hz, ζ, modal mass m) on a moving base with base participation Γ (kg) along y,
/// shape φ = 1 along y at the point "tip".
inline structure::ModalModel one_mode_on_base(double f_hz, double zeta, double mass_kg, double participation_kg) {
  structure::ModalModel m;
  m.natural_frequencies_hz = Eigen::VectorXd::Constant(1, f_hz);
  m.damping_ratios = Eigen::VectorXd::Constant(1, zeta);
  m.modal_masses_kg = Eigen::VectorXd::Constant(1, mass_kg);
  Eigen::MatrixXd shape(2, 1);
  shape << 0.0, 1.0;
  m.points = {{"tip", shape, Eigen::RowVectorXd::Zero(1)}};
  m.base_participation = Eigen::MatrixXd(1, 2);
  m.base_participation << 0.0, participation_kg;
  return m;
}

/// A damper at the point "tip", driven along y, with the bed `world`.
inline structure::CosimulationDamper tip_damper(const dem::WorldOptions& world, double container_mass_kg) {
  structure::CosimulationDamper d;
  d.name = "tip";
  d.point = "tip";
  d.drive_direction = {0.0, 1.0};
  d.container_mass_kg = container_mass_kg;
  d.world = world;
  return d;
}

/// A single sphere floating in the middle of a box `length_m` long (the drive axis) without
/// gravity: it keeps the container's start velocity and touches no wall as long as that
/// carries it less than (length − 1 cm)/2 (each test states why it does not).
inline dem::WorldOptions lone_sphere(double length_m) {
  return bed(0.005, {length_m, 0.03, 0.03}, {1, 1, 1}, 2e7, {0.0, 0.0, 0.0}, dem::InitialPlacement::kCentredLattice);
}

}  // namespace pdamp::test
