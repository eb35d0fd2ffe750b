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

/// The ranges WorldOptions::validate() and DamperSimulationOptions::validate() accept
/// (one source of truth: the case reader and the documentation take them from here).
/// Each is wide enough for any damper the model describes and narrow enough that a
/// value outside is a unit or typing mistake, or would make the run meaningless.
namespace limits {
/// Restitution: what formulas::DampingTable can turn into a damping coefficient.
inline constexpr double kMinRestitution = formulas::DampingTable::kMinRestitution;
/// Sliding friction μ: measured dry values stay below ~1.5; 10 leaves room for rough
/// interlocking surfaces while catching percentages (30 for 0.3).
inline constexpr double kMaxFriction = 10.0;
/// Rolling friction μ_r caps the rolling torque at μ_r·R*·F_n: above 1 the lever arm
/// would exceed the sphere.
inline constexpr double kMaxRollingFriction = 1.0;
/// Sphere radius, m: below 10 µm adhesion (van der Waals), which the model lacks,
/// dominates contacts; above 1 m it is no particle damper.
inline constexpr double kMinRadius_m = 1e-5;
inline constexpr double kMaxRadius_m = 1.0;
/// All particles of a world: the neighbour rows index slots with int (~20 listed
/// partners per sphere at most), and 1e8 spheres already need ~60 GB.
inline constexpr long long kMaxParticles = 100'000'000;
/// |gravity| component, m/s²: 1000 g (centrifuge tests); beyond, a unit mistake.
inline constexpr double kMaxGravity_m_s2 = 1e4;
/// Largest normal impact speed, m/s: above ~1 km/s impacts are ballistic (plastic
/// flow, fracture), outside Hertz plus a restitution law; and the speed sets the time
/// step (t_c ∝ v^−1/5), so 1e60 m/s gives a run of ~1e20 steps and 1e200 overflows
/// the contact time so that the step would grow instead.
inline constexpr double kMaxImpactSpeed_m_s = 1000.0;
/// A given time step, s: 0 (automatic) or in this range. The automatic bound of
/// stiff 10 µm spheres at 1 km/s is ~1e-9 s; above 1e-3 s no Hertz contact of any
/// material the model takes is resolved (the bound check refuses it anyway).
inline constexpr double kMinTimeStep_s = 1e-10;
inline constexpr double kMaxTimeStep_s = 1e-3;
/// Steps per contact time at the largest impact speed: below 20 heavily damped contacts
/// overshoot (ε = 0.05 realises up to 0.11 at 10 steps); from 20 on one impact's
/// restitution error is about (0.6 ln²ε + 0.1)/N (restitution_error_bound; docs/dem.md
/// "Integration and time step"). Beyond 10,000 only the cost grows.
inline constexpr int kMinStepsPerContact = 20;
inline constexpr int kMaxStepsPerContact = 10'000;
/// Verlet skin over the largest radius: below 1% the lists are rebuilt nearly every
/// step; above 2 they hold most of the bed.
inline constexpr double kMinSkinFraction = 0.01;
inline constexpr double kMaxSkinFraction = 2.0;
/// Ball lot diameter variation, m: ISO 3290-1 grade G2000 allows 100 µm; 1 mm is
/// beyond any graded ball (a unit mistake, e.g. µm given as mm).
inline constexpr double kMaxLotDiameterVariation_m = 1e-3;
/// OpenMP threads: more than the largest machines have is a mistake.
inline constexpr int kMaxThreads = 1024;
}  // namespace limits

/// A named isotropic elastic material (particles, container walls, inner structures,
/// wall layers all refer to materials by their index in WorldOptions::materials).
struct MaterialOptions {
  std::string name = "steel";
  formulas::Material material;  ///< density kg/m³, Young's modulus Pa, Poisson ratio
};

