// What a co-simulation run needs before its first step (private to the library): input
// checks, the modal arrays with the containers, the excitation's shapes and the common step
// (docs/cosimulation.md §1-3), shared by cosimulation.cpp and cosimulation_run.cpp.
#pragma once

#include <array>
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/structure/cosimulation_damper.hpp"
#include "pdamp/structure/cosimulation_options.hpp"
#include "pdamp/structure/cosimulation_result.hpp"
#include "pdamp/structure/cosimulation_state.hpp"
#include "pdamp/structure/damper_coupling.hpp"

namespace pdamp::structure::detail {

/// The structure's Verlet step: ω_max·dt at most this (frequency error (ωdt)²/24 = 1.7e-4 at
/// the limit); the automatic step is shortened to kStructureStepTarget/ω_max, whose frequency
/// error (ωdt)²/24 is 1e-4 of that at 0.2 — far below the beds' own.
inline constexpr double kStructureStepLimit = 0.2;
inline constexpr double kStructureStepTarget = 0.05;
/// A continuation warns when its frequency moves by more than this fraction to fit whole
/// steps of the carried dt, or when the carried dt exceeds the run's own automatic step by
/// more than this fraction (a few per cent fewer steps per contact change nothing measurable;
/// the automatic step of a continuation also counts the state's energy, which the sweep's
/// planning from rest does not).
inline constexpr double kFrequencyChangeWarning = 1e-4;
inline constexpr double kCarriedStepMargin = 0.1;

/// A run of any kind in one struct: what the run's code reads (CosimulationRun's kinds each
/// fill their part; the others keep their defaults).
struct RunOptions : CosimulationSettings {
  enum class Kind { kDecay, kSteadyState, kSweep } kind = Kind::kDecay;  ///< which CosimulationRun
  CosimulationExcitation excitation;   ///< kFreeDecay for a DecayRun
  double duration_s = 0.0;             ///< DecayRun, SweepRun
  double sweep_end_frequency_hz = 0.0; ///< SweepRun; 0 otherwise
  int transient_periods = 0, min_transient_periods = 0, analysed_periods = 1;  ///< SteadyStateRun
  bool settle_until_stable = false;    ///< SteadyStateRun
  double stable_tolerance = 1e-3;      ///< SteadyStateRun
  double excitation_phase_rad = 0.0;   ///< SteadyStateRun, SweepRun
  /// All violations, one line each, "field = value: rule" (prefix "cosimulation.").
  std::vector<std::string> validate(const ModalModel& model) const;
};
RunOptions run_options(const CosimulationRun& run);

inline bool harmonic(const CosimulationExcitation& e) { return e.kind != CosimulationExcitationKind::kFreeDecay; }
inline bool sweeping(const RunOptions& o) { return harmonic(o.excitation) && o.sweep_end_frequency_hz > 0.0; }

/// Joins violations into one message, one per line.
std::string join(const std::vector<std::string>& lines);

/// Everything a run needs before its worlds: modal arrays with the empty containers, the
/// excitation's shapes and the assumed peak site speeds.
struct Prepared {
  CoupledModel coupled;
  Eigen::MatrixXd M, M_inv, B, R;
  Eigen::MatrixXd T;  ///< modes x dampers: the sites' translation across the drive, t_d = z × n_d
  Eigen::VectorXd w, K, C;
  double omega = 0.0, U = 0.0;
  /// The modal load per unit drive factor: F·Φ_pᵀe (force, factor sin ψ) or U·P_e (base,
  /// factor −ü_b/U = ψ̇² sin ψ − ψ̈ cos ψ).
  Eigen::VectorXd load_shape, base_shape, force_shape;
  std::vector<double> drive_dot_e, across_dot_e, peak_speed;
  std::vector<std::string> warnings;
};

/// Every violation of the inputs, one per line (a continuation drops the free decay's
/// need of a non-zero start: it starts from the state).
void validate_inputs(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                     const RunOptions& options, bool continuation);

/// Whether `state` can be continued with these inputs: one line per misfit.
void validate_state(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                    const RunOptions& options, const CosimulationState& state);

/// Modal arrays, excitation shapes and peak speeds for the start q, v at frequency f_hz.
Prepared prepare(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                 const RunOptions& options, double f_hz, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

/// The common time step of a fresh start and the worlds' options (time_step_s still theirs).
struct StepPlan {
  double dt = 0.0;
  std::int64_t steps_per_period = 0;
  std::vector<dem_reference::WorldOptions> world_options;
  std::vector<std::string> warnings;
};
StepPlan plan_step(const Prepared& P, const std::vector<CosimulationDamper>& dampers, const RunOptions& options,
                   double f_hz);

/// |W − (D_s + D_dem + ΔE_s + ΔE_bed)| / max(|W|, D_s + D_dem, |ΔE_s|) (CosimulationEnergy).
double ledger_error(const CosimulationEnergy& e);

/// The energy terms of CosimulationEnergy in one order (sums and checkpoints).
std::array<double*, 11> energy_terms(CosimulationEnergy& e);

/// The given start vector, or zeros of length n when it is empty.
Eigen::VectorXd start_vector(const Eigen::VectorXd& given, Eigen::Index n);

/// Time τ at which a linear sweep from f₀ at rate r (Hz/s) has run `cycles` cycles:
/// f₀τ + ½rτ² = k, rationalised (τ = 2k/(f₀ + √(f₀² + 2rk))) so that r → 0 needs no case.
double sweep_cycle_time(double f0, double rate, double cycles);

/// A bed's η* and m_app/m_bed from its force and site amplitudes at ω (the Level II measure,
/// docs/cosimulation.md §5): P = ½F̂ conj V̂, V̂ = iωŷ; NaN for an empty bed or a still site.
void bed_measures(std::complex<double> force_hat, std::complex<double> y, double omega, double m_bed,
                  std::vector<double>& eta_star, std::vector<double>& apparent_mass_fraction);

}  // namespace pdamp::structure::detail
