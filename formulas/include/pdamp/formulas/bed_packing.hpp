// Containers and the collected lattice bed: the clearance h of a real bed
// (docs/theory.md §9, "Clearance of a real bed") and the DEM's initial placement.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pdamp::formulas {

using Vec3 = std::array<double, 3>;

enum class ContainerShape { kBox, kCylinder };

/// Rigid container, centred at the origin of its own frame.
/// Fields of the other shape are ignored.
struct Container {
  ContainerShape shape = ContainerShape::kBox;
  Vec3 box_inner_size_m{0.0, 0.0, 0.0};  ///< box: inner lengths along x, y, z, m
  double cylinder_inner_radius_m = 0.0;  ///< cylinder: inner radius, m
  double cylinder_inner_length_m = 0.0;  ///< cylinder: inner length along its axis, m
  int cylinder_axis = 0;                 ///< cylinder: axis 0 = x, 1 = y, 2 = z
  /// Inner length along an axis (cylinder: its length, or 2R across it), m.
  /// Throws std::invalid_argument unless axis is 0, 1 or 2.
  double inner_length(int axis) const;
  /// The free space inside a lining of thickness t >= 0 (a buffered wall's layer): the
  /// faces normal to `axis` lined (box faces; a cylinder's end caps when it is the
  /// cylinder's axis, else its mantle), or every face for axis = −1. t = 0: unchanged.
  Container lined(double thickness_m, int axis) const;
  /// One line per violation of the shape in use ("<prefix>.box_inner_size_m[1] = -0.06:
  /// must be > 0 and finite"; no prefix and dot when prefix is empty): positive finite
  /// sizes, cylinder_axis in 0..2. Empty when valid.
  std::vector<std::string> validate(const std::string& prefix) const;
};

/// How the bed is placed before the run.
struct LatticePacking {
  int drive_axis = 0;     ///< 0 = x, 1 = y, 2 = z
  int collect_side = -1;  ///< −1: collected against the wall at −L/2 of the drive axis; +1: at +L/2
  /// Direction of gravity as an axis (0..2) and sign (−1 or +1: gravity points to the
  /// wall at sign·L/2), or nullopt for no gravity: the lowest sites of each slab fill
  /// first, and in a box the bed rests on that wall.
  std::optional<std::pair<int, int>> gravity_axis_sign;
  /// Explicit simple-cubic lattice counts along x, y, z (each >= 1, count <= their
  /// product, and the lattice must fit); nullopt = fill each slab (the plane normal
  /// to the drive) with every site that fits, lowest first.
  std::optional<std::array<int, 3>> lattice_counts;
  /// Gap between neighbouring lanes, m, finite and >= 0 (box only). A lane is a row of
  /// spheres along the drive; lanes sit side by side along the transverse axes that are
  /// not along gravity (rows along gravity rest on each other and keep pitch 2r). The
  /// lanes' pitch is 2r + lane_gap_m and the block stays centred, so each side wall
  /// keeps half of what is left. 0 = touching lanes (pitch 2r). With automatic counts
  /// the lanes that fit are floor((L + g)/(2r + g)).
  double lane_gap_m = 0.0;
  /// true: lane_gap_m is ignored and the width left over by the lanes (n of them, from
  /// the counts, or floor(L/2r)) is shared equally: g = (L − n·2r)/n, so every lane owns
  /// the width L/n and the side walls keep g/2 each (box only).
  bool lane_gap_auto = false;
  /// false: simple cubic (slab pitch 2r along the drive). true: face-centred stacking of the
  /// automatic slabs (cylinder only, no explicit counts): every other slab is registered r
  /// further along both transverse axes and sits in the hollows of its neighbours, slab pitch
  /// r·√2 (each sphere touches four of each neighbouring slab); packing fraction 0.74 in bulk
  /// against 0.52, so a bed that settles looser than simple cubic (a cylinder slumping under
  /// gravity across its axis) can be started in a container shorter than its cubic lattice.
  bool staggered = false;
};

/// A collected lattice of touching spheres (simple cubic of pitch 2r, or staggered).
struct LatticeBed {
  std::vector<Vec3> centres_m;  ///< container frame, m
  int slabs = 0;                ///< sphere rows along the drive
  /// Extent of the packed bed along the drive, m: slabs·2r (staggered: (slabs − 1)·r√2 + 2r).
  double bed_extent_m = 0.0;
  double clearance_m = 0.0;     ///< h = inner length along the drive − bed_extent_m (the lattice as placed)
  /// The clearance of the bed once it has settled (docs/collect_and_collide.md §8): a box
  /// with gravity across the drive whose lanes are stacked more than one sphere high does
  /// not keep its simple cubic lattice. Under the drive the upper spheres fall into the
  /// grooves or onto the free base, so each lane's bottom row takes min(N_lane, floor(L/2r))
  /// spheres (N_lane the spheres of that lane at every height) and the bed's extent is the
  /// longest bottom row: settled_clearance_m = L − max_lane min(N_lane, floor(L/2r))·2r,
  /// m. It may be 0 (the bottom rows fill the container: the bed jams). Equal to
  /// clearance_m for a bed one sphere high, a cylinder, or no gravity across the drive.
  double settled_clearance_m = 0.0;
  /// Spheres left above the settled bottom rows (0: the bed settles into one layer).
  int settled_upper_spheres = 0;
  /// Most spheres one slab puts in one lane, stacked across gravity (1: one sphere high;
  /// a slab 8 across and 2 high: 2). 1 for a cylinder or without gravity across the drive.
  int spheres_per_lane = 1;
};

/// Places `count` (>= 1) spheres of radius r (> 0) on a simple cubic lattice of pitch
/// 2r against the collect wall, slab by slab (slabs normal to the drive axis; slab j's
/// centres at collect_side·(L/2 − r − 2r·j) along the drive).
///
/// Cross-section sites of a slab:
/// - box: n = floor(L/2r) sites along each transverse axis (or the explicit counts),
///   centred, except along gravity, where the lowest row rests on the wall gravity
///   points to (centre r from it); across gravity the lanes are spaced by
///   packing.lane_gap_m (or the shared leftover width, lane_gap_auto), which leaves
///   the drive direction and so the clearance unchanged for given counts;
/// - cylinder driven along its axis: the square lattice sites with |offset| + r <= R,
///   registered on the axis or offset by r along either transverse axis, whichever
///   holds the most sites (the first of (0,0), (r,0), (0,r), (r,r) on ties); explicit
///   counts give an n_a × n_b block, centred, except along gravity, where it sits as
///   low as the curved wall allows. A cylinder driven across its axis is not supported.
/// packing.staggered (cylinder, automatic sites only): the slabs alternate between that
/// registration and the one shifted by r along both transverse axes, at pitch r√2 along the
/// drive (slab j's centres at collect_side·(L/2 − r − r√2·j)); it needs R >= (1 + √2)·r for
/// a shifted site.
/// Each slab is filled lowest first (height against gravity, then x, y, z ascending:
/// deterministic); only the last slab may be partial. bed_extent counts it whole. A relative tolerance of 1e-9 absorbs round-off in "fits" (L = 6·2r fits 6).
///
/// Throws std::invalid_argument with the numbers for invalid input, when the spheres
/// do not fit (explicit lattice larger than the container, count above the lattice,
/// no site in the cross-section, clearance not > 0), or for a cylinder driven across
/// its axis ("not supported yet").
LatticeBed collected_lattice(const Container& container, int count, double radius_m,
                             const LatticePacking& packing);

}  // namespace pdamp::formulas
