// Initial placement: lattice collected against a wall (formulas::collected_lattice),
// the same lattice centred, or seeded random non-overlapping positions; radii with the
// group's spread or ball-lot tolerance (seeded), lanes spaced by the compartment's lane gap.
#include "initial_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pdamp/formulas/bed_packing.hpp"

namespace pdamp::dem_reference::detail {

namespace {

constexpr int kRandomAttempts = 2000;

/// Uniform in [0, 1) from the standard-specified mt19937_64 sequence (the standard
/// distributions are implementation-defined: results would differ between libraries).
double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

std::string where(std::size_t compartment) {
  return "compartments[" + std::to_string(compartment) + "]";
}

std::optional<std::pair<int, int>> gravity_axis_sign(const Vec3& g) {
  int axis = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(g[static_cast<std::size_t>(a)]) > std::abs(g[static_cast<std::size_t>(axis)])) axis = a;
  }
  const double value = g[static_cast<std::size_t>(axis)];
  if (value == 0.0) return std::nullopt;
  return std::make_pair(axis, value > 0.0 ? 1 : -1);
}

formulas::LatticePacking packing_of(const CompartmentOptions& c, const Vec3& gravity_body) {
  formulas::LatticePacking packing;
  packing.drive_axis = c.collect_axis;
  packing.collect_side = c.collect_side;
  packing.gravity_axis_sign = gravity_axis_sign(gravity_body);
  if (c.lattice_counts.size() == 3) {
    packing.lattice_counts = std::array<int, 3>{c.lattice_counts[0], c.lattice_counts[1], c.lattice_counts[2]};
  }
  packing.lane_gap_m = c.lane_gap_m;
  packing.lane_gap_auto = c.lane_gap_auto;
  packing.staggered = c.staggered_lattice;
  return packing;
}

/// Fraction of the radius the ball-lot tolerance may take at most: the time-step bound
/// (world_setup.cpp, from radius_m·(1 − radius_spread)) then errs by under 1%.
constexpr double kMaxToleranceFraction = 0.01;

/// Radius of one sphere of the group from one uniform draw u in [0, 1) (exactly one
/// draw per sphere whatever the options, so that the random placement's sequence does
/// not depend on them). A spread gives the bits of r(1 + s(2u − 1)); otherwise the
/// ball-lot tolerance gives r − Δu, Δ = min(V_DwL/2, r/100); both zero: r exactly.
double draw_radius(const ParticleGroupOptions& group, double u) {
  if (group.radius_spread > 0.0 || group.lot_diameter_variation_m == 0.0) {
    return group.radius_m * (1.0 + group.radius_spread * (2.0 * u - 1.0));
  }
  const double range = std::min(0.5 * group.lot_diameter_variation_m, kMaxToleranceFraction * group.radius_m);
  return group.radius_m - range * u;
}

/// Largest distance a centre may have from the compartment centre along each axis, and
/// for a cylinder the largest radial distance.
bool inside_container(const formulas::Container& box, const Vec3& p, double r) {
  if (box.shape == formulas::ContainerShape::kBox) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (std::abs(p[a]) > 0.5 * box.box_inner_size_m[a] - r) return false;
    }
    return true;
  }
  const auto axis = static_cast<std::size_t>(box.cylinder_axis);
  double rho2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    if (a != axis) rho2 += p[a] * p[a];
  }
  const double rmax = box.cylinder_inner_radius_m - r;
  return std::abs(p[axis]) <= 0.5 * box.cylinder_inner_length_m - r && rmax > 0.0 && rho2 <= rmax * rmax;
}

/// Index of an inner structure (plate/pin) of compartment `id` overlapping the sphere, or −1.
int overlapping_structure(const std::vector<WallFeature>& walls, int id, const Vec3& body, double r) {
  double n[3];
  const double p[3] = {body[0], body[1], body[2]};
  int index = 0;
  for (const auto& w : walls) {
    if (w.compartment != id || (w.kind != WallKind::kBox && w.kind != WallKind::kPin)) continue;
    if (wall_gap(w, p, r, n) < 0.0) return index;
    ++index;
  }
  return -1;
}

}  // namespace

