// Result files of a DEM run (time-series CSV, VTK legacy snapshots), written to a
// temporary file beside the target and renamed over it (strict_json::write_file_atomically),
// so no reader sees a partial file.
#include "pdamp/dem_reference/result_files.hpp"

#include <functional>
#include <sstream>
#include <stdexcept>

#include "pdamp/strict_json/output_file.hpp"

namespace pdamp::dem_reference {

namespace {

/// The text `body` writes, stored atomically (strict_json::write_file_atomically).
void write_atomically(const std::string& path, const std::function<void(std::ostream&)>& body) {
  std::ostringstream out;
  out.precision(17);
  body(out);
  strict_json::write_file_atomically(path, out.str());
}

}  // namespace

void write_time_series_csv(const std::string& path, const TimeSeries& series) {
  const std::size_t rows = series.time_s.size();
  for (const auto* column : {&series.container_position_m, &series.container_velocity_m_s, &series.force_n,
                             &series.bed_relative_position_m, &series.bed_momentum_kg_m_s, &series.kinetic_energy_j}) {
    if (column->size() != rows) {
      throw std::invalid_argument(path + ": time series columns differ in length (" + std::to_string(column->size()) +
                                  " vs " + std::to_string(rows) + " times)");
    }
  }
  write_atomically(path, [&](std::ostream& out) {
    out << "time_s,container_position_m,container_velocity_m_s,force_n,bed_relative_position_m,"
           "bed_momentum_kg_m_s,kinetic_energy_j\n";
    for (std::size_t k = 0; k < rows; ++k) {
      out << series.time_s[k] << ',' << series.container_position_m[k] << ',' << series.container_velocity_m_s[k]
          << ',' << series.force_n[k] << ',' << series.bed_relative_position_m[k] << ','
          << series.bed_momentum_kg_m_s[k] << ',' << series.kinetic_energy_j[k] << '\n';
    }
  });
}

void write_vtk_snapshot(const std::string& path, const ParticleSnapshot& s) {
  const std::size_t n = s.positions_m.size();
  if (s.radii_m.size() != n || s.velocities_m_s.size() != n || s.angular_velocities_rad_s.size() != n ||
      s.compartments.size() != n) {
    throw std::invalid_argument(path + ": snapshot arrays differ in length");
  }
  write_atomically(path, [&](std::ostream& out) {
    out << "# vtk DataFile Version 3.0\n";
    out << "pdamp DEM particles at t = " << s.time_s << " s\n";
    out << "ASCII\nDATASET POLYDATA\n";
    out << "POINTS " << n << " double\n";
    for (const auto& p : s.positions_m) out << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
    out << "VERTICES " << n << ' ' << 2 * n << '\n';
    for (std::size_t i = 0; i < n; ++i) out << "1 " << i << '\n';
    out << "POINT_DATA " << n << '\n';
    out << "SCALARS radius_m double 1\nLOOKUP_TABLE default\n";
    for (const double r : s.radii_m) out << r << '\n';
    out << "SCALARS compartment int 1\nLOOKUP_TABLE default\n";
    for (const int c : s.compartments) out << c << '\n';
    out << "VECTORS velocity_m_s double\n";
    for (const auto& v : s.velocities_m_s) out << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
    out << "VECTORS angular_velocity_rad_s double\n";
    for (const auto& w : s.angular_velocities_rad_s) out << w[0] << ' ' << w[1] << ' ' << w[2] << '\n';
  });
}

}  // namespace pdamp::dem_reference
