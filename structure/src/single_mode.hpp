// Private: the single-mode averaged oscillator shared by backbones and free decay.
#pragma once

#include <cstdint>

#include "pdamp/structure/damper_coupling.hpp"

namespace pdamp::structure::detail {

/// Mode j at modal amplitude a with every damper at X_d = |b_dj| a (backbone.hpp states
/// the model). No allocation: layer_eta_star (one slot per layer, dampers' layers in order)
/// receives η* at the converged frequency when not null.
struct SingleMode {
  double natural_angular_frequency_rad_s = 0.0;  ///< Ω_n
  double added_damping_ratio = 0.0;
  double structural_damping_ratio = 0.0;
  double effective_modal_mass_kg = 0.0;
  std::uint32_t loss_warnings = 0;
  bool converged = false;
};
SingleMode single_mode(const CoupledModel& coupled, int mode, double modal_amplitude, double frequency_tolerance,
                       int max_iterations, double* layer_eta_star);

}  // namespace pdamp::structure::detail