InitialBed place_particles(const WorldOptions& options, const std::vector<WallFeature>& walls,
                           const Vec3& gravity_body) {
  InitialBed bed;
  std::mt19937_64 rng(options.seed);
  for (std::size_t ci = 0; ci < options.compartments.size(); ++ci) {
    const auto& c = options.compartments[ci];
    const int id = static_cast<int>(ci);
    const auto first = bed.positions_m.size();
    double r_max = 0.0;
    int count = 0;
    for (const auto& group : c.particles) {
      for (int k = 0; k < group.count; ++k) {
        const double r = draw_radius(group, uniform(rng));
        bed.radii_m.push_back(r);
        bed.materials.push_back(group.material);
        bed.compartments.push_back(id);
        r_max = std::max(r_max, group.radius_m * (1.0 + group.radius_spread));
        ++count;
      }
    }
    const formulas::Container inner = layered_container(c);
    const auto packing = packing_of(c, gravity_body);
    std::optional<formulas::LatticeBed> lattice;
    try {
      lattice = formulas::collected_lattice(inner, count, r_max, packing);
    } catch (const std::invalid_argument& e) {
      if (c.placement != InitialPlacement::kRandom) {
        throw std::invalid_argument(where(ci) + ": " + e.what());
      }
    }
    // The free travel of the settled bed (a bed stacked across gravity spreads onto the
    // base in its first period): the h the closed forms and the case take.
    bed.clearances_m.push_back(lattice ? lattice->settled_clearance_m : std::numeric_limits<double>::quiet_NaN());
    if (c.placement != InitialPlacement::kRandom) {
      const double shift = c.placement == InitialPlacement::kCentredLattice
                               ? -0.5 * static_cast<double>(c.collect_side) * lattice->clearance_m
                               : 0.0;
      for (int k = 0; k < count; ++k) {
        Vec3 p = lattice->centres_m[static_cast<std::size_t>(k)];
        p[static_cast<std::size_t>(c.collect_axis)] += shift;
        const Vec3 body{p[0] + c.offset_m[0], p[1] + c.offset_m[1], p[2] + c.offset_m[2]};
        const double r = bed.radii_m[first + static_cast<std::size_t>(k)];
        const int hit = overlapping_structure(walls, id, body, r);
        if (hit >= 0) {
          std::ostringstream msg;
          msg << where(ci) << ": lattice site " << k << " at (" << p[0] << ", " << p[1] << ", " << p[2]
              << ") m overlaps inner structure " << hit
              << " (plates first, then pins): move the structure or use random placement";
          throw std::invalid_argument(msg.str());
        }
        bed.positions_m.push_back(body);
      }
      continue;
    }
    // Random placement: rejection sampling against the spheres placed so far (O(N²),
    // meant for beds of up to a few thousand spheres; large beds use the lattice).
    for (int k = 0; k < count; ++k) {
      const double r = bed.radii_m[first + static_cast<std::size_t>(k)];
      bool placed = false;
      for (int attempt = 0; attempt < kRandomAttempts && !placed; ++attempt) {
        Vec3 p{};
        for (std::size_t a = 0; a < 3; ++a) {
          const double half = inner.shape == formulas::ContainerShape::kBox
                                  ? 0.5 * inner.box_inner_size_m[a]
                                  : (static_cast<int>(a) == inner.cylinder_axis ? 0.5 * inner.cylinder_inner_length_m
                                                                                : inner.cylinder_inner_radius_m);
          p[a] = (2.0 * uniform(rng) - 1.0) * (half - r);
        }
        if (!inside_container(inner, p, r)) continue;
        const Vec3 body{p[0] + c.offset_m[0], p[1] + c.offset_m[1], p[2] + c.offset_m[2]};
        if (overlapping_structure(walls, id, body, r) >= 0) continue;
        bool free = true;
        for (std::size_t q = first; q < bed.positions_m.size() && free; ++q) {
          const double dx = bed.positions_m[q][0] - body[0];
          const double dy = bed.positions_m[q][1] - body[1];
          const double dz = bed.positions_m[q][2] - body[2];
          const double rr = bed.radii_m[q] + r;
          free = dx * dx + dy * dy + dz * dz >= rr * rr;
        }
        if (free) {
          bed.positions_m.push_back(body);
          placed = true;
        }
      }
      if (!placed) {
        std::ostringstream msg;
        msg << where(ci) << ": random placement found no free position for particle " << k + 1 << " of "
            << count << " (radius " << r << " m) in " << kRandomAttempts
            << " attempts: use fewer or smaller particles, a larger container, or a lattice placement";
        throw std::invalid_argument(msg.str());
      }
    }
  }
  return bed;
}

}  // namespace pdamp::dem_reference::detail
