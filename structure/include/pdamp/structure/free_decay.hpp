// Free decay of a modal model with particle dampers by slowly varying amplitude: per mode an
// envelope a_j(t) with dE_j/dt = −E_cycle(X)/T (docs/theory.md §7.6, docs/structure_coupling.md §7).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

struct FreeDecayOptions {
  /// a_j(0): initial amplitude of every mode (units of q_j; for a release from q(0), q̇(0)
  /// use a_j = √(q_j² + (q̇_j/ω_j)²)), >= 0, one per mode, not all 0.
  Eigen::VectorXd initial_modal_amplitudes;
  double duration_s = 0.0;             ///< end of the integration, s, > 0
  std::vector<double> sample_times_s;  ///< output instants, s, ascending in [0, duration_s]
  /// Settling measure: the envelope bound Σ_j |e·φ_j(p)| a_j of the displacement at
  /// `threshold_point` along `threshold_direction` (empty point: the first damper's site
  /// along its drive). Settled when it falls below threshold_m, or, with threshold_m = 0,
  /// below threshold_fraction of its initial value.
  std::string threshold_point;
  Eigen::Vector2d threshold_direction{1.0, 0.0};
  double threshold_m = 0.0;            ///< m, >= 0
  double threshold_fraction = 0.01;    ///< in (0, 1), used when threshold_m = 0
  /// RK4 step rule: dt = min(max_step_s, step_log_change / max_j(ζ_j Ω_j)), i.e. each step
  /// lets ln a_j change by at most step_log_change; RK4's local error is then about
  /// step_log_change⁵/120 of ln a per step times the relative variation of the rate over the
  /// step (2.6e-9 at the default 0.05; exact for a constant rate). A mode decayed below 1e-9
  /// of its initial amplitude leaves the rule (and stops dissipating). A step that would
  /// cross a loss-model jump (the onset) is cut to end just past it (bisection), so no RK4
  /// stage straddles the jump. In (0, 0.2].
  double step_log_change = 0.05;
  double max_step_s = 0.0;             ///< s, 0 = duration_s/20 (a cap where the decay stalls), >= 0
  /// Warn when a mode other than the largest carries more than this fraction of a damper's
  /// amplitude Σ_j |b_dj| a_j (single-mode averaging then misjudges η*), in (0, 1).
  double second_mode_warning_fraction = 0.1;
  CouplingOptions coupling;
  std::vector<std::string> validate(Eigen::Index modes) const;
};

struct DecaySample {
  double time_s = 0.0;
  Eigen::VectorXd modal_amplitudes;           ///< a_j(t)
  std::vector<double> damper_amplitudes_m;    ///< Σ_j |b_dj| a_j per damper, m
  double threshold_measure_m = 0.0;           ///< the settling measure, m
  double mechanical_energy_j = 0.0;           ///< Σ_j ½ k_j a_j², J
  std::vector<double> layer_dissipated_energy_j;  ///< cumulative per layer since t = 0, J
  double structural_dissipated_energy_j = 0.0;    ///< cumulative, J
  std::vector<double> layer_power_w;          ///< instantaneous cycle-averaged power per layer, W
};

struct FreeDecay {
  enum class Outcome { kSettled, kNotSettled };
  Outcome outcome = Outcome::kNotSettled;
  std::vector<std::string> layer_names;       ///< "<damper>/<layer>", the order of the per-layer vectors
  std::vector<DecaySample> samples;           ///< at options.sample_times_s
  double settling_time_s = 0.0;               ///< NaN when not settled within duration_s
  double threshold_used_m = 0.0;              ///< m
  /// ζ_eq = δ/√(4π² + δ²), δ = ln(measure(0)/measure(t_s))/(f_d t_s) with f_d the damped
  /// frequency of the mode dominating the measure at t = 0 (a linear mode gives its ζ). NaN if not settled.
  double equivalent_damping_ratio = 0.0;
  int dominant_mode = 0;
  std::size_t steps = 0;
  std::vector<std::string> warnings;
  double solve_time_s = 0.0;
  std::string brief_report() const;
};

/// Integrates the envelopes with RK4 in ln a_j (each mode decays at −ζ_j(a_j)Ω_j(a_j) from
/// backbone_point: single-mode averaging, every damper at X_dj = |b_dj| a_j for mode j) and
/// the per-layer dissipated energies. Throws std::invalid_argument for invalid inputs.
FreeDecay free_decay(const ModalModel& model, const std::vector<Damper>& dampers, const FreeDecayOptions& options);

/// The equivalent viscous damping ratio of a decay that falls from `initial` to `threshold`
/// in `settling_time_s` at `frequency_hz`: ζ_eq = δ/√(4π² + δ²), δ = ln(initial/threshold)/(f t_s)
/// the logarithmic decrement per cycle (a linear mode gives its own ζ).
double equivalent_damping_ratio(double initial, double threshold, double frequency_hz, double settling_time_s);

/// `count` instants evenly spaced over [0, duration_s], both ends included exactly.
std::vector<double> uniform_sample_times(double duration_s, int count);

}  // namespace pdamp::structure
