// Result files of a DEM run (time-series CSV, VTK XML snapshots and their series), written to a
// temporary file beside the target and renamed over it (base::write_file_atomically),
// so no reader sees a partial file.
#include "pdamp/dem_reference/result_files.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "pdamp/base/output_file.hpp"

namespace pdamp::dem_reference {

namespace {

/// The text `body` writes, stored atomically (base::write_file_atomically).
void write_atomically(const std::string& path, const std::function<void(std::ostream&)>& body) {
  std::ostringstream out;
  out.precision(17);
  body(out);
  base::write_file_atomically(path, out.str());
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

/// A VTK XML PolyData file at `time_s` (its TimeValue field): `piece`, the <Piece> element
/// with its arrays' declarations, then the appended arrays themselves. Written atomically.
void write_polydata(const std::string& path, double time_s, const std::string& piece, const AppendedArrays& data) {
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\""
      << (std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian") << "\" header_type=\"UInt64\">\n"
      << "  <PolyData>\n"
      << "    <FieldData>\n      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
      << time_s << "</DataArray>\n    </FieldData>\n"
      << piece << "  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _" << data.bytes()
      << "\n  </AppendedData>\n</VTKFile>\n";
  base::write_file_atomically(path, out.str());
}

}  // namespace

void write_vtp_snapshot(const std::string& path, const ParticleSnapshot& s) {
  const std::size_t n = s.positions_m.size();
  if (s.radii_m.size() != n || s.velocities_m_s.size() != n || s.angular_velocities_rad_s.size() != n ||
      s.compartments.size() != n || s.contacts.size() != n) {
    throw std::invalid_argument(path + ": snapshot arrays differ in length");
  }
  std::vector<std::int64_t> connectivity(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);  // one vertex cell per particle
  }
  std::vector<std::int32_t> compartments(s.compartments.begin(), s.compartments.end());
  std::vector<std::int32_t> contacts(s.contacts.begin(), s.contacts.end());
  AppendedArrays data;
  const auto radius = data.add(s.radii_m);
  const auto velocity = data.add(flat(s.velocities_m_s));
  const auto spin = data.add(flat(s.angular_velocities_rad_s));
  const auto compartment = data.add(compartments);
  const auto contact = data.add(contacts);
  const auto points = data.add(flat(s.positions_m));
  const auto connectivity_at = data.add(connectivity);
  const auto offsets_at = data.add(offsets);
  std::ostringstream piece;
  piece << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
        << "      <PointData Scalars=\"radius_m\" Vectors=\"velocity_m_s\">\n"
        << data_array("Float64", "radius_m", 1, radius) << data_array("Float64", "velocity_m_s", 3, velocity)
        << data_array("Float64", "angular_velocity_rad_s", 3, spin) << data_array("Int32", "compartment", 1, compartment)
        << data_array("Int32", "contacts", 1, contact)
        << "      </PointData>\n      <Points>\n" << data_array("Float64", "", 3, points) << "      </Points>\n"
        << "      <Verts>\n" << data_array("Int64", "connectivity", 1, connectivity_at)
        << data_array("Int64", "offsets", 1, offsets_at) << "      </Verts>\n    </Piece>\n";
  write_polydata(path, s.time_s, piece.str(), data);
}

namespace {

/// Polygons for the container geometry: points, each polygon's point indices, and per
/// polygon the part (0 the container's walls, 1 a plate, 2 a pin) and the compartment.
struct Polygons {
  std::vector<double> points;
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::int32_t> part, compartment;

