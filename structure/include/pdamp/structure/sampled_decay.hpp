#pragma once
// The settling of a decay known at sampled instants (a DEM-in-the-loop free decay): its
// envelope, settling time, frequency and equivalent damping ratio, the static offset it
// decays about, and the integral of its squared envelope. The free_decay solver's own
// measures are computed inside it; these serve decays that only a time history describes.
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/base/record.hpp"
#include "pdamp/structure/modal_model.hpp"
#include "pdamp/surrogate/decay_field.hpp"

namespace pdamp::structure {

/// The settling of a sampled site displacement y(t) about an offset y_s.
struct SampledSettling {
  std::vector<double> envelope_time_s, envelope_m;  ///< one per whole period: the largest |y − y_s| and its instant
  std::vector<double> sample_envelope_m;            ///< the envelope at every sample (linear in ln between periods)
  double settling_time_s = NAN;                     ///< s; NaN: not settled within the record
  double frequency_hz = NAN;  ///< from the zero crossings of y − y_s up to settling (or the whole record)
  double damping_ratio = NAN; ///< ζ_eq = δ/√(4π² + δ²), δ = ln(initial/threshold)/(f t_s); NaN if not settled
  static const base::Fields<SampledSettling>& fields();
};

/// The envelope is the largest |y − offset| over each whole period `period_s` (placed at
/// its instant); the decay settles where the envelope, interpolated in ln between the last
/// period at or above `threshold_m` and the next, crosses it, if no later period rises
/// above it again (0 when no period is above it). The frequency comes from the zero
/// crossings of y − offset (interpolated) up to settling, `fallback_frequency_hz` with fewer
/// than three; ζ_eq from the logarithmic decrement between `initial_m` and `threshold_m`.
/// `t` ascending, y of its size.
SampledSettling sampled_settling(const std::vector<double>& t, const Eigen::VectorXd& y, double offset, double period_s,
                                 double initial_m, double threshold_m, double fallback_frequency_hz);

/// The static displacement of the first damper's site along its drive under the beds'
/// weight resting on their walls: y_s = b_0ᵀ K⁻¹ Σ_d b_d m_d g_d, K = diag(m_j ω_j²), b_d the
/// drive shapes (modes x dampers), m_d = bed_masses_kg[d] (kg) and g_d =
/// drive_gravity_m_s2[d] the gravity along damper d's drive (m/s²).
double static_site_offset(const ModalModel& modal, const Eigen::MatrixXd& drive_shapes,
                          const std::vector<double>& bed_masses_kg, const std::vector<double>& drive_gravity_m_s2);

/// The first-harmonic response of one bed over each whole period of a sampled decay
/// (surrogate::DecayPeriodResponse): the periods lie between successive upward zero crossings
/// of y − offset (interpolated); X̂ and F̂ are the coefficients at Ω = 2π/T over the period
/// (trapezoid on the samples, linear between them) of the signals with the envelope's decay
/// e^{−λt} taken out (λ from the neighbouring periods), and the bed's impedance F̂/(sX̂),
/// s = −λ + iΩ, gives η* and m_app/m_bed exactly for a linear bed on a decaying motion. y is
/// the site displacement along the drive at the samples, F the force the container applies to
/// the bed (the negative of what the bed exerts on it) as CosimulationHistory::container_load_n
/// holds it: each sample the mean over the interval ending there (centred on the samples
/// here, as the mean of the two intervals either side). `t` ascending; y and force of its size;
/// bed_mass_kg > 0. Periods whose measures are not finite are left out.
std::vector<surrogate::DecayPeriodResponse> bed_response_per_period(const std::vector<double>& t,
                                                                   const Eigen::VectorXd& y, double offset,
                                                                   const Eigen::VectorXd& force_on_bed_n,
                                                                   double bed_mass_kg);

/// ½∫e² dt of sampled values e(t) (trapezoid on e²), m²·s for an envelope in m.
double half_integral_square(const std::vector<double>& t, const std::vector<double>& e);

}  // namespace pdamp::structure
