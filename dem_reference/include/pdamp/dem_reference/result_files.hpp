// Result files of a DEM run: time-series CSV and VTK particle snapshots, written atomically.
#pragma once

#include <string>

#include "pdamp/dem_reference/damper_simulation.hpp"

namespace pdamp::dem_reference {

/// CSV with a header row (time_s, container_position_m, container_velocity_m_s,
/// force_n, bed_relative_position_m, bed_momentum_kg_m_s, kinetic_energy_j), one row
/// per sample. Written to a temporary file beside `path` and renamed over it;
/// std::runtime_error naming the path if writing fails.
void write_time_series_csv(const std::string& path, const TimeSeries& series);

/// VTK legacy ASCII POLYDATA (ParaView: Glyph filter scaled by the `radius_m` array gives
/// spheres) with point data radius_m, velocity_m_s, angular_velocity_rad_s and
/// compartment. Atomic as above.
void write_vtk_snapshot(const std::string& path, const ParticleSnapshot& snapshot);

}  // namespace pdamp::dem_reference
