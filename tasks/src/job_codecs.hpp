// The JSON forms of the results that tasks hand between processes (executor.hpp): exact
// (doubles through CBOR) and read back only by the same build.
#pragma once

#include <nlohmann/json.hpp>

#include "pdamp/structure/dem_frequency_response.hpp"
#include "pdamp/surrogate/effective_field.hpp"

namespace pdamp::surrogate {

inline void to_json(nlohmann::json& j, const FieldPoint& p) {
  j = nlohmann::json::array({p.eta_star, p.eta_star_stderr, p.e_diss_j, p.apparent_mass_kg, p.apparent_mass_fraction,
                             p.motion_mode, static_cast<int>(p.status)});
}
inline void from_json(const nlohmann::json& j, FieldPoint& p) {
  j.at(0).get_to(p.eta_star);
  j.at(1).get_to(p.eta_star_stderr);
  j.at(2).get_to(p.e_diss_j);
  j.at(3).get_to(p.apparent_mass_kg);
  j.at(4).get_to(p.apparent_mass_fraction);
  j.at(5).get_to(p.motion_mode);
  p.status = static_cast<PointStatus>(j.at(6).get<int>());
}

}  // namespace pdamp::surrogate

namespace pdamp::structure {

inline void to_json(nlohmann::json& j, const SteppedSinePoint& p) {
  j = nlohmann::json::array({p.sweep, p.frequency_hz, p.requested_frequency_hz, p.magnitude, p.phase_deg, p.bed_eta_star,
                             p.bed_apparent_mass_fraction, p.spread, p.standard_error, p.energy_error,
                             p.transient_periods, p.stable, p.steps, p.time_step_s, p.wall_time_s, p.warnings,
                             p.analysed_periods, p.converged, p.window_periods, p.window_max_relative_change,
                             p.window_relative_drift, p.window_relative_spread, p.period_magnitudes});
}
inline void from_json(const nlohmann::json& j, SteppedSinePoint& p) {
  j.at(0).get_to(p.sweep);
  j.at(1).get_to(p.frequency_hz);
  j.at(2).get_to(p.requested_frequency_hz);
  j.at(3).get_to(p.magnitude);
  j.at(4).get_to(p.phase_deg);
  j.at(5).get_to(p.bed_eta_star);
  j.at(6).get_to(p.bed_apparent_mass_fraction);
  j.at(7).get_to(p.spread);
  j.at(8).get_to(p.standard_error);
  j.at(9).get_to(p.energy_error);
  j.at(10).get_to(p.transient_periods);
  j.at(11).get_to(p.stable);
  j.at(12).get_to(p.steps);
  j.at(13).get_to(p.time_step_s);
  j.at(14).get_to(p.wall_time_s);
  j.at(15).get_to(p.warnings);
  j.at(16).get_to(p.analysed_periods);
  j.at(17).get_to(p.converged);
  j.at(18).get_to(p.window_periods);
  j.at(19).get_to(p.window_max_relative_change);
  j.at(20).get_to(p.window_relative_drift);
  j.at(21).get_to(p.window_relative_spread);
  j.at(22).get_to(p.period_magnitudes);
}
inline void to_json(nlohmann::json& j, const SteppedSineBranch& b) {
  j = nlohmann::json::array({b.sweep, b.points, b.wall_time_s, static_cast<int>(b.outcome), b.message});
}
inline void from_json(const nlohmann::json& j, SteppedSineBranch& b) {
  j.at(0).get_to(b.sweep);
  j.at(1).get_to(b.points);
  j.at(2).get_to(b.wall_time_s);
  b.outcome = static_cast<dem_reference::Outcome>(j.at(3).get<int>());
  j.at(4).get_to(b.message);
}

}  // namespace pdamp::structure
