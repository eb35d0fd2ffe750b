// CSV import of measured effective fields: column checks, number parsing, full-grid check.
#include "pdamp/surrogate/measured_import.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include "pdamp/base/csv_text.hpp"
#include "pdamp/base/input_file.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

#include "file_io.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;

namespace {

enum Column : int { kFrequency, kAmplitude, kEta, kStderr, kApparentMass, kMotionMode, kColumns };
constexpr std::array<std::string_view, kColumns> kNames = {"frequency_hz",    "amplitude_m",      "eta_star",
                                                           "eta_star_stderr", "apparent_mass_kg", "motion_mode"};
constexpr int kRequiredColumns = 3;  // frequency_hz, amplitude_m, eta_star
/// Smallest stroke, m (0.1 µm, as the case files): below, no rig resolves X.
constexpr double kMinAmplitude_m = 1e-7;

/// One data row as read, before it is placed on the grid.
struct Row {
  std::size_t line = 0;
  double frequency_hz = 0.0;
  double amplitude_m = 0.0;
  FieldPoint point;
};

class CsvReader {
 public:
  explicit CsvReader(const std::string& file_name) : file_(file_name) {}

  /// The message goes through printable(): a file name, column name or cell from a
  /// binary file must not cut (NUL) or break (newline) the one-line message.
  [[noreturn]] void fail(std::size_t line, std::string_view column, const std::string& rule) const {
    throw std::invalid_argument(base::printable(file_ + ": line " + std::to_string(line) +
                                                    (column.empty() ? "" : ", column " + std::string(column)) + ": " +
                                                    rule));
  }

  /// A finite number filling the whole cell.
  double parse_number(std::string_view cell, std::size_t line, std::string_view column) const {
    double value = 0.0;
    const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    if (cell.empty() || error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
      std::string rule = "\"";  // built by appending: GCC 12 warns falsely (-Wrestrict) on "..." + string
      rule.append(cell).append("\" is not a finite number");
      fail(line, column, rule);
    }
    return value;
  }

 private:
  std::string file_;
};

}  // namespace

std::vector<std::string> MeasuredImportOptions::validate() const {
  std::vector<std::string> problems;
  if (!positive_finite(clearance_m))
    problems.push_back("clearance_m = " + format_number(clearance_m, 12) + ": must be > 0 and finite");
  if (!positive_finite(bed_mass_kg))
    problems.push_back("bed_mass_kg = " + format_number(bed_mass_kg, 12) + ": must be > 0 and finite");
  if (model_version < 0) problems.push_back("model_version = " + std::to_string(model_version) + ": must be >= 0");
  return problems;
}

