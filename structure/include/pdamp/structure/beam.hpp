// Euler-Bernoulli beam finite elements in a plane (Hermite cubics for bending, linear
// axial bars) and their modal reduction. A straight beam along x, made of segments;
// supports, point masses and named points sit at positions along the axis (nodes are
// placed there). Input structs validate themselves; docs/structures.md documents them.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// Physical ranges of a beam model (BeamModel::validate, ModalDamping::validate): wide
/// enough for any structure a particle damper is fitted to, narrow enough that nonsense (a
/// 1e308 m segment, a 1e-320 m section, a 1e300 kg point mass) is refused naming its field
/// instead of failing in the eigen-solve or giving overflowing responses.
namespace beam_limits {
inline constexpr double kMinSegmentLength_m = 1e-4;  ///< 0.1 mm
inline constexpr double kMaxSegmentLength_m = 1e4;   ///< 10 km
inline constexpr double kMinSectionSize_m = 1e-5;    ///< 10 µm (a wall thickness)
inline constexpr double kMaxSectionSize_m = 100.0;
inline constexpr double kMaxStiffness = 1e15;        ///< spring supports, N/m and N m/rad (a rigid support)
inline constexpr double kMaxPointMass_kg = 1e7;      ///< 10,000 t
inline constexpr double kMaxRotaryInertia_kg_m2 = 1e7;
/// Elements of the whole beam: the eigenproblem is dense (3 DOFs per node, O(n³) work and
/// O(n²) memory): 500 elements solve in about 4 s, 1000 in over a minute (and lose the
/// softest modes to round-off), while a few dozen resolve the modes a damper design needs.
inline constexpr int kMaxElements = 500;
inline constexpr std::size_t kMaxSegments = 100;
inline constexpr std::size_t kMaxSupports = 100;
inline constexpr std::size_t kMaxPoints = 1000;       ///< point masses, and named points
inline constexpr double kMaxDampingRatio = 1.0;      ///< ζ of a vibration mode
inline constexpr double kMaxRayleighAlpha_1_s = 1e4;
inline constexpr double kMaxRayleighBeta_s = 1.0;
}  // namespace beam_limits

enum class SectionShape { kSolidRectangle, kHollowRectangle, kSolidCircle, kHollowCircle };

/// Cross-section. Rectangles: `depth_m` is the in-plane (y) size, `width_m` the
/// out-of-plane size; circles use `diameter_m`; hollow ones a `wall_thickness_m`.
struct Section {
  SectionShape shape = SectionShape::kSolidRectangle;
  double width_m = 0.0;
  double depth_m = 0.0;
  double diameter_m = 0.0;
  double wall_thickness_m = 0.0;
  double area_m2() const;
  double second_moment_m4() const;  ///< about z (bending in the x-y plane)
};

struct BeamMaterial {
  double youngs_modulus_pa = 206e9;  ///< spring steel
  double density_kg_m3 = 7850.0;
};

struct BeamSegment {
  double length_m = 0.0;
  Section section;
  BeamMaterial material;
  int elements = 10;  ///< finite elements in this segment, >= 1
};

/// A support at a position along the axis. Clamped fixes x, y and rotation; pinned
/// fixes x and y; a spring support adds the given stiffnesses to ground (0 = none).
/// Under base excitation every support, springs included, moves with the base.
struct Support {
  enum class Kind { kClamped, kPinned, kSpring };
  Kind kind = Kind::kClamped;
  double position_m = 0.0;
  double axial_stiffness_n_m = 0.0;        ///< x, spring supports only
  double transverse_stiffness_n_m = 0.0;   ///< y, spring supports only
  double rotational_stiffness_n_m_rad = 0.0;
};

/// A rigid body attached at a point (container, end effector): mass and rotary inertia about z.
struct PointMass {
  std::string name;
  double position_m = 0.0;
  double mass_kg = 0.0;
  double rotary_inertia_kg_m2 = 0.0;
};

/// A weight the beam carries whose inertia is modelled elsewhere (a damper's container and
/// beds, coupled through structure::Damper): it loads the geometric stiffness only.
struct CarriedWeight {
  double position_m = 0.0;
  double mass_kg = 0.0;  ///< >= 0
};

