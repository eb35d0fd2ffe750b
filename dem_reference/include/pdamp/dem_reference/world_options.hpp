// Options of the reference DEM world: materials, contact pairs, compartments, integration.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdamp/formulas/bed_packing.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/formulas/hertz_impact.hpp"

namespace pdamp::dem_reference {

using Vec3 = formulas::Vec3;

/// A named isotropic elastic material (particles, container walls, inner structures,
/// wall layers all refer to materials by their index in WorldOptions::materials).
struct MaterialOptions {
  std::string name = "steel";
  formulas::Material material;  ///< density kg/m³, Young's modulus Pa, Poisson ratio
};

/// Normal coefficient of restitution of one material pair (PHYSICS.md §6).
/// Precedence: `model` if set, else the table if it is non-empty, else `constant`.
struct RestitutionOptions {
  double constant = 0.8;                 ///< ε, dimensionless, in (0, 1]
  std::vector<double> table_speeds_m_s;  ///< tabulated ε(v): normal impact speeds, m/s, >= 0, strictly increasing
  std::vector<double> table_values;      ///< ε at those speeds, in (0, 1], same length (>= 2)
  /// Any ε(v) law of formulas/ (e.g. Thornton or a fit); overrides constant and table.
  std::shared_ptr<const formulas::RestitutionModel> model;
};

/// Contact parameters of one material pair; order of the two materials is irrelevant.
struct ContactPairOptions {
  int material_a = 0;            ///< index into WorldOptions::materials
  int material_b = 0;            ///< index into WorldOptions::materials
  RestitutionOptions restitution;
  double friction = 0.3;         ///< sliding friction μ, dimensionless, >= 0
  /// Rolling friction μ_r, dimensionless, >= 0: the rolling torque is capped at
  /// μ_r·R*·F_n (elastic-plastic spring model, docs/dem.md).
  double rolling_friction = 0.0;
};

/// One family of spheres in a compartment.
struct ParticleGroupOptions {
  int count = 36;                     ///< number of spheres, >= 1
  double radius_m = 0.005;            ///< nominal radius r, m, > 0
  /// Polydispersity: radii uniform in [r(1−s), r(1+s)] drawn with WorldOptions::seed;
  /// s dimensionless in [0, 0.5). 0 = monodisperse.
  double radius_spread = 0.0;
  int material = 0;                   ///< index into WorldOptions::materials
};

enum class InitialPlacement {
  kCollectedLattice,  ///< simple-cubic lattice against a wall (default, PHYSICS.md §3)
  kCentredLattice,    ///< the same lattice shifted to the middle of the drive axis
  kRandom,            ///< random non-overlapping positions (seeded)
};

/// An axis-aligned solid box inside a compartment (an internal plate when thin).
struct PlateOptions {
  Vec3 centre_m{0.0, 0.0, 0.0};  ///< in the compartment frame, m
  Vec3 size_m{0.0, 0.0, 0.0};    ///< full edge lengths along x, y, z, m, each > 0
  int material = -1;             ///< index into materials; −1 = the compartment's wall material
};

/// An axis-aligned solid cylinder (pin) inside a compartment.
struct PinOptions {
  Vec3 centre_m{0.0, 0.0, 0.0};  ///< in the compartment frame, m
  int axis = 2;                  ///< 0 = x, 1 = y, 2 = z
  double radius_m = 0.0;         ///< > 0
  double length_m = 0.0;         ///< > 0
  int material = -1;             ///< index into materials; −1 = the compartment's wall material
};

/// Buffered walls: a polymer layer on container walls (PHYSICS.md §5). The sphere
/// presses into the layer (Hertz with the layer's modulus); once it has penetrated
/// the whole thickness the hard wall acts in addition.
struct WallLayerOptions {
  double thickness_m = 0.0;  ///< layer thickness, m, >= 0; 0 = no layer
  int material = 0;          ///< index into materials: modulus at the design frequency and temperature
  /// −1: all walls; 0..2: only the walls normal to that axis (box faces; for a
  /// cylinder the end caps if it is the cylinder axis, else the mantle).
  int axis = -1;
};

/// One compartment: a container with its own particles, moving with the damper body.
struct CompartmentOptions {
  formulas::Container container{formulas::ContainerShape::kBox, {0.160, 0.061, 0.040}, 0.0, 0.0, 0};
  Vec3 offset_m{0.0, 0.0, 0.0};  ///< centre of the container in the damper body frame, m
  int wall_material = 0;         ///< index into materials
  std::vector<ParticleGroupOptions> particles{ParticleGroupOptions{}};
  InitialPlacement placement = InitialPlacement::kCollectedLattice;
  int collect_axis = 0;   ///< lattice slabs stack along this axis (set it to the drive axis), 0..2
  int collect_side = -1;  ///< −1: bed against the wall at −L/2 of collect_axis; +1: at +L/2
  /// Explicit lattice counts along x, y, z (product >= particle count); empty = fill
  /// each slab with every site that fits, lowest first.
  std::vector<int> lattice_counts;
  std::vector<PlateOptions> plates;
  std::vector<PinOptions> pins;
  WallLayerOptions layer;
};

/// Time integration, neighbour search and instability detection.
struct IntegrationOptions {
  /// Time step, s; 0 = automatic: min(t_c(v_max)/steps_per_contact, rayleigh_fraction·T_R),
  /// t_c the Hertz contact time of the stiffest pair at max_impact_speed_m_s and T_R
  /// the Rayleigh time of the smallest sphere. A value above that bound is refused.
  double time_step_s = 0.0;
  int steps_per_contact = 50;      ///< >= 40
  double rayleigh_fraction = 0.25; ///< fraction of the Rayleigh time, in (0, 1]
  /// Largest normal impact speed expected, m/s, > 0 (run_harmonic raises it to at
  /// least 2XΩ + √(2|g|L) of the drive).
  double max_impact_speed_m_s = 1.0;
  /// Verlet skin as a fraction of the largest radius, in (0, 2]: pairs closer than
  /// r_i + r_j + skin are listed; the list is rebuilt when a particle has moved more
  /// than skin/2 relative to the container.
  double skin_fraction = 0.2;
  /// Instability: overlap above this fraction of the smaller radius, in (0, 1).
  double max_overlap_fraction = 0.1;
};

/// Everything that defines a world (see docs/dem.md for the model).
struct WorldOptions {
  std::vector<MaterialOptions> materials{MaterialOptions{}};
  /// Pair parameters used for every material pair not listed in `pairs`.
  ContactPairOptions default_pair;
  std::vector<ContactPairOptions> pairs;
  std::vector<CompartmentOptions> compartments{CompartmentOptions{}};
  Vec3 gravity_m_s2{0.0, 0.0, -formulas::kStandardGravity};  ///< world frame, any vector incl. zero
  IntegrationOptions integration;
  std::uint64_t seed = 1;  ///< seeds every random choice (radii, random placement)
  /// OpenMP threads, >= 0 (0 = all available). Small worlds run serially whatever
  /// this says: results are identical run to run for a fixed thread count.
  int threads = 1;

  /// All violations, one line each ("field = value: rule"), prefixed by `prefix`.
  std::vector<std::string> validate(const std::string& prefix = "dem.") const;
};

}  // namespace pdamp::dem_reference
