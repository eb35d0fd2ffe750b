// Closed-form implementation of the LossModel lookup interface.
#include "pdamp/surrogate/loss_model.hpp"

#include <limits>
#include <string>
#include <utility>

namespace pdamp::surrogate {

ClosedFormLossModel::ClosedFormLossModel(formulas::DamperModel model, double clearance_m,
                                         formulas::ModelOptions options)
    : model_(model), clearance_m_(clearance_m), options_(std::move(options)) {}

DamperResponse ClosedFormLossModel::evaluate(double frequency_hz, double stroke_m) const {
  const auto loss = formulas::reduced_loss_factor(model_, clearance_m_, stroke_m, frequency_hz, options_);
  // The closed forms describe dissipation only; the bed's inertia is not modelled.
  return {loss.eta_star, std::numeric_limits<double>::quiet_NaN(), std::string(formulas::to_string(loss.regime))};
}

}  // namespace pdamp::surrogate
