// The world's state: state_hash(), and save_state() / restore_state() for checkpoints.
#include "pdamp/dem_reference/world.hpp"

#include <bit>
#include <cstdint>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "world_impl.hpp"

namespace pdamp::dem_reference {

std::uint64_t World::state_hash() const {
  const Impl& w = *impl_;
  std::uint64_t hash = 14695981039346656037ULL;
  // In the caller's particle order: the hash does not see the internal numbering.
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz}) {
    for (const int k : w.index_of) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(v->data() + k);
      for (std::size_t b = 0; b < sizeof(double); ++b) {
        hash ^= bytes[b];
        hash *= 1099511628211ULL;
      }
    }
  }
  return hash;
}

// ------------------------------------------------------------------ checkpoints

namespace {

using detail::ContactHistory;
using detail::ContactKey;
using detail::Partition;
using detail::RowList;
using detail::Slot;

void write_rows(StateWriter& out, const RowList& rows, bool with_rolling) {
  out.i32s(rows.offsets);
  out.i64(static_cast<std::int64_t>(rows.slots.size()));
  for (const Slot& s : rows.slots) {
    out.i32(s.i);
    out.i32(s.j);
    out.i32(s.contact);
  }
  out.i64(static_cast<std::int64_t>(rows.pool.size()));
  for (std::size_t e = 0; e < rows.pool.size(); ++e) {
    out.i32(rows.pool.keys[e].i);
    out.i32(rows.pool.keys[e].j);
    const ContactHistory& h = rows.pool.state[e].history;
    for (double v : {h.ft[0], h.ft[1], h.ft[2], h.inv_kt_prev, h.gamma, h.fd_prev, h.fn_prev}) out.f64(v);
    if (with_rolling)
      for (double v : rows.pool.rolling[e]) out.f64(v);
  }
}

/// Reads rows written by write_rows. `partner_ok(i, j)` says whether row i may list
/// partner j (a later particle, or a wall of i's compartment); `params(i, j)` gives the
/// contact parameters, which depend on the options only and are not stored.
template <class PartnerOk, class Params>
void read_rows(StateReader& in, RowList& rows, int n, bool with_rolling, PartnerOk&& partner_ok, Params&& params) {
  const auto un = static_cast<std::size_t>(n);
  rows.offsets = in.i32s("rows.offsets", un + 1, 0, std::numeric_limits<int>::max());
  const std::size_t slots = in.count("rows.slots", static_cast<std::size_t>(std::numeric_limits<int>::max()), 12);
  if (rows.offsets[0] != 0 || static_cast<std::size_t>(rows.offsets[un]) != slots)
    in.fail("rows.offsets", "must run from 0 to the slot count " + std::to_string(slots));
  for (std::size_t i = 0; i < un; ++i)
    if (rows.offsets[i + 1] < rows.offsets[i]) in.fail("rows.offsets", "must not decrease");
  rows.slots.resize(slots);
  for (auto& s : rows.slots) {
    s.i = in.i32("rows.slot.i");
    s.j = in.i32("rows.slot.j");
    s.contact = in.i32("rows.slot.contact");
  }
  const std::size_t entry_bytes = 8 + 7 * 8 + (with_rolling ? 24 : 0);
  const std::size_t pool = in.count("rows.pool", slots, entry_bytes);
  rows.pool.resize(pool);
  for (std::size_t e = 0; e < pool; ++e) {
    ContactKey& key = rows.pool.keys[e];
    key.i = in.i32_in("rows.pool.key.i", 0, n - 1);
    key.j = in.i32("rows.pool.key.j");
    if (!partner_ok(key.i, key.j)) in.fail("rows.pool.key.j", "= " + std::to_string(key.j) + ": no partner of particle " + std::to_string(key.i));
    ContactHistory& h = rows.pool.state[e].history;
    for (double* v : {&h.ft[0], &h.ft[1], &h.ft[2], &h.inv_kt_prev, &h.gamma, &h.fd_prev, &h.fn_prev})
      *v = in.finite("rows.pool.history");
    if (with_rolling)
      for (double& v : rows.pool.rolling[e]) v = in.finite("rows.pool.rolling_torque");
    rows.pool.state[e].params = params(key.i, key.j);
  }
  std::vector<unsigned char> used(pool, 0);
  for (std::size_t i = 0; i < un; ++i) {
    for (int k = rows.offsets[i]; k < rows.offsets[i + 1]; ++k) {
      const Slot& s = rows.slots[static_cast<std::size_t>(k)];
      if (s.i != static_cast<int>(i) || !partner_ok(s.i, s.j)) {
        std::ostringstream msg;  // a stream: GCC 12 flags "(" + std::string with a false -Wrestrict
        msg << "(" << s.i << ", " << s.j << ") in row " << i << ": not a pair this world can list";
        in.fail("rows.slot", msg.str());
      }
      if (s.contact < -1 || s.contact >= static_cast<int>(pool)) in.fail("rows.slot.contact", "points outside the pool");
      if (s.contact >= 0) {
        const auto c = static_cast<std::size_t>(s.contact);
        if (used[c]++ != 0 || rows.pool.keys[c].i != s.i || rows.pool.keys[c].j != s.j)
          in.fail("rows.slot.contact", "does not belong to its pair (or is shared)");
      }
    }
  }
  rows.target.clear();
}

}  // namespace

