// LossModel backed by an effective field (interpolated η* and apparent-mass fraction).
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

}  // namespace

EffectiveFieldLossModel::EffectiveFieldLossModel(const EffectiveField& field, const LookupOptions& options)
    : eta_star_(field, FieldColumn::kEtaStar, options) {
  if (given_at_every_ok_point(field)) {
    apparent_mass_fraction_.emplace(field, FieldColumn::kApparentMassFraction, options);
  }
  motion_modes_.reserve(field.points.size());
  for (const auto& p : field.points) motion_modes_.push_back(p.motion_mode);
}

DamperResponse EffectiveFieldLossModel::evaluate(double frequency_hz, double stroke_m) const {
  DamperResponse response;
  response.eta_star = eta_star_.evaluate(frequency_hz, stroke_m).value;
  response.apparent_mass_fraction = apparent_mass_fraction_
                                        ? apparent_mass_fraction_->evaluate(frequency_hz, stroke_m).value
                                        : std::numeric_limits<double>::quiet_NaN();
  response.regime = motion_modes_[eta_star_.nearest_point(frequency_hz, stroke_m)];
  return response;
}

}  // namespace pdamp::surrogate
