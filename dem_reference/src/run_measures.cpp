// The drive-bin measure and the energy ledger of a driven run (docs/dem.md "Run machinery").
#include "pdamp/dem_reference/run_measures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace pdamp::dem_reference {

const base::Fields<EnergyBalance>& EnergyBalance::fields() {
  using E = EnergyBalance;
  static const auto f =
      base::Fields<E>()
          .field("container_work_j", &E::container_work_j, "J", "work W the container did on the bed")
          .field("normal_damping_j", &E::normal_damping_j, "J", "dissipated by the contacts' normal damping")
          .field("friction_j", &E::friction_j, "J", "dissipated by sliding friction")
          .field("rolling_j", &E::rolling_j, "J", "dissipated by rolling resistance")
          .field("delta_kinetic_j", &E::delta_kinetic_j, "J", "change of the bed's kinetic energy")
          .field("delta_potential_j", &E::delta_potential_j, "J", "change of its potential energy")
          .field("delta_elastic_j", &E::delta_elastic_j, "J", "change of the contacts' elastic energy")
          .field("relative_error", &E::relative_error, "1", "|W - (D + dE)| / max(|W|, D)", base::kHidden);
  return f;
}

EnergyBalance EnergyLedger::balance(const EnergyAccount& now) const {
  EnergyBalance eb;
  eb.container_work_j = now.container_work_j - opening_.container_work_j;
  eb.normal_damping_j = now.normal_damping_j - opening_.normal_damping_j;
  eb.friction_j = now.friction_j - opening_.friction_j;
  eb.rolling_j = now.rolling_j - opening_.rolling_j;
  eb.delta_kinetic_j = now.kinetic_j - opening_.kinetic_j;
  eb.delta_potential_j = now.potential_j - opening_.potential_j;
  eb.delta_elastic_j = now.elastic_j - opening_.elastic_j;
  const double dissipated = eb.dissipated_j();
  const double scale = std::max(std::abs(eb.container_work_j), dissipated);
  eb.relative_error = scale > 0.0 ? std::abs(eb.container_work_j - dissipated - eb.delta_energy_j()) / scale : 0.0;
  return eb;
}

DriveBinMeasure::DriveBinMeasure(std::int64_t steps_per_period, double frequency_hz, double bed_mass_kg)
    : frequency_hz_(frequency_hz),
      bed_mass_kg_(bed_mass_kg),
      period_bin_(steps_per_period),
      all_bin_(steps_per_period),
      steps_per_period_(steps_per_period) {
  if (!(std::isfinite(frequency_hz) && frequency_hz > 0.0) || !(std::isfinite(bed_mass_kg) && bed_mass_kg > 0.0)) {
    std::ostringstream msg;
    msg << "DriveBinMeasure: frequency_hz = " << frequency_hz << " and bed_mass_kg = " << bed_mass_kg
        << ": both must be finite and > 0";
    throw std::invalid_argument(msg.str());
  }
}

void DriveBinMeasure::add(std::int64_t step, double force_n, double velocity_m_s) {
  period_bin_.add(step, force_n, velocity_m_s);
  if (period_bin_.samples() < steps_per_period_) return;
  eta_star_per_period_.push_back(period_bin_.result(frequency_hz_).reduced_loss_factor(bed_mass_kg_));
  all_bin_.merge(period_bin_);
  period_bin_.clear();
}

