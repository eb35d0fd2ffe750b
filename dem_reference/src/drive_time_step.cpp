// The time-step rule of a drive and the settling before it (docs/dem.md "Run machinery").
#include "pdamp/dem_reference/drive_time_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "vec3_ops.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::norm;

/// Inner extent of a compartment along gravity (g_norm = |g| > 0), m.
double extent_along_gravity(const CompartmentOptions& c, const Vec3& gravity, double g_norm) {
  double h = 0.0;
  for (int a = 0; a < 3; ++a) h += std::abs(gravity[static_cast<std::size_t>(a)]) / g_norm * c.container.inner_length(a);
  return h;
}

/// The inner extent of the tallest compartment along gravity, m (the settling time of a
/// random placement).
double fall_height(const WorldOptions& w) {
  const double g = norm(w.gravity_m_s2);
  if (g == 0.0) return 0.0;
  double height = 0.0;
  for (const auto& c : w.compartments) height = std::max(height, extent_along_gravity(c, w.gravity_m_s2, g));
  return height;
}

/// Largest free fall of a sphere, m: per compartment, its inner extent H along gravity
/// less the smallest sphere diameter 2r_min, the largest of these (0 without gravity).
/// A sphere's centre moves between r from the floor and r from the ceiling, so it falls
/// at most H − 2r (from rest at the ceiling onto the floor). Not H − h_bed: a sphere
/// thrown up from a multi-layer bed can land beside it, in the clearance of a collected
/// bed; for one layer (h_bed = 2r) the two agree. The drive's own speed is in 2V.
double free_fall_height(const WorldOptions& w) {
  const double g = norm(w.gravity_m_s2);
  if (g == 0.0) return 0.0;
  double height = 0.0;
  for (const auto& c : w.compartments) {
    const double h = extent_along_gravity(c, w.gravity_m_s2, g);
    double r_min = std::numeric_limits<double>::infinity();
    for (const auto& p : c.particles) r_min = std::min(r_min, p.radius_m * (1.0 - p.radius_spread));
    if (!std::isfinite(r_min)) r_min = 0.0;
    height = std::max(height, std::max(0.0, h - 2.0 * r_min));
  }
  return height;
}

void check_timing(const DriveTiming& drive) {
  std::ostringstream errors;
  if (!(std::isfinite(drive.period_s) && drive.period_s > 0.0)) {
    errors << "drive period_s = " << drive.period_s << ": must be finite and > 0 s\n";
  }
  if (drive.blocks_per_period < 1) errors << "drive blocks_per_period = " << drive.blocks_per_period << ": must be >= 1\n";
  if (!(std::isfinite(drive.impact_speed_m_s) && drive.impact_speed_m_s >= 0.0)) {
    errors << "drive impact_speed_m_s = " << drive.impact_speed_m_s << ": must be finite and >= 0 m/s\n";
  }
  std::string text = errors.str();
  if (!text.empty()) {
    text.pop_back();
    throw std::invalid_argument(text);
  }
}

/// The warning for a user step dt above the automatic bound (docs/dem.md).
std::string user_step_warning(const DriveTimeStep& t, double user_step) {
  std::ostringstream w;
  w << "dem.integration.time_step_s = " << user_step << " s is above the automatic bound "
    << t.bound.max_time_step_s << " s: " << t.steps_per_contact << " steps per contact at the impact speed "
    << t.impact_speed_m_s << " m/s (automatic: " << t.bound.steps_per_contact << ")";
  const double e_min = smallest_restitution(t.world);
  if (std::isfinite(e_min)) {
    w << "; one impact then realises a restitution low by up to (0.6 ln^2(e) + 0.1)/N = "
      << 100.0 * restitution_error_bound(e_min, t.steps_per_contact) << "% at e = " << e_min;
  } else {
    w << "; one impact then realises a restitution low by up to (0.6 ln^2(e) + 0.1)/N of e";
  }
  w << " (docs/dem.md)";
  return w.str();
}

}  // namespace

double drive_impact_speed(const WorldOptions& world, double peak_container_speed_m_s) {
  return 2.0 * peak_container_speed_m_s + std::sqrt(2.0 * norm(world.gravity_m_s2) * free_fall_height(world));
}

