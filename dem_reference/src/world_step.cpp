// The step: World::step, its stages (advance), the integration and the force sweep with the contact pieces it inlines.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <exception>
#include <string>
#include <vector>

#include "contact_law.hpp"
#include "walls.hpp"
#include "world_impl.hpp"

// Everything the step calls per particle or per contact is in this translation unit (or in
// a header: the lane kernel), so that the compiler inlines it into the row loop: the sweep
// and its pieces, the integration. What the step calls out of line, a few times per step at
// most (the rebuild decision and the list rebuild, the partitions' merges, the record), is
// in the other files of the world (world_impl.hpp lists them).

namespace pdamp::dem_reference {

namespace {

using detail::Contact;
using detail::ContactKey;
using detail::ContactKinematics;
using detail::ContactResult;
using detail::ForceArrays;
using detail::LoadSums;
using detail::PairGeometry;
using detail::Partition;
using detail::PartitionSweep;
using detail::RowList;
using detail::Slot;
using detail::StagedContact;
using detail::StepDissipation;
using detail::WaitingPair;
using detail::WaitingWall;
using detail::WallFrame;
using detail::run_team;
using detail::kAheadChunk;
using detail::kBalanceStride;
using detail::kDoublesPerLine;
using detail::kHealthStride;
using detail::kIntegratePrefetch;
using detail::kPrefetchSlots;
using detail::kRowBlock;
using detail::kTimingStride;
using Clock = std::chrono::steady_clock;

/// Adds a pair's force and torques (ContactResult): F on i and −F on j, R_i·c + m on i and
/// R_j·c − m on j; j's directly, or through the halo when j is beyond the partition.
[[gnu::always_inline]] inline void apply_pair_force(const ForceArrays& to, const ContactResult& r,
                                                    const PairGeometry& g) {
  const std::size_t i = g.i, j = g.j;
  to.fx[i] += r.f[0];
  to.fy[i] += r.f[1];
  to.fz[i] += r.f[2];
  to.tx[i] += g.ri * r.c[0] + r.m[0];
  to.ty[i] += g.ri * r.c[1] + r.m[1];
  to.tz[i] += g.ri * r.c[2] + r.m[2];
  if (j < to.end) {
    to.fx[j] -= r.f[0];
    to.fy[j] -= r.f[1];
    to.fz[j] -= r.f[2];
    to.tx[j] += g.rj * r.c[0] - r.m[0];
    to.ty[j] += g.rj * r.c[1] - r.m[1];
    to.tz[j] += g.rj * r.c[2] - r.m[2];
  } else {
    double* b = to.halo + 6 * (j - to.end);
    b[0] -= r.f[0];
    b[1] -= r.f[1];
    b[2] -= r.f[2];
    b[3] += g.rj * r.c[0] - r.m[0];
    b[4] += g.rj * r.c[1] - r.m[1];
    b[5] += g.rj * r.c[2] - r.m[2];
  }
}

/// Adds a wall contact's force F and torque R_i·c + m on particle i, and its share of the
/// container load: F, and its moment about the container origin r_c × F + m (r_c: the
/// contact point relative to the origin).
[[gnu::always_inline]] inline void apply_wall_force(const ForceArrays& to, LoadSums& load, const ContactResult& r,
                                                    std::size_t i, double ri, const double* rc) {
  to.fx[i] += r.f[0];
  to.fy[i] += r.f[1];
  to.fz[i] += r.f[2];
  to.tx[i] += ri * r.c[0] + r.m[0];
  to.ty[i] += ri * r.c[1] + r.m[1];
  to.tz[i] += ri * r.c[2] + r.m[2];
  load.force[0] += r.f[0];
  load.force[1] += r.f[1];
  load.force[2] += r.f[2];
  load.moment[0] += rc[1] * r.f[2] - rc[2] * r.f[1] + r.m[0];
  load.moment[1] += rc[2] * r.f[0] - rc[0] * r.f[2] + r.m[1];
  load.moment[2] += rc[0] * r.f[1] - rc[1] * r.f[0] + r.m[2];
}

/// Prefetches the history of pair slot s, if it has one in the pool (read in slot order but
/// sparsely: only touching pairs have an entry, so the hardware prefetcher misses them).
[[gnu::always_inline]] inline void prefetch_history(const Slot* slots, int slot_count, const Contact* pool, int s) {
  if (s >= slot_count) return;
  const int contact = slots[s].contact;
  if (contact < 0) return;
  const auto* entry = reinterpret_cast<const char*>(pool + contact);
  __builtin_prefetch(entry, 1);
  __builtin_prefetch(entry + sizeof(Contact) - 1, 1);
}

/// The contacts waiting in w[0..kN) as the lanes of one kernel call: each one's parameters,
/// history and rolling torque, pooled in `rows` or staged in this step in `staged` (found by
/// index: staging may move the staged ones), and where its result goes.
template <int kN, class Waiting>
[[gnu::always_inline]] inline detail::ContactLanes<kN> contact_lanes(RowList& rows, std::vector<StagedContact>& staged,
                                                                     const Waiting* w, ContactResult* out) {
  detail::ContactLanes<kN> c;
  for (int l = 0; l < kN; ++l) {
    Contact* state;
    double* torque;
    if (w[l].contact >= 0) {
      state = &rows.pool.state[static_cast<std::size_t>(w[l].contact)];
      torque = rows.pool.rolling_torque(static_cast<std::size_t>(w[l].contact));
    } else {
      StagedContact& s = staged[static_cast<std::size_t>(w[l].fresh)];
      state = &s.contact;
      torque = s.torque;
    }
    c.params[l] = &state->params;
    c.history[l] = &state->history;
    c.rolling_torque[l] = torque;
    c.out[l] = &out[l];
  }
  return c;
}

}  // namespace

Contact World::Impl::particle_pair_contact(std::size_t a, std::size_t b) const {
  Contact c;
  c.params = law.particle_pair(radius[a], mass[a], material[a], radius[b], mass[b], material[b]);
  return c;
}

// The curvature is that of the wall part nearest to where the particle was when the
// contact was listed (the last rebuild): a sphere sliding over a pin's rim keeps it.
Contact World::Impl::particle_wall_contact(std::size_t a, int wall) const {
  const auto& w = walls[static_cast<std::size_t>(wall)];
  const double listed_at[3] = {rx[a], ry[a], rz[a]};
  Contact c;
  c.params = law.particle_wall(radius[a], mass[a], material[a], w.material,
                               detail::contact_curvature_radius(w, listed_at), w.layer_thickness_m);
  return c;
}

// Normal, overlap and relative motion of W::kWidth touching pairs (lane l: g[l]):
// contact-point velocity of i relative to j, v_i − v_j + (r_i ω_i + r_j ω_j) × n, and
// ω_i − ω_j. One IEEE operation order for every width (see detail::contact_force_lanes).
template <class W>
inline detail::KinematicsLanes<W> World::Impl::pair_kinematics(const PairGeometry* const* g) const {
  const auto at = [&](const std::vector<double>& a, bool of_i) {
    return W::gather([&](int l) { return a[of_i ? g[l]->i : g[l]->j]; });
  };
  const W dist = sqrt(W::gather([&](int l) { return g[l]->d2; }));
  const W inv = W::splat(1.0) / dist;
  detail::KinematicsLanes<W> k;
  k.n[0] = W::gather([&](int l) { return g[l]->dx; }) * inv;
  k.n[1] = W::gather([&](int l) { return g[l]->dy; }) * inv;
  k.n[2] = W::gather([&](int l) { return g[l]->dz; }) * inv;
  k.delta = W::gather([&](int l) { return g[l]->sum; }) - dist;
  const W ri = W::gather([&](int l) { return g[l]->ri; }), rj = W::gather([&](int l) { return g[l]->rj; });
  const W wi[3] = {at(wx, true), at(wy, true), at(wz, true)};
  const W wj[3] = {at(wx, false), at(wy, false), at(wz, false)};
  const W ax = ri * wi[0] + rj * wj[0], ay = ri * wi[1] + rj * wj[1], az = ri * wi[2] + rj * wj[2];
  k.v[0] = at(vx, true) - at(vx, false) + ay * k.n[2] - az * k.n[1];
  k.v[1] = at(vy, true) - at(vy, false) + az * k.n[0] - ax * k.n[2];
  k.v[2] = at(vz, true) - at(vz, false) + ax * k.n[1] - ay * k.n[0];
  for (int c = 0; c < 3; ++c) k.w[c] = wi[c] - wj[c];
  return k;
}

// A step in one OpenMP region: the rebuild check (before: a rebuild has parallel loops
// of its own), then per partition integrate the head (up to early_end), barrier, sweep
// (integrating just ahead of the rows), barrier, fresh contacts and halo forces. On the
// steps that sample the stage times the partitions are integrated whole before the
// sweep (the same arithmetic: the results do not depend on it).
void World::Impl::advance(bool timed, const ContainerState& previous) {
  const auto t0 = timed ? Clock::now() : Clock::time_point{};
  if (rebuild_due || displacement_bound(previous) > 0.5 * skin) {
    rebuild_due = false;
    rebuild_lists();
  } else if (parts.size() > 1 && steps % kBalanceStride == 0 && imbalanced()) {
    plan_partitions();
  }
  const auto t1 = timed ? Clock::now() : Clock::time_point{};
  auto t2 = t1;
  const int count = static_cast<int>(parts.size());
  run_team(
      team(),
      [&](int t, int size) {
        for (int p = t; p < count; p += size) {
          Partition& part = parts[static_cast<std::size_t>(p)];
          part.max_d2 = part.max_u2 = 0.0;
          integrate(part.begin, timed ? part.end : part.early_end, part);
        }
      },
      [&](int t, int size) {
        if (timed && t == 0) t2 = Clock::now();
        for (int p = t; p < count; p += size) sweep(parts[static_cast<std::size_t>(p)], !timed);
      },
      [&](int t, int size) {
        if (t == 0) commit_fresh_contacts();
        for (int p = t; p < count; p += size) reduce_halo(p);
      });
  gather();
  if (timed) {
    const auto t3 = Clock::now();
    const auto span = [](Clock::time_point a, Clock::time_point b) {
      return kTimingStride * std::chrono::duration<double>(b - a).count();
    };
    stage_times.neighbour_s += span(t0, t1);
    stage_times.integrate_s += span(t1, t2);
    stage_times.contact_forces_s += span(t2, t3);
  }
}

namespace {

/// The particle arrays integrate_rows reads and writes (raw: the rows of one call never
/// alias, which lets the compiler put neighbouring particles in the lanes of a register).
struct IntegrationArrays {
  double* __restrict x;
  double* __restrict y;
  double* __restrict z;
  double* __restrict vx;
  double* __restrict vy;
  double* __restrict vz;
  double* __restrict wx;
  double* __restrict wy;
  double* __restrict wz;
  double* __restrict fx;
  double* __restrict fy;
  double* __restrict fz;
  double* __restrict tx;
  double* __restrict ty;
  double* __restrict tz;
  const double* __restrict inv_mass;
  const double* __restrict inv_inertia;
  const double* __restrict mass;
  const double* __restrict rx;
  const double* __restrict ry;
  const double* __restrict rz;
};

/// One step of rows [begin, end) (at most kDoublesPerLine, one cache line): the kick with the
/// forces and torques of the current positions, the drift, the squared displacement since the
/// last rebuild (in the container's body frame as to_body gives it: R^T (x − c), R the
/// container's orientation when kRotated, else x − c) into d2_max, and the forces reset to
/// gravity for the next sweep. Each particle takes the
/// operations of the scalar update in the same order whatever the lanes, so the bits do not
/// depend on how the compiler vectorises the loop; the largest displacement is a max, which
/// does not depend on the order either.
template <bool kRotated>
void integrate_rows(const IntegrationArrays a, int begin, int end, double h, const double* g, const double* c,
                    const double* R, double& d2_max) {
  // The rows' squared displacements, their max taken after the loop: a max reduction inside
  // it would keep the loop scalar (without -ffinite-math-only the compiler may not reorder it).
  double u2_of[kDoublesPerLine];
  for (int k = begin; k < end; ++k) {
    const double im = a.inv_mass[k] * h;
    const double ii = a.inv_inertia[k] * h;
    a.vx[k] += a.fx[k] * im;
    a.vy[k] += a.fy[k] * im;
    a.vz[k] += a.fz[k] * im;
    a.wx[k] += a.tx[k] * ii;
    a.wy[k] += a.ty[k] * ii;
    a.wz[k] += a.tz[k] * ii;
    a.x[k] += a.vx[k] * h;
    a.y[k] += a.vy[k] * h;
    a.z[k] += a.vz[k] * h;
    const double d0 = a.x[k] - c[0], d1 = a.y[k] - c[1], d2 = a.z[k] - c[2];
    double b0 = d0, b1 = d1, b2 = d2;
    if constexpr (kRotated) {
      b0 = R[0] * d0 + R[3] * d1 + R[6] * d2;
      b1 = R[1] * d0 + R[4] * d1 + R[7] * d2;
      b2 = R[2] * d0 + R[5] * d1 + R[8] * d2;
    }
    const double ux = b0 - a.rx[k], uy = b1 - a.ry[k], uz = b2 - a.rz[k];
    u2_of[k - begin] = ux * ux + uy * uy + uz * uz;
    a.fx[k] = a.mass[k] * g[0];
    a.fy[k] = a.mass[k] * g[1];
    a.fz[k] = a.mass[k] * g[2];
    a.tx[k] = 0.0;
    a.ty[k] = 0.0;
    a.tz[k] = 0.0;
  }
  for (int r = 0; r < end - begin; ++r) d2_max = std::max(d2_max, u2_of[r]);
}

}  // namespace

void World::Impl::integrate(int begin, int end, Partition& part) {
  const IntegrationArrays arrays{x.data(),  y.data(),  z.data(),  vx.data(),       vy.data(),          vz.data(),
                                 wx.data(), wy.data(), wz.data(), fx.data(),       fy.data(),          fz.data(),
                                 tx.data(), ty.data(), tz.data(), inv_mass.data(), inv_inertia.data(), mass.data(),
                                 rx.data(), ry.data(), rz.data()};
  const double* const g = options.gravity_m_s2.data();
  const double* const c = container.position_m.data();
  const double* const R = container.orientation.data();
  double d2_max = part.max_d2;
  // Cache line by cache line, the lines kIntegratePrefetch particles ahead requested first
  // (a large bed streams its arrays through the step).
  for (int line = begin; line < end;) {
    const int line_end = std::min(end, (line / kDoublesPerLine + 1) * kDoublesPerLine);
    if (line % kDoublesPerLine == 0 && line + kIntegratePrefetch < n) {
      const auto ahead = static_cast<std::size_t>(line + kIntegratePrefetch);
      for (const auto* v : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz}) {
        __builtin_prefetch(v->data() + ahead, 1);
      }
      for (const auto* v : {&inv_mass, &inv_inertia, &mass, &rx, &ry, &rz}) __builtin_prefetch(v->data() + ahead, 0);
    }
    if (rotated) {
      integrate_rows<true>(arrays, line, line_end, dt, g, c, R, d2_max);
    } else {
      integrate_rows<false>(arrays, line, line_end, dt, g, c, R, d2_max);
    }
    line = line_end;
  }
  part.max_d2 = d2_max;
}