  std::int64_t point(const Vec3& p) {
    points.insert(points.end(), p.begin(), p.end());
    return static_cast<std::int64_t>(points.size() / 3 - 1);
  }
  void polygon(const std::vector<std::int64_t>& corners, int part_id, int compartment_id) {
    connectivity.insert(connectivity.end(), corners.begin(), corners.end());
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
    part.push_back(part_id);
    compartment.push_back(compartment_id);
  }
  /// The six faces of an axis-aligned box of full edge lengths `size` about `centre`.
  void box(const Vec3& centre, const Vec3& size, int part_id, int compartment_id) {
    std::int64_t corner[8];
    for (int k = 0; k < 8; ++k)
      corner[k] = point({centre[0] + ((k & 1) ? 0.5 : -0.5) * size[0], centre[1] + ((k & 2) ? 0.5 : -0.5) * size[1],
                         centre[2] + ((k & 4) ? 0.5 : -0.5) * size[2]});
    static const int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    for (const auto& f : kFaces) polygon({corner[f[0]], corner[f[1]], corner[f[2]], corner[f[3]]}, part_id, compartment_id);
  }
  /// An axis-aligned cylinder (`axis` 0..2) as 48 side quads and its two end discs.
  void cylinder(const Vec3& centre, int axis, double radius, double length, int part_id, int compartment_id) {
    constexpr int kSides = 48;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    std::vector<std::int64_t> ends[2];
    for (int e = 0; e < 2; ++e)
      for (int k = 0; k < kSides; ++k) {
        Vec3 p = centre;
        const double angle = 2.0 * M_PI * k / kSides;
        p[axis] += (e ? 0.5 : -0.5) * length;
        p[u] += radius * std::cos(angle);
        p[v] += radius * std::sin(angle);
        ends[e].push_back(point(p));
      }
    for (int k = 0; k < kSides; ++k) {
      const int next = (k + 1) % kSides;
      polygon({ends[0][k], ends[0][next], ends[1][next], ends[1][k]}, part_id, compartment_id);
    }
    polygon(ends[0], part_id, compartment_id);
    polygon(ends[1], part_id, compartment_id);
  }
};

}  // namespace

void write_container_vtp(const std::string& path, const WorldOptions& world, const Vec3& displacement_m, double time_s) {
  Polygons g;
  for (std::size_t i = 0; i < world.compartments.size(); ++i) {
    const auto& c = world.compartments[i];
    const int id = static_cast<int>(i);
    Vec3 centre{};
    for (int k = 0; k < 3; ++k) centre[k] = c.offset_m[k] + displacement_m[k];
    // Plates and pins are placed in the compartment frame, centred on the container.
    const auto shifted = [&](const Vec3& p) { return Vec3{centre[0] + p[0], centre[1] + p[1], centre[2] + p[2]}; };
    if (c.container.shape == formulas::ContainerShape::kBox)
      g.box(centre, c.container.box_inner_size_m, 0, id);
    else
      g.cylinder(centre, c.container.cylinder_axis, c.container.cylinder_inner_radius_m, c.container.cylinder_inner_length_m, 0, id);
    for (const auto& plate : c.plates) g.box(shifted(plate.centre_m), plate.size_m, 1, id);
    for (const auto& pin : c.pins) g.cylinder(shifted(pin.centre_m), pin.axis, pin.radius_m, pin.length_m, 2, id);
  }
  AppendedArrays data;
  const auto part = data.add(g.part);
  const auto compartment = data.add(g.compartment);
  const auto points = data.add(g.points);
  const auto connectivity = data.add(g.connectivity);
  const auto offsets = data.add(g.offsets);
  std::ostringstream piece;
  piece << "    <Piece NumberOfPoints=\"" << g.points.size() / 3
        << "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" << g.offsets.size() << "\">\n"
        << "      <CellData Scalars=\"part\">\n" << data_array("Int32", "part", 1, part)
        << data_array("Int32", "compartment", 1, compartment) << "      </CellData>\n"
        << "      <Points>\n" << data_array("Float64", "", 3, points) << "      </Points>\n"
        << "      <Polys>\n" << data_array("Int64", "connectivity", 1, connectivity) << data_array("Int64", "offsets", 1, offsets)
        << "      </Polys>\n    </Piece>\n";
  write_polydata(path, time_s, piece.str(), data);
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
