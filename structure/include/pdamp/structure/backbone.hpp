// Backbones of a modal model with particle dampers: per mode, the single-mode averaged
// natural frequency and added damping ratio as functions of the damper amplitude
// (docs/theory.md §7.5, docs/structure_coupling.md §6; NLvib's nonlinear modal analysis in its
// single-mode, single-harmonic form).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

struct BackboneOptions {
  int mode = 0;                          ///< mode index j, in [0, modes)
  std::size_t reference_damper = 0;      ///< the damper whose amplitude X_d parametrises the backbone
  std::vector<double> damper_amplitudes_m;  ///< X_d, m, > 0 (any order)
  /// η* and m_app depend on f: the frequency solves Ω = Ω_n(Ω, X) by fixed-point iteration
  /// to this relative tolerance, in (0, 1e-3].
  double frequency_tolerance = 1e-12;
  int max_iterations = 100;              ///< >= 1
  CouplingOptions coupling;
  std::vector<std::string> validate() const;
};

/// The single-mode averaged oscillator of mode j at one amplitude a (modal, X_d = |b_dj| a):
///   k_j = m_j ω_j²,  m_eff = m_j + Σ_d m_c|φ_j(d)|² + Σ_d b_dj² Σ_l m_bed,l (m_app/m_bed)_l,
///   c_eff = 2ζ_j ω_j m_j + Σ_d b_dj² Σ_l η*_l m_bed,l Ω,
///   Ω_n = √(k_j/m_eff),  ζ = c_eff/(2 m_eff Ω_n),  ω_d = Ω_n √(1 − ζ²),
/// with η* and m_app taken at (Ω_n/2π, X_d): evaluating them at ω_d instead changes the
/// result by O(ζ²) only. Cross-mode coupling through the containers and beds is dropped
/// (single-mode averaging): valid while one mode dominates the damper's motion.
struct BackbonePoint {
  double damper_amplitude_m = 0.0;        ///< X of the reference damper, m
  double modal_amplitude = 0.0;           ///< a (units of q_j)
  double natural_frequency_hz = 0.0;      ///< Ω_n/2π, Hz (undamped, with the beds' apparent mass; η* taken here)
  double damped_frequency_hz = 0.0;       ///< ω_d/2π, Hz
  double added_damping_ratio = 0.0;       ///< ζ_add = Σ b² η* m_bed/(2 m_eff)
  double structural_damping_ratio = 0.0;  ///< ζ_j ω_j m_j/(m_eff Ω_n)
  double effective_modal_mass_kg = 0.0;   ///< m_eff, kg
  std::vector<double> layer_eta_star;     ///< η* per layer (dampers' layers in order)
  std::vector<double> layer_damper_amplitude_m;  ///< X of each layer's damper, m
  std::uint32_t loss_warnings = 0;        ///< OR of the layers' bits
  bool converged = true;                  ///< the frequency fixed point met the tolerance
};

struct Backbone {
  int mode = 0;
  std::vector<BackbonePoint> points;      ///< in the order of options.damper_amplitudes_m
  /// Modal mass ratio μ = Σ_d b_dj² Σ_l m_bed,l / m_j (the small-mass-ratio check ζ_add ≈ ½η*μ holds for μ << 1), dimensionless.
  double modal_mass_ratio = 0.0;
  std::vector<std::string> warnings;
  double solve_time_s = 0.0;
};

/// One backbone point of mode j at modal amplitude a (the kernel the free decay reuses).
BackbonePoint backbone_point(const CoupledModel& coupled, int mode, double modal_amplitude,
                             double frequency_tolerance = 1e-12, int max_iterations = 100);

/// The backbone of options.mode over options.damper_amplitudes_m; throws
/// std::invalid_argument for invalid inputs or a reference damper with φ_j(d)·n = 0.
Backbone backbone(const ModalModel& model, const std::vector<Damper>& dampers, const BackboneOptions& options);

}  // namespace pdamp::structure