// Forces of the rows of one partition, in blocks of rows: the pairs of the block, then
// its walls (flat loops over many slots: rows are short, and a loop per row would pay
// a mispredicted exit per particle). A particle's walls thus follow all its pair forces
// (from its own row and from earlier rows naming it), so its sums run in the same
// order as with all walls after all pairs. Touching contacts are evaluated
// SweepLanes::kWidth at a time (contact_force_lanes; the rest of a block with fewer
// lanes) and their forces added one after the other, in slot order.
// With integrate_ahead, the particles a slot needs are integrated just before it (a
// particle's data then come from memory once per step).
template <bool kPrefetch>
void World::Impl::sweep(Partition& part, bool integrate_ahead) {
  using Lanes = detail::simd::SweepLanes;
  constexpr int kLanes = Lanes::kWidth;
  const WallFrame frame = wall_frame();
  PartitionSweep sweep{part,
                       ForceArrays{fx.data(), fy.data(), fz.data(), tx.data(), ty.data(), tz.data(), part.halo.data(),
                                   static_cast<std::size_t>(part.end)},
                       dt,
                       overlap_limit,
                       {},
                       {}};
  int ahead = integrate_ahead ? part.early_end : part.end;  // the particles before it are integrated
  double u2_max = part.max_u2;
  const Slot* const pair_slots = pairs.slots.data();
  const int pair_slot_count = static_cast<int>(pairs.slots.size());
  const Contact* const pair_state = pairs.pool.state.data();
  const Slot* const wall_slots = wall_rows.slots.data();
  WaitingPair waiting_pairs[kLanes];
  WaitingWall waiting_walls[kLanes];
  int pair_count = 0, wall_count = 0;
  for (int block = part.begin; block < part.end; block += kRowBlock) {
    const int block_end = std::min(part.end, block + kRowBlock);
    if (block_end > ahead) integrate_to(part, ahead, block_end);
    // The block's pairs; touching ones wait until SweepLanes::kWidth of them are evaluated
    // together (pair_kinematics and contact_force_lanes).
    const int pair_last = pairs.offsets[static_cast<std::size_t>(block_end)];
    for (int s = pairs.offsets[static_cast<std::size_t>(block)]; s < pair_last; ++s) {
      if (kPrefetch) prefetch_history(pair_slots, pair_slot_count, pair_state, s + kPrefetchSlots);
      const Slot& slot = pair_slots[s];
      if (slot.j >= ahead && ahead < part.end) integrate_to(part, ahead, slot.j + 1);
      if (!touching_pair(slot, s, part, waiting_pairs[pair_count])) continue;
      if (++pair_count == kLanes) {
        contact_forces<Lanes>(waiting_pairs, sweep);
        pair_count = 0;
      }
    }
    flush(waiting_pairs, pair_count, sweep);
    // Then its walls, in the same lanes.
    const int wall_last = wall_rows.offsets[static_cast<std::size_t>(block_end)];
    for (int s = wall_rows.offsets[static_cast<std::size_t>(block)]; s < wall_last; ++s) {
      if (!touching_wall(wall_slots[s], s, frame, sweep, waiting_walls[wall_count])) continue;
      if (++wall_count == kLanes) {
        contact_forces<Lanes>(waiting_walls, sweep);
        wall_count = 0;
      }
    }
    flush(waiting_walls, wall_count, sweep);
    // The block's forces are complete (but for what earlier partitions add: reduce_halo).
    for (int row = std::max(block, part.head_end); row < block_end; ++row) {
      u2_max = std::max(u2_max, drift2(static_cast<std::size_t>(row)));
    }
  }
  part.max_u2 = u2_max;
  part.dissipation = sweep.dissipation;
  part.load = sweep.load;
}

