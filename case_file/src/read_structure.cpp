// Format 2 `structure`: a beam (structure::BeamModel, ModalDamping) or modal data.
#include <filesystem>
#include <limits>

#include "pdamp/structure/imported_modal_data.hpp"
#include "pdamp/base/input_file.hpp"
#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace st = structure;

namespace {

/// Numbers whose range the beam's own validate() owns are read finite only.
constexpr Range kFinite{};
constexpr int kAnyInt = std::numeric_limits<int>::max();

/// A line of BeamModel::validate() or ModalDamping::validate() ("segments/0/length_m =
/// -1: must be > 0 m", "segments is empty: ...") as the error at `prefix`/<field>.
[[noreturn]] void fail_validation(const ObjectReader& r, const std::string& prefix, const std::string& line) {
  const auto cut = line.find(' ');
  const std::string field = line.substr(0, cut);
  r.fail(prefix + field, cut == std::string::npos ? line : line.substr(cut + 1));
}

st::Section read_section(ObjectReader& r) {
  st::Section section;
  const std::string shape =
      r.text("shape", std::nullopt, {"solid_rectangle", "hollow_rectangle", "solid_circle", "hollow_circle"});
  const bool rectangle = shape == "solid_rectangle" || shape == "hollow_rectangle";
  const bool hollow = shape == "hollow_rectangle" || shape == "hollow_circle";
  section.shape = shape == "solid_rectangle"    ? st::SectionShape::kSolidRectangle
                  : shape == "hollow_rectangle" ? st::SectionShape::kHollowRectangle
                  : shape == "solid_circle"     ? st::SectionShape::kSolidCircle
                                                : st::SectionShape::kHollowCircle;
  // Only the dimensions of the shape are keys: a diameter on a rectangle is a mistake.
  if (rectangle) {
    section.width_m = r.number("width_m", std::nullopt, kFinite, " m");
    section.depth_m = r.number("depth_m", std::nullopt, kFinite, " m");
  } else {
    section.diameter_m = r.number("diameter_m", std::nullopt, kFinite, " m");
  }
  if (hollow) section.wall_thickness_m = r.number("wall_thickness_m", std::nullopt, kFinite, " m");
  return section;
}

/// A segment's material: the name of a `materials` entry, or its own numbers.
st::BeamMaterial read_beam_material(ObjectReader& r, const Case& c) {
  st::BeamMaterial material;
  if (r.is_string("material")) {
    const std::string name = r.text("material", std::nullopt);
    if (!c.materials.count(name)) r.fail("material", "'" + name + "' is not defined in /materials (nor built in)");
    material.youngs_modulus_pa = c.materials.at(name).youngs_modulus_pa;
    material.density_kg_m3 = c.materials.at(name).density_kg_m3;
    return material;
  }
  r.object("material", true, [&](ObjectReader& m) {
    material.youngs_modulus_pa = m.number("youngs_modulus_pa", std::nullopt, limits::kModulus, " Pa");
    material.density_kg_m3 = m.number("density_kg_m3", std::nullopt, limits::kDensity, " kg/m^3");
  });
  return material;
}

void read_beam(ObjectReader& r, const Case& c, StructureSpec& s) {
  st::BeamModel& beam = s.beam;
  if (!r.has("segments")) r.fail("segments", "required (an array of at least one segment)");
  r.array("segments", [&](ObjectReader& g) {
    st::BeamSegment segment;
    segment.length_m = g.number("length_m", std::nullopt, kFinite, " m");
    g.object("section", true, [&](ObjectReader& x) { segment.section = read_section(x); });
    segment.material = read_beam_material(g, c);
    segment.elements = g.integer("elements", st::BeamSegment{}.elements, -kAnyInt, kAnyInt);
    beam.segments.push_back(segment);
  }, st::beam_limits::kMaxSegments);
  r.array("supports", [&](ObjectReader& p) {
    st::Support support;
    const std::string kind = p.text("kind", std::nullopt, {"clamped", "pinned", "spring"});
    support.kind = kind == "clamped" ? st::Support::Kind::kClamped
                   : kind == "pinned" ? st::Support::Kind::kPinned
                                      : st::Support::Kind::kSpring;
    support.position_m = p.number("position_m", std::nullopt, kFinite, " m");
    if (support.kind == st::Support::Kind::kSpring) {
      support.axial_stiffness_n_m = p.number("axial_stiffness_n_m", 0.0, kFinite, " N/m");
      support.transverse_stiffness_n_m = p.number("transverse_stiffness_n_m", 0.0, kFinite, " N/m");
      support.rotational_stiffness_n_m_rad = p.number("rotational_stiffness_n_m_rad", 0.0, kFinite, " N m/rad");
    }
    beam.supports.push_back(support);
  }, st::beam_limits::kMaxSupports);
  r.array("point_masses", [&](ObjectReader& p) {
    st::PointMass mass;
    mass.name = p.text("name", std::nullopt);
    mass.position_m = p.number("position_m", std::nullopt, kFinite, " m");
    mass.mass_kg = p.number("mass_kg", std::nullopt, kFinite, " kg");
    mass.rotary_inertia_kg_m2 = p.number("rotary_inertia_kg_m2", 0.0, kFinite, " kg m^2");
    beam.point_masses.push_back(mass);
  }, st::beam_limits::kMaxPoints);
  r.array("points", [&](ObjectReader& p) {
    st::NamedPoint point;
    point.name = p.text("name", std::nullopt);
    point.position_m = p.number("position_m", std::nullopt, kFinite, " m");
    beam.points.push_back(point);
  }, st::beam_limits::kMaxPoints);
  beam.axial_gravity_m_s2 = r.number("axial_gravity_m_s2", 0.0, limits::kGravity, " m/s^2");
  beam.geometric_stiffness = r.boolean("geometric_stiffness", false);
  s.mode_count = r.integer("mode_count", StructureSpec{}.mode_count, 1, 100);
  const auto read_damping = [&](ObjectReader& d) {
    if (d.has("rayleigh_alpha_1_s") || d.has("rayleigh_beta_s")) {
      s.damping.ratios.clear();
      s.damping.rayleigh_alpha_1_s = d.number("rayleigh_alpha_1_s", 0.0, kFinite, " 1/s");
      s.damping.rayleigh_beta_s = d.number("rayleigh_beta_s", 0.0, kFinite, " s");
    } else if (d.has("ratios")) {
      s.damping.ratios = d.number_array("ratios", kFinite, "", 1);
    } else {
      d.resolved()["ratios"] = s.damping.ratios;
    }
  };
  r.object("damping", false, read_damping);
  if (!r.has("damping")) {
    ObjectReader defaults(r.file(), empty_object(), r.pointer() + "/damping", r.resolved()["damping"]);
    read_damping(defaults);
  }
  for (const auto& line : beam.validate()) fail_validation(r, "", line);
  for (const auto& line : s.damping.validate()) fail_validation(r, "damping/", line);
  for (const auto& p : beam.point_masses) s.point_names.push_back(p.name);
  for (const auto& p : beam.points) s.point_names.push_back(p.name);
}

/// The modal file, relative to the case file's folder unless absolute, read safely
/// and parsed by structure/; its errors name that file and their pointer in it.
void read_modal_data(ObjectReader& r, StructureSpec& s) {
  const std::string file = r.text("file", std::nullopt);
  if (file.empty()) r.fail("file", "must not be empty (the path of the modal data file)");
  s.modal_data_file = resolve_case_relative(r, file);
  const nlohmann::json document = base::parse_json_document(base::read_input_file(s.modal_data_file),
                                                                    s.modal_data_file);
  try {
    s.modal_data = st::modal_model_from_json(document);
  } catch (const st::ModalDataError& e) {
    // what() is "<pointer>: <rule>" ("/" for the document itself).
    const std::string what = e.what();
    const std::size_t shown = e.pointer().empty() ? 1 : e.pointer().size();
    throw CaseError(s.modal_data_file, e.pointer(), what.substr(std::min(what.size(), shown + 2)));
  }
  for (const auto& p : s.modal_data->points) s.point_names.push_back(p.name);
}

}  // namespace

StructureSpec read_structure(ObjectReader& r, const Case& c) {
  StructureSpec s;
  const std::string kind = r.text("kind", std::nullopt, {"beam", "modal_data"});
  if (kind == "beam") {
    s.kind = StructureSpec::Kind::kBeam;
    read_beam(r, c, s);
  } else {
    s.kind = StructureSpec::Kind::kModalData;
    read_modal_data(r, s);
  }
  return s;
}

}  // namespace pdamp::case_file::detail
