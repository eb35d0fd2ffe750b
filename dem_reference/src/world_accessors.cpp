// The World's public accessors: particles and bed, contacts and census, counters, memory; particles set by hand.
#include "pdamp/dem_reference/world.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "walls.hpp"
#include "world_impl.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::Partition;
using detail::StagedContact;
using detail::WallFeature;

}  // namespace

void World::set_particle_state(int i, const Vec3& position_m, const Vec3& velocity_m_s,
                               const Vec3& angular_velocity_rad_s) {
  Impl& w = *impl_;
  const auto k = w.place(i);
  // The energy set here is supplied, not created: keep the growth check honest (only
  // this particle's kinetic and potential energy change).
  const auto own_energy = [&]() {
    const Vec3 v = w.full_velocity(k);
    const Vec3 om = w.full_angular_velocity(k);
    const auto& g = w.options.gravity_m_s2;
    return 0.5 * w.mass[k] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
           0.5 / w.inv_inertia[k] * (om[0] * om[0] + om[1] * om[1] + om[2] * om[2]) -
           w.mass[k] * (g[0] * w.x[k] + g[1] * w.y[k] + g[2] * w.z[k]);
  };
  const double before = own_energy();
  w.x[k] = position_m[0];
  w.y[k] = position_m[1];
  w.z[k] = position_m[2];
  // Half-step velocities such that the full-step velocity is the one given.
  const double s = 0.5 * w.dt * w.inv_mass[k];
  const double r = 0.5 * w.dt * w.inv_inertia[k];
  w.vx[k] = velocity_m_s[0] - s * w.fx[k];
  w.vy[k] = velocity_m_s[1] - s * w.fy[k];
  w.vz[k] = velocity_m_s[2] - s * w.fz[k];
  w.wx[k] = angular_velocity_rad_s[0] - r * w.tx[k];
  w.wy[k] = angular_velocity_rad_s[1] - r * w.ty[k];
  w.wz[k] = angular_velocity_rad_s[2] - r * w.tz[k];
  w.initial_energy += own_energy() - before;
  w.rebuild_due = true;
}

void World::add_velocity(const Vec3& velocity_m_s) {
  Impl& w = *impl_;
  const double before = w.kinetic_energy();
  for (std::size_t k = 0; k < static_cast<std::size_t>(w.n); ++k) {
    w.vx[k] += velocity_m_s[0];
    w.vy[k] += velocity_m_s[1];
    w.vz[k] += velocity_m_s[2];
  }
  w.initial_energy += w.kinetic_energy() - before;
  w.refresh_bound();
}

const WorldOptions& World::options() const { return impl_->options; }
double World::time_step_s() const { return impl_->dt; }
double World::time_s() const { return impl_->time; }
std::int64_t World::step_count() const { return impl_->steps; }
const TimeStepBound& World::time_step_bound() const { return impl_->bound; }
const WorldStatus& World::status() const { return impl_->status; }
const ContainerLoad& World::load() const { return impl_->load; }
const ContainerState& World::container() const { return impl_->container; }
int World::particle_count() const { return impl_->n; }
int World::compartment_count() const { return static_cast<int>(impl_->options.compartments.size()); }

Vec3 World::position(int i) const {
  const auto k = impl_->place(i);
  return {impl_->x[k], impl_->y[k], impl_->z[k]};
}
Vec3 World::velocity(int i) const { return impl_->full_velocity(impl_->place(i)); }
Vec3 World::angular_velocity(int i) const { return impl_->full_angular_velocity(impl_->place(i)); }
double World::radius(int i) const { return impl_->radius[impl_->place(i)]; }
double World::mass(int i) const { return impl_->mass[impl_->place(i)]; }
int World::compartment(int i) const { return impl_->compartment[impl_->place(i)]; }
double World::bed_mass_kg() const { return impl_->bed_mass; }
double World::clearance_m(int c) const { return impl_->clearances.at(static_cast<std::size_t>(c)); }

Vec3 World::bed_momentum() const {
  Vec3 p{0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < static_cast<std::size_t>(impl_->n); ++k) {
    const Vec3 v = impl_->full_velocity(k);
    const double m = impl_->mass[k];
    for (std::size_t a = 0; a < 3; ++a) p[a] += m * v[a];
  }
  return p;
}