WallFrame World::Impl::wall_frame() const {
  WallFrame f;
  f.orientation = container.orientation;
  f.rotated = rotated;
  for (std::size_t a = 0; a < 3; ++a) {
    f.position[a] = container.position_m[a];
    f.velocity[a] = container_velocity[a];
    f.angular_velocity[a] = container.angular_velocity_rad_s[a];
  }
  return f;
}

// Integrates the partition's particles up to `upto` (exclusive), at least kAheadChunk at a
// time (long runs stream better than one particle per row).
inline void World::Impl::integrate_to(Partition& part, int& ahead, int upto) {
  const int to = std::min(part.end, std::max(upto, ahead + kAheadChunk));
  integrate(ahead, to, part);
  ahead = to;
}

// The distance test of pair slot s (both particles integrated): false when the two do not
// touch (a contact that has just ended loses its history); else the pair's geometry and
// where its history is: in the pool, or staged now in the partition for a first touch.
inline bool World::Impl::touching_pair(const Slot& slot, int s, Partition& part, WaitingPair& out) {
  const auto i = static_cast<std::size_t>(slot.i), j = static_cast<std::size_t>(slot.j);
  const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
  const double ri = radius[i], rj = radius[j];
  const double d2 = dx * dx + dy * dy + dz * dz;
  const double sum = ri + rj;
  if (d2 >= sum * sum) {
    if (slot.contact >= 0 && pairs.pool.state[static_cast<std::size_t>(slot.contact)].history.gamma >= 0.0) {
      pairs.pool.reset(static_cast<std::size_t>(slot.contact));
    }
    return false;
  }
  int fresh = -1;
  if (slot.contact < 0) {
    StagedContact& staged = part.fresh_pairs.emplace_back();
    staged.slot = s;
    staged.key = ContactKey{slot.i, slot.j};
    staged.contact = particle_pair_contact(i, j);
    fresh = static_cast<int>(part.fresh_pairs.size()) - 1;
  }
  out = WaitingPair{PairGeometry{dx, dy, dz, d2, sum, ri, rj, i, j}, slot.contact, fresh};
  return true;
}

