// Import of measured effective fields (test-rig data) from CSV onto a grid.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/surrogate/effective_field.hpp"

namespace pdamp::surrogate {

/// What the CSV does not say about the measured damper.
struct MeasuredImportOptions {
  double clearance_m = 0.0;                              ///< clearance h of the measured damper, m, > 0
  double bed_mass_kg = 0.0;                              ///< m_bed of the measured damper, kg, > 0
  AxisSpacing frequency_spacing = AxisSpacing::kLinear;  ///< interpolation coordinate along f
  AxisSpacing amplitude_spacing = AxisSpacing::kLinear;  ///< interpolation coordinate along X
  std::string case_hash;                                 ///< case_hash() of the matching case, or "" if none
  int model_version = 0;                                 ///< version of the measurement procedure, >= 0
  /// One line per violated rule ("bed_mass_kg = 0: must be > 0 and finite"); empty if valid.
  std::vector<std::string> validate() const;
};

/// Measured field from CSV text (docs/effective_fields.md, "Measured fields"):
/// - lines starting with '#' and blank lines are ignored; the first other line is the
///   header; cells are separated by commas, spaces around them are ignored, no quoting;
///   a leading UTF-8 byte-order mark is skipped; a NUL byte (a binary file) is refused;
/// - columns (any order, each at most once): frequency_hz (Hz, > 0), amplitude_m (m, > 0),
///   eta_star (1, >= 0) required; eta_star_stderr (1, >= 0), apparent_mass_kg (kg, >= 0),
///   motion_mode (printable text without commas) optional, an empty cell meaning "not given";
///   every number finite;
/// - η* >= 0 because a passive damper only dissipates (E_diss = Re(P)/Ω >= 0,
///   docs/complex_power.md); it has no upper bound: 4/π is the peak of the free plastic
///   bed's ideal orbit, but an elastic bed can resonate above it;
/// - m_app >= 0: a particle bed far below its contact frequencies reacts as a mass
///   between about 0 (detached) and m_bed (locked); a negative value is a rig sign error;
/// - the rows must form a full grid: every distinct frequency with every distinct
///   amplitude exactly once, in any order.
/// E_diss = η*·½ m_bed (2πfX)² and m_app/m_bed are derived; every point is status ok,
/// source "measured". Any violation throws std::invalid_argument
/// "<file_name>: line N[, column C]: <rule>" (quoted cells escaped to one printable line).
EffectiveField measured_field_from_csv(std::string_view text, const std::string& file_name,
                                       const MeasuredImportOptions& options);
/// The same, reading the file at `path` through base::read_input_file:
/// std::invalid_argument "<path>: <reason>" for a missing file, a directory, a FIFO
/// (refused at once, never read), a device or a file above 256 MiB.
EffectiveField import_measured_csv(const std::filesystem::path& path, const MeasuredImportOptions& options);

}  // namespace pdamp::surrogate
