// LossModel backed by an effective field (interpolated η* and apparent-mass fraction).
#include <algorithm>
#include <cmath>
#include <limits>

#include "pdamp/surrogate/loss_model.hpp"  // declares EffectiveFieldLossModel next to ClosedFormLossModel

namespace pdamp::surrogate {

namespace {

/// True if every ok point gives the column (then it can be interpolated everywhere η* can).
bool given_at_every_ok_point(const EffectiveField& field) {
  for (const auto& p : field.points) {
    if (p.status == PointStatus::kOk && !std::isfinite(p.apparent_mass_fraction)) return false;
  }
  return true;
}

std::uint32_t loss_warnings_of(std::uint8_t lookup_warnings) {
  std::uint32_t bits = 0;
  if (lookup_warnings & (kClampedAxis0 | kClampedAxis1)) bits |= kLossOutsideFieldGrid;
  if (lookup_warnings & kRescaledClearance) bits |= kLossRescaledClearance;
  return bits;
}

/// The field's stroke axis in metres of the damper looked up (clearance h): (f, X) fields
/// map X = X_F·h/h_F (equal X/h), (Γ, X/h) fields X = s·h.
StrokeRange stroke_axis_m(const EffectiveField& field, const LookupOptions& options) {
  const auto& nodes = field.grid.axis1.values;
  const double clearance_m = options.clearance_m > 0.0 ? options.clearance_m : field.clearance_m;
  const double scale = field.grid.axes() == GridAxes::kFrequencyAmplitude ? clearance_m / field.clearance_m
                                                                          : clearance_m;
  return {nodes.front() * scale, nodes.back() * scale};
}

}  // namespace

EffectiveFieldLossModel::EffectiveFieldLossModel(const EffectiveField& field, const LookupOptions& options)
    : eta_star_(field, FieldColumn::kEtaStar, options), strokes_m_(stroke_axis_m(field, options)) {
  if (given_at_every_ok_point(field)) {
    apparent_mass_fraction_.emplace(field, FieldColumn::kApparentMassFraction, options);
  }
  motion_modes_.reserve(field.points.size());
  for (const auto& p : field.points) motion_modes_.push_back(p.motion_mode);
}

DamperResponse EffectiveFieldLossModel::evaluate(double frequency_hz, double stroke_m) const {
  DamperResponse response;
  const LookupResult eta = eta_star_.evaluate(frequency_hz, stroke_m);
  response.eta_star = eta.value;
  response.d_eta_star_d_stroke_1_m = eta.d_value_d_amplitude;
  response.warnings = loss_warnings_of(eta.warnings);
  if (apparent_mass_fraction_) {
    const LookupResult mass = apparent_mass_fraction_->evaluate(frequency_hz, stroke_m);
    response.apparent_mass_fraction = mass.value;
    response.d_apparent_mass_fraction_d_stroke_1_m = mass.d_value_d_amplitude;
  } else {
    response.apparent_mass_fraction = std::numeric_limits<double>::quiet_NaN();
    response.d_apparent_mass_fraction_d_stroke_1_m = std::numeric_limits<double>::quiet_NaN();
    response.warnings |= kLossApparentMassMissing;
  }
  response.regime = motion_modes_[eta_star_.nearest_point(frequency_hz, stroke_m)];
  return response;
}

StrokeRange EffectiveFieldLossModel::stroke_range_m(double /*frequency_hz*/) const { return strokes_m_; }

std::vector<std::string> EffectiveFieldLossModel::warning_messages(double frequency_hz, double stroke_m) const {
  const LookupResult eta = eta_star_.evaluate(frequency_hz, stroke_m);
  std::vector<std::string> sentences = eta_star_.describe(eta.warnings);
  if (!apparent_mass_fraction_) sentences.emplace_back("the effective field gives no apparent mass");
  return sentences;
}

}  // namespace pdamp::surrogate
