// Effective-field points from the reference DEM.
#include "pdamp/surrogate/dem_evaluator.hpp"

#include "pdamp/dem_reference/world.hpp"

namespace pdamp::surrogate {

PointEvaluator dem_evaluator(const dem_reference::DamperSimulationOptions& base) {
  return [base](double frequency_hz, double amplitude_m) {
    auto options = base;
    options.frequency_hz = frequency_hz;
    options.amplitude_m = amplitude_m;
    // Approached from above only below the approach stroke; at and above it from rest.
    if (amplitude_m >= options.approach_amplitude_m) options.approach_amplitude_m = 0.0;
    const auto result = dem_reference::run_harmonic(options);
    FieldPoint point;
    if (result.summary.outcome != dem_reference::Outcome::kCompleted) {
      point.status = PointStatus::kFailed;
      point.motion_mode = std::string(dem_reference::to_string(result.summary.outcome)) + ": " + result.summary.message;
      return point;
    }
    point.status = PointStatus::kOk;
    point.eta_star = result.eta_star;
    point.eta_star_stderr = result.eta_star_stderr;
    point.e_diss_j = result.e_diss_j;
    point.apparent_mass_kg = result.apparent_mass_kg;
    point.apparent_mass_fraction = result.apparent_mass_kg / result.bed_mass_kg;
    point.motion_mode = std::string(dem_reference::to_string(result.motion_mode));
    return point;
  };
}

int dem_model_version() { return dem_reference::kPhysicsModelVersion; }

}  // namespace pdamp::surrogate
