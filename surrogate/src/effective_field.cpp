// Effective-field data, provenance stamps, and the strict JSON field file format.
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "field_format.hpp"
#include "file_io.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/strict_object.hpp"
#include "text_util.hpp"

#ifndef PDAMP_VERSION
#error "PDAMP_VERSION must be defined by the build (surrogate/CMakeLists.txt)"
#endif

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;
using nlohmann::json;

namespace {

constexpr std::string_view kFormat = "pdamp.effective_field";
constexpr int kFormatVersion = 1;
constexpr std::string_view kStorageOrder = "row_major";
constexpr std::string_view kLabelUnit = "label";
/// Relative tolerance for table coordinates against the axis nodes: hand-edited files
/// may round, but not enough to move a point onto another node.
constexpr double kCoordinateTolerance = 1e-9;

/// The table's columns after the two coordinates: FieldPoint::fields() in order.
enum Column : int {
  kEtaStar,
  kEtaStarStderr,
  kEDiss,
  kApparentMass,
  kApparentMassFraction,
  kMotionMode,
  kStatus,
  kValueColumns
};
}  // namespace

const base::Fields<FieldPoint>& FieldPoint::fields() {
  static const auto f =
      base::Fields<FieldPoint>()
          .field("eta_star", &FieldPoint::eta_star, "1", "reduced loss factor eta* = E_diss/(1/2 m_bed |V*|^2)",
                 base::kNullable)
          .field("eta_star_stderr", &FieldPoint::eta_star_stderr, "1",
                 "standard error of eta* (0 for the closed forms; null: not known)", base::kNullable)
          .field("e_diss_j", &FieldPoint::e_diss_j, "J", "energy dissipated per cycle, Re(P)/Omega", base::kNullable)
          .field("apparent_mass_kg", &FieldPoint::apparent_mass_kg, "kg",
                 "apparent mass Im(F* conj V*)/(Omega |V*|^2) (null: not given)", base::kNullable)
          .field("apparent_mass_fraction", &FieldPoint::apparent_mass_fraction, "1",
                 "apparent mass over bed mass (null: not given)", base::kNullable)
          .field("motion_mode", &FieldPoint::motion_mode, std::string(kLabelUnit),
                 "motion-mode or regime label (empty: none)")
          .field("status", &FieldPoint::status, std::string(kLabelUnit), "ok, missing or failed");
  return f;
}

namespace {

bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

bool is_iso8601_utc(const std::string& text) {
  // YYYY-MM-DDThh:mm:ssZ
  constexpr std::string_view kPattern = "dddd-dd-ddTdd:dd:ddZ";
  if (text.size() != kPattern.size()) return false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const bool digit = text[k] >= '0' && text[k] <= '9';
    if (kPattern[k] == 'd' ? !digit : text[k] != kPattern[k]) return false;
  }
  return true;
}

json row_of(const EffectiveField& field, std::size_t k) {
  json row = json::array({field.grid.coordinate0(k), field.grid.coordinate1(k)});
  for (auto& value : FieldPoint::fields().to_array(field.points[k])) row.push_back(std::move(value));
  return row;
}

/// Metadata and columns (everything but the table) in the writer's key order.
nlohmann::ordered_json metadata_of(const EffectiveField& field) {
  nlohmann::ordered_json doc;
  doc["format"] = kFormat;
  doc["format_version"] = kFormatVersion;
  const Provenance& p = field.provenance;
  doc["provenance"] = {{"source", to_string(p.source)},
                       {"case_hash", p.case_hash},
                       {"model_version", p.model_version},
                       {"pdamp_version", p.pdamp_version},
                       {"created_utc", p.created_utc}};
  if (p.approach_amplitude_m > 0.0) doc["provenance"]["approach_amplitude_m"] = p.approach_amplitude_m;
  doc["clearance_m"] = field.clearance_m;
  doc["bed_mass_kg"] = field.bed_mass_kg;
  doc["axes"] = nlohmann::ordered_json::array();
  doc["axes"].push_back(detail::axis_json(field.grid.axis0));
  doc["axes"].push_back(detail::axis_json(field.grid.axis1));
  doc["storage_order"] = kStorageOrder;
  doc["columns"] = nlohmann::ordered_json::array();
  for (const Axis* axis : {&field.grid.axis0, &field.grid.axis1}) {
    doc["columns"].push_back({{"name", to_string(axis->quantity)}, {"unit", unit_of(axis->quantity)}});
  }
  for (const auto& column : FieldPoint::fields().entries())
    doc["columns"].push_back({{"name", column.name}, {"unit", column.unit}});
  return doc;
}