struct NamedPoint {
  std::string name;
  double position_m = 0.0;
};

/// Modal damping: a ratio per mode (the last repeats for higher modes), or Rayleigh
/// C = αM + βK (ζ_j = α/(2ω_j) + βω_j/2).
struct ModalDamping {
  std::vector<double> ratios{0.0};
  std::optional<double> rayleigh_alpha_1_s;
  std::optional<double> rayleigh_beta_s;
  /// Problems, one line each (ratios/1 = -0.1: must be >= 0, ...); Rayleigh terms, when
  /// given, replace the ratios.
  std::vector<std::string> validate() const;
};

struct BeamModel {
  std::vector<BeamSegment> segments;
  std::vector<Support> supports;
  std::vector<PointMass> point_masses;
  std::vector<NamedPoint> points;
  std::vector<CarriedWeight> carried_weights;
  /// Gravity's component along +x (from the first end to the other), m/s². A standing
  /// beam clamped at its first end has −9.81, a hanging one +9.81; 0 for a horizontal beam.
  double axial_gravity_m_s2 = 0.0;
  /// Add the geometric stiffness of the axial force that gravity causes (compression
  /// softens a standing beam), so a vertical beam with a tip mass has the right frequency.
  bool geometric_stiffness = false;

  double length_m() const;
  /// Problems, one line each, naming the field (segments/0/length_m, ...) and the allowed range.
  std::vector<std::string> validate() const;
};

/// Assembles M and K, solves the generalized eigenproblem and keeps the lowest
/// `mode_count` mass-normalised modes, their shapes at every named point and point mass
/// (by name), and the base participation. Throws std::invalid_argument on invalid input,
/// a mode_count above the number of elastic modes, or a beam buckled by gravity. A free
/// structure or mechanism is fine: its rigid modes (0 Hz, counted exactly from the
/// supports) are dropped and said so in `rigid_modes_dropped`.
struct BeamModalResult {
  ModalModel modal;
  int rigid_modes_dropped = 0;
};
BeamModalResult beam_modal_model(const BeamModel& beam, int mode_count, const ModalDamping& damping);

/// The assembled finite-element matrices of a beam, over all DOFs (fixed ones included).
/// DOF ordering: node i (nodes sorted by x) owns DOFs 3i (u, axial, m), 3i + 1 (w,
/// transverse y, m) and 3i + 2 (θ about z, rad); ModalModel::mode_shapes uses the same rows.
struct BeamMatrices {
  Eigen::VectorXd node_positions_m;    ///< x of each node, ascending, m
  Eigen::MatrixXd mass_kg;             ///< consistent mass matrix incl. point masses (kg, kg m, kg m²)
  Eigen::MatrixXd stiffness_n_m;       ///< elastic + spring (+ geometric, if enabled) stiffness
  std::vector<Eigen::Index> fixed_dofs;  ///< DOFs held by clamped and pinned supports, ascending
};
/// Throws std::invalid_argument if the beam does not validate.
BeamMatrices beam_matrices(const BeamModel& beam);

/// The shape of every mode of `modal` (the modal model of this beam) at position x (m)
/// along the axis, as the finite elements interpolate it: linear in u, Hermite cubics in w
/// and θ = dw/dx inside the element holding x. Exact for the FE model wherever x lies, with
/// no node there (a node placed next to another would make a sliver element). Throws
/// std::invalid_argument when modal.mode_shapes does not fit the beam's mesh or x is off it.
PointModeShape beam_point_shape(const BeamModel& beam, const ModalModel& modal, const std::string& name,
                                double position_m);
/// Modal amplitudes of the static deflection under a force (x, y) and moment (about z)
/// at position x_m along the beam: q0 = Φᵀ M u_static, the initial state of a release.
Eigen::VectorXd static_deflection_modal_amplitudes(const BeamModel& beam, const ModalModel& modal,
                                                   double position_m, const Eigen::Vector2d& force_n,
                                                   double moment_n_m);

}  // namespace pdamp::structure
