// A damper whose bed is a reference-DEM World, as the co-simulation couples it to a modal
// model: the site, the drive and rotation axes, the empty container.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world_options.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// A particle damper whose bed is a DEM World. The container is rigid; its body frame is
/// the World's frame at rest (gravity, compartments and placement as in `world`). The
/// container's origin is the site: it moves along `container_drive_axis` by the site's
/// displacement along `drive_direction` n, along c = rotation axis × drive axis by its
/// displacement across the drive (t = z × n), and, with `rotation`, turns about
/// `container_rotation_axis` by the site's rotation about the structure's z. The bed's load
/// along the drive and across it (and its moment about the rotation axis) returns to the
/// structure; the empty container is a point mass in x and y with its rotary inertia, as in
/// damper_coupling.hpp (mass_with_containers_kg).
struct CosimulationDamper {
  std::string name;                           ///< label for reports and messages
  std::string point;                          ///< named point of the ModalModel (the site)
  Eigen::Vector2d drive_direction{1.0, 0.0};  ///< unit vector n in the structure's x-y plane
  double container_mass_kg = 0.0;             ///< empty container m_c, kg, >= 0, finite
  double container_rotary_inertia_kg_m2 = 0.0; ///< about the out-of-plane axis at the site, kg·m², >= 0 (Damper)
  /// The bed. integration.time_step_s is overwritten by the co-simulation's common step
  /// and max_impact_speed_m_s raised to the drive's (cosimulation_options.hpp); threads as given.
  dem_reference::WorldOptions world;
  /// Unit vector of the container frame that follows n (the DEM's drive axis).
  dem_reference::Vec3 container_drive_axis{1.0, 0.0, 0.0};
  /// Unit vector of the container frame that is the structure's z (out of the plane),
  /// perpendicular to container_drive_axis: the axis of the site's rotation.
  dem_reference::Vec3 container_rotation_axis{0.0, 0.0, 1.0};
  /// true: the container turns with the site (orientation and angular velocity passed to
  /// World::step) and the bed's moment about the rotation axis returns to the modes;
  /// false: the container only translates (a warning names the modes that rotate the site).
  bool rotation = true;
  /// One line per violated rule (field = value: rule), without the "dampers[i]." prefix.
  std::vector<std::string> validate(const ModalModel& model) const;
};

/// Rodrigues rotation about a unit axis by angle θ (rad), row-major (body → world): the
/// container's orientation when it turns with its site.
dem_reference::Matrix3 rotation_about(const dem_reference::Vec3& unit_axis, double angle_rad);

}  // namespace pdamp::structure
