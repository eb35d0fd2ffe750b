// The work split between threads: partitions planned and re-planned, a step's merges in partition order.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <vector>

#include "world_impl.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::Partition;
using detail::RowList;
using detail::StagedContact;
using detail::kContactWork;
using detail::kImbalance;
using detail::kParticleWork;

}  // namespace

// Splits the particles into contiguous ranges of about equal work (kParticleWork per
// particle, 1 per listed slot, kContactWork per slot with a pool entry, i.e. a recent
// contact) and finds each range's reach: the particles beyond its end that its rows
// name.
void World::Impl::plan_partitions() {
  const int count = static_cast<int>(parts.size());
  const auto weight = [&](std::size_t i) {
    long long w = kParticleWork;
    for (const RowList* rows : {&pairs, &wall_rows}) {
      for (int s = rows->offsets[i]; s < rows->offsets[i + 1]; ++s) {
        w += rows->slots[static_cast<std::size_t>(s)].contact >= 0 ? kContactWork : 1;
      }
    }
    return w;
  };
  long long total = 0;
  if (count > 1) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) total += weight(i);
  }
  long long sum = 0;
  int i = 0;
  int reached = 0;  // largest halo_end of the partitions so far
  for (int p = 0; p < count; ++p) {
    Partition& part = parts[static_cast<std::size_t>(p)];
    part.begin = i;
    if (p == count - 1) {
      i = n;
    } else {
      const long long goal = total * (p + 1) / count;
      while (i < n && sum < goal) sum += weight(static_cast<std::size_t>(i++));
    }
    part.end = i;
    part.head_end = std::clamp(reached, part.begin, part.end);
    int reach = part.end;
    for (int k = part.begin; k < part.end; ++k) {
      const int row_end = pairs.offsets[static_cast<std::size_t>(k) + 1];
      if (row_end > pairs.offsets[static_cast<std::size_t>(k)]) {
        reach = std::max(reach, pairs.slots[static_cast<std::size_t>(row_end) - 1].j + 1);
      }
    }
    part.halo_end = reach;
    part.halo.assign(6 * static_cast<std::size_t>(reach - part.end), 0.0);
    reached = std::max(reached, reach);
  }
  int longest_head = 0;
  for (const auto& part : parts) longest_head = std::max(longest_head, part.head_end - part.begin);
  for (auto& part : parts) part.early_end = std::min(part.end, part.begin + longest_head);
}

// Whether the work of the last step (in the units of plan_partitions, with the contacts
// actually computed) differs between the partitions by more than kImbalance. The
// partitions are planned at a rebuild; a bed that settles or compresses afterwards
// (a collected bed under gravity: contacts form at the bottom first) moves the work.
// Deterministic: counts, not clocks.
bool World::Impl::imbalanced() const {
  long long most = 0, total = 0;
  for (const auto& part : parts) {
    const long long slots = (pairs.offsets[static_cast<std::size_t>(part.end)] -
                             pairs.offsets[static_cast<std::size_t>(part.begin)]) +
                            (wall_rows.offsets[static_cast<std::size_t>(part.end)] -
                             wall_rows.offsets[static_cast<std::size_t>(part.begin)]);
    const long long work = kParticleWork * (part.end - part.begin) + slots +
                           (kContactWork - 1) * part.dissipation.contacts;
    most = std::max(most, work);
    total += work;
  }
  return static_cast<double>(most) * static_cast<double>(parts.size()) > (1.0 + kImbalance) * static_cast<double>(total);
}

// Appends the contacts first touched in this step to the pools, in partition order
// (the place in the pool does not change any result).
void World::Impl::commit_fresh_contacts() {
  const auto commit = [](std::vector<StagedContact>& staged, RowList& rows) {
    for (const auto& s : staged) {
      rows.slots[static_cast<std::size_t>(s.slot)].contact = rows.pool.add(s.key, s.contact, s.torque);
    }
    staged.clear();
  };
  for (auto& part : parts) {
    commit(part.fresh_pairs, pairs);
    commit(part.fresh_walls, wall_rows);
  }
}

// Adds to the particles of partition `owner` the halo forces of the partitions before
// it, in partition order, and clears those halo entries.
void World::Impl::reduce_halo(int owner) {
  Partition& mine = parts[static_cast<std::size_t>(owner)];
  for (int p = 0; p < owner; ++p) {
    Partition& from = parts[static_cast<std::size_t>(p)];
    const int first = std::max(from.end, mine.begin);
    const int last = std::min(from.halo_end, mine.end);
    for (int i = first; i < last; ++i) {
      const auto k = static_cast<std::size_t>(i);
      double* b = from.halo.data() + 6 * static_cast<std::size_t>(i - from.end);
      fx[k] += b[0];
      fy[k] += b[1];
      fz[k] += b[2];
      tx[k] += b[3];
      ty[k] += b[4];
      tz[k] += b[5];
      b[0] = b[1] = b[2] = b[3] = b[4] = b[5] = 0.0;
    }
  }
  for (int i = mine.begin; i < mine.head_end; ++i) mine.max_u2 = std::max(mine.max_u2, drift2(static_cast<std::size_t>(i)));
}

// Sums over the partitions, in partition order: the container load and the bound's inputs.
void World::Impl::gather() {
  load = ContainerLoad{};
  max_d2 = max_u2 = 0.0;
  for (const auto& part : parts) {
    for (std::size_t a = 0; a < 3; ++a) {
      load.force_n[a] += part.load.force[a];
      load.moment_nm[a] += part.load.moment[a];
    }
    max_d2 = std::max(max_d2, part.max_d2);
    max_u2 = std::max(max_u2, part.max_u2);
  }
}

}  // namespace pdamp::dem_reference
