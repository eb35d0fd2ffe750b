// Lookup of an effective field by drive frequency and stroke, with normalised rescaling.
#include "pdamp/surrogate/field_lookup.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"

#include <cmath>
#include <stdexcept>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "text_util.hpp"

namespace pdamp::surrogate {

using base::format_number;
using base::positive_finite;

namespace {

/// Clearances closer than this (relative) are the same damper: no rescaling warning.
constexpr double kSameClearance = 1e-12;

double column_of(const FieldPoint& p, FieldColumn column) {
  if (p.status != PointStatus::kOk) return FieldPoint::kUnknown;
  switch (column) {
    case FieldColumn::kEtaStar: return p.eta_star;
    case FieldColumn::kEtaStarStderr: return p.eta_star_stderr;
    case FieldColumn::kEDiss: return p.e_diss_j;
    case FieldColumn::kApparentMass: return p.apparent_mass_kg;
    case FieldColumn::kApparentMassFraction: return p.apparent_mass_fraction;
  }
  return FieldPoint::kUnknown;
}

std::string axis_range_text(const Axis& axis) {
  return std::string(to_string(axis.quantity)) + " range [" + format_number(axis.values.front(), 12) + ", " +
         format_number(axis.values.back(), 12) + "]";
}

/// The field's grid once field and options are known to be valid (std::invalid_argument otherwise).
const Grid& validated_grid(const EffectiveField& field, const LookupOptions& options) {
  detail::throw_if_any(field.validate(), "effective field");
  detail::throw_if_any(options.validate(), "lookup options");
  return field.grid;
}

}  // namespace

std::vector<double> column_values(const EffectiveField& field, FieldColumn column) {
  std::vector<double> values;
  values.reserve(field.points.size());
  for (const auto& p : field.points) values.push_back(column_of(p, column));
  return values;
}

std::vector<std::string> LookupOptions::validate() const {
  std::vector<std::string> problems;
  if (!(clearance_m >= 0.0 && std::isfinite(clearance_m))) {
    problems.push_back("clearance_m = " + format_number(clearance_m, 12) +
                       ": must be >= 0 and finite (0 = the field's own)");
  }
  return problems;
}

FieldLookup::FieldLookup(const EffectiveField& field, FieldColumn column, const LookupOptions& options)
    : interpolator_(validated_grid(field, options), column_values(field, column), options.out_of_range),
      column_(column),
      axes_(field.grid.axes()),
      field_clearance_m_(field.clearance_m),
      clearance_m_(options.clearance_m > 0.0 ? options.clearance_m : field.clearance_m) {
  status_.reserve(field.points.size());
  for (const auto& p : field.points) status_.push_back(p.status);
  // (f, X) fields reused for another clearance: the point of equal Γ and X/h at h_F.
  const double ratio = field_clearance_m_ / clearance_m_;  // h_F/h
  frequency_scale_ = 1.0 / std::sqrt(ratio);
  amplitude_scale_ = ratio;
  const bool rescaled = std::abs(ratio - 1.0) > kSameClearance;
  base_warnings_ = rescaled ? kRescaledClearance : 0;
  if (!rescaled) {
    frequency_scale_ = 1.0;
    amplitude_scale_ = 1.0;
  }
}

FieldLookup::Mapped FieldLookup::map(double frequency_hz, double amplitude_m) const {
  if (axes_ == GridAxes::kFrequencyAmplitude) {
    return {frequency_hz * frequency_scale_, amplitude_m * amplitude_scale_, frequency_scale_, 0.0, amplitude_scale_};
  }
  const double omega = 2.0 * formulas::kPi * frequency_hz;
  const double gamma_per_stroke = omega * omega / formulas::kStandardGravity;  // Γ/X = Ω²/g
  const double intensity = amplitude_m * gamma_per_stroke;
  return {intensity, amplitude_m / clearance_m_, 2.0 * intensity / frequency_hz, gamma_per_stroke, 1.0 / clearance_m_};
}

LookupResult FieldLookup::evaluate(double frequency_hz, double amplitude_m) const {
  if (!positive_finite(frequency_hz) || !positive_finite(amplitude_m)) [[unlikely]] {
    throw std::invalid_argument("field lookup at frequency_hz = " + format_number(frequency_hz, 12) +
                                ", amplitude_m = " + format_number(amplitude_m, 12) + ": both must be > 0 and finite");
  }
  const Mapped m = map(frequency_hz, amplitude_m);
  BilinearInterpolator::Result r;
  try {
    r = interpolator_.evaluate(m.x0, m.x1);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("field lookup at frequency_hz = " + format_number(frequency_hz, 12) +
                                ", amplitude_m = " + format_number(amplitude_m, 12) + ": " + e.what());
  }
  if (std::isnan(r.value)) [[unlikely]] {
    missing_point(frequency_hz, amplitude_m);
  }
  LookupResult out;
  out.value = r.value;
  out.d_value_d_frequency = r.d_dx0 * m.dx0_df;
  out.d_value_d_amplitude = r.d_dx0 * m.dx0_dX + r.d_dx1 * m.dx1_dX;
  out.warnings =
      static_cast<std::uint8_t>(base_warnings_ | (r.clamped0 ? kClampedAxis0 : 0) | (r.clamped1 ? kClampedAxis1 : 0));
  return out;
}

std::size_t FieldLookup::nearest_point(double frequency_hz, double amplitude_m) const {
  const Mapped m = map(frequency_hz, amplitude_m);
  return interpolator_.nearest_node(m.x0, m.x1);
}

void FieldLookup::missing_point(double frequency_hz, double amplitude_m) const {
  const Grid& grid = interpolator_.grid();
  const std::size_t k = nearest_point(frequency_hz, amplitude_m);
  const bool no_value_in_column = column_ != FieldColumn::kEtaStar && status_[k] == PointStatus::kOk;
  throw std::invalid_argument(
      "field lookup at frequency_hz = " + format_number(frequency_hz, 12) +
      ", amplitude_m = " + format_number(amplitude_m, 12) +
      ": the grid cell around this point holds a point without a value (nearest node " +
      std::string(to_string(grid.axis0.quantity)) + " = " + format_number(grid.coordinate0(k), 12) + ", " +
      std::string(to_string(grid.axis1.quantity)) + " = " + format_number(grid.coordinate1(k), 12) + ", status " +
      std::string(to_string(status_[k])) + (no_value_in_column ? ", column not given by the field's source" : "") +
      "); the field cannot answer here: compute the missing points or stay away from them");
}

std::vector<std::string> FieldLookup::describe(std::uint8_t warnings) const {
  std::vector<std::string> lines;
  const Grid& grid = interpolator_.grid();
  for (const auto& [bit, axis] : {std::pair{kClampedAxis0, &grid.axis0}, std::pair{kClampedAxis1, &grid.axis1}}) {
    if ((warnings & bit) != 0) {
      lines.push_back("outside the field's " + axis_range_text(*axis) +
                      ": the value at the nearest edge was used (out-of-range policy \"clamp\")");
    }
  }
  if ((warnings & kRescaledClearance) != 0) {
    lines.push_back("field made for clearance " + format_number(field_clearance_m_, 12) + " m used for clearance " +
                    format_number(clearance_m_, 12) +
                    " m at equal intensity and stroke/clearance: valid only where eta* depends on those two "
                    "alone (docs/effective_fields.md, normalised lookup)");
  }
  return lines;
}

}  // namespace pdamp::surrogate