void World::save_state(StateWriter& out) const {
  const Impl& w = *impl_;
  const bool with_rolling = w.pairs.pool.with_rolling;
  out.tag("world");
  out.i32(w.n);
  out.i32(static_cast<std::int32_t>(w.options.compartments.size()));
  out.i32(static_cast<std::int32_t>(w.walls.size()));
  out.i32(static_cast<std::int32_t>(w.parts.size()));
  out.u8(with_rolling ? 1 : 0);
  out.f64(w.dt);
  out.i32(static_cast<std::int32_t>(w.status.outcome));
  out.text(w.status.message);
  out.f64(w.time);
  out.i64(w.steps);
  out.i64(w.rebuilds);
  out.u8(w.rebuild_due ? 1 : 0);
  const ContainerState& c = w.container;
  for (const auto* v : {&c.position_m, &c.velocity_m_s, &c.angular_velocity_rad_s})
    for (double x : *v) out.f64(x);
  for (double x : c.orientation) out.f64(x);
  out.u8(w.rotated ? 1 : 0);
  for (double x : w.container_velocity) out.f64(x);
  for (const auto* l : {&w.load, &w.load_previous})
    for (const auto* v : {&l->force_n, &l->moment_nm})
      for (double x : *v) out.f64(x);
  for (double x : {w.container_work, w.normal_damping, w.friction, w.rolling, w.initial_energy, w.max_d2, w.max_u2})
    out.f64(x);
  out.tag("particles");
  out.i32s(w.order);
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx, &w.ty,
                        &w.tz, &w.rx, &w.ry, &w.rz})
    out.f64s(*v);
  out.tag("pairs");
  write_rows(out, w.pairs, with_rolling);
  out.tag("walls");
  write_rows(out, w.wall_rows, with_rolling);
  out.tag("partitions");
  for (const Partition& p : w.parts) {
    for (int v : {p.begin, p.end, p.head_end, p.halo_end, p.early_end}) out.i32(v);
    for (double v : {p.max_d2, p.max_u2, p.dissipation.normal_damping, p.dissipation.friction, p.dissipation.rolling,
                     p.dissipation.max_overlap_ratio})
      out.f64(v);
    out.i32(p.dissipation.contacts);
    for (const double* v : {p.load.force, p.load.moment})
      for (int a = 0; a < 3; ++a) out.f64(v[a]);
  }
  out.tag("end of world");
}