// The gap of wall slot s: false when the particle does not touch the wall (a contact that
// has just ended loses its history); else its kinematics, an overlap beyond the instability
// limit recorded, and where its history is (pooled, or staged now for a first touch).
inline bool World::Impl::touching_wall(const Slot& slot, int s, const WallFrame& frame, PartitionSweep& sweep,
                                       WaitingWall& out) {
  const auto i = static_cast<std::size_t>(slot.i);
  const double ri = radius[i];
  double p[3];
  to_body(x[i], y[i], z[i], p);
  double n_body[3];
  const double gap = detail::wall_gap(walls[static_cast<std::size_t>(slot.j)], p, ri, n_body);
  if (gap >= 0.0) {
    if (slot.contact >= 0 && wall_rows.pool.state[static_cast<std::size_t>(slot.contact)].history.gamma >= 0.0) {
      wall_rows.pool.reset(static_cast<std::size_t>(slot.contact));
    }
    return false;
  }
  wall_kinematics(i, ri, n_body, gap, frame, out);
  StepDissipation& diss = sweep.dissipation;
  // A buffer layer's surface is exempt: a sphere sinks into a soft layer by a good part of
  // its thickness (that is the layer's purpose), and beyond the thickness the hard face
  // under it engages, whose overlap is watched.
  if (out.k.delta > sweep.overlap_limit * ri && walls[static_cast<std::size_t>(slot.j)].layer_thickness_m == 0.0)
    diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, out.k.delta / ri);
  out.fresh = -1;
  if (slot.contact < 0) {
    StagedContact& staged = sweep.part.fresh_walls.emplace_back();
    staged.slot = s;
    staged.key = ContactKey{slot.i, slot.j};
    staged.contact = particle_wall_contact(i, slot.j);
    out.fresh = static_cast<int>(sweep.part.fresh_walls.size()) - 1;
  }
  out.contact = slot.contact;
  return true;
}

