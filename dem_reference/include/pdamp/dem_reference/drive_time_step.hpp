// The time step of a driven DEM run and the settling before the drive starts: run
// machinery shared by every driver (harmonic, a structure's modal integration).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace pdamp::dem_reference {

/// The largest impact speed of a drive whose container moves at up to
/// peak_container_speed_m_s (>= 0): a collected bed leaving one wall at the peak speed V
/// meets the other wall coming at V (2V), plus the largest free fall of a sphere
/// √(2|g|H_free), H_free = H − 2r_min of the tallest compartment (docs/dem.md
/// "Integration and time step"), m/s.
double drive_impact_speed(const WorldOptions& world, double peak_container_speed_m_s);

/// What the time-step rule needs to know of a drive.
struct DriveTiming {
  double period_s = 0.0;          ///< period of the drive (the unit of analysis), s, > 0
  int blocks_per_period = 1;      ///< recording blocks per period, >= 1
  double impact_speed_m_s = 0.0;  ///< largest impact speed of the drive (drive_impact_speed), m/s, >= 0
};

/// The time step chosen for a drive and what it implies.
struct DriveTimeStep {
  /// The options to build the World with: integration.time_step_s = time_step_s, and
  /// max_impact_speed_m_s raised to the drive's impact speed (for a user step above the
  /// automatic bound: the lower speed whose bound that step is, see drive_time_step()).
  WorldOptions world;
  TimeStepBound bound;             ///< the automatic bound at impact_speed_m_s
  double time_step_s = 0.0;        ///< dt = period_s / steps_per_period, s
  std::int64_t steps_per_block = 0;  ///< whole steps per recording block
  std::int64_t steps_per_period = 0;  ///< steps_per_block × blocks_per_period
  double impact_speed_m_s = 0.0;   ///< max(world's max_impact_speed_m_s, the drive's), m/s
  double stability_limit_s = 0.0;  ///< largest user step accepted: min(T_R, t_c/20), s
  double steps_per_contact = 0.0;  ///< t_c(impact_speed_m_s) / time_step_s
  std::vector<std::string> warnings;  ///< one, when a user step is above the automatic bound
};

/// The time-step rule of a drive (docs/dem.md "Integration and time step"): the target
/// step is the automatic bound at the impact speed (at most limits::kMaxTimeStep_s), or
/// the user's world.integration.time_step_s; it is then shortened so that a period is a
/// whole number of blocks of whole steps. A user step above the automatic bound is
/// accepted up to the stability limit min(T_R, t_c/20) with a warning giving the steps per
/// contact at the impact speed and the restitution error bound (0.6 ln²ε + 0.1)/N.
/// Throws std::invalid_argument: invalid world options, a timing out of range (naming the
/// field), a user step above the stability limit (naming the limits).
DriveTimeStep drive_time_step(const WorldOptions& world, const DriveTiming& drive);

/// The automatic settling time, s: 0 without gravity, 0.01 s for lattice placements,
/// 2√(2H/|g|) + 0.02 s when some compartment places its spheres at random (H the tallest
/// compartment's extent along gravity: the fall from anywhere, twice over, and a margin).
double automatic_settling_time_s(const WorldOptions& world);

/// Called after each settling step with the step index (0-based); e.g. progress.
using SettlingObserver = std::function<void(std::int64_t step)>;

/// Settles the bed: `steps` steps with the container held at rest in `start`'s position
/// and orientation, then gives every particle the container's translational velocity
/// start.velocity_m_s, so that the drive starts
/// with the bed at rest relative to the container (as on the collect-and-collide orbit at
/// detachment). Returns false, without the boost, when the world stops during settling
/// (status() is kUnstable or kFailed).
bool settle(World& world, const ContainerState& start, std::int64_t steps,
            const SettlingObserver& after_step = {});

}  // namespace pdamp::dem_reference
