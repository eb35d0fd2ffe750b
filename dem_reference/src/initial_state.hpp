// Initial placement of the particles: collected or centred lattice, or random.
#pragma once

#include <vector>

#include "pdamp/dem_reference/world_options.hpp"
#include "walls.hpp"

namespace pdamp::dem_reference::detail {

struct InitialBed {
  std::vector<Vec3> positions_m;  ///< body frame
  std::vector<double> radii_m;
  std::vector<int> materials;
  std::vector<int> compartments;
  std::vector<double> clearances_m;  ///< per compartment; NaN when no lattice fits
};

/// Radii (seeded), positions and clearances. gravity_body: gravity in the body frame.
/// Throws std::invalid_argument naming the numbers when particles do not fit.
InitialBed place_particles(const WorldOptions& options, const std::vector<WallFeature>& walls,
                           const Vec3& gravity_body);

}  // namespace pdamp::dem_reference::detail
