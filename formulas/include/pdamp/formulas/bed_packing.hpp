// Containers and the collected lattice bed: the clearance h of a real bed
// (PHYSICS.md "Clearance of a real bed") and the DEM's initial placement.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace pdamp::formulas {

using Vec3 = std::array<double, 3>;

enum class ContainerShape { kBox, kCylinder };

/// Rigid container, centred at the origin of its own frame.
struct Container {
  ContainerShape shape = ContainerShape::kBox;
  Vec3 box_inner_size_m{0.0, 0.0, 0.0};  ///< box: inner lengths along x, y, z, m
  double cylinder_inner_radius_m = 0.0;  ///< cylinder: inner radius, m
  double cylinder_inner_length_m = 0.0;  ///< cylinder: inner length along its axis, m
  int cylinder_axis = 0;                 ///< cylinder: axis 0 = x, 1 = y, 2 = z
  /// Inner length along an axis (cylinder: its length, or 2R across it), m.
  double inner_length(int axis) const;
  std::vector<std::string> validate(const std::string& prefix) const;
};

/// How the bed is placed before the run.
struct LatticePacking {
  int drive_axis = 0;     ///< 0 = x, 1 = y, 2 = z
  int collect_side = -1;  ///< −1: collected against the wall at −L/2 of the drive axis; +1: at +L/2
  /// Direction of gravity as an axis (0..2) and sign, or nullopt for no gravity: the
  /// lowest sites of each slab fill first, and the bed rests on that wall.
  std::optional<std::pair<int, int>> gravity_axis_sign;
  /// Explicit simple-cubic lattice counts along x, y, z; nullopt = fill each slab
  /// (the plane normal to the drive) with every site that fits, lowest first.
  std::optional<std::array<int, 3>> lattice_counts;
};

/// A collected simple-cubic lattice of touching spheres (pitch 2r).
struct LatticeBed {
  std::vector<Vec3> centres_m;  ///< container frame, m
  int slabs = 0;                ///< sphere rows along the drive
  double bed_extent_m = 0.0;    ///< slabs·2r: extent of the packed bed along the drive
  double clearance_m = 0.0;     ///< h = inner length along the drive − bed_extent_m
};

/// Places `count` spheres of radius r against the collect wall, slab by slab.
/// Throws std::invalid_argument with the numbers when they do not fit (or the
/// clearance would not be positive), or for a cylinder driven across its axis.
LatticeBed collected_lattice(const Container& container, int count, double radius_m,
                             const LatticePacking& packing);

}  // namespace pdamp::formulas