// A touching wall's contact in the world frame: the normal n = R·n_body (into the wall), the
// overlap δ = −gap, the contact point r_c = x_i + r_i n − c relative to the container origin
// c, and the velocity of the particle's surface there relative to the wall's,
// v_i + ω_i × r_i n − (v_c + ω_c × r_c), with ω_i − ω_c.
inline void World::Impl::wall_kinematics(std::size_t i, double ri, const double* n_body, double gap,
                                         const WallFrame& frame, WaitingWall& out) const {
  ContactKinematics& k = out.k;
  if (frame.rotated) {
    const auto& R = frame.orientation;
    k.n[0] = R[0] * n_body[0] + R[1] * n_body[1] + R[2] * n_body[2];
    k.n[1] = R[3] * n_body[0] + R[4] * n_body[1] + R[5] * n_body[2];
    k.n[2] = R[6] * n_body[0] + R[7] * n_body[1] + R[8] * n_body[2];
  } else {
    k.n[0] = n_body[0];
    k.n[1] = n_body[1];
    k.n[2] = n_body[2];
  }
  k.delta = -gap;
  const double* cp = frame.position;
  const double* cv = frame.velocity;
  const double* cw = frame.angular_velocity;
  const double arm[3] = {ri * k.n[0], ri * k.n[1], ri * k.n[2]};
  double* rc = out.rc;
  rc[0] = x[i] + arm[0] - cp[0];
  rc[1] = y[i] + arm[1] - cp[1];
  rc[2] = z[i] + arm[2] - cp[2];
  const double vw[3] = {cv[0] + cw[1] * rc[2] - cw[2] * rc[1], cv[1] + cw[2] * rc[0] - cw[0] * rc[2],
                        cv[2] + cw[0] * rc[1] - cw[1] * rc[0]};
  k.v[0] = vx[i] + wy[i] * arm[2] - wz[i] * arm[1] - vw[0];
  k.v[1] = vy[i] + wz[i] * arm[0] - wx[i] * arm[2] - vw[1];
  k.v[2] = vz[i] + wx[i] * arm[1] - wy[i] * arm[0] - vw[2];
  k.w[0] = wx[i] - cw[0];
  k.w[1] = wy[i] - cw[1];
  k.w[2] = wz[i] - cw[2];
  out.i = i;
  out.ri = ri;
}