namespace {

void save_sums(const formulas::DriveBinAccumulator::Sums& sums, StateWriter& out) {
  for (double v : {sums.force.real(), sums.force.imag(), sums.velocity.real(), sums.velocity.imag(), sums.max_abs_velocity,
                   sums.phase.real(), sums.phase.imag()})
    out.f64(v);
  out.i64(sums.samples);
  out.i64(sums.next_step);
  out.i32(sums.started ? 1 : 0);
}

formulas::DriveBinAccumulator::Sums restore_sums(StateReader& in, const std::string& name) {
  formulas::DriveBinAccumulator::Sums sums;
  const double fr = in.finite((name + ".force").c_str()), fi = in.finite((name + ".force").c_str());
  const double vr = in.finite((name + ".velocity").c_str()), vi = in.finite((name + ".velocity").c_str());
  sums.force = {fr, fi};
  sums.velocity = {vr, vi};
  sums.max_abs_velocity = in.finite((name + ".max_abs_velocity").c_str());
  const double pr = in.finite((name + ".phase").c_str()), pi = in.finite((name + ".phase").c_str());
  sums.phase = {pr, pi};
  // The rotated phase stays on the unit circle to round-off (recomputed every 64 steps).
  if (std::abs(std::abs(sums.phase) - 1.0) > 1e-9) in.fail(name + ".phase", "is not a unit phase");
  sums.samples = in.i64((name + ".samples").c_str());
  sums.next_step = in.i64((name + ".next_step").c_str());
  sums.started = in.i32_in((name + ".started").c_str(), 0, 1) == 1;
  if (sums.samples < 0) in.fail(name + ".samples", "must not be negative");
  return sums;
}

}  // namespace

// The whole state at any step (a checkpoint mid-period): both bins with their phases.
void DriveBinMeasure::save(StateWriter& out) const {
  save_sums(all_bin_.sums(), out);
  save_sums(period_bin_.sums(), out);
  out.f64s(eta_star_per_period_);
}

void DriveBinMeasure::restore(StateReader& in) {
  const auto all = restore_sums(in, "drive_bin");
  if (all.samples % steps_per_period_ != 0)
    in.fail("drive_bin.samples", std::to_string(all.samples) + ": must be whole periods of " +
                                     std::to_string(steps_per_period_) + " steps");
  const auto period = restore_sums(in, "drive_bin.period");
  if (period.samples >= steps_per_period_)
    in.fail("drive_bin.period.samples", std::to_string(period.samples) + ": must be less than a period of " +
                                            std::to_string(steps_per_period_) + " steps");
  const auto periods = in.finite_f64s_up_to("drive_bin.eta_star_per_period", 100000);
  if (static_cast<std::int64_t>(periods.size()) != all.samples / steps_per_period_)
    in.fail("drive_bin.eta_star_per_period", "holds " + std::to_string(periods.size()) + " periods, the sums " +
                                                 std::to_string(all.samples / steps_per_period_));
  all_bin_.restore_sums(all);
  period_bin_.restore_sums(period);
  eta_star_per_period_ = periods;
}

DriveBinMeasures DriveBinMeasure::result() const {
  if (eta_star_per_period_.empty()) {
    throw std::invalid_argument("DriveBinMeasure::result: no whole period accumulated yet");
  }
  // Complex power over all completed periods (docs/theory.md §1): the sum of the periods' bins.
  const auto cp = all_bin_.result(frequency_hz_);
  DriveBinMeasures m;
  m.eta_star = cp.reduced_loss_factor(bed_mass_kg_);
  m.e_diss_j = cp.e_diss_j;
  m.energy_per_cycle_j = cp.energy_per_cycle_j;
  m.apparent_mass_kg = cp.apparent_mass_kg;
  m.eta_star_per_period = eta_star_per_period_;
  const auto& per = m.eta_star_per_period;
  const int periods = completed_periods();
  const double mean = std::accumulate(per.begin(), per.end(), 0.0) / periods;
  double var = 0.0;
  for (const double e : per) var += (e - mean) * (e - mean);
  var = periods > 1 ? var / (periods - 1) : 0.0;
  m.eta_star_stderr = periods > 1 ? std::sqrt(var / periods) : std::numeric_limits<double>::quiet_NaN();
  m.eta_star_variation = mean != 0.0 ? std::sqrt(var) / std::abs(mean) : 0.0;
  return m;
}

}  // namespace pdamp::dem_reference