/// Normal coefficient of restitution of one material pair (docs/theory.md §6).
/// Precedence: `model` if set, else the table if it is non-empty, else `constant`.
struct RestitutionOptions {
  double constant = 0.8;                 ///< ε, dimensionless, in [0.01, 1] (limits::kMinRestitution)
  std::vector<double> table_speeds_m_s;  ///< tabulated ε(v): normal impact speeds, m/s, >= 0, strictly increasing
  std::vector<double> table_values;      ///< ε at those speeds, in [0.01, 1], same length (>= 2)
  /// Any ε(v) law of formulas/ (e.g. Thornton or a fit); overrides constant and table.
  /// Validation samples it over [0, integration.max_impact_speed_m_s] (run_harmonic:
  /// the raised speed) and requires ε in [0.01, 1] there; a faster first touch gets
  /// ε clamped into [0.01, 1]. Called from several threads at once: must be
  /// thread-safe; an exception it throws stops the world (WorldStatus kFailed).
  std::shared_ptr<const formulas::RestitutionModel> model;
};

/// Contact parameters of one material pair; order of the two materials is irrelevant.
struct ContactPairOptions {
  int material_a = 0;            ///< index into WorldOptions::materials
  int material_b = 0;            ///< index into WorldOptions::materials
  RestitutionOptions restitution;
  double friction = 0.3;         ///< sliding friction μ, dimensionless, in [0, 10]
  /// Rolling friction μ_r, dimensionless, in [0, 1]: the rolling torque is capped at
  /// μ_r·R*·F_n (elastic-plastic spring model, docs/dem.md).
  double rolling_friction = 0.0;
};

/// One family of spheres in a compartment.
struct ParticleGroupOptions {
  int count = 36;                     ///< number of spheres, >= 1 (all groups of the world: <= 1e8)
  double radius_m = 0.005;            ///< nominal radius r, m, in [1e-5, 1]
  /// Polydispersity: radii uniform in [r(1−s), r(1+s)] drawn with WorldOptions::seed;
  /// s dimensionless in [0, 0.5). 0 = monodisperse.
  double radius_spread = 0.0;
  int material = 0;                   ///< index into WorldOptions::materials
  /// Manufacturing tolerance of the balls when radius_spread = 0: the variation of ball
  /// lot diameter V_DwL of ISO 3290-1 (the largest minus the smallest mean diameter in
  /// a lot), m, in [0, 1e-3]. Radii are drawn uniform in [r − Δ, r] with WorldOptions::seed,
  /// Δ = min(V_DwL/2, r/100) (r = radius_m is the lot's largest ball, the one the
  /// container and the lattice pitch are sized for; the cap keeps tiny spheres, which are
  /// no graded balls, within 1% of the time-step bound). It breaks the exact symmetry
  /// of a collected lattice, whose lanes would otherwise move as clones (docs/dem.md
  /// "Initial state"). Default 5 µm: grade G100, the usual grade of steel balls sold
  /// for dampers and general use. 0 = identical spheres (the perfect lattice). Ignored
  /// when radius_spread > 0 (the spread is then the whole size distribution).
  double lot_diameter_variation_m = 5e-6;
};

enum class InitialPlacement {
  kCollectedLattice,  ///< simple-cubic lattice against a wall (default, docs/theory.md §3)
  kCentredLattice,    ///< the same lattice shifted to the middle of the drive axis
  kRandom,            ///< random non-overlapping positions (seeded)
};

/// An axis-aligned solid box inside a compartment (an internal plate when thin). It
/// must reach into the container and must not fill it; it may run through a wall (a
/// baffle fixed to the wall: the part outside is never touched).
struct PlateOptions {
  Vec3 centre_m{0.0, 0.0, 0.0};  ///< in the compartment frame, m
  Vec3 size_m{0.0, 0.0, 0.0};    ///< full edge lengths along x, y, z, m, each > 0
  int material = -1;             ///< index into materials; −1 = the compartment's wall material
};

/// An axis-aligned solid cylinder (pin) inside a compartment. It must reach into the
/// container; it may run through walls (a pin fixed in both walls is longer than the
/// container).
struct PinOptions {
  Vec3 centre_m{0.0, 0.0, 0.0};  ///< in the compartment frame, m
  int axis = 2;                  ///< 0 = x, 1 = y, 2 = z
  double radius_m = 0.0;         ///< > 0
  double length_m = 0.0;         ///< > 0
  int material = -1;             ///< index into materials; −1 = the compartment's wall material
};

