// Complex-power measure of damper dissipation (Yang's method, PHYSICS.md §1).
#pragma once

#include <complex>
#include <span>

namespace pdamp::formulas {

/// Fourier amplitudes at the drive frequency and the derived measures.
/// Convention: a signal s(t) has s(t) ≈ Re(S* e^{iΩt}) at Ω, S* = (2/N)·DFT_k.
struct ComplexPower {
  std::complex<double> force_amplitude;     ///< F*, N
  std::complex<double> velocity_amplitude;  ///< V*, m/s
  std::complex<double> power;               ///< P = ½ F*·conj(V*), W
  double angular_frequency = 0.0;           ///< Ω = 2πf, rad/s
  double e_diss_j = 0.0;                    ///< Re(P)/Ω, J
  double energy_per_cycle_j = 0.0;          ///< 2π·E_diss, J
  double apparent_mass_kg = 0.0;            ///< Im(F*·conj V*)/(Ω|V*|²), kg
  int periods = 0;                          ///< whole periods analysed
  int samples_per_period = 0;
  /// η* = E_diss/(½ m_bed |V*|²), dimensionless; bed_mass_kg > 0.
  double reduced_loss_factor(double bed_mass_kg) const;
};

/// Complex power of the force the container applies to the bed and the container
/// velocity, both sampled at step dt_s from the start of a period. The record must
/// hold a whole number of periods with an integer number of samples per period
/// (T/dt integer within 1e-9 relative): anything else throws std::invalid_argument
/// naming the numbers, since a non-integer window leaks other frequencies into the
/// bin at Ω. Uses FFTW (one cached plan per length).
ComplexPower complex_power(std::span<const double> force_n, std::span<const double> velocity_m_s,
                           double dt_s, double frequency_hz);

}  // namespace pdamp::formulas
