// The energy account and the instability checks: a step's record, the energies, the overlap and energy-growth checks.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "contact_law.hpp"
#include "walls.hpp"
#include "world_impl.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::Slot;

}  // namespace

void World::Impl::record(const ContainerState& previous) {
  double max_ratio = 0.0;
  for (const auto& part : parts) {
    const auto& d = part.dissipation;
    normal_damping += d.normal_damping;
    friction += d.friction;
    rolling += d.rolling;
    max_ratio = std::max(max_ratio, d.max_overlap_ratio);
  }
  // Trapezoidal work of the container load over the step's displacement and rotation.
  double work = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    work += 0.5 * (load_previous.force_n[a] + load.force_n[a]) * (container.position_m[a] - previous.position_m[a]);
    work += 0.5 * (load_previous.moment_nm[a] + load.moment_nm[a]) * container.angular_velocity_rad_s[a] * dt;
  }
  container_work += work;
  load_previous = load;
  if (max_ratio > overlap_limit) {
    std::ostringstream msg;
    msg << "overlap reached " << max_ratio << " of a radius (limit " << overlap_limit << ") at t = " << time
        << " s: the time step " << dt
        << " s does not resolve the contacts; lower integration.time_step_s or raise "
           "integration.max_impact_speed_m_s / integration.steps_per_contact";
    mark_unstable(msg.str());
  }
}

void World::Impl::check_health() {
  const double kinetic = kinetic_energy();
  if (!std::isfinite(kinetic)) {
    std::ostringstream msg;
    msg << "non-finite particle velocities at t = " << time << " s (step " << steps
        << "): lower integration.time_step_s or check the material moduli";
    mark_unstable(msg.str());
    return;
  }
  const double energy = kinetic + potential_energy() + elastic_energy();
  const double dissipated = normal_damping + friction + rolling;
  const double created = energy - (initial_energy + container_work - dissipated);
  const double threshold = std::max(0.5 * energy_scale, 0.05 * (std::abs(container_work) + dissipated));
  if (created > threshold) {
    std::ostringstream msg;
    msg << "energy growth: " << created << " J appeared that no work supplied (threshold " << threshold
        << " J) at t = " << time << " s: lower integration.time_step_s";
    mark_unstable(msg.str());
  }
}

void World::Impl::mark_failed(const std::string& what) {
  std::ostringstream msg;
  msg << "step " << steps + 1 << " (t = " << time + dt << " s) failed: " << what;
  status.outcome = Outcome::kFailed;
  status.message = msg.str();
}

void World::Impl::mark_unstable(const std::string& message) {
  if (status.outcome == Outcome::kUnstable) return;
  status.outcome = Outcome::kUnstable;
  status.message = message;
}

double World::Impl::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    const Vec3 v = full_velocity(k);
    const Vec3 w = full_angular_velocity(k);
    e += 0.5 * mass[k] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
         0.5 / inv_inertia[k] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  return e;
}

double World::Impl::potential_energy() const {
  const auto& g = options.gravity_m_s2;
  double e = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    e -= mass[k] * (g[0] * x[k] + g[1] * y[k] + g[2] * z[k]);
  }
  return e;
}

double World::Impl::elastic_energy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    for (int s = pairs.offsets[i]; s < pairs.offsets[i + 1]; ++s) {
      const Slot& slot = pairs.slots[static_cast<std::size_t>(s)];
      if (slot.contact < 0) continue;
      const auto c = static_cast<std::size_t>(slot.contact);
      const auto j = static_cast<std::size_t>(slot.j);
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const double delta = radius[i] + radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
      const auto& params = pairs.pool.state[c].params;
      e += detail::stored_energy(params, law, pairs.pool.state[c].history,
                                 pairs.pool.rolling_torque(c), delta);
    }
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    for (int s = wall_rows.offsets[i]; s < wall_rows.offsets[i + 1]; ++s) {
      const Slot& slot = wall_rows.slots[static_cast<std::size_t>(s)];
      if (slot.contact < 0) continue;
      const auto c = static_cast<std::size_t>(slot.contact);
      double p[3];
      to_body(x[i], y[i], z[i], p);
      double nb[3];
      const double gap = detail::wall_gap(walls[static_cast<std::size_t>(slot.j)], p, radius[i], nb);
      const auto& params = wall_rows.pool.state[c].params;
      e += detail::stored_energy(params, law, wall_rows.pool.state[c].history,
                                 wall_rows.pool.rolling_torque(c), -gap);
    }
  }
  return e;
}

EnergyAccount World::energy() const {
  const Impl& w = *impl_;
  EnergyAccount e;
  e.container_work_j = w.container_work;
  e.normal_damping_j = w.normal_damping;
  e.friction_j = w.friction;
  e.rolling_j = w.rolling;
  e.kinetic_j = w.kinetic_energy();
  e.potential_j = w.potential_energy();
  e.elastic_j = w.elastic_energy();
  return e;
}

}  // namespace pdamp::dem_reference