void require_valid(const EffectiveField& field) { detail::throw_if_any(field.validate(), "effective field"); }

}  // namespace

namespace detail {

nlohmann::ordered_json axis_json(const Axis& axis) {
  return {{"name", to_string(axis.quantity)},
          {"unit", unit_of(axis.quantity)},
          {"spacing", to_string(axis.spacing)},
          {"values", axis.values}};
}

Axis read_axis(const json& value, const std::string& pointer, const std::string& file, int index) {
  base::StrictObject object(value, pointer, file);
  Axis axis;
  const std::string name = object.string("name");
  const auto quantity = axis_quantity_from_string(name);
  if (!quantity) {
    object.fail("name",
                "unknown axis \"" + name + "\" (allowed: frequency_hz, amplitude_m, intensity, stroke_over_clearance)");
  }
  axis.quantity = *quantity;
  const bool first = index == 0;
  if ((first && axis.quantity != AxisQuantity::kFrequencyHz && axis.quantity != AxisQuantity::kIntensity) ||
      (!first && axis.quantity != AxisQuantity::kAmplitudeM && axis.quantity != AxisQuantity::kStrokeOverClearance)) {
    object.fail("name", "\"" + name + "\" cannot be axis " + std::to_string(index) +
                            ": axis 0 is frequency_hz or intensity, axis 1 amplitude_m or stroke_over_clearance");
  }
  object.expect_string("unit", unit_of(axis.quantity));
  const std::string spacing = object.string("spacing");
  const auto parsed_spacing = axis_spacing_from_string(spacing);
  if (!parsed_spacing) object.fail("spacing", "is \"" + spacing + "\", must be \"linear\" or \"log\"");
  axis.spacing = *parsed_spacing;
  const json& values = object.array("values");
  if (values.empty()) object.fail("values", "must hold at least one node");
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::string at = object.pointer("values") + "/" + std::to_string(k);
    axis.values.push_back(object.number_value(values[k], at, true, unit_of(axis.quantity)));
    if (k > 0 && !(axis.values[k] > axis.values[k - 1])) {
      base::fail_at(file, at,
                    format_number(axis.values[k], 12) + " must be > the previous node " +
                        format_number(axis.values[k - 1], 12) + " (axis values strictly increasing)");
    }
  }
  object.finish();
  return axis;
}

}  // namespace detail

