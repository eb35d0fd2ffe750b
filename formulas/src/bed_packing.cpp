// Collected bed in a box or cylinder (simple cubic; staggered in a cylinder): sphere centres
// and the clearance h.
#include "pdamp/formulas/bed_packing.hpp"

#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace pdamp::formulas {
namespace {

/// Most lattice sites of one slab that collected_lattice builds (the largest bed's
/// sphere count).
constexpr double kMaxSlabSites = 1e7;


/// Relative round-off allowance in "fits" tests: L = n·2r computed in floating point
/// may land a few ulps below n·2r and must still hold n sites.
constexpr double kFitTolerance = 1e-9;

using base::format_number;
using base::positive_finite;
using base::violation;

std::string field(const std::string& prefix, const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

bool is_axis(int axis) { return axis >= 0 && axis <= 2; }

[[noreturn]] void reject(const std::string& what) {
  throw std::invalid_argument("collected_lattice: " + what);
}

std::string counts_text(const std::array<int, 3>& n) {
  return std::to_string(n[0]) + " x " + std::to_string(n[1]) + " x " + std::to_string(n[2]);
}

/// Whole sites of pitch 2r along an inner length L.
int sites_along(double length_m, double radius_m) {
  return static_cast<int>(std::floor(length_m / (2.0 * radius_m) * (1.0 + kFitTolerance)));
}

/// Whole lanes of width 2r with gaps g between neighbours along an inner length L:
/// n·2r + (n − 1)·g <= L.
int lanes_along(double length_m, double radius_m, double gap_m) {
  if (gap_m == 0.0) return sites_along(length_m, radius_m);
  return static_cast<int>(std::floor((length_m + gap_m) / (2.0 * radius_m + gap_m) * (1.0 + kFitTolerance)));
}

/// Where the packing puts a slab's sites: the two transverse axes (ascending) and,
/// when gravity lies along one of them, which one and its sign.
struct CrossSection {
  int axis_a = 0;
  int axis_b = 0;
  int gravity_axis = -1;  ///< -1: no gravity, or gravity along the drive
  int gravity_sign = 0;
};

/// Positions of n sites of pitch 2r centred on 0.
std::vector<double> centred_positions(int n, double radius_m) {
  std::vector<double> positions(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) positions[i] = (i - 0.5 * (n - 1)) * 2.0 * radius_m;
  return positions;
}

/// Positions of n sites along a box axis of inner length L: centred, or resting on
/// the wall at sign·L/2 when gravity points there (row i = 0 lowest).
std::vector<double> box_positions(int n, double length_m, double radius_m, int gravity_sign) {
  if (gravity_sign == 0) return centred_positions(n, radius_m);
  std::vector<double> positions(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) positions[i] = gravity_sign * (0.5 * length_m - radius_m - 2.0 * radius_m * i);
  return positions;
}

Vec3 site(const CrossSection& cs, double along_a, double along_b) {
  Vec3 p{0.0, 0.0, 0.0};
  p[cs.axis_a] = along_a;
  p[cs.axis_b] = along_b;
  return p;
}

/// Gap between the lanes along a transverse box axis of inner length L holding n lanes:
/// none along gravity (rows rest on each other), else the given or the shared gap.
double lane_gap(const LatticePacking& packing, const CrossSection& cs, int axis, double length_m, int n,
                double radius_m) {
  if (axis == cs.gravity_axis) return 0.0;
  if (packing.lane_gap_auto) return std::max(0.0, (length_m - n * 2.0 * radius_m) / n);
  return packing.lane_gap_m;
}

/// Positions of n lanes of pitch 2r + g centred on 0 (g = 0: centred_positions).
std::vector<double> spaced_positions(int n, double radius_m, double gap_m) {
  if (gap_m == 0.0) return centred_positions(n, radius_m);
  std::vector<double> positions(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) positions[i] = (i - 0.5 * (n - 1)) * (2.0 * radius_m + gap_m);
  return positions;
}

std::vector<Vec3> box_sites(const Container& c, double r, const CrossSection& cs, int n_a, int n_b,
                            const LatticePacking& packing) {
  const auto positions = [&](int axis, int n) {
    const double length = c.box_inner_size_m[axis];
    if (axis == cs.gravity_axis) return box_positions(n, length, r, cs.gravity_sign);
    return spaced_positions(n, r, lane_gap(packing, cs, axis, length, n, r));
  };
  const auto pa = positions(cs.axis_a, n_a);
  const auto pb = positions(cs.axis_b, n_b);
  std::vector<Vec3> sites;
  sites.reserve(pa.size() * pb.size());
  for (const double a : pa) {
    for (const double b : pb) sites.push_back(site(cs, a, b));
  }
  return sites;
}

bool inside_disk(double a, double b, double radius_m, double disk_radius_m) {
  return std::hypot(a, b) + radius_m <= disk_radius_m * (1.0 + kFitTolerance);
}

/// Every site of the square lattice (pitch 2r, registered at offsets o_a, o_b) whose
/// sphere lies inside the disk of radius R.
std::vector<Vec3> disk_lattice(double r, double disk_radius_m, const CrossSection& cs, double o_a,
                               double o_b) {
  const int reach = static_cast<int>(std::ceil(disk_radius_m / (2.0 * r))) + 1;
  std::vector<Vec3> sites;
  for (int i = -reach; i <= reach; ++i) {
    for (int j = -reach; j <= reach; ++j) {
      const double a = o_a + 2.0 * r * i;
      const double b = o_b + 2.0 * r * j;
      if (inside_disk(a, b, r, disk_radius_m)) sites.push_back(site(cs, a, b));
    }
  }
  return sites;
}

/// The registration of the square lattice (pitch 2r) whose disk holds the most sites: the
/// first of (0,0), (r,0), (0,r), (r,r) on ties.
std::pair<double, double> best_registration(double r, double disk_radius_m, const CrossSection& cs) {
  std::pair<double, double> best{0.0, 0.0};
  std::size_t most = 0;
  for (const auto& [o_a, o_b] :
       {std::pair{0.0, 0.0}, std::pair{r, 0.0}, std::pair{0.0, r}, std::pair{r, r}}) {
    const std::size_t n = disk_lattice(r, disk_radius_m, cs, o_a, o_b).size();
    if (n > most) {
      most = n;
      best = {o_a, o_b};
    }
  }
  return best;
}

/// An n_a × n_b block in the disk, centred, except along gravity, where its lowest
/// row sits as deep as the wall allows: the row's outer sites touch the wall at depth
/// √((R − r)² − w²), w = the half-width of the row's centres. Throws if a site sticks out.
std::vector<Vec3> cylinder_sites_block(double r, double disk_radius_m, const CrossSection& cs, int n_a,
                                       int n_b) {
  std::vector<double> pa = centred_positions(n_a, r);
  std::vector<double> pb = centred_positions(n_b, r);
  if (cs.gravity_axis == cs.axis_a || cs.gravity_axis == cs.axis_b) {
    const bool along_a = cs.gravity_axis == cs.axis_a;
    const int n_row = along_a ? n_b : n_a;  // sites in one row across gravity
    const int n_rows = along_a ? n_a : n_b;
    const double half_width = (n_row - 1) * r;
    const double reach = disk_radius_m - r;
    const double depth = reach > half_width ? std::sqrt(reach * reach - half_width * half_width) : 0.0;
    std::vector<double>& rows = along_a ? pa : pb;
    for (int i = 0; i < n_rows; ++i) rows[i] = cs.gravity_sign * (depth - 2.0 * r * i);
  }
  std::vector<Vec3> sites;
  for (const double a : pa) {
    for (const double b : pb) {
      if (!inside_disk(a, b, r, disk_radius_m)) {
        reject("lattice_counts give " + std::to_string(n_a) + " x " + std::to_string(n_b) +
               " sites across the cylinder for radius_m = " + format_number(r, 12) +
               ": they do not fit in inner_radius_m = " + format_number(disk_radius_m, 12));
      }
      sites.push_back(site(cs, a, b));
    }
  }
  return sites;
}

std::vector<std::string> packing_problems(const Container& container, int count, double radius_m,
                                          const LatticePacking& packing) {
  std::vector<std::string> problems = container.validate("container");
  if (count < 1) problems.push_back("count = " + std::to_string(count) + ": must be >= 1");
  if (!positive_finite(radius_m)) problems.push_back(violation("radius_m", radius_m, "> 0 and finite"));
  if (!is_axis(packing.drive_axis)) {
    problems.push_back("packing.drive_axis = " + std::to_string(packing.drive_axis) + ": must be 0, 1 or 2");
  }
  if (packing.collect_side != -1 && packing.collect_side != 1) {
    problems.push_back("packing.collect_side = " + std::to_string(packing.collect_side) +
                       ": must be -1 or +1");
  }
  if (packing.gravity_axis_sign) {
    const auto [axis, sign] = *packing.gravity_axis_sign;
    if (!is_axis(axis))
      problems.push_back("packing.gravity axis = " + std::to_string(axis) + ": must be 0, 1 or 2");
    if (sign != -1 && sign != 1)
      problems.push_back("packing.gravity sign = " + std::to_string(sign) + ": must be -1 or +1");
  }
  if (!base::non_negative_finite(packing.lane_gap_m))
    problems.push_back(violation("packing.lane_gap_m", packing.lane_gap_m, ">= 0 and finite"));
  if ((packing.lane_gap_m != 0.0 || packing.lane_gap_auto) && container.shape != ContainerShape::kBox) {
    problems.push_back("packing.lane_gap_m = " +
                       (packing.lane_gap_auto ? std::string("auto") : format_number(packing.lane_gap_m, 12)) +
                       ": lane gaps are supported in a box only (must be 0 for a cylinder)");
  }
  if (packing.staggered && container.shape != ContainerShape::kCylinder)
    problems.push_back("packing.staggered: supported in a cylinder only (a box takes the simple cubic lattice)");
  if (packing.staggered && packing.lattice_counts)
    problems.push_back("packing.staggered: takes the automatic sites (no lattice_counts)");
  if (packing.lattice_counts) {
    for (int i = 0; i < 3; ++i) {
      const int n = (*packing.lattice_counts)[i];
      if (n < 1) {
        problems.push_back("packing.lattice_counts[" + std::to_string(i) + "] = " + std::to_string(n) +
                           ": must be >= 1");
      }
    }
  }
  return problems;
}

}  // namespace

double Container::inner_length(int axis) const {
  if (!is_axis(axis))
    throw std::invalid_argument("Container::inner_length: axis = " + std::to_string(axis) +
                                ": must be 0, 1 or 2");
  if (shape == ContainerShape::kBox) return box_inner_size_m[axis];
  return axis == cylinder_axis ? cylinder_inner_length_m : 2.0 * cylinder_inner_radius_m;
}

Container Container::lined(double thickness_m, int axis) const {
  Container inner = *this;
  if (!(thickness_m > 0.0)) return inner;
  const auto covered = [&](int face_axis) { return axis < 0 || axis == face_axis; };
  if (shape == ContainerShape::kBox) {
    for (int a = 0; a < 3; ++a)
      if (covered(a)) inner.box_inner_size_m[static_cast<std::size_t>(a)] -= 2.0 * thickness_m;
  } else {
    if (covered(cylinder_axis)) inner.cylinder_inner_length_m -= 2.0 * thickness_m;
    if (axis < 0 || axis != cylinder_axis) inner.cylinder_inner_radius_m -= thickness_m;
  }
  return inner;
}

std::vector<std::string> Container::validate(const std::string& prefix) const {
  std::vector<std::string> problems;
  const auto positive = [&](double value, const std::string& name) {
    if (!positive_finite(value)) problems.push_back(violation(field(prefix, name), value, "> 0 and finite"));
  };
  switch (shape) {
    case ContainerShape::kBox:
      for (int i = 0; i < 3; ++i)
        positive(box_inner_size_m[i], "box_inner_size_m[" + std::to_string(i) + "]");
      break;
    case ContainerShape::kCylinder:
      positive(cylinder_inner_radius_m, "cylinder_inner_radius_m");
      positive(cylinder_inner_length_m, "cylinder_inner_length_m");
      if (!is_axis(cylinder_axis)) {
        problems.push_back(field(prefix, "cylinder_axis") + " = " + std::to_string(cylinder_axis) +
                           ": must be 0, 1 or 2");
      }
      break;
    default:
      problems.push_back(field(prefix, "shape") + " = " + std::to_string(static_cast<int>(shape)) +
                         ": must be box or cylinder");
  }
  return problems;
}

namespace {

/// The settled clearance of a box's bed stacked across gravity (LatticeBed): the spheres of
/// each lane (a row along the drive at one position across both the drive and gravity)
/// drop onto the base as far as it holds them. Observed in the DEM (docs/collect_and_collide.md
/// §8): 7 slabs of 8 × 2 spheres (r = 2.5 mm) in 40 mm settle into 8 bottom rows, wall to
/// wall (jammed); 4 slabs in 28 mm into 5 bottom rows and 3 mm of travel.
void settle(LatticeBed& bed, const CrossSection& cs, bool cylinder, double length, double r, int per_slab) {
  bed.settled_clearance_m = bed.clearance_m;
  if (cylinder || cs.gravity_axis < 0) return;
  const int across = cs.axis_a == cs.gravity_axis ? cs.axis_b : cs.axis_a;
  std::map<double, int> lanes, first_slab;  // position across gravity -> spheres in the lane
  for (std::size_t k = 0; k < bed.centres_m.size(); ++k) {
    ++lanes[bed.centres_m[k][across]];
    if (k < static_cast<std::size_t>(per_slab)) ++first_slab[bed.centres_m[k][across]];
  }
  for (const auto& [position, spheres] : first_slab) bed.spheres_per_lane = std::max(bed.spheres_per_lane, spheres);
  const int fit = static_cast<int>(std::floor(length / (2.0 * r) * (1.0 + kFitTolerance)));
  int longest = 0;
  bed.settled_upper_spheres = 0;
  for (const auto& [position, spheres] : lanes) {
    longest = std::max(longest, std::min(spheres, fit));
    bed.settled_upper_spheres += std::max(0, spheres - fit);
  }
  bed.settled_clearance_m = std::max(0.0, length - longest * 2.0 * r);
}

}  // namespace

LatticeBed collected_lattice(const Container& container, int count, double radius_m,
                             const LatticePacking& packing) {
  if (const auto problems = packing_problems(container, count, radius_m, packing); !problems.empty()) {
    std::string text;
    for (const auto& line : problems) text += (text.empty() ? "" : "\n") + line;
    reject(text);
  }
  const double r = radius_m;
  const int drive = packing.drive_axis;
  const bool cylinder = container.shape == ContainerShape::kCylinder;
  if (cylinder && drive != container.cylinder_axis) {
    reject("a cylinder driven across its axis (drive_axis = " + std::to_string(drive) +
           ", cylinder_axis = " + std::to_string(container.cylinder_axis) + ") is not supported yet");
  }

  CrossSection cs;
  cs.axis_a = drive == 0 ? 1 : 0;
  cs.axis_b = drive == 2 ? 1 : 2;
  if (packing.gravity_axis_sign && packing.gravity_axis_sign->first != drive) {
    cs.gravity_axis = packing.gravity_axis_sign->first;
    cs.gravity_sign = packing.gravity_axis_sign->second;
  }
  const double length = container.inner_length(drive);

  // A slab's sites are built and sorted: a cross-section of 1e9 sites (a 100 m box of
  // 5 mm spheres, or 10 µm spheres in a real container) would take minutes and
  // gigabytes for a bed that may hold 36 spheres. Beyond the largest bed (1e7 spheres)
  // the caller must give the counts.
  const auto refuse_huge = [&](double per_slab) {
    if (per_slab > kMaxSlabSites)
      reject("the cross-section normal to axis " + std::to_string(drive) + " holds about " +
             format_number(per_slab, 12) + " lattice sites of radius_m = " + format_number(r, 12) + " (more than " +
             format_number(kMaxSlabSites, 12) + "): give lattice_counts (the lanes the bed really has)");
  };
  std::vector<Vec3> sites, shifted_sites;  // shifted: the staggered lattice's odd slabs
  if (packing.lattice_counts) {
    const auto& n = *packing.lattice_counts;
    refuse_huge(static_cast<double>(n[cs.axis_a]) * n[cs.axis_b]);
    const long long capacity = static_cast<long long>(n[0]) * n[1] * n[2];
    if (count > capacity) {
      reject("count = " + std::to_string(count) + " spheres > " + std::to_string(capacity) +
             " sites of lattice_counts " + counts_text(n));
    }
    const auto check_fit = [&](int axis) {
      const double inner = container.inner_length(axis);
      if (n[axis] * 2.0 * r > inner * (1.0 + kFitTolerance)) {
        reject("lattice_counts " + counts_text(n) + " with radius_m = " + format_number(r, 12) + ": " +
               std::to_string(n[axis]) + " sites need " + format_number(n[axis] * 2.0 * r, 12) + " m along axis " +
               std::to_string(axis) + ", the inner length is " + format_number(inner, 12) + " m");
      }
    };
    check_fit(drive);
    if (cylinder) {
      sites = cylinder_sites_block(r, container.cylinder_inner_radius_m, cs, n[cs.axis_a], n[cs.axis_b]);
    } else {
      check_fit(cs.axis_a);
      check_fit(cs.axis_b);
      for (const int axis : {cs.axis_a, cs.axis_b}) {
        const double inner = container.inner_length(axis);
        const double gap = lane_gap(packing, cs, axis, inner, n[axis], r);
        const double width = n[axis] * 2.0 * r + (n[axis] - 1) * gap;
        if (width > inner * (1.0 + kFitTolerance)) {
          reject("lattice_counts " + counts_text(n) + " with radius_m = " + format_number(r, 12) +
                 " and lane_gap_m = " + format_number(gap, 12) + ": " + std::to_string(n[axis]) + " lanes need " +
                 format_number(width, 12) + " m along axis " + std::to_string(axis) + ", the inner length is " +
                 format_number(inner, 12) + " m");
        }
      }
      sites = box_sites(container, r, cs, n[cs.axis_a], n[cs.axis_b], packing);
    }
  } else if (cylinder) {
    refuse_huge(3.14159265358979323846 * std::pow(container.cylinder_inner_radius_m / (2.0 * r), 2));
    const auto [o_a, o_b] = best_registration(r, container.cylinder_inner_radius_m, cs);
    sites = disk_lattice(r, container.cylinder_inner_radius_m, cs, o_a, o_b);
    if (packing.staggered) {
      shifted_sites = disk_lattice(r, container.cylinder_inner_radius_m, cs, o_a + r, o_b + r);
      if (shifted_sites.empty())
        reject("staggered: no shifted site fits in inner_radius_m = " + format_number(container.cylinder_inner_radius_m, 12) +
               " for radius_m = " + format_number(r, 12) + " (needs inner_radius_m >= (1 + sqrt 2)·radius_m)");
    }
  } else {
    const auto lanes = [&](int axis) {
      const double inner = container.box_inner_size_m[axis];
      // Along gravity rows stack at pitch 2r; "auto" shares what floor(L/2r) lanes leave.
      const bool spaced = axis != cs.gravity_axis && !packing.lane_gap_auto;
      return lanes_along(inner, r, spaced ? packing.lane_gap_m : 0.0);
    };
    refuse_huge(static_cast<double>(lanes(cs.axis_a)) * lanes(cs.axis_b));
    sites = box_sites(container, r, cs, lanes(cs.axis_a), lanes(cs.axis_b), packing);
  }
  if (sites.empty()) {
    reject("no sphere of radius_m = " + format_number(r, 12) + " fits in the cross-section normal to axis " +
           std::to_string(drive) + " (inner lengths " + format_number(container.inner_length(cs.axis_a), 12) + " and " +
           format_number(container.inner_length(cs.axis_b), 12) + " m)");
  }

  // Lowest first (height against gravity), then by position: a strict, deterministic
  // order. Sites of one row share bitwise-equal heights (one expression per row index).
  const auto height = [&](const Vec3& p) {
    return cs.gravity_axis < 0 ? 0.0 : -cs.gravity_sign * p[cs.gravity_axis];
  };
  const auto lowest_first = [&](std::vector<Vec3>& list) {
    std::sort(list.begin(), list.end(), [&](const Vec3& p, const Vec3& q) {
      return std::tuple(height(p), p[0], p[1], p[2]) < std::tuple(height(q), q[0], q[1], q[2]);
    });
  };
  lowest_first(sites);
  lowest_first(shifted_sites);

  // Slab j's sites: the shifted set on odd slabs when staggered. The shifted slab sits in the
  // hollows of its neighbours: its centres are r off along both transverse axes, so touching
  // needs (r√2)² + p² = (2r)², p = r√2.
  const auto slab_sites = [&](int slab) -> const std::vector<Vec3>& {
    return packing.staggered && slab % 2 == 1 ? shifted_sites : sites;
  };
  const double pitch = packing.staggered ? std::sqrt(2.0) * r : 2.0 * r;
  LatticeBed bed;
  for (int placed = 0; placed < count; bed.slabs++) placed += static_cast<int>(slab_sites(bed.slabs).size());
  const int per_slab = static_cast<int>(sites.size());
  bed.bed_extent_m = packing.staggered ? (bed.slabs - 1) * pitch + 2.0 * r : bed.slabs * 2.0 * r;
  bed.clearance_m = length - bed.bed_extent_m;
  if (!(bed.clearance_m > 0.0)) {
    reject("count = " + std::to_string(count) + " spheres of radius_m = " + format_number(r, 12) + " fill " +
           std::to_string(bed.slabs) + " slabs of " + std::to_string(per_slab) + " sites" +
           (packing.staggered ? " (staggered)" : "") + ", extent " + format_number(bed.bed_extent_m, 12) +
           " m along axis " + std::to_string(drive) + " of inner length " + format_number(length, 12) +
           " m: clearance_m = " + format_number(bed.clearance_m, 12) + " must be > 0");
  }

  bed.centres_m.reserve(static_cast<std::size_t>(count));
  for (int slab = 0, placed = 0; placed < count; ++slab) {
    for (const Vec3& site : slab_sites(slab)) {
      if (placed == count) break;
      Vec3 centre = site;
      centre[drive] = packing.collect_side * (0.5 * length - r - pitch * slab);
      bed.centres_m.push_back(centre);
      ++placed;
    }
  }
  settle(bed, cs, cylinder, length, r, per_slab);
  return bed;
}

}  // namespace pdamp::formulas
