// The reference DEM as a point evaluator of effective-field sweeps.
#pragma once

#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/surrogate/sweep.hpp"

namespace pdamp::surrogate {

/// Evaluator that runs dem_reference::run_harmonic at each (f, X) with `base`'s other
/// options: η*, its standard error, E_diss, apparent mass and the motion-mode label. With
/// base.approach_amplitude_m > 0 (the descending branch), a point below that stroke is
/// approached from it and a point at or above it starts from rest.
/// An unstable or failed run is recorded as a failed point with the reason (the sweep
/// goes on); invalid options throw std::invalid_argument at the first point.
PointEvaluator dem_evaluator(const dem_reference::DamperSimulationOptions& base);

/// Physics-model version of dem_evaluator's points (hashed into the results file).
int dem_model_version();

}  // namespace pdamp::surrogate
