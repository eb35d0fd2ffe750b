// Effective fields: the damper's characteristic diagram over a grid, with provenance,
// and its self-describing JSON file format (docs/effective_fields.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/base/record.hpp"
#include "pdamp/surrogate/grid.hpp"

namespace pdamp::surrogate {

/// Whether a grid point holds values.
enum class PointStatus {
  kOk,       ///< values present (η* and E_diss finite)
  kMissing,  ///< not computed yet (values NaN)
  kFailed,   ///< the evaluator gave up on this point (values NaN); see motion_mode for why
};
std::string_view to_string(PointStatus status);
std::optional<PointStatus> point_status_from_string(std::string_view name);

/// Where a field's values came from.
enum class FieldSource { kFormulas, kDem, kMeasured };
std::string_view to_string(FieldSource source);
std::optional<FieldSource> field_source_from_string(std::string_view name);

/// The damper's response at one grid point (docs/theory.md §1). NaN marks "not given".
struct FieldPoint {
  static constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
  double eta_star = kUnknown;                ///< reduced loss factor η* = E_diss/E_kin, dimensionless
  double eta_star_stderr = kUnknown;         ///< standard error of η* (0 for closed forms; NaN unknown)
  double e_diss_j = kUnknown;                ///< E_diss = Re(P)/Ω = η*·½ m_bed (XΩ)², J
  double apparent_mass_kg = kUnknown;        ///< m_app = Im(F* conj V*)/(Ω|V*|²), kg; NaN not given
  double apparent_mass_fraction = kUnknown;  ///< m_app/m_bed, dimensionless; NaN not given
  std::string motion_mode;                   ///< motion-mode or regime label, free text ("" if none)
  PointStatus status = PointStatus::kMissing;
  bool operator==(const FieldPoint& other) const;  ///< NaN equals NaN here (same "not given")
  /// The value columns of a field file, a sweep's log line and a job's result.
  static const base::Fields<FieldPoint>& fields();
};

/// Who made a field, from what, when.
struct Provenance {
  FieldSource source = FieldSource::kFormulas;
  std::string case_hash;      ///< hash of the case the field was made for (case_hash()); any text
  int model_version = 0;      ///< physics-model version of the source, set by the caller, >= 0
  std::string pdamp_version;  ///< pdamp release that wrote the field ("0.1.0")
  std::string created_utc;    ///< creation time, UTC ISO 8601 "YYYY-MM-DDThh:mm:ssZ"
  /// How the DEM points were reached: 0 (default, the key absent from the file) every point
  /// from rest, the ascending branch; X_a > 0 every point below X_a approached from X_a, the
  /// descending branch a decay follows (docs/dem.md, "Approach").
  double approach_amplitude_m = 0.0;
  bool operator==(const Provenance&) const = default;
};

/// Provenance stamped now with this build's pdamp version.
Provenance make_provenance(FieldSource source, std::string case_hash, int model_version);
/// The current UTC time as "YYYY-MM-DDThh:mm:ssZ".
std::string utc_timestamp_now();
/// The pdamp version this library was built as ("0.1.0").
std::string_view pdamp_version();
/// 16 hex digits of the 64-bit FNV-1a hash of case_json.dump() (object keys sorted, so the
/// hash depends on content, not on key order or whitespace). The caller chooses what
/// goes in: drop names and descriptions that do not change the physics.
std::string case_hash(const nlohmann::json& case_json);

/// Physical ranges of a field point's values, checked by every reader (field files, sweep
/// logs and shards, merges) and by EffectiveField::validate. η*: a passive bed averages
/// η* >= 0, a measured point scatters about 0 by its standard error (the shipped DEM fields
/// reach −0.006), so −1; above, no collect-and-collide orbit or DEM bed comes near 100 (the
/// ideal peaks are about 1-1.4). m_app/m_bed: the ideal orbits give −0.58 to 1, the DEM
/// 0.19-1.6, so ±10.
inline constexpr double kMinEtaStar = -1.0, kMaxEtaStar = 100.0;
inline constexpr double kMaxApparentMassFraction = 10.0;
/// "" when η* (NaN: not given) and m_app/m_bed (NaN: not given) are in their ranges, else the rule
/// broken ("eta_star = 1e+300: must be in [-1, 100]").
std::string field_value_problem(double eta_star, double apparent_mass_fraction);

/// η*, E_diss, apparent mass and motion mode over a grid, with provenance.
struct EffectiveField {
  Grid grid;
  std::vector<FieldPoint> points;  ///< one per grid node, in grid storage order (Grid::index)
  Provenance provenance;
  double clearance_m = 0.0;  ///< clearance h of the damper the field belongs to, m, > 0
  double bed_mass_kg = 0.0;  ///< mass of all particles m_bed, kg, > 0
  /// Shape and value rules (grid valid, one point per node, ok points with finite η* and
  /// E_diss, stderr >= 0, clearance and bed mass > 0); one line each, empty if valid.
  std::vector<std::string> validate() const;
  bool operator==(const EffectiveField&) const = default;
};

/// The field as a JSON document (format "pdamp.effective_field", version 1); NaN is
/// written as null. Throws std::invalid_argument if the field does not validate().
nlohmann::json to_json(const EffectiveField& field);
/// Reads and strictly validates a field document. Any violation throws
/// std::invalid_argument("<file_name>: <JSON pointer>: <rule>") for the first problem:
/// unknown or missing keys, wrong types, wrong units, axes missing or not strictly
/// increasing, non-finite numbers, null where a value is required, table shape or
/// coordinates not matching the axes.
EffectiveField effective_field_from_json(const nlohmann::json& document, const std::string& file_name);
/// Reads a field file through base::read_input_file and parse_json_document:
/// std::invalid_argument "<path>: <reason>" for a missing file, a directory, a FIFO
/// (refused at once, never read), a device or a file above 256 MiB, "<path>: malformed
/// JSON: ..." or "<path>: <pointer>: duplicate key", and every rule of
/// effective_field_from_json (which also refuses more than kMaxGridNodes nodes at /axes
/// and a motion_mode holding control characters).
EffectiveField read_effective_field(const std::filesystem::path& path);
/// Writes the field atomically: a temporary file in the same folder, fsync, then rename
/// over `path`, so readers see the old file or the new one, never a partial one.
/// std::invalid_argument for an invalid field, std::runtime_error for I/O failures.
void write_effective_field(const EffectiveField& field, const std::filesystem::path& path);

}  // namespace pdamp::surrogate