/// Buffered walls: a polymer layer on container walls (docs/theory.md §5). The sphere
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
  Vec3 offset_m{0.0, 0.0, 0.0};  ///< centre of the container in the damper body frame, m, finite
  int wall_material = 0;         ///< index into materials
  std::vector<ParticleGroupOptions> particles{ParticleGroupOptions{}};
  InitialPlacement placement = InitialPlacement::kCollectedLattice;
  int collect_axis = 0;   ///< lattice slabs stack along this axis (set it to the drive axis), 0..2
  int collect_side = -1;  ///< −1: bed against the wall at −L/2 of collect_axis; +1: at +L/2
  /// Explicit lattice counts along x, y, z (product >= particle count); empty = fill
  /// each slab with every site that fits, lowest first.
  std::vector<int> lattice_counts;
  /// Gap between neighbouring lanes of the lattice (rows of spheres along collect_axis,
  /// side by side across it; not along gravity, where rows rest on each other), m,
  /// finite, >= 0, box containers only: lane pitch 2r + lane_gap_m, block centred
  /// (formulas::LatticePacking::lane_gap_m). 0 = touching lanes (pitch 2r, the closed
  /// form's bed). With automatic counts fewer lanes may fit: floor((L + g)/(2r + g)).
  double lane_gap_m = 0.0;
  /// true ("auto"): lane_gap_m is ignored and the width the n lanes leave is shared
  /// equally, g = (L − n·2r)/n: each lane owns L/n, the side walls keep g/2 (shipped
  /// 61 mm box, 6 lanes of 10 mm: g = 0.167 mm). Box containers only.
  bool lane_gap_auto = false;
  /// Face-centred stacking of the automatic slabs, cylinder only (formulas::LatticePacking::
  /// staggered): slab pitch r√2, denser than the simple cubic lattice.
  bool staggered_lattice = false;
  std::vector<PlateOptions> plates;
  std::vector<PinOptions> pins;
  WallLayerOptions layer;
};

/// Time integration, neighbour search and instability detection.
struct IntegrationOptions {
  /// Time step, s; 0 = automatic: min(t_c(v_max)/N, rayleigh_fraction·T_R), t_c the
  /// Hertz contact time of the stiffest pair at max_impact_speed_m_s, T_R the Rayleigh
  /// time of the smallest sphere and N the steps per contact (automatic_steps_per_contact
  /// unless steps_per_contact is given). A value above that bound is refused.
  /// Otherwise in [1e-10, 1e-3] s (limits::kMinTimeStep_s, kMaxTimeStep_s).
  double time_step_s = 0.0;
  /// Steps per contact time of the automatic step: 0 = automatic (the fewest in [20, 50]
  /// that keep one impact's restitution error within 1 %, automatic_steps_per_contact),
  /// else in [20, 10000].
  int steps_per_contact = 0;
  double rayleigh_fraction = 0.25; ///< fraction of the Rayleigh time, in (0, 1]
  /// Largest normal impact speed expected, m/s, in (0, 1000] (run_harmonic raises it
  /// to at least 2XΩ + √(2|g|(H − 2r)) of the drive, which must stay <= 1000 m/s as well).
  double max_impact_speed_m_s = 1.0;
  /// Verlet skin as a fraction of the largest radius, in [0.01, 2]: pairs closer than
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
  /// World frame, any vector incl. zero with components in [−1e4, 1e4] m/s².
  Vec3 gravity_m_s2{0.0, 0.0, -formulas::kStandardGravity};
  IntegrationOptions integration;
  std::uint64_t seed = 1;  ///< seeds every random choice (radii, random placement)
  /// OpenMP threads, in [0, 1024] (0 = all available). Small worlds run serially whatever
  /// this says: results are identical run to run for a fixed thread count.
  int threads = 1;

  /// All violations, one line each ("field = value: rule"), prefixed by `prefix`.
  std::vector<std::string> validate(const std::string& prefix = "dem.") const;
};

}  // namespace pdamp::dem_reference