EffectiveField measured_field_from_csv(std::string_view text, const std::string& file_name,
                                       const MeasuredImportOptions& options) {
  detail::throw_if_any(options.validate(), "measured import options");
  const CsvReader reader(file_name);
  std::array<int, kColumns> position;  // position[c] = cell index of column c, -1 if absent
  position.fill(-1);
  std::size_t header_cells = 0;
  bool have_header = false;
  std::vector<Row> rows;

  // Spreadsheets often save CSV as UTF-8 with a byte-order mark; it is not part of the
  // first column's name.
  constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";
  if (text.substr(0, kUtf8Bom.size()) == kUtf8Bom) text.remove_prefix(kUtf8Bom.size());
  std::size_t line_number = 0;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find('\n', begin), text.size());
    const std::string_view line = base::trim_blanks(text.substr(begin, end - begin));
    begin = end + 1;
    ++line_number;
    // A NUL byte means a binary file (a spreadsheet's native format, a UTF-16 export):
    // say so, instead of an "unknown column" quoting bytes the user never typed.
    if (const auto nul = line.find('\0'); nul != std::string_view::npos) {
      reader.fail(line_number, "",
                  "byte " + std::to_string(nul + 1) +
                      " is NUL: this is a binary file, not CSV text (save it as CSV, UTF-8); the line starts \"" +
                      std::string(line.substr(0, std::min<std::size_t>(line.size(), 24))) +
                      "\"");
    }
    if (line.empty() || line.front() == '#') continue;
    const auto cells = base::split_csv_line(line);
    if (!have_header) {
      have_header = true;
      header_cells = cells.size();
      for (std::size_t k = 0; k < cells.size(); ++k) {
        const auto it = std::find(kNames.begin(), kNames.end(), cells[k]);
        if (it == kNames.end()) {
          reader.fail(line_number, cells[k],
                      "unknown column (allowed: frequency_hz, amplitude_m, eta_star, eta_star_stderr, "
                      "apparent_mass_kg, motion_mode)");
        }
        const auto c = static_cast<std::size_t>(it - kNames.begin());
        if (position[c] >= 0) reader.fail(line_number, cells[k], "appears twice in the header");
        position[c] = static_cast<int>(k);
      }
      for (int c = 0; c < kRequiredColumns; ++c) {
        if (position[c] < 0) reader.fail(line_number, kNames[c], "missing from the header (required column)");
      }
      continue;
    }
    if (cells.size() != header_cells) {
      reader.fail(line_number, "",
                  std::to_string(cells.size()) + " cells, the header has " + std::to_string(header_cells));
    }
    auto cell = [&](int c) {
      return position[c] < 0 ? std::string_view{} : cells[static_cast<std::size_t>(position[c])];
    };
    auto optional_number = [&](int c) {
      return cell(c).empty() ? FieldPoint::kUnknown : reader.parse_number(cell(c), line_number, kNames[c]);
    };
    Row row;
    row.line = line_number;
    row.frequency_hz = reader.parse_number(cell(kFrequency), line_number, kNames[kFrequency]);
    row.amplitude_m = reader.parse_number(cell(kAmplitude), line_number, kNames[kAmplitude]);
    // The drive ranges of the DEM (dem_reference::limits) and of the case file: a rig
    // cannot drive outside them, and a value there is a unit or column mistake.
    namespace lim = dem_reference::limits;
    if (!(row.frequency_hz >= lim::kMinFrequency_hz && row.frequency_hz <= lim::kMaxFrequency_hz))
      reader.fail(line_number, kNames[kFrequency],
                  format_number(row.frequency_hz, 12) + ": must be in [" + format_number(lim::kMinFrequency_hz, 12) +
                      ", " + format_number(lim::kMaxFrequency_hz, 12) + "] (in Hz)");
    if (!(row.amplitude_m >= kMinAmplitude_m && row.amplitude_m <= lim::kMaxAmplitude_m))
      reader.fail(line_number, kNames[kAmplitude],
                  format_number(row.amplitude_m, 12) + ": must be in [" + format_number(kMinAmplitude_m, 12) + ", " +
                      format_number(lim::kMaxAmplitude_m, 12) + "] (in m)");
    FieldPoint& p = row.point;
    p.eta_star = reader.parse_number(cell(kEta), line_number, kNames[kEta]);
    // η* = E_diss/(½ m_bed V²) with E_diss = Re(P)/Ω the mean power the container puts
    // into the bed (docs/complex_power.md): a passive damper only dissipates, so η* >= 0
    // (0: a bed locked to the container). A negative value is a sign or phase error of
    // the rig; near-zero noise should be recorded as 0 with its standard error.
    // The free, fully plastic bed of the ideal collect-and-collide orbit peaks at 4/π;
    // an elastic bed (polymer walls) can resonate and exceed it, so the bound is set far
    // above, at kMaxEtaStar: a value beyond is a unit or column mistake (a percentage,
    // E_diss in the η* column), not a damper.
    if (!(p.eta_star >= 0.0 && p.eta_star <= kMaxEtaStar))
      reader.fail(line_number, kNames[kEta],
                  format_number(p.eta_star, 12) + ": must be in [0, " + format_number(kMaxEtaStar, 12) +
                      "] (>= 0: a passive damper dissipates)");
    p.eta_star_stderr = optional_number(kStderr);
    if (p.eta_star_stderr < 0.0)
      reader.fail(line_number, kNames[kStderr], format_number(p.eta_star_stderr, 12) + ": must be >= 0");
    p.apparent_mass_kg = optional_number(kApparentMass);
    // m_app of a particle bed lies between about 0 (bed detached) and m_bed (locked to
    // the container); m_app < 0 would be a spring-like reaction (−k/Ω²,
    // docs/complex_power.md) that a bed far below its contact frequencies does not
    // show, so it is taken as a sign error of the rig.
    if (p.apparent_mass_kg < 0.0)
      reader.fail(line_number, kNames[kApparentMass], format_number(p.apparent_mass_kg, 12) + ": must be >= 0 (in kg)");
    p.apparent_mass_fraction = p.apparent_mass_kg / options.bed_mass_kg;  // NaN stays NaN
    p.motion_mode = std::string(cell(kMotionMode));
    if (detail::has_control_byte(p.motion_mode)) {
      reader.fail(line_number, kNames[kMotionMode],
                  "\"" + p.motion_mode + "\" holds control characters (must be printable text)");
    }
    const double velocity = 2.0 * formulas::kPi * row.frequency_hz * row.amplitude_m;  // |V*| = XΩ
    p.e_diss_j = p.eta_star * 0.5 * options.bed_mass_kg * velocity * velocity;
    p.status = PointStatus::kOk;
    rows.push_back(std::move(row));
  }
  if (!have_header) reader.fail(line_number, "", "no header line (the file holds no data)");
  if (rows.empty()) reader.fail(line_number, "", "no data rows after the header");

  EffectiveField field;
  field.grid.axis0 = {AxisQuantity::kFrequencyHz, options.frequency_spacing, {}};
  field.grid.axis1 = {AxisQuantity::kAmplitudeM, options.amplitude_spacing, {}};
  for (const auto& row : rows) {
    field.grid.axis0.values.push_back(row.frequency_hz);
    field.grid.axis1.values.push_back(row.amplitude_m);
  }
  for (auto* values : {&field.grid.axis0.values, &field.grid.axis1.values}) {
    std::sort(values->begin(), values->end());
    values->erase(std::unique(values->begin(), values->end()), values->end());
  }
  const std::size_t n0 = field.grid.axis0.size();
  const std::size_t n1 = field.grid.axis1.size();
  std::vector<std::size_t> line_of(n0 * n1, 0);  // 0 = no row yet
  field.points.resize(n0 * n1);
  for (auto& row : rows) {
    const auto i0 = static_cast<std::size_t>(
        std::lower_bound(field.grid.axis0.values.begin(), field.grid.axis0.values.end(), row.frequency_hz) -
        field.grid.axis0.values.begin());
    const auto i1 = static_cast<std::size_t>(
        std::lower_bound(field.grid.axis1.values.begin(), field.grid.axis1.values.end(), row.amplitude_m) -
        field.grid.axis1.values.begin());
    const std::size_t k = field.grid.index(i0, i1);
    if (line_of[k] != 0) {
      reader.fail(row.line, "",
                  "frequency_hz = " + format_number(row.frequency_hz, 12) +
                      ", amplitude_m = " + format_number(row.amplitude_m, 12) + " repeats line " +
                      std::to_string(line_of[k]) + " (each grid point once)");
    }
    line_of[k] = row.line;
    field.points[k] = std::move(row.point);
  }
  for (std::size_t k = 0; k < line_of.size(); ++k) {
    if (line_of[k] == 0) {
      reader.fail(line_number, "",
                  "the rows do not form a full grid: " + std::to_string(n0) + " frequencies x " + std::to_string(n1) +
                      " amplitudes need " + std::to_string(n0 * n1) +
                      " rows, and frequency_hz = " + format_number(field.grid.coordinate0(k), 12) +
                      ", amplitude_m = " + format_number(field.grid.coordinate1(k), 12) +
                      " has none (values must repeat exactly across rows)");
    }
  }
  field.provenance = make_provenance(FieldSource::kMeasured, options.case_hash, options.model_version);
  field.clearance_m = options.clearance_m;
  field.bed_mass_kg = options.bed_mass_kg;
  return field;
}

EffectiveField import_measured_csv(const std::filesystem::path& path, const MeasuredImportOptions& options) {
  // read_text_file refuses a directory ("is a directory", not "no header") and a FIFO
  // (at once, no hang) before any parsing.
  return measured_field_from_csv(detail::read_text_file(path), path.string(), options);
}

}  // namespace pdamp::surrogate