// W::kWidth waiting pairs in the lanes of a W: their kinematics (pair_kinematics), an overlap
// beyond the instability limit recorded (δ/r_min of the pair), the contact law, and their
// forces added one after the other, in slot order. Out of line: inlined into the row loop,
// its many live lanes cost the loop its registers (measured at 10,000 spheres: 7% more
// instructions in the sweep).
template <class W>
void World::Impl::contact_forces(const WaitingPair* w, PartitionSweep& sweep) {
  constexpr int kN = W::kWidth;
  const PairGeometry* g[kN];
  for (int l = 0; l < kN; ++l) g[l] = &w[l].g;
  const detail::KinematicsLanes<W> kin = pair_kinematics<W>(g);
  StepDissipation& diss = sweep.dissipation;
  for (int l = 0; l < kN; ++l) {
    const double delta = lane(kin.delta, l);
    const double rmin = w[l].g.ri < w[l].g.rj ? w[l].g.ri : w[l].g.rj;
    if (delta > sweep.overlap_limit * rmin) diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, delta / rmin);
  }
  ContactResult out[kN];
  detail::contact_force_lanes<W>(contact_lanes<kN>(pairs, sweep.part.fresh_pairs, w, out), kin, sweep.h, law, diss);
  for (int l = 0; l < kN; ++l) apply_pair_force(sweep.forces, out[l], w[l].g);
}

