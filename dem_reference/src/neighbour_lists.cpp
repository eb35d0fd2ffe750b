// The neighbour lists: when to rebuild them (the displacement bound), the rebuild, the renumbering in cell order.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include "walls.hpp"
#include "world_impl.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::ContactKey;
using detail::Slot;
using detail::kLocalityWindow;
using detail::run_team;

/// Contiguous static chunk [begin, end) of n items for thread t of a team of `size`.
std::pair<int, int> chunk(int n, int t, int size) {
  const auto ln = static_cast<long long>(n);
  return {static_cast<int>(ln * t / size), static_cast<int>(ln * (t + 1) / size)};
}

}  // namespace

// Upper bound of the body-frame displacement since the last rebuild that the coming
// step can reach (the lists stay valid while it is below skin/2). With l = Rᵀ(x − c):
//   |l_{n+1} − r| <= |l_n − r| + |x_{n+1} − x_n| + |c_{n+1} − c_n| + ‖R_{n+1} − R_n‖_F |l_n|,
// where x_{n+1} − x_n = v_{n+1/2}·dt is known once the forces of step n are, and |l_n|
// is at most the reach of the grid box (a particle outside the container has first
// overlapped a wall by more than the instability limit). Taking each term's maximum
// over the particles keeps it an upper bound. Deciding before the step (rather than
// after integrating, as an exact check would) is what lets the sweep integrate just
// ahead of the force rows. The drift term is a few nm per step against a skin/2 of
// 0.1 r: rebuilds come at most a step earlier than with the exact check. (Without a
// renumbering, when the lists are rebuilt does not change any result: a listed pair
// that does not touch adds nothing, and the rows keep their order.)
double World::Impl::displacement_bound(const ContainerState& previous) const {
  double dc2 = 0.0, dr2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    const double d = container.position_m[a] - previous.position_m[a];
    dc2 += d * d;
  }
  for (std::size_t a = 0; a < 9; ++a) {
    const double d = container.orientation[a] - previous.orientation[a];
    dr2 += d * d;
  }
  return std::sqrt(max_d2) + std::sqrt(max_u2) + std::sqrt(dc2) + std::sqrt(dr2) * reach;
}

// The bound's inputs from scratch (after the start, or a velocity change by hand).
void World::Impl::refresh_bound() {
  max_d2 = max_u2 = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    double body[3];
    to_body(x[k], y[k], z[k], body);
    const double dx = body[0] - rx[k], dy = body[1] - ry[k], dz = body[2] - rz[k];
    max_d2 = std::max(max_d2, dx * dx + dy * dy + dz * dz);
    max_u2 = std::max(max_u2, drift2(k));
  }
}

void World::Impl::rebuild_lists() {
  ++rebuilds;
  const auto un = static_cast<std::size_t>(n);
  for (std::size_t k = 0; k < un; ++k) {
    double body[3];
    to_body(x[k], y[k], z[k], body);
    rx[k] = body[0];
    ry[k] = body[1];
    rz[k] = body[2];
  }
  grid.bin(rx.data(), ry.data(), rz.data(), n);
  // Only touching contacts carry history over; the pools shrink to them first.
  pairs.pool.drop_ended();
  wall_rows.pool.drop_ended();
  const int list_threads = team();
  grid.find_pairs(rx.data(), ry.data(), rz.data(), radius.data(), compartment.data(), n, skin, list_threads,
                  pairs.offsets, pairs.slots);
  if (renumbering_pays()) {
    renumber_particles();
    grid.find_pairs(rx.data(), ry.data(), rz.data(), radius.data(), compartment.data(), n, skin, list_threads,
                    pairs.offsets, pairs.slots);
  }
  run_team(list_threads, [&](int t, int size) {
    const auto [begin, end] = chunk(n, t, size);
    for (int i = begin; i < end; ++i) {
      const auto a = static_cast<std::size_t>(i);
      for (int s = pairs.offsets[a]; s < pairs.offsets[a + 1]; ++s) {
        Slot& slot = pairs.slots[static_cast<std::size_t>(s)];
        slot.i = i;
        const auto b = static_cast<std::size_t>(slot.j);
        const double dx = rx[b] - rx[a], dy = ry[b] - ry[a], dz = rz[b] - rz[a];
        const double sum = radius[a] + radius[b];
        slot.contact = dx * dx + dy * dy + dz * dz < sum * sum ? detail::kFreshContact : -1;
      }
    }
  });
  detail::attach_contacts(pairs, [&](int a, int b) {
    return particle_pair_contact(static_cast<std::size_t>(a), static_cast<std::size_t>(b)).params;
  });

  // Walls within the skin of each particle, in (particle, wall) order.
  detail::resize_with_margin(wall_rows.offsets, un + 1);
  wall_rows.slots.clear();
  wall_rows.offsets[0] = 0;
  for (std::size_t k = 0; k < un; ++k) {
    const auto c = static_cast<std::size_t>(compartment[k]);
    const double p[3] = {rx[k], ry[k], rz[k]};
    double nrm[3];
    for (int w = wall_begin[c]; w < wall_end[c]; ++w) {
      const double gap = detail::wall_gap(walls[static_cast<std::size_t>(w)], p, radius[k], nrm);
      if (gap < skin) {
        if (wall_rows.slots.size() == wall_rows.slots.capacity()) {
          wall_rows.slots.reserve(wall_rows.slots.size() + wall_rows.slots.size() / 8 + 16);
        }
        wall_rows.slots.push_back(Slot{static_cast<int>(k), w, gap < 0.0 ? detail::kFreshContact : -1});
      }
    }
    wall_rows.offsets[k + 1] = static_cast<int>(wall_rows.slots.size());
  }
  detail::attach_contacts(wall_rows, [&](int a, int w) {
    return particle_wall_contact(static_cast<std::size_t>(a), w).params;
  });
  plan_partitions();
}

