// Physically meaningful ranges of the quantities a user gives (case keys and the CLI's
// flags),
// in SI units. They exist to refuse nonsense (a 1e308 Hz drive, a 1e-300 m sphere,
// a 1e200 m/s impact) with a message naming the key, before a closed form overflows
// or a DEM run is planned for 1e10 s; they are wide enough for every real particle
// damper (docs/bad_inputs.md lists them). Ranges a module's options own (the DEM's in
// dem_reference::limits, formulas::ModelOptions::validate(),
// structure::BeamModel::validate()) are taken from there, not restated here.
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::case_file {

/// Allowed interval of a number, with its text for messages.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  bool contains(double v) const { return std::isfinite(v) && (min_exclusive ? v > min : v >= min) && v <= max; }
  std::string text() const {
    std::ostringstream out;
    out << "must be a finite number";
    if (std::isfinite(min)) out << (min_exclusive ? " > " : " >= ") << min;
    if (std::isfinite(max)) out << (std::isfinite(min) ? " and" : "") << " <= " << max;
    return out.str();
  }
};

namespace limits {
/// Particle radius: the DEM's [10 µm, 1 m] (below, adhesion dominates contacts).
inline constexpr Range kParticleRadius{dem_reference::limits::kMinRadius_m, dem_reference::limits::kMaxRadius_m};
/// Container dimensions: 10 µm to 100 m.
inline constexpr Range kContainerSize{1e-5, 100.0};
/// Positions inside a container (body frame), m.
inline constexpr Range kPosition{-100.0, 100.0};
/// Clearance (free travel of the bed): 1 µm to 100 m.
inline constexpr Range kClearance{1e-6, 100.0};
/// Container stroke X: 0.1 µm to the DEM's 10 m.
inline constexpr Range kStroke{1e-7, dem_reference::limits::kMaxAmplitude_m};
/// Drive frequency: the DEM's [0.01 Hz, 10 kHz] (above, the container is no rigid body).
inline constexpr Range kFrequency{dem_reference::limits::kMinFrequency_hz, dem_reference::limits::kMaxFrequency_hz};
/// Intensity Γ = X Ω²/g.
inline constexpr Range kIntensity{1e-4, 1e5};
/// Density: 1 kg/m³ (foams) to 1e5 kg/m³ (above osmium's 22,590).
inline constexpr Range kDensity{1.0, 1e5};
/// Young's modulus: 1 kPa (gels) to 2 TPa (above diamond's 1.2 TPa).
inline constexpr Range kModulus{1e3, 2e12};
/// Poisson ratio: [0, 0.5] (0.5: incompressible rubbers and polyurethanes; the thin
/// bonded layer law takes that limit, formulas/layered_contact.hpp).
inline constexpr Range kPoisson{0.0, 0.5};
/// Impact speed: (0, 1000] m/s; above it impacts are ballistic and the Hertz laws (and
/// the DEM's time step) mean nothing.
inline constexpr Range kImpactSpeed{0.0, dem_reference::limits::kMaxImpactSpeed_m_s, true};
/// Bed mass: (0, 1e6] kg.
inline constexpr Range kMass{0.0, 1e6, true};
/// Rotary inertia: [0, 1e6] kg·m², 0 allowed (neglected).
inline constexpr Range kRotaryInertia{0.0, 1e6};
/// Gravity components: |g_i| <= 1e4 m/s² (1000 g, a centrifuge rig), 0 allowed.
inline constexpr Range kGravity{-dem_reference::limits::kMaxGravity_m_s2, dem_reference::limits::kMaxGravity_m_s2};
/// Force amplitudes and static loads on a structure, N: |F| <= 1e7 (a 1000 t weight).
inline constexpr Range kForce{-1e7, 1e7};
/// Allowable tip strain of a buffer layer δ_max/t: (0, 1] (1: the design impact
/// compresses the layer fully; formulas::BufferDesignInput::allowable_strain).
inline constexpr Range kAllowableStrain{0.0, 1.0, true};
/// Durations of a simulated decay, s: (0, 1e5] (a day of vibration).
inline constexpr Range kDuration{0.0, 1e5, true};
}  // namespace limits

}  // namespace pdamp::case_file
