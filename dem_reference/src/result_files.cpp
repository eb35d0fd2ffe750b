// Result files of a DEM run (time-series CSV, VTK XML snapshots and their series), written to a
// temporary file beside the target and renamed over it (strict_json::write_file_atomically),
// so no reader sees a partial file.
#include "pdamp/dem_reference/result_files.hpp"

#include <bit>
#include <cstdint>
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

namespace {

/// VTK XML's appended raw data: each array is a UInt64 byte count, then its bytes, in the
/// machine's byte order (declared in the file header), so ParaView reads it without parsing text.
class AppendedArrays {
 public:
  /// Adds an array and returns its offset in the appended block.
  template <class T>
  std::size_t add(const std::vector<T>& values) {
    const std::size_t offset = bytes_.size();
    const std::uint64_t size = values.size() * sizeof(T);
    bytes_.append(reinterpret_cast<const char*>(&size), sizeof size);
    bytes_.append(reinterpret_cast<const char*>(values.data()), size);
    return offset;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

std::vector<double> flat(const std::vector<Vec3>& vectors) {
  std::vector<double> out;
  out.reserve(3 * vectors.size());
  for (const auto& v : vectors) out.insert(out.end(), v.begin(), v.end());
  return out;
}

std::string data_array(const char* type, const char* name, int components, std::size_t offset) {
  std::ostringstream out;
  out << "        <DataArray type=\"" << type << "\"" << (name[0] ? std::string(" Name=\"") + name + "\"" : "")
      << " NumberOfComponents=\"" << components << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  return out.str();
}

}  // namespace

void write_vtp_snapshot(const std::string& path, const ParticleSnapshot& s) {
  const std::size_t n = s.positions_m.size();
  if (s.radii_m.size() != n || s.velocities_m_s.size() != n || s.angular_velocities_rad_s.size() != n ||
      s.compartments.size() != n) {
    throw std::invalid_argument(path + ": snapshot arrays differ in length");
  }
  std::vector<std::int64_t> connectivity(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);  // one vertex cell per particle
  }
  std::vector<std::int32_t> compartments(s.compartments.begin(), s.compartments.end());
  AppendedArrays data;
  const auto radius = data.add(s.radii_m);
  const auto velocity = data.add(flat(s.velocities_m_s));
  const auto spin = data.add(flat(s.angular_velocities_rad_s));
  const auto compartment = data.add(compartments);
  const auto points = data.add(flat(s.positions_m));
  const auto connectivity_at = data.add(connectivity);
  const auto offsets_at = data.add(offsets);
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\""
      << (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n"
      << "  <PolyData>\n"
      << "    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
      << s.time_s << "</DataArray>\n    </FieldData>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
      << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
      << "      <PointData Scalars=\"radius_m\" Vectors=\"velocity_m_s\">\n"
      << data_array("Float64", "radius_m", 1, radius) << data_array("Float64", "velocity_m_s", 3, velocity)
      << data_array("Float64", "angular_velocity_rad_s", 3, spin) << data_array("Int32", "compartment", 1, compartment)
      << "      </PointData>\n      <Points>\n" << data_array("Float64", "", 3, points) << "      </Points>\n"
      << "      <Verts>\n" << data_array("Int64", "connectivity", 1, connectivity_at)
      << data_array("Int64", "offsets", 1, offsets_at) << "      </Verts>\n"
      << "    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _" << data.bytes()
      << "\n  </AppendedData>\n</VTKFile>\n";
  strict_json::write_file_atomically(path, out.str());
}

void write_pvd_series(const std::string& path, const std::vector<std::pair<double, std::string>>& files) {
  write_atomically(path, [&](std::ostream& out) {
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
    for (const auto& [time_s, file] : files)
      out << "    <DataSet timestep=\"" << time_s << "\" group=\"\" part=\"0\" file=\"" << file << "\"/>\n";
    out << "  </Collection>\n</VTKFile>\n";
  });
}

}  // namespace pdamp::dem_reference