void World::restore_state(StateReader& in) {
  const Impl& now = *impl_;
  auto staged = std::make_unique<Impl>(now);
  Impl& w = *staged;
  const bool with_rolling = w.pairs.pool.with_rolling;
  const auto same = [&](const char* field, long long saved, long long here) {
    if (saved != here)
      in.fail(field, "= " + std::to_string(saved) + " in the state, " + std::to_string(here) +
                         " in this world: a state of another world (other case, options or thread count)");
  };
  in.expect_tag("world");
  same("particles", in.i32("particles"), w.n);
  same("compartments", in.i32("compartments"), static_cast<long long>(w.options.compartments.size()));
  same("walls", in.i32("walls"), static_cast<long long>(w.walls.size()));
  same("partitions", in.i32("partitions"), static_cast<long long>(w.parts.size()));
  same("rolling resistance", in.boolean("rolling resistance") ? 1 : 0, with_rolling ? 1 : 0);
  const double dt = in.f64("time_step_s");
  if (std::bit_cast<std::uint64_t>(dt) != std::bit_cast<std::uint64_t>(w.dt)) {
    std::ostringstream msg;
    msg.precision(17);
    msg << "= " << dt << " s in the state, " << w.dt << " s in this world: a state of another world";
    in.fail("time_step_s", msg.str());
  }
  w.status.outcome = static_cast<Outcome>(in.i32_in("status.outcome", 0, 2));
  w.status.message = in.text("status.message", 1 << 16);
  w.time = in.finite("time_s");
  w.steps = in.i64("steps");
  w.rebuilds = in.i64("rebuilds");
  if (w.steps < 0 || w.rebuilds < 0) in.fail("steps", "must not be negative");
  w.rebuild_due = in.boolean("rebuild_due");
  ContainerState& c = w.container;
  for (auto* v : {&c.position_m, &c.velocity_m_s, &c.angular_velocity_rad_s})
    for (double& x : *v) x = in.finite("container");
  for (double& x : c.orientation) x = in.finite("container.orientation");
  w.rotated = in.boolean("container.rotated");
  for (double& x : w.container_velocity) x = in.finite("container.velocity");
  for (auto* l : {&w.load, &w.load_previous})
    for (auto* v : {&l->force_n, &l->moment_nm})
      for (double& x : *v) x = in.finite("load");
  for (double* x : {&w.container_work, &w.normal_damping, &w.friction, &w.rolling, &w.initial_energy, &w.max_d2, &w.max_u2})
    *x = in.finite("energy account");

  in.expect_tag("particles");
  const auto un = static_cast<std::size_t>(w.n);
  w.order = in.i32s("order", un, 0, w.n - 1);
  std::vector<unsigned char> seen(un, 0);
  for (int id : w.order)
    if (seen[static_cast<std::size_t>(id)]++ != 0) in.fail("order", "is no permutation of the particles");
  for (std::size_t k = 0; k < un; ++k) w.index_of[static_cast<std::size_t>(w.order[k])] = static_cast<int>(k);
  // What the options fix, at the state's places: particle id order[k] sits at place k.
  for (std::size_t k = 0; k < un; ++k) {
    const std::size_t from = now.place(w.order[k]);
    w.radius[k] = now.radius[from];
    w.mass[k] = now.mass[from];
    w.inv_mass[k] = now.inv_mass[from];
    w.inv_inertia[k] = now.inv_inertia[from];
    w.material[k] = now.material[from];
    w.compartment[k] = now.compartment[from];
  }
  for (auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx, &w.ty, &w.tz,
                  &w.rx, &w.ry, &w.rz})
    *v = in.finite_f64s("particles", un);

  in.expect_tag("pairs");
  read_rows(
      in, w.pairs, w.n, with_rolling,
      [&](int i, int j) {
        return j > i && j < w.n && w.compartment[static_cast<std::size_t>(i)] == w.compartment[static_cast<std::size_t>(j)];
      },
      [&](int a, int b) { return w.particle_pair_contact(static_cast<std::size_t>(a), static_cast<std::size_t>(b)).params; });
  in.expect_tag("walls");
  read_rows(
      in, w.wall_rows, w.n, with_rolling,
      [&](int i, int j) {
        const auto c = static_cast<std::size_t>(w.compartment[static_cast<std::size_t>(i)]);
        return j >= w.wall_begin[c] && j < w.wall_end[c];
      },
      [&](int a, int wall) { return w.particle_wall_contact(static_cast<std::size_t>(a), wall).params; });

  in.expect_tag("partitions");
  int next = 0;
  for (Partition& p : w.parts) {
    p.begin = in.i32_in("partition.begin", next, next);
    p.end = in.i32_in("partition.end", p.begin, w.n);
    p.head_end = in.i32_in("partition.head_end", p.begin, p.end);
    p.halo_end = in.i32_in("partition.halo_end", p.end, w.n);
    p.early_end = in.i32_in("partition.early_end", p.begin, p.end);
    next = p.end;
    for (double* v : {&p.max_d2, &p.max_u2, &p.dissipation.normal_damping, &p.dissipation.friction,
                      &p.dissipation.rolling, &p.dissipation.max_overlap_ratio})
      *v = in.finite("partition");
    p.dissipation.contacts = in.i32_in("partition.contacts", 0, std::numeric_limits<int>::max());
    for (double* v : {p.load.force, p.load.moment})
      for (int a = 0; a < 3; ++a) v[a] = in.finite("partition.load");
    p.halo.assign(6 * static_cast<std::size_t>(p.halo_end - p.end), 0.0);
    p.fresh_pairs.clear();
    p.fresh_walls.clear();
  }
  if (next != w.n) in.fail("partitions", "must cover every particle");
  in.expect_tag("end of world");
  impl_ = std::move(staged);
}

}  // namespace pdamp::dem_reference
