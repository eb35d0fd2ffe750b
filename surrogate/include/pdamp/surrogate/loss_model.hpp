// The damper's characteristic as seen by structures and optimisers: one small
// lookup interface that both the closed forms and the effective fields satisfy.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/field_lookup.hpp"

namespace pdamp::surrogate {

/// The damper's response at one operating point (PHYSICS.md §1).
struct DamperResponse {
  double eta_star = 0.0;                ///< reduced loss factor η*, dimensionless
  double apparent_mass_fraction = 1.0;  ///< m_app/m_bed; NaN where the source does not give it
  std::string regime;                   ///< motion regime or mode label
};

/// η* and friends as a function of drive frequency (Hz) and stroke (m).
class LossModel {
 public:
  virtual ~LossModel() = default;
  virtual DamperResponse evaluate(double frequency_hz, double stroke_m) const = 0;
};

/// LossModel from the closed forms of formulas/ for one clearance.
class ClosedFormLossModel final : public LossModel {
 public:
  ClosedFormLossModel(formulas::DamperModel model, double clearance_m, formulas::ModelOptions options = {});
  DamperResponse evaluate(double frequency_hz, double stroke_m) const override;

 private:
  formulas::DamperModel model_;
  double clearance_m_;
  formulas::ModelOptions options_;
};

/// LossModel from an effective field (DEM, formulas or measured): η* and the apparent-mass
/// fraction interpolated bilinearly (FieldLookup), the regime label of the nearest node.
/// Lookups near missing points and, with kError, outside the grid throw
/// std::invalid_argument. The LossModel interface has no warning channel: callers that
/// must report clamped or rescaled lookups call lookup().evaluate() for the warning bits.
class EffectiveFieldLossModel final : public LossModel {
 public:
  /// Throws std::invalid_argument if the field or the options do not validate.
  explicit EffectiveFieldLossModel(const EffectiveField& field, const LookupOptions& options = {});
  /// η* at (f, X); apparent_mass_fraction NaN when the field does not give it at every ok point.
  DamperResponse evaluate(double frequency_hz, double stroke_m) const override;
  /// η* lookup with derivatives and warning bits, for optimisers.
  const FieldLookup& lookup() const { return eta_star_; }

 private:
  FieldLookup eta_star_;
  std::optional<FieldLookup> apparent_mass_fraction_;  ///< absent when the field does not give it
  std::vector<std::string> motion_modes_;              ///< per grid node, storage order
};

}  // namespace pdamp::surrogate
