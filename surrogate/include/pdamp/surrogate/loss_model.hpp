// The damper's characteristic as seen by structures and optimisers: one small
// lookup interface that both the closed forms and the effective fields satisfy.
#pragma once

#include <string>

#include "pdamp/formulas/collect_and_collide.hpp"

namespace pdamp::surrogate {

/// The damper's response at one operating point (PHYSICS.md §1).
struct DamperResponse {
  double eta_star = 0.0;          ///< reduced loss factor η*, dimensionless
  double apparent_mass_fraction = 1.0;  ///< m_app/m_bed; NaN where the source does not give it
  std::string regime;             ///< motion regime or mode label
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
  ClosedFormLossModel(formulas::DamperModel model, double clearance_m,
                      formulas::ModelOptions options = {});
  DamperResponse evaluate(double frequency_hz, double stroke_m) const override;

 private:
  formulas::DamperModel model_;
  double clearance_m_;
  formulas::ModelOptions options_;
};

}  // namespace pdamp::surrogate
