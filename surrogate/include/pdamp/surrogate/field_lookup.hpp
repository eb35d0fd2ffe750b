// Physical lookup in an effective field: (frequency, stroke) in, η* (or another column)
// with derivatives out, for either grid kind and optionally another clearance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/interpolator.hpp"

namespace pdamp::surrogate {

/// The numeric column a FieldLookup interpolates.
enum class FieldColumn { kEtaStar, kEtaStarStderr, kEDiss, kApparentMass, kApparentMassFraction };
/// That column of every point in storage order (NaN where the point is not ok or gives no value).
std::vector<double> column_values(const EffectiveField& field, FieldColumn column);

/// How a FieldLookup treats the edges and which damper it serves.
struct LookupOptions {
  /// Outside the grid: kClamp (default: edge value, derivative 0, warning bit) or kError.
  OutOfRangePolicy out_of_range = OutOfRangePolicy::kClamp;
  /// Clearance h of the damper looked up, m: 0 = the field's own clearance; another
  /// value > 0 reuses the field at equal Γ and X/h (normalised lookup, warning bit
  /// kRescaledClearance; docs/effective_fields.md says when that is physically allowed).
  double clearance_m = 0.0;
  /// One line per violated rule ("clearance_m = -1: must be >= 0 and finite"); empty if valid.
  std::vector<std::string> validate() const;
};

/// Warning bits of a LookupResult.
enum LookupWarning : std::uint8_t {
  kClampedAxis0 = 1,       ///< outside the field's axis 0 (frequency or Γ): edge value used
  kClampedAxis1 = 2,       ///< outside the field's axis 1 (stroke or X/h): edge value used
  kRescaledClearance = 4,  ///< field made for another clearance, reused at equal Γ and X/h
};

struct LookupResult {
  double value = 0.0;                ///< the column at (f, X): η* by default
  double d_value_d_frequency = 0.0;  ///< ∂value/∂f, per Hz (0 along a clamped direction)
  double d_value_d_amplitude = 0.0;  ///< ∂value/∂X, per m
  std::uint8_t warnings = 0;         ///< LookupWarning bits; 0 = inside the grid at its own clearance
};

/// Bilinear lookup of one column in the field's own axes, driven by frequency and stroke.
///
/// Mapping of a query (f, X) for clearance h onto the field's axes (field clearance h_F):
/// - (Γ, X/h) field: Γ = X(2πf)²/g, s = X/h. With h ≠ h_F this is the normalised lookup.
/// - (f, X) field: with h = h_F directly; otherwise through the point of equal Γ and X/h
///   at h_F: X_F = X·h_F/h, f_F = f·√(h/h_F).
/// Derivatives follow by the chain rule (∂Γ/∂f = 2Γ/f, ∂Γ/∂X = Γ/X, ∂s/∂X = 1/h).
///
/// A lookup in a grid cell that touches a missing or failed point (NaN) throws
/// std::invalid_argument naming the point; so does kError outside the grid, and a
/// frequency or stroke that is not > 0 and finite. Thread-safe for concurrent lookups;
/// no allocation on the non-throwing path.
class FieldLookup {
 public:
  /// Throws std::invalid_argument if the field or the options do not validate.
  explicit FieldLookup(const EffectiveField& field, FieldColumn column = FieldColumn::kEtaStar,
                       const LookupOptions& options = {});

  LookupResult evaluate(double frequency_hz, double amplitude_m) const;
  /// Storage index of the grid node nearest to the mapped query (for labels such as motion_mode).
  std::size_t nearest_point(double frequency_hz, double amplitude_m) const;
  /// One sentence per warning bit, naming the field's ranges and clearances.
  std::vector<std::string> describe(std::uint8_t warnings) const;

  double clearance_m() const { return clearance_m_; }  ///< clearance looked up, m
  const BilinearInterpolator& interpolator() const { return interpolator_; }

 private:
  struct Mapped {
    double x0, x1;                  ///< query in the field's axis units
    double dx0_df, dx0_dX, dx1_dX;  ///< chain-rule factors (∂x1/∂f is 0 for both grid kinds)
  };
  Mapped map(double frequency_hz, double amplitude_m) const;
  [[noreturn]] void missing_point(double frequency_hz, double amplitude_m) const;

  BilinearInterpolator interpolator_;
  std::vector<PointStatus> status_;
  FieldColumn column_;
  GridAxes axes_;
  double field_clearance_m_;
  double clearance_m_;
  double frequency_scale_;  ///< (f, X) fields: f_F = f·frequency_scale_
  double amplitude_scale_;  ///< (f, X) fields: X_F = X·amplitude_scale_
  std::uint8_t base_warnings_;
};

}  // namespace pdamp::surrogate
