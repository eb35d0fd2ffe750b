// A bed's characteristic along a free decay: the first-harmonic response of each period of a
// DEM-in-the-loop decay, gathered into an effective field over the strokes the decay passed
// through (docs/optimizer.md, "Calibrated beds"). Unlike a field of steady states, it holds the state
// the bed is in when the amplitude comes down at the rate a decay brings it down: below the
// collect-and-collide onset a bed coming down from collect-and-collide rolls without impacts
// (m_app/m_bed near κ/(1+κ), η* near 0), where a bed driven at constant amplitude from rest
// keeps hitting the walls.
#pragma once

#include <span>
#include <vector>

#include "pdamp/surrogate/effective_field.hpp"

namespace pdamp::surrogate {

/// The bed's first-harmonic response over one period of a decay (docs/theory.md §1: with the
/// force the container applies to the bed F̂ and the container velocity V̂ at Ω,
/// η* = Re(F̂ conj V̂)/(Ω m_bed |V̂|²) and m_app/m_bed = Im(F̂ conj V̂)/(Ω m_bed |V̂|²)).
struct DecayPeriodResponse {
  double time_s = 0.0;                  ///< the period's middle, s
  double frequency_hz = 0.0;            ///< 1/(the period's duration), Hz
  double stroke_m = 0.0;                ///< |X̂|, the container's displacement amplitude, m
  double eta_star = 0.0;                ///< η* of the period, dimensionless
  double apparent_mass_fraction = 0.0;  ///< m_app/m_bed of the period, dimensionless
};

/// Stroke bins per decade of decay_field (1.33 times from one node to the next: the decay of
/// the shipped link passes each bin in 5-20 periods, so a bin averages over the period-to-
/// period scatter of the bed's state).
inline constexpr int kDecayFieldBinsPerDecade = 8;

/// The field of a bed from the periods of its decay: nodes log-spaced at the centres of
/// `bins_per_decade` bins per decade of stroke, each the mean of the periods whose stroke
/// falls in its bin (η*, its standard error, m_app/m_bed), a bin no period fell into
/// interpolated between its neighbours (motion_mode "decay_interpolated"); two frequency
/// nodes, 0.8 and 1.25 times the periods' mean frequency, with the same values (the decay
/// runs at one frequency: the field does not say how the bed answers at another, and a
/// lookup there is clamped to these values). The first period (the release) is left out.
/// std::invalid_argument with fewer than two periods after it, a non-finite value, or a
/// field that does not validate.
EffectiveField decay_field(std::span<const DecayPeriodResponse> periods, double clearance_m, double bed_mass_kg,
                           const Provenance& provenance, int bins_per_decade = kDecayFieldBinsPerDecade);

}  // namespace pdamp::surrogate