Vec3 World::bed_centre_of_mass() const {
  Vec3 c{0.0, 0.0, 0.0};
  const Impl& w = *impl_;
  for (std::size_t k = 0; k < static_cast<std::size_t>(w.n); ++k) {
    c[0] += w.mass[k] * w.x[k];
    c[1] += w.mass[k] * w.y[k];
    c[2] += w.mass[k] * w.z[k];
  }
  for (auto& v : c) v /= w.bed_mass;
  return c;
}

ContactCensus World::contact_census(const Vec3& down) const {
  const Impl& w = *impl_;
  auto& flags = w.census_flags;
  flags.assign(static_cast<std::size_t>(w.n), 0);
  const auto& pair_pool = w.pairs.pool;
  for (std::size_t e = 0; e < pair_pool.size(); ++e) {
    if (pair_pool.state[e].history.gamma < 0.0) continue;
    flags[static_cast<std::size_t>(pair_pool.keys[e].i)] |= 1;
    flags[static_cast<std::size_t>(pair_pool.keys[e].j)] |= 1;
  }
  const double norm = std::sqrt(down[0] * down[0] + down[1] * down[1] + down[2] * down[2]);
  const auto& R = w.container.orientation;
  const auto& wall_pool = w.wall_rows.pool;
  for (std::size_t e = 0; e < wall_pool.size(); ++e) {
    if (wall_pool.state[e].history.gamma < 0.0) continue;
    const auto i = static_cast<std::size_t>(wall_pool.keys[e].i);
    flags[i] |= 2;
    if (norm > 0.0) {
      double p[3];
      w.to_body(w.x[i], w.y[i], w.z[i], p);
      double nb[3];
      detail::wall_gap(w.walls[static_cast<std::size_t>(wall_pool.keys[e].j)], p, w.radius[i], nb);
      double along = 0.0;
      for (std::size_t a = 0; a < 3; ++a) along += (R[3 * a] * nb[0] + R[3 * a + 1] * nb[1] + R[3 * a + 2] * nb[2]) * down[a];
      if (along > 0.70710678 * norm) flags[i] |= 4;
    }
  }
  ContactCensus census;
  for (const unsigned char f : flags) {
    census.touching_walls += (f & 2) ? 1 : 0;
    census.touching_base += (f & 4) ? 1 : 0;
    census.airborne += f == 0 ? 1 : 0;
  }
  return census;
}

std::vector<int> World::contacts_per_particle() const {
  const Impl& w = *impl_;
  std::vector<int> count(static_cast<std::size_t>(w.n), 0);
  const auto& pairs = w.pairs.pool;
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    if (pairs.state[e].history.gamma < 0.0) continue;  // listed, not touching
    ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(pairs.keys[e].i)])];
    ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(pairs.keys[e].j)])];
  }
  const auto& walls = w.wall_rows.pool;
  for (std::size_t e = 0; e < walls.size(); ++e)
    if (walls.state[e].history.gamma >= 0.0) ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(walls.keys[e].i)])];
  return count;
}

int World::contact_count() const {
  int count = 0;
  for (const auto& c : impl_->pairs.pool.state) count += c.history.gamma >= 0.0 ? 1 : 0;
  return count;
}

std::int64_t World::neighbour_rebuilds() const { return impl_->rebuilds; }
const StageTimes& World::stage_times() const { return impl_->stage_times; }

std::size_t World::memory_bytes() const {
  const Impl& w = *impl_;
  std::size_t bytes = 0;
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx,
                        &w.ty, &w.tz, &w.radius, &w.mass, &w.inv_mass, &w.inv_inertia, &w.rx, &w.ry, &w.rz,
                        &w.scratch}) {
    bytes += v->capacity() * sizeof(double);
  }
  for (const auto* v : {&w.material, &w.compartment, &w.order, &w.index_of, &w.scratch_index}) {
    bytes += v->capacity() * sizeof(int);
  }
  for (const auto& p : w.parts) {
    bytes += sizeof(Partition) + p.halo.capacity() * sizeof(double) +
             (p.fresh_pairs.capacity() + p.fresh_walls.capacity()) * sizeof(StagedContact);
  }
  bytes += w.pairs.memory_bytes() + w.wall_rows.memory_bytes();
  bytes += w.grid.memory_bytes() + w.walls.capacity() * sizeof(WallFeature);
  return bytes;
}

}  // namespace pdamp::dem_reference