// Whether renumbering the particles in cell order (CellGrid::order) would bring the
// neighbours of the new pair list markedly closer in memory: it counts the listed pairs
// farther apart than kLocalityWindow places now and in cell order. Renumbering costs a
// pass over all arrays and changes the order of the force sums; it is done when the
// bed has mixed (a fluidised bed loses any order within a few periods), not when the
// order is already good (a collected lattice is in lattice order, which serves the
// sweep better than the cell order: cells are wider than the lattice spacing, so a
// cell row mixes two lattice rows). Deterministic: integer counts of the same lists.
bool World::Impl::renumbering_pays() {
  const auto un = static_cast<std::size_t>(n);
  if (pairs.offsets.size() != un + 1 || pairs.slots.empty()) return false;
  const auto& cell_order = grid.order();
  auto& rank = scratch_index;
  for (std::size_t k = 0; k < un; ++k) rank[static_cast<std::size_t>(cell_order[k])] = static_cast<int>(k);
  long long far_now = 0, far_cells = 0;
  for (std::size_t i = 0; i < un; ++i) {
    for (int s = pairs.offsets[i]; s < pairs.offsets[i + 1]; ++s) {
      const auto j = static_cast<std::size_t>(pairs.slots[static_cast<std::size_t>(s)].j);
      far_now += j - i > static_cast<std::size_t>(kLocalityWindow) ? 1 : 0;
      far_cells += std::abs(rank[j] - rank[i]) > kLocalityWindow ? 1 : 0;
    }
  }
  const auto listed = static_cast<long long>(pairs.slots.size());
  return 2 * far_now > 3 * far_cells + listed / 10;
}

// Renumbers the particles in the grid's cell order. Each array is gathered into the
// scratch array, which then takes its place (a swap of buffers, no copy back). Needs
// the ranks left in scratch_index by renumbering_pays().
void World::Impl::renumber_particles() {
  const auto& perm = grid.order();  // perm[k]: old place of the particle at new place k
  const auto& rank = scratch_index;  // rank[old place] = new place
  const auto un = static_cast<std::size_t>(n);
  // A pair keeps i < j: if the new numbers swap the two, the stored spring force and
  // rolling torque (which act on i) change sign; everything else is symmetric.
  auto& pool = pairs.pool;
  for (std::size_t e = 0; e < pool.size(); ++e) {
    auto& key = pool.keys[e];
    int i = rank[static_cast<std::size_t>(key.i)];
    int j = rank[static_cast<std::size_t>(key.j)];
    if (i > j) {
      std::swap(i, j);
      double* ft = pool.state[e].history.ft;
      double* mr = pool.rolling_torque(e);
      for (std::size_t a = 0; a < 3; ++a) {
        ft[a] = -ft[a];
        if (mr) mr[a] = -mr[a];
      }
    }
    key = ContactKey{i, j};
  }
  for (auto& key : wall_rows.pool.keys) key.i = rank[static_cast<std::size_t>(key.i)];
  for (auto* v : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz, &radius, &mass, &inv_mass,
                  &inv_inertia, &rx, &ry, &rz}) {
    for (std::size_t k = 0; k < un; ++k) scratch[k] = (*v)[static_cast<std::size_t>(perm[k])];
    v->swap(scratch);
  }
  for (auto* v : {&material, &compartment, &order}) {
    for (std::size_t k = 0; k < un; ++k) scratch_index[k] = (*v)[static_cast<std::size_t>(perm[k])];
    v->swap(scratch_index);
  }
  for (std::size_t k = 0; k < un; ++k) index_of[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
  grid.adopt_order();
}

}  // namespace pdamp::dem_reference
