// Complex-power measure of damper dissipation (Yang's method, PHYSICS.md §1).
//
// Derivation and conventions: docs/complex_power.md.
#pragma once

#include <complex>
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
  /// η* = E_diss/(½ m_bed |V*|²), dimensionless (PHYSICS.md §1); a viscous damper c
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

}  // namespace pdamp::formulas
