// One mode's free decay by the loss models and by the DEM in the loop (mode_decay.hpp).
#include "pdamp/tasks/mode_decay.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/tasks/decay.hpp"

namespace pdamp::tasks {

namespace st = structure;

const base::Fields<ModeDecayCheck>& ModeDecayCheck::fields() {
  using M = ModeDecayCheck;
  static const auto f =
      base::Fields<M>()
          .derived("mode", [](const M& m) { return m.mode + 1; }, "", "the mode, from 1")
          .field("frequency_hz", &M::frequency_hz, "Hz", "its frequency with the damper (the periods' length)")
          .field("damper_amplitude_m", &M::damper_amplitude_m, "m", "the damper's stroke at the start")
          .field("predicted_damping_ratio", &M::predicted_damping_ratio, "1",
                 "damping ratio the beds add over the decay, by the layers' loss models", base::kNullable)
          .field("dem_damping_ratio", &M::dem_damping_ratio, "1", "the same by the DEM in the loop", base::kNullable)
          .field("bare_damping_ratio", &M::bare_damping_ratio, "1", "the decay's with the containers empty (subtracted)",
                 base::kNullable)
          .field("relative_difference", &M::relative_difference, "1", "(predicted - DEM)/DEM", base::kNullable)
          .derived("whole_relative_difference", [](const M& m) { return m.whole_relative_difference(); }, "1",
                   "the same of the mode's whole damping ratio, the bare decay's plus the added", base::kNullable)
          .field("dem_final_fraction", &M::dem_final_fraction, "1", "the DEM decay's last period over its first",
                 base::kNullable)
          .field("solve_time_s", &M::wall_time_s, "s", "wall time of the DEM decay");
  return f;
}

namespace {

/// The largest |q| over each whole period of 1/frequency_hz from t = 0.
std::vector<double> period_peaks(const std::vector<double>& time_s, const Eigen::VectorXd& q, double frequency_hz) {
  std::vector<double> peaks;
  std::size_t i = 0;
  for (int k = 0; !time_s.empty(); ++k) {
    const double end = (k + 1) / frequency_hz;
    if (time_s.back() < end * (1.0 - 1e-9)) break;  // whole periods only
    double peak = 0.0;
    for (; i < time_s.size() && time_s[i] < end; ++i) peak = std::max(peak, std::abs(q[static_cast<Eigen::Index>(i)]));
    peaks.push_back(peak);
  }
  return peaks;
}

/// ζ of mode `mode` in the averaged decay of `modal` with `damper` from q0 (its envelope a_j).
double averaged_damping_ratio(const st::ModalModel& modal, const st::Damper& damper, const Eigen::VectorXd& q0,
                              Eigen::Index mode, double frequency_hz, const ModeDecayWindow& window) {
  st::FreeDecayOptions o;
  o.initial_modal_amplitudes = q0.cwiseAbs();
  o.duration_s = window.periods / frequency_hz;
  o.sample_times_s = st::uniform_sample_times(o.duration_s, 20 * window.periods + 1);
  o.threshold_fraction = window.amplitude_fraction;
  const st::FreeDecay d = st::free_decay(modal, {damper}, o);
  std::vector<double> t;
  Eigen::VectorXd a(static_cast<Eigen::Index>(d.samples.size()));
  for (std::size_t k = 0; k < d.samples.size(); ++k) {
    t.push_back(d.samples[k].time_s);
    a[static_cast<Eigen::Index>(k)] = d.samples[k].modal_amplitudes[mode];
  }
  return modal_decay_damping_ratio(t, a, frequency_hz, window.amplitude_fraction);
}

}  // namespace

double modal_decay_damping_ratio(const std::vector<double>& time_s, const Eigen::VectorXd& q, double frequency_hz,
                                 double fraction) {
  const std::vector<double> peaks = period_peaks(time_s, q, frequency_hz);
  std::vector<double> t, log_amplitude;
  for (std::size_t k = 0; k < peaks.size() && peaks[k] > 0.0 && peaks[k] >= fraction * peaks.front(); ++k) {
    t.push_back(static_cast<double>(k) / frequency_hz);
    log_amplitude.push_back(std::log(peaks[k]));
  }
  if (t.size() < 2) return NAN;
  const double n = static_cast<double>(t.size());
  const double t_mean = std::accumulate(t.begin(), t.end(), 0.0) / n;
  const double y_mean = std::accumulate(log_amplitude.begin(), log_amplitude.end(), 0.0) / n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    sxy += (t[k] - t_mean) * (log_amplitude[k] - y_mean);
    sxx += (t[k] - t_mean) * (t[k] - t_mean);
  }
  return -sxy / sxx / (2.0 * std::acos(-1.0) * frequency_hz);
}

ModeDecayCheck mode_decay_check(const case_file::Case& c, std::size_t damper_index, const st::ModalModel& modal,
                                st::Damper damper, const std::string& site, int mode, double modal_amplitude,
                                double frequency_hz, const ModeDecayWindow& window, const std::string& label,
                                const std::string& periods_pointer, base::RunHooks& hooks) {
  ModeDecayCheck out;
  out.mode = mode;
  out.frequency_hz = frequency_hz;
  damper.point = site;
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(modal.mode_count()));
  q0[mode] = modal_amplitude;
  st::Damper empty = damper;
  empty.layers.clear();
  out.damper_amplitude_m = std::abs(st::couple(modal, {empty}).drive_shapes(mode, 0) * modal_amplitude);
  out.bare_damping_ratio = averaged_damping_ratio(modal, empty, q0, mode, frequency_hz, window);
  out.predicted_damping_ratio = averaged_damping_ratio(modal, damper, q0, mode, frequency_hz, window) - out.bare_damping_ratio;

  st::CosimulationDamper bed = case_file::cosimulation_damper(c, damper_index);
  bed.point = site;
  case_file::DecayTask decay;
  decay.initial_state = case_file::DecayTask::InitialState::kModalAmplitudes;
  decay.modal_amplitudes.assign(q0.data(), q0.data() + q0.size());
  decay.duration_s = window.periods / frequency_hz;
  decay.settling_threshold = window.amplitude_fraction;
  const auto started = std::chrono::steady_clock::now();
  // Nothing after the first period below the fraction enters the measure: the run ends
  // there (0.9 of it, under the 0.976 that two sampled peaks allow; DecayStop).
  const DecayStop stop{mode, frequency_hz, 0.9 * window.amplitude_fraction};
  const DemDecay d = dem_decay(c, modal, {damper}, {bed}, q0, decay, label, periods_pointer, {}, hooks, 0, &stop,
                               ForcedStart{window.forced_start_periods, frequency_hz, kDescendingBranchFactor});
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const auto& h = d.cosimulation.history;
  const Eigen::VectorXd q = h.modal_displacements.col(mode);
  out.dem_damping_ratio =
      modal_decay_damping_ratio(h.time_s, q, frequency_hz, window.amplitude_fraction) - out.bare_damping_ratio;
  const std::vector<double> peaks = period_peaks(h.time_s, q, frequency_hz);
  if (!peaks.empty() && peaks.front() > 0.0) out.dem_final_fraction = peaks.back() / peaks.front();
  out.relative_difference = (out.predicted_damping_ratio - out.dem_damping_ratio) / out.dem_damping_ratio;
  return out;
}

}  // namespace pdamp::tasks
