// Complex-power measure of damper dissipation (Yang's method, docs/theory.md §1).
//
// Derivation and conventions: docs/complex_power.md.
#pragma once

#include <complex>
#include <cstdint>
#include <span>

namespace pdamp::formulas {

/// Fourier amplitudes at the drive frequency and the derived measures.
/// Convention: a signal s(t) has s(t) ≈ Re(S* e^{iΩt}) at Ω, S* = (2/N)·X[k], where
/// X[k] = Σₙ sₙ e^{−2πi kn/N} is the DFT bin at k = number of whole periods in the
/// record of N samples, and t = 0 is the first sample.
struct ComplexPower {
  std::complex<double> force_amplitude;     ///< F*, N
  std::complex<double> velocity_amplitude;  ///< V*, m/s
  std::complex<double> power;               ///< P = ½ F*·conj(V*), W
  double angular_frequency = 0.0;           ///< Ω = 2πf, rad/s
  double e_diss_j = 0.0;                    ///< Re(P)/Ω, J
  double energy_per_cycle_j = 0.0;          ///< 2π·E_diss = mean power × period, J
  /// Im(F*·conj V*)/(Ω|V*|²), kg: the in-phase-with-acceleration part of the force
  /// per unit acceleration; m for a rigid mass, −k/Ω² for a spring of stiffness k.
  double apparent_mass_kg = 0.0;
  int periods = 0;             ///< whole periods analysed, k >= 1
  int samples_per_period = 0;  ///< T/dt, >= 3
  /// η* = E_diss/(½ m_bed |V*|²), dimensionless (docs/theory.md §1); a viscous damper c
  /// gives c/(m_bed Ω). Throws std::invalid_argument unless bed_mass_kg > 0 and finite.
  double reduced_loss_factor(double bed_mass_kg) const;
};

/// Complex power of the force the container applies to the bed (N) and the container
/// velocity (m/s), both sampled at step dt_s (> 0) from the start of a period, at the
/// drive frequency frequency_hz (> 0). Positive Re(P) is power flowing into the bed.
///
/// The record must hold a whole number of periods with an integer number of samples
/// per period: T/dt = 1/(f·dt) must be an integer >= 3 within 1e-9 relative, and the
/// length N a multiple of it. Anything else throws std::invalid_argument naming the
/// numbers, since a non-integer window leaks other frequencies into the bin at Ω.
/// Also rejected: empty or unequal-length signals, non-finite samples, and a velocity
/// with no component at Ω (|V*| <= 1e-12 × the largest value of the period-averaged
/// velocity), for which m_app and η* are undefined.
///
/// Harmonics jΩ (j ≠ 1) and a DC offset are orthogonal to the bin and do not change
/// the result. The record is folded onto one period (the sum over periods) and bin 1
/// of an FFTW r2c transform of length T/dt taken: identical to bin k of the length-N
/// DFT, at O(N) cost. One FFTW plan is cached per T/dt (planning serialised by a mutex,
/// execution not; per-thread workspaces): safe to call from several threads.
ComplexPower complex_power(std::span<const double> force_n, std::span<const double> velocity_m_s, double dt_s,
                           double frequency_hz);

/// How a sampled force is held over its time step (docs/complex_power.md "Step by step").
enum class StepForce {
  /// F_k acts constant over [t_k − dt/2, t_k + dt/2]: the leapfrog impulse F_k·dt of
  /// the DEM step. ∫ e^{−iΩt} over the step is dt·sinc(Ωdt/2)·e^{−iΩt_k}.
  kConstant,
  /// F linear between the samples (trapezoidal): the weight is dt·sinc²(Ωdt/2)·e^{−iΩt_k}.
  kLinear,
};

/// The Fourier coefficient at Ω of a force and a velocity, accumulated one time step
/// at a time (no record kept): exact for a force held over each step as `force_model`
/// says, whatever its harmonics, and exact for a velocity whose content lies below
/// M/2 harmonics (a sampled pure harmonic: the container's). The record must be whole
/// periods of M = steps_per_period steps, dt = T/M; sample k is at t_k = k·dt (k the
/// step index passed to add(), any origin: only whole periods matter).
///
///   F* = (2/N)·w·Σ_k F_k e^{−2πi k/M},  V* = (2/N)·Σ_k v_k e^{−2πi k/M},
///   w = sinc(π/M) (kConstant) or sinc²(π/M) (kLinear), N the number of samples.
///
/// Unlike complex_power() on block averages, harmonics at (jM' ± 1)Ω of a coarser
/// record of M' blocks do not fold into the bin: only (jM ± 1)Ω would, and M is the
/// number of steps per period. The phase e^{−2πi k/M} is rotated step by step and
/// recomputed from k every 64 steps (round-off < 1e-13).
class DriveBinAccumulator {
 public:
  /// steps_per_period >= 3; throws std::invalid_argument otherwise.
  explicit DriveBinAccumulator(std::int64_t steps_per_period, StepForce force_model = StepForce::kConstant);
  /// Adds the samples of step k (N, m/s).
  void add(std::int64_t step, double force_n, double velocity_m_s);
  /// Adds another accumulator's sums (same steps_per_period and force model).
  void merge(const DriveBinAccumulator& other);
  void clear();
  std::int64_t samples() const { return samples_; }
  /// The accumulator's whole state (a checkpoint of a run at any step): the sums and the
  /// rotated step phase, so restore_sums continues to the bit wherever they were taken.
  struct Sums {
    std::complex<double> force{0.0, 0.0};
    std::complex<double> velocity{0.0, 0.0};
    double max_abs_velocity = 0.0;
    std::int64_t samples = 0;
    std::complex<double> phase{1.0, 0.0};  ///< e^{−2πi k/M} of the next step, as rotated
    std::int64_t next_step = 0;
    bool started = false;                  ///< false: the next add() takes its phase from its step index
  };
  Sums sums() const { return {force_sum_, velocity_sum_, max_abs_velocity_, samples_, phase_, next_step_, started_}; }
  void restore_sums(const Sums& sums);
  /// The measures at frequency_hz from the sums so far. Throws std::invalid_argument
  /// unless the samples are a positive whole number of periods, are finite, and the
  /// velocity has a component at Ω (the rules of complex_power()).
  ComplexPower result(double frequency_hz) const;

 private:
  std::int64_t steps_per_period_;
  double weight_;                      ///< sinc(π/M) or sinc²(π/M)
  std::complex<double> rotor_;         ///< e^{−2πi/M}
  std::complex<double> phase_{1.0, 0.0};
  std::int64_t next_step_ = 0;
  bool started_ = false;
  std::complex<double> force_sum_{0.0, 0.0};
  std::complex<double> velocity_sum_{0.0, 0.0};
  double max_abs_velocity_ = 0.0;
  std::int64_t samples_ = 0;
};

}  // namespace pdamp::formulas