namespace {

Provenance read_provenance(const json& value, const std::string& pointer, const std::string& file) {
  base::StrictObject object(value, pointer, file);
  Provenance p;
  const std::string source = object.string("source");
  const auto parsed = field_source_from_string(source);
  if (!parsed) object.fail("source", "is \"" + source + "\", must be \"formulas\", \"dem\" or \"measured\"");
  p.source = *parsed;
  p.case_hash = object.string("case_hash");
  p.model_version = static_cast<int>(object.integer("model_version", 0, 1'000'000'000));
  p.pdamp_version = object.string("pdamp_version");
  if (p.pdamp_version.empty()) object.fail("pdamp_version", "must not be empty");
  p.created_utc = object.string("created_utc");
  if (!is_iso8601_utc(p.created_utc)) {
    object.fail("created_utc", "is \"" + p.created_utc + "\", must be UTC ISO 8601 \"YYYY-MM-DDThh:mm:ssZ\"");
  }
  if (object.contains("approach_amplitude_m")) p.approach_amplitude_m = object.number("approach_amplitude_m", true, "m");
  object.finish();
  return p;
}

/// Where each column sits in a table row: names[c] and units[c] for c = 0, 1 (the axes)
/// and 2 + Column for the value columns; position[c] is the column's index in the file.
struct TableLayout {
  std::vector<std::string_view> names;
  std::vector<std::string_view> units;
  std::vector<std::size_t> position;
};

/// The columns list: the two axes and every value column exactly once, in any order, each with its unit.
TableLayout read_columns(const json& columns, const std::string& pointer, const Grid& grid, const std::string& file) {
  TableLayout layout;
  layout.names = {to_string(grid.axis0.quantity), to_string(grid.axis1.quantity)};
  layout.units = {unit_of(grid.axis0.quantity), unit_of(grid.axis1.quantity)};
  for (const auto& column : FieldPoint::fields().entries()) {
    layout.names.push_back(column.name);
    layout.units.push_back(column.unit);
  }
  constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  layout.position.assign(layout.names.size(), kAbsent);
  for (std::size_t k = 0; k < columns.size(); ++k) {
    base::StrictObject column(columns[k], pointer + "/" + std::to_string(k), file);
    const std::string name = column.string("name");
    const auto it = std::find(layout.names.begin(), layout.names.end(), name);
    if (it == layout.names.end()) {
      std::string allowed;
      for (auto n : layout.names) allowed += (allowed.empty() ? "" : ", ") + std::string(n);
      column.fail("name", "unknown column \"" + name + "\" (allowed: " + allowed + ")");
    }
    const auto c = static_cast<std::size_t>(it - layout.names.begin());
    if (layout.position[c] != kAbsent) column.fail("name", "column \"" + name + "\" appears twice");
    layout.position[c] = k;
    column.expect_string("unit", layout.units[c]);
    column.finish();
  }
  for (std::size_t c = 0; c < layout.names.size(); ++c) {
    if (layout.position[c] == kAbsent) {
      base::fail_at(file, pointer, "missing column \"" + std::string(layout.names[c]) + "\"");
    }
  }
  return layout;
}

/// Table row k (at `at`): coordinates equal to node k, then the point with its null rules.
FieldPoint read_row(const json& row, const std::string& at, std::size_t k, const TableLayout& layout, const Grid& grid,
                    const std::string& file) {
  if (!row.is_array() || row.size() != layout.names.size()) {
    base::fail_at(file, at,
                    "must be an array of " + std::to_string(layout.names.size()) + " entries (one per column)");
  }
  auto cell_at = [&](std::size_t c) { return at + "/" + std::to_string(layout.position[c]); };
  auto cell = [&](std::size_t c) -> const json& { return row[layout.position[c]]; };
  auto finite = [&](std::size_t c, bool positive) {
    const json& v = cell(c);
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      const std::string unit = layout.units[c] == "1" ? "" : " (in " + std::string(layout.units[c]) + ")";
      base::fail_at(file, cell_at(c),
                    "must be a finite number" + unit + ", got " +
                        (v.is_number() ? format_number(v.get<double>(), 12) : std::string(v.type_name())));
    }
    const double x = v.get<double>();
    if (positive && !(x > 0.0)) base::fail_at(file, cell_at(c), "must be > 0");
    return x;
  };
  auto nullable_number = [&](std::size_t c) { return cell(c).is_null() ? FieldPoint::kUnknown : finite(c, false); };
  auto text = [&](std::size_t c) {
    if (!cell(c).is_string()) {
      base::fail_at(file, cell_at(c), std::string("must be a string, got ") + cell(c).type_name());
    }
    return cell(c).get<std::string>();
  };
  // Coordinates: rows in storage order (row i0·n1 + i1), each matching its axis nodes.
  const std::size_t n1 = grid.axis1.size();
  const double nodes[2] = {grid.coordinate0(k), grid.coordinate1(k)};
  for (std::size_t c = 0; c < 2; ++c) {
    const double x = finite(c, true);
    if (std::abs(x - nodes[c]) > kCoordinateTolerance * nodes[c]) {
      base::fail_at(file, cell_at(c),
                    std::string(layout.names[c]) + " = " + format_number(x, 12) + " does not match the axis node " +
                        format_number(nodes[c], 12) + " (rows in storage order, row i0*n1 + i1 = " +
                        std::to_string(k / n1) + "*" + std::to_string(n1) + " + " + std::to_string(k % n1) + ")");
    }
  }
  constexpr std::size_t kFirstValue = 2;
  FieldPoint p;
  const std::string status = text(kFirstValue + kStatus);
  const auto parsed_status = point_status_from_string(status);
  if (!parsed_status) {
    base::fail_at(file, cell_at(kFirstValue + kStatus),
                    "is \"" + status + "\", must be \"ok\", \"missing\" or \"failed\"");
  }
  p.status = *parsed_status;
  p.eta_star = nullable_number(kFirstValue + kEtaStar);
  p.eta_star_stderr = nullable_number(kFirstValue + kEtaStarStderr);
  p.e_diss_j = nullable_number(kFirstValue + kEDiss);
  p.apparent_mass_kg = nullable_number(kFirstValue + kApparentMass);
  p.apparent_mass_fraction = nullable_number(kFirstValue + kApparentMassFraction);
  p.motion_mode = text(kFirstValue + kMotionMode);
  if (detail::has_control_byte(p.motion_mode)) {
    base::fail_at(file, cell_at(kFirstValue + kMotionMode),
                    "\"" + base::printable(p.motion_mode) +
                        "\" holds control characters; a motion mode must be printable text");
  }
  const bool ok = p.status == PointStatus::kOk;
  for (const int c : {kEtaStar, kEDiss}) {
    const bool missing = std::isnan(c == kEtaStar ? p.eta_star : p.e_diss_j);
    if (ok && missing)
      base::fail_at(file, cell_at(kFirstValue + c), "null: must be a finite number for status \"ok\"");
  }
  if (!ok && !std::isnan(p.eta_star)) {
    base::fail_at(file, cell_at(kFirstValue + kEtaStar), "must be null for status \"" + status + "\"");
  }
  if (p.eta_star_stderr < 0.0) base::fail_at(file, cell_at(kFirstValue + kEtaStarStderr), "must be >= 0 or null");
  if (const std::string problem = field_value_problem(p.eta_star, p.apparent_mass_fraction); !problem.empty())
    base::fail_at(file, cell_at(kFirstValue + (problem.starts_with("eta_star") ? kEtaStar : kApparentMassFraction)),
                         problem);
  return p;
}

}  // namespace

std::string field_value_problem(double eta_star, double apparent_mass_fraction) {
  if (!std::isnan(eta_star) && !(eta_star >= kMinEtaStar && eta_star <= kMaxEtaStar))
    return "eta_star = " + format_number(eta_star, 12) + ": must be in [" + format_number(kMinEtaStar, 12) + ", " +
           format_number(kMaxEtaStar, 12) + "] (docs/effective_fields.md, file format)";
  if (!std::isnan(apparent_mass_fraction) && !(std::abs(apparent_mass_fraction) <= kMaxApparentMassFraction))
    return "apparent_mass_fraction = " + format_number(apparent_mass_fraction, 12) + ": must be in [" +
           format_number(-kMaxApparentMassFraction, 12) + ", " + format_number(kMaxApparentMassFraction, 12) + "]";
  return "";
}

bool FieldPoint::operator==(const FieldPoint& other) const {
  return same_number(eta_star, other.eta_star) && same_number(eta_star_stderr, other.eta_star_stderr) &&
         same_number(e_diss_j, other.e_diss_j) && same_number(apparent_mass_kg, other.apparent_mass_kg) &&
         same_number(apparent_mass_fraction, other.apparent_mass_fraction) && motion_mode == other.motion_mode &&
         status == other.status;
}

std::string_view to_string(PointStatus status) {
  switch (status) {
    case PointStatus::kOk: return "ok";
    case PointStatus::kMissing: return "missing";
    case PointStatus::kFailed: return "failed";
  }
  return "unknown";
}

std::optional<PointStatus> point_status_from_string(std::string_view name) {
  for (auto s : {PointStatus::kOk, PointStatus::kMissing, PointStatus::kFailed}) {
    if (to_string(s) == name) return s;
  }
  return std::nullopt;
}

std::string_view to_string(FieldSource source) {
  switch (source) {
    case FieldSource::kFormulas: return "formulas";
    case FieldSource::kDem: return "dem";
    case FieldSource::kMeasured: return "measured";
  }
  return "unknown";
}

std::optional<FieldSource> field_source_from_string(std::string_view name) {
  for (auto s : {FieldSource::kFormulas, FieldSource::kDem, FieldSource::kMeasured}) {
    if (to_string(s) == name) return s;
  }
  return std::nullopt;
}

std::string_view pdamp_version() { return PDAMP_VERSION; }

std::string utc_timestamp_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::array<char, 32> text{};
  std::strftime(text.data(), text.size(), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text.data();
}

Provenance make_provenance(FieldSource source, std::string case_hash, int model_version) {
  return {source, std::move(case_hash), model_version, std::string(pdamp_version()), utc_timestamp_now()};
}

std::string case_hash(const json& case_json) {
  // FNV-1a 64 (offset basis and prime from the FNV reference): not cryptographic, but
  // its only job is to notice that a results file belongs to another case.
  std::uint64_t hash = 14695981039346656037ULL;
  for (unsigned char c : case_json.dump()) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  std::array<char, 17> text{};
  std::snprintf(text.data(), text.size(), "%016llx", static_cast<unsigned long long>(hash));
  return text.data();
}

std::vector<std::string> EffectiveField::validate() const {
  std::vector<std::string> problems = grid.validate();
  if (!positive_finite(clearance_m)) {
    problems.push_back("clearance_m = " + format_number(clearance_m, 12) + ": must be > 0 and finite");
  }
  if (!positive_finite(bed_mass_kg)) {
    problems.push_back("bed_mass_kg = " + format_number(bed_mass_kg, 12) + ": must be > 0 and finite");
  }
  if (provenance.model_version < 0) {
    problems.push_back("provenance.model_version = " + std::to_string(provenance.model_version) + ": must be >= 0");
  }
  if (provenance.pdamp_version.empty()) problems.emplace_back("provenance.pdamp_version: must not be empty");
  if (!is_iso8601_utc(provenance.created_utc)) {
    problems.push_back("provenance.created_utc = \"" + provenance.created_utc +
                       "\": must be UTC ISO 8601 \"YYYY-MM-DDThh:mm:ssZ\"");
  }
  if (points.size() != grid.size()) {
    problems.push_back("points: " + std::to_string(points.size()) + " points for a grid of " +
                       std::to_string(grid.axis0.size()) + " x " + std::to_string(grid.axis1.size()) + " = " +
                       std::to_string(grid.size()) + " nodes");
    return problems;
  }
  for (std::size_t k = 0; k < points.size(); ++k) {
    const FieldPoint& p = points[k];
    const std::string at = "points[" + std::to_string(k) + "]";
    const bool ok = p.status == PointStatus::kOk;
    if (ok && !std::isfinite(p.eta_star)) {
      problems.push_back(at + ".eta_star = " + format_number(p.eta_star, 12) + ": must be finite for status ok");
    }
    if (ok && !std::isfinite(p.e_diss_j)) {
      problems.push_back(at + ".e_diss_j = " + format_number(p.e_diss_j, 12) + ": must be finite for status ok");
    }
    if (!ok && !std::isnan(p.eta_star)) {
      problems.push_back(at + ".eta_star = " + format_number(p.eta_star, 12) + ": must be NaN (no value) for status " +
                         std::string(to_string(p.status)));
    }
    if (const std::string problem = field_value_problem(p.eta_star, p.apparent_mass_fraction); !problem.empty())
      problems.push_back(at + "." + problem);
    if (!std::isnan(p.eta_star_stderr) && !(p.eta_star_stderr >= 0.0 && std::isfinite(p.eta_star_stderr))) {
      problems.push_back(at + ".eta_star_stderr = " + format_number(p.eta_star_stderr, 12) +
                         ": must be >= 0 and finite, or NaN");
    }
    for (const auto& [name, value] :
         {std::pair{".e_diss_j", p.e_diss_j}, std::pair{".apparent_mass_kg", p.apparent_mass_kg},
          std::pair{".apparent_mass_fraction", p.apparent_mass_fraction}}) {
      if (std::isinf(value))
        problems.push_back(at + name + " = " + format_number(value, 12) + ": must be finite or NaN");
    }
  }
  return problems;
}

json to_json(const EffectiveField& field) {
  require_valid(field);
  json doc = json::parse(metadata_of(field).dump());
  doc["table"] = json::array();
  for (std::size_t k = 0; k < field.points.size(); ++k) doc["table"].push_back(row_of(field, k));
  return doc;
}

EffectiveField effective_field_from_json(const json& document, const std::string& file_name) {
  base::StrictObject root(document, "", file_name);
  root.expect_string("format", kFormat);
  root.integer("format_version", kFormatVersion, kFormatVersion);
  EffectiveField field;
  field.provenance = read_provenance(root.required("provenance"), root.pointer("provenance"), file_name);
  field.clearance_m = root.number("clearance_m", true, "m");
  field.bed_mass_kg = root.number("bed_mass_kg", true, "kg");

  const json& axes = root.array("axes");
  if (axes.size() != 2) {
    root.fail("axes",
              "has " + std::to_string(axes.size()) +
                  " entries, must have 2 (frequency_hz and amplitude_m, or intensity and stroke_over_clearance)");
  }
  field.grid.axis0 = detail::read_axis(axes[0], root.pointer("axes") + "/0", file_name, 0);
  field.grid.axis1 = detail::read_axis(axes[1], root.pointer("axes") + "/1", file_name, 1);
  try {
    (void)field.grid.axes();
  } catch (const std::invalid_argument& e) {
    root.fail("axes", e.what());
  }
  if (field.grid.size() > kMaxGridNodes) {
    root.fail("axes", std::to_string(field.grid.axis0.size()) + " x " + std::to_string(field.grid.axis1.size()) +
                          " = " + std::to_string(field.grid.size()) + " nodes, must be <= " +
                          std::to_string(kMaxGridNodes));
  }
  root.expect_string("storage_order", kStorageOrder);

  const TableLayout layout = read_columns(root.array("columns"), root.pointer("columns"), field.grid, file_name);
  const json& table = root.array("table");
  if (table.size() != field.grid.size()) {
    root.fail("table", "has " + std::to_string(table.size()) + " rows, the axes need " +
                           std::to_string(field.grid.axis0.size()) + " x " + std::to_string(field.grid.axis1.size()) +
                           " = " + std::to_string(field.grid.size()) + " (one per node)");
  }
  for (std::size_t k = 0; k < table.size(); ++k) {
    field.points.push_back(
        read_row(table[k], root.pointer("table") + "/" + std::to_string(k), k, layout, field.grid, file_name));
  }
  root.finish();
  return field;
}

EffectiveField read_effective_field(const std::filesystem::path& path) {
  // read_json_file refuses directories, FIFOs and duplicate keys with "<path>: ..." messages.
  return effective_field_from_json(detail::read_json_file(path), detail::file_label(path));
}

void write_effective_field(const EffectiveField& field, const std::filesystem::path& path) {
  require_valid(field);
  // One top-level key per line, and one axis, column or table row per line: an
  // indented dump would put every number on its own line.
  const nlohmann::ordered_json metadata = metadata_of(field);
  std::string text = "{\n";
  for (const auto& [key, value] : metadata.items()) {
    text += "  " + json(key).dump() + ": ";
    if (value.is_array()) {
      text += "[\n";
      for (std::size_t k = 0; k < value.size(); ++k) {
        text += "    " + value[k].dump() + (k + 1 < value.size() ? ",\n" : "\n");
      }
      text += "  ],\n";
    } else {
      text += value.dump() + ",\n";
    }
  }
  text += "  \"table\": [\n";
  for (std::size_t k = 0; k < field.points.size(); ++k) {
    text += "    " + row_of(field, k).dump() + (k + 1 < field.points.size() ? ",\n" : "\n");
  }
  text += "  ]\n}\n";
  detail::write_file_atomically(path, text);
}

}  // namespace pdamp::surrogate
