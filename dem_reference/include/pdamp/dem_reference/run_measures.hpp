// The measures of a driven DEM run, for any driver: the complex power in the drive bin
// (per analysed period and over all) and the energy balance over a window.
#pragma once

#include <cstdint>
#include <vector>

#include "pdamp/base/record.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/formulas/complex_power.hpp"

namespace pdamp::dem_reference {

/// Energy balance over a window: work of the container against the dissipation in the
/// contacts plus the change of the particles' energy.
struct EnergyBalance {
  double container_work_j = 0.0;
  double normal_damping_j = 0.0;
  double friction_j = 0.0;
  double rolling_j = 0.0;
  double delta_kinetic_j = 0.0;
  double delta_potential_j = 0.0;
  double delta_elastic_j = 0.0;
  /// |W − (D + ΔE)| / max(|W|, D): target < 0.02.
  double relative_error = 0.0;
  /// D = normal damping + friction + rolling, J.
  double dissipated_j() const { return normal_damping_j + friction_j + rolling_j; }
  /// ΔE = change of kinetic + potential + elastic energy, J.
  double delta_energy_j() const { return delta_kinetic_j + delta_potential_j + delta_elastic_j; }
  static const base::Fields<EnergyBalance>& fields();
};

/// The energy balance over a window of any drive. The world keeps the cumulative
/// account (container work and dissipation summed inside every step), so the ledger
/// needs the account only at the window's two ends: no per-step cost.
class EnergyLedger {
 public:
  /// Opens the window at `opening` (World::energy() at its start).
  explicit EnergyLedger(const EnergyAccount& opening) : opening_(opening) {}
  /// The balance from the opening to `now` (World::energy() at the window's end).
  EnergyBalance balance(const EnergyAccount& now) const;
  const EnergyAccount& opening() const { return opening_; }

 private:
  EnergyAccount opening_;
};

/// Complex-power measures at the drive frequency (docs/theory.md §1) over the analysed
/// periods, from the drive bin accumulated every step.
struct DriveBinMeasures {
  double eta_star = 0.0;            ///< reduced loss factor over all periods
  double eta_star_stderr = 0.0;     ///< sample sd of the per-period values / √n; NaN for one period
  double eta_star_variation = 0.0;  ///< sample sd / |mean| of the per-period values (0 for one period)
  double e_diss_j = 0.0;            ///< Re(P)/Ω, J
  double energy_per_cycle_j = 0.0;  ///< 2π·E_diss, J
  double apparent_mass_kg = 0.0;    ///< Im(F*·conj V*)/(Ω|V*|²), kg
  std::vector<double> eta_star_per_period;  ///< from each period's own bin
};

/// The drive-bin measure of any drive: fed every step with the force of the container on
/// the particles and a reference velocity (the container's) along the drive, it closes a
/// period every steps_per_period steps (its η* from that period's bin) and sums the
/// closed periods into the measure over all. The reference velocity must have a
/// component at the frequency (a harmonic drive, or a structure responding at it).
/// formulas::DriveBinAccumulator with StepForce::kConstant: the leapfrog's F_k is the
/// impulse F_k·dt over [t_k − dt/2, t_k + dt/2].
class DriveBinMeasure {
 public:
  /// steps_per_period >= 3 (whole steps per period of frequency_hz), bed_mass_kg > 0.
  /// Throws std::invalid_argument otherwise.
  DriveBinMeasure(std::int64_t steps_per_period, double frequency_hz, double bed_mass_kg);
  /// Adds step k (drive step index, t_k = k·dt): force (N) and velocity (m/s) along the
  /// drive. Throws std::invalid_argument (formulas::DriveBinAccumulator::result) when a
  /// period closes without a velocity component at the frequency.
  void add(std::int64_t step, double force_n, double velocity_m_s);
  int completed_periods() const { return static_cast<int>(eta_star_per_period_.size()); }
  /// η* of each completed period so far.
  const std::vector<double>& eta_star_per_period() const { return eta_star_per_period_; }
  /// The measures over the completed periods (a period in progress does not count).
  /// Throws std::invalid_argument before the first period is complete.
  DriveBinMeasures result() const;
  /// Checkpoints at a period's end (checkpoint.hpp): the completed periods' sums and η*.
  /// restore throws std::invalid_argument for a state that does not fit (a period in
  /// progress, non-finite sums, a sample count that is not whole periods).
  void save(StateWriter& out) const;
  void restore(StateReader& in);

 private:
  double frequency_hz_;
  double bed_mass_kg_;
  formulas::DriveBinAccumulator period_bin_;
  formulas::DriveBinAccumulator all_bin_;
  std::vector<double> eta_star_per_period_;
  std::int64_t steps_per_period_;
};

}  // namespace pdamp::dem_reference