DriveTimeStep drive_time_step(const WorldOptions& world, const DriveTiming& drive) {
  check_timing(drive);
  DriveTimeStep t;
  t.world = world;
  auto& integ = t.world.integration;
  integ.max_impact_speed_m_s = std::max(integ.max_impact_speed_m_s, drive.impact_speed_m_s);
  const double user_step = integ.time_step_s;
  integ.time_step_s = 0.0;
  t.bound = time_step_bound(t.world);
  const TimeStepBound& bound = t.bound;
  t.impact_speed_m_s = integ.max_impact_speed_m_s;
  // Stability limit: the Rayleigh time (the explicit critical step of the wave through a
  // sphere, Li, Xu & Thornton 2005) and limits::kMinStepsPerContact at the impact speed.
  const double fewest_steps = limits::kMinStepsPerContact;
  t.stability_limit_s = std::min(bound.rayleigh_time_s, bound.contact_time_s / fewest_steps);
  if (user_step > t.stability_limit_s) {
    std::ostringstream msg;
    msg << "dem.integration.time_step_s = " << user_step << ": must be <= " << t.stability_limit_s
        << " s, the stability limit: the Rayleigh time " << bound.rayleigh_time_s << " s or "
        << fewest_steps << " steps of the contact time " << bound.contact_time_s << " s at "
        << integ.max_impact_speed_m_s << " m/s (the automatic step is " << bound.max_time_step_s << " s: "
        << bound.steps_per_contact << " steps per contact or " << integ.rayleigh_fraction << " of the Rayleigh time)";
    throw std::invalid_argument(msg.str());
  }
  // The automatic bound of metre-sized soft spheres can exceed the largest step the
  // integration takes (limits::kMaxTimeStep_s): the run then steps at that limit.
  const double target_step = user_step > 0.0 ? user_step : std::min(bound.max_time_step_s, limits::kMaxTimeStep_s);
  const int blocks = drive.blocks_per_period;
  t.steps_per_block = static_cast<std::int64_t>(std::ceil(drive.period_s / (blocks * target_step) - 1e-9));
  t.steps_per_period = t.steps_per_block * blocks;
  t.time_step_s = drive.period_s / static_cast<double>(t.steps_per_period);
  integ.time_step_s = t.time_step_s;
  t.steps_per_contact = bound.contact_time_s / t.time_step_s;
  if (t.time_step_s > bound.max_time_step_s) {
    // A user step between the automatic bound and the stability limit: accepted, with
    // what it costs. The world checks its step against its own bound at
    // max_impact_speed_m_s, so it is built at the (lower) speed whose bound this step
    // is: t_c ∝ v^{−1/5}, v_w = v·(t_c(v)/(N_c·dt))^5. That speed only sets the world's
    // bound and its energy-growth threshold (½m_bed v_w²); restitution laws were
    // validated up to v above.
    t.warnings.push_back(user_step_warning(t, user_step));
    const double ratio = bound.contact_time_s / (bound.steps_per_contact * t.time_step_s);
    integ.max_impact_speed_m_s = t.impact_speed_m_s * std::pow(ratio, 5.0);
    integ.rayleigh_fraction = std::min(1.0, std::max(integ.rayleigh_fraction, t.time_step_s / bound.rayleigh_time_s));
    for (int k = 0; k < 8 && time_step_bound(t.world).max_time_step_s < t.time_step_s; ++k) {
      integ.max_impact_speed_m_s *= 1.0 - 1e-9 * (1 << (2 * k));
      if (integ.rayleigh_fraction < 1.0) integ.rayleigh_fraction = std::min(1.0, integ.rayleigh_fraction * (1.0 + 1e-12));
    }
  }
  return t;
}

double automatic_settling_time_s(const WorldOptions& world) {
  const double g_norm = norm(world.gravity_m_s2);
  if (g_norm == 0.0) return 0.0;
  bool random = false;
  for (const auto& c : world.compartments) random = random || c.placement == InitialPlacement::kRandom;
  return random ? 2.0 * std::sqrt(2.0 * fall_height(world) / g_norm) + 0.02 : 0.01;
}

bool settle(World& world, const ContainerState& start, std::int64_t steps, const SettlingObserver& after_step) {
  ContainerState rest = start;
  rest.velocity_m_s = {0.0, 0.0, 0.0};
  rest.angular_velocity_rad_s = {0.0, 0.0, 0.0};
  for (std::int64_t k = 0; k < steps; ++k) {
    world.step(rest);
    if (world.status().outcome != Outcome::kCompleted) return false;
    if (after_step) after_step(k);
  }
  world.add_velocity(start.velocity_m_s);
  return true;
}

}  // namespace pdamp::dem_reference