// W::kWidth waiting wall contacts in the lanes of a W: the contact law, then their forces and
// their share of the container load, one after the other, in slot order.
template <class W>
inline void World::Impl::contact_forces(const WaitingWall* w, PartitionSweep& sweep) {
  constexpr int kN = W::kWidth;
  const ContactKinematics* kin[kN];
  for (int l = 0; l < kN; ++l) kin[l] = &w[l].k;
  ContactResult out[kN];
  detail::contact_force_lanes<W>(contact_lanes<kN>(wall_rows, sweep.part.fresh_walls, w, out),
                                 detail::load_kinematics<W>(kin), sweep.h, law, sweep.dissipation);
  for (int l = 0; l < kN; ++l) apply_wall_force(sweep.forces, sweep.load, out[l], w[l].i, w[l].ri, w[l].rc);
}

// The count < SweepLanes::kWidth contacts left waiting at the end of a block: four lanes at a
// time (eight-lane builds), two, then one.
template <class Waiting>
inline void World::Impl::flush(const Waiting* w, int& count, PartitionSweep& sweep) {
  int done = 0;
#if defined(PDAMP_LANES_AVX2)
  if constexpr (detail::simd::SweepLanes::kWidth > 4) {
    for (; count - done >= 4; done += 4) contact_forces<detail::simd::LanesAvx2>(w + done, sweep);
  }
#endif
  if constexpr (detail::simd::SweepLanes::kWidth > 2) {
    for (; count - done >= 2; done += 2) contact_forces<detail::simd::Lanes2>(w + done, sweep);
  }
  for (; done < count; ++done) contact_forces<detail::simd::Lanes1>(w + done, sweep);
  count = 0;
}

// The sweeps the constructor's first forces call (world_setup.cpp).
template void World::Impl::sweep<true>(Partition& part, bool integrate_ahead);
template void World::Impl::sweep<false>(Partition& part, bool integrate_ahead);

const ContainerLoad& World::step(const ContainerState& next) {
  Impl& w = *impl_;
  if (w.status.outcome != Outcome::kCompleted) return w.load;
  const bool timed = w.steps % kTimingStride == 0;
  const ContainerState previous = w.container;
  w.container = next;
  w.rotated = next.orientation != kIdentity;
  for (std::size_t a = 0; a < 3; ++a) {
    w.container_velocity[a] = (next.position_m[a] - previous.position_m[a]) / w.dt;
  }
  // A failure inside the step (a restitution law that throws, memory for a list that
  // outgrew its reserve) leaves the particles half advanced: the world stops, as on an
  // instability, and says why; the caller's loop sees status() and ends the run.
  try {
    w.advance(timed, previous);
  } catch (const std::exception& e) {
    w.mark_failed(e.what());
    return w.load;
  } catch (...) {
    w.mark_failed("unknown exception");
    return w.load;
  }
  const auto t3 = timed ? Clock::now() : Clock::time_point{};
  w.time += w.dt;
  ++w.steps;
  w.record(previous);
  if (w.steps % kHealthStride == 0) w.check_health();
  if (timed) w.stage_times.record_s += kTimingStride * std::chrono::duration<double>(Clock::now() - t3).count();
  return w.load;
}

const ContainerLoad& World::step(const ContainerMotion& motion) {
  return step(motion.state(impl_->time + impl_->dt));
}

}  // namespace pdamp::dem_reference
