// Result files of a DEM run: time-series CSV and VTK XML particle snapshots with their
// ParaView series, written atomically.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pdamp/dem_reference/damper_simulation.hpp"

namespace pdamp::dem_reference {

/// CSV with a header row (time_s, container_position_m, container_velocity_m_s,
/// force_n, bed_relative_position_m, bed_momentum_kg_m_s, kinetic_energy_j), one row
/// per sample. Written to a temporary file beside `path` and renamed over it;
/// std::runtime_error naming the path if writing fails.
void write_time_series_csv(const std::string& path, const TimeSeries& series);

/// VTK XML PolyData (.vtp, binary appended: ParaView and VTK's vtkXMLPolyDataReader), one
/// vertex per particle at its centre in the world frame (the container moves in it: x_c(t)
/// along the drive), with point data radius_m (ParaView: Glyph, sphere, scaled by it gives
/// the spheres), velocity_m_s and angular_velocity_rad_s (world frame), compartment, and
/// the time in the field TimeValue. Atomic as above.
void write_vtp_snapshot(const std::string& path, const ParticleSnapshot& snapshot);

/// The containers' inner walls (box faces, or a cylinder's mantle and ends), plates and
/// pins as VTK XML polygons in the world frame, moved by `displacement_m` from their
/// position at rest (the container's translation at `time_s`), with cell data `part`
/// (0 wall, 1 plate, 2 pin) and `compartment`. Not drawn: polymer wall layers (the inner
/// walls are the hard ones). Atomic as above.
void write_container_vtp(const std::string& path, const WorldOptions& world, const Vec3& displacement_m, double time_s);

/// A ParaView data series (.pvd): `files` as (time in s, file name relative to the .pvd),
/// so that ParaView's time controls step through the snapshots at their times.
void write_pvd_series(const std::string& path, const std::vector<std::pair<double, std::string>>& files);

}  // namespace pdamp::dem_reference
