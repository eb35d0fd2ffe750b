// The co-simulation run (docs/cosimulation.md §3-5, §8): its state as members, a coupled step
// as named, timed stages, and the measures fed after each step behind one interface; and
// cosimulate(), which runs it through (cosimulation.hpp).
#include "pdamp/structure/cosimulation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string_view>

#include "cosimulation_plan.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/dem_reference/drive_time_step.hpp"

namespace pdamp::structure {

namespace {

namespace dem = pdamp::dem_reference;
using base::format_number;
using detail::kTwoPi;
using Clock = std::chrono::steady_clock;

/// The progress clock is read every this many steps.
constexpr std::int64_t kProgressStride = 256;

double dot3(const dem::Vec3& a, const dem::Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

/// The drive at a step of the run: sin ψ, cos ψ, ψ̇ (rad/s), ψ̈ (rad/s²) and ψ − φ (rad).
struct Drive {
  double s = 0.0, c = 0.0, rate = 0.0, acceleration = 0.0, phase = 0.0;
};

/// What the measures read after a step: the state at its end and the drive at both ends
/// (references to the run's own members, so the view is built once).
struct StepView {
  const std::int64_t& step;  ///< the run's steps done, this one included
  const double& time_s;      ///< t at the step's end (the history's clock), s
  const Drive& before;
  const Drive& after;
  const Eigen::VectorXd& q;
  const std::vector<double>& site_y;      ///< y_d along the drive, m
  const std::vector<double>& site_theta;  ///< θ_d, rad
  const std::vector<double>& force;       ///< F_d, what the container applies to its bed along n, N
  const std::vector<double>& moment;      ///< M_d about the rotation axis, N m
};

/// A measure of the run, fed after every step (docs/cosimulation.md §5, §6a): the sampled
/// histories, the steady state's first harmonics, a sweep's cycles.
class RunMeasure {
 public:
  virtual ~RunMeasure() = default;
  /// After each step. A measure may move the run's end (`end_step`, in the run's steps): the
  /// steady state ends the transient once the response has settled.
  virtual void after_step(const StepView& s, std::int64_t& end_step) = 0;
  /// Its part of the result after `steps` steps of the run.
  virtual void write(CosimulationResult& result, std::int64_t steps) const = 0;
  /// The same, moving out what is large; the measure is spent afterwards.
  virtual void release(CosimulationResult& result, std::int64_t steps) { write(result, steps); }
  /// The progress stage it is in ("decay", "transient", "analysis", "sweep").
  virtual std::string_view stage() const = 0;
};

/// The sampled histories (CosimulationHistory), every `sample_every` steps of the run, into
/// arrays allocated for the whole run (the step loop allocates nothing).
class SampledHistory final : public RunMeasure {
 public:
  /// `earlier`: the histories of a restored run so far (rows up to max_samples), else none.
  SampledHistory(std::int64_t sample_every, std::int64_t max_samples, Eigen::Index modes, std::size_t dampers,
                 const CosimulationHistory* earlier)
      : sample_every_(sample_every), max_samples_(max_samples) {
    const auto columns = static_cast<Eigen::Index>(dampers);
    history_.time_s.reserve(static_cast<std::size_t>(max_samples));
    history_.modal_displacements.resize(max_samples, modes);
    history_.site_displacement_m.resize(max_samples, columns);
    history_.site_rotation_rad.resize(max_samples, columns);
    history_.container_load_n.resize(max_samples, columns);
    history_.container_moment_nm.resize(max_samples, columns);
    if (earlier) {
      samples_ = static_cast<Eigen::Index>(earlier->time_s.size());
      history_.time_s = earlier->time_s;
      history_.modal_displacements.topRows(samples_) = earlier->modal_displacements;
      history_.site_displacement_m.topRows(samples_) = earlier->site_displacement_m;
      history_.site_rotation_rad.topRows(samples_) = earlier->site_rotation_rad;
      history_.container_load_n.topRows(samples_) = earlier->container_load_n;
      history_.container_moment_nm.topRows(samples_) = earlier->container_moment_nm;
      history_.pending_load_sum_n = earlier->pending_load_sum_n;
      history_.pending_moment_sum_nm = earlier->pending_moment_sum_nm;
      history_.pending_steps = earlier->pending_steps;
    }
    history_.pending_load_sum_n.resize(dampers, 0.0);
    history_.pending_moment_sum_nm.resize(dampers, 0.0);
  }

  /// One sample: t, q, y_d, θ_d, and the bed's force and moment on the container (−F_d, −M_d).
  void record(double t, const Eigen::VectorXd& q, const std::vector<double>& site_y,
              const std::vector<double>& site_theta, const std::vector<double>& force,
              const std::vector<double>& moment) {
    if (samples_ >= max_samples_) return;
    auto& h = history_;
    h.time_s.push_back(t);
    h.modal_displacements.row(samples_) = q.transpose();
    for (std::size_t d = 0; d < site_y.size(); ++d) {
      const auto col = static_cast<Eigen::Index>(d);
      h.site_displacement_m(samples_, col) = site_y[d];
      h.site_rotation_rad(samples_, col) = site_theta[d];
      h.container_load_n(samples_, col) = -force[d];
      h.container_moment_nm(samples_, col) = -moment[d];
    }
    ++samples_;
  }

  /// The bed's force and moment are averaged over the steps since the last sample (an
  /// impact lasts a few steps, far shorter than a sample interval: a value read at the
  /// sample alone would alias it); the motion is read at the sample.
  void after_step(const StepView& s, std::int64_t&) override {
    auto& h = history_;
    for (std::size_t d = 0; d < s.force.size(); ++d)
      h.pending_load_sum_n[d] += s.force[d], h.pending_moment_sum_nm[d] += s.moment[d];
    ++h.pending_steps;
    if (s.step % sample_every_ != 0) return;
    for (std::size_t d = 0; d < s.force.size(); ++d) {
      h.pending_load_sum_n[d] /= static_cast<double>(h.pending_steps);
      h.pending_moment_sum_nm[d] /= static_cast<double>(h.pending_steps);
    }
    record(s.time_s, s.q, s.site_y, s.site_theta, h.pending_load_sum_n, h.pending_moment_sum_nm);
    std::fill(h.pending_load_sum_n.begin(), h.pending_load_sum_n.end(), 0.0);
    std::fill(h.pending_moment_sum_nm.begin(), h.pending_moment_sum_nm.end(), 0.0);
    h.pending_steps = 0;
  }

  void write(CosimulationResult& result, std::int64_t) const override {
    auto& h = result.history;
    h.time_s = history_.time_s;
    h.modal_displacements = history_.modal_displacements.topRows(samples_);
    h.site_displacement_m = history_.site_displacement_m.topRows(samples_);
    h.site_rotation_rad = history_.site_rotation_rad.topRows(samples_);
    h.container_load_n = history_.container_load_n.topRows(samples_);
    h.container_moment_nm = history_.container_moment_nm.topRows(samples_);
    h.pending_load_sum_n = history_.pending_load_sum_n;
    h.pending_moment_sum_nm = history_.pending_moment_sum_nm;
    h.pending_steps = history_.pending_steps;
  }

  void release(CosimulationResult& result, std::int64_t) override {
    auto& h = history_;
    for (auto* m : {&h.modal_displacements, &h.site_displacement_m, &h.site_rotation_rad, &h.container_load_n,
                    &h.container_moment_nm})
      m->conservativeResize(samples_, m->cols());
    result.history = std::move(h);
  }

  std::string_view stage() const override { return "decay"; }

 private:
  std::int64_t sample_every_ = 1;
  Eigen::Index max_samples_ = 0;
  Eigen::Index samples_ = 0;
  CosimulationHistory history_;
};

/// A harmonic run at one frequency (docs/cosimulation.md §5): the first harmonic at Ω of the
/// first site in each period, Ŷ = i(2/N) Σ y_k e^{−iψ_k} (the stability test of the
/// transient), and over the analysed periods of q, every site and every bed's force, with the
/// beds' η* and m_app from them.
class SteadyStateMeasure final : public RunMeasure {
 public:
  SteadyStateMeasure(const detail::RunOptions& options, std::int64_t steps_per_period, double frequency_hz,
                     std::vector<double> bed_masses_kg, Eigen::Index modes)
      : steps_per_period_(steps_per_period),
        transient_steps_(options.transient_periods * steps_per_period),
        min_transient_steps_(std::int64_t{options.min_transient_periods} * steps_per_period),
        analysed_periods_(options.analysed_periods),
        settle_until_stable_(options.settle_until_stable),
        stable_tolerance_(options.stable_tolerance),
        amplitude_(options.excitation.amplitude),
        frequency_hz_(frequency_hz),
        bed_masses_kg_(std::move(bed_masses_kg)),
        site_sum_(bed_masses_kg_.size(), {0.0, 0.0}),
        bed_force_sum_(bed_masses_kg_.size(), {0.0, 0.0}),
        modal_sum_(Eigen::VectorXcd::Zero(modes)),
        analysing_(options.transient_periods == 0),
        analysis_start_(analysing_ ? 0 : -1) {
    steady_.period_site_amplitudes_m.reserve(
        static_cast<std::size_t>(options.transient_periods + options.analysed_periods));
  }

  void after_step(const StepView& s, std::int64_t& end_step) override {
    // e^{−iΩt}·i·(2/N): amplitude against sin Ωt.
    const std::complex<double> kernel(s.after.s, s.after.c);  // i·e^{−iΩt} = sin + i cos
    period_sum_ += s.site_y[0] * kernel;
    if (analysing_) {
      for (std::size_t d = 0; d < site_sum_.size(); ++d)
        site_sum_[d] += s.site_y[d] * kernel, bed_force_sum_[d] += s.force[d] * kernel;
      for (Eigen::Index j = 0; j < modal_sum_.size(); ++j) modal_sum_[j] += s.q[j] * kernel;
    }
    if (s.step % steps_per_period_ != 0) return;
    const double amplitude = std::abs(period_sum_) * 2.0 / static_cast<double>(steps_per_period_);
    period_sum_ = {0.0, 0.0};
    auto& periods = steady_.period_site_amplitudes_m;
    if (periods.size() < periods.capacity()) periods.push_back(amplitude);
    if (analysing_) return;
    if (settle_until_stable_ && s.step >= min_transient_steps_)
      steady_.stable = amplitudes_converged(amplitude_window(periods), stable_tolerance_);
    if (steady_.stable || s.step >= transient_steps_) {
      const AmplitudeWindow w = amplitude_window(periods);  // the window the transient ends with
      steady_.window_periods = w.periods;
      steady_.window_max_relative_change = w.max_relative_change;
      steady_.window_relative_drift = w.relative_drift;
      steady_.window_relative_spread = w.relative_spread;
      analysing_ = true;
      analysis_start_ = s.step;
      end_step = s.step + analysed_periods_ * steps_per_period_;
    }
  }

  void write(CosimulationResult& result, std::int64_t steps) const override {
    auto& ss = result.steady_state;
    ss = steady_;
    ss.frequency_hz = frequency_hz_;
    ss.transient_periods = static_cast<int>(std::max<std::int64_t>(analysis_start_, 0) / steps_per_period_);
    const std::int64_t analysed_steps = analysis_start_ >= 0 ? steps - analysis_start_ : 0;
    ss.analysed_periods = static_cast<int>(analysed_steps / steps_per_period_);
    ss.modal_amplitudes = Eigen::VectorXcd::Zero(modal_sum_.size());
    if (analysed_steps > 0 && analysed_steps % steps_per_period_ == 0) {
      const double scale = 2.0 / static_cast<double>(analysed_steps);
      ss.modal_amplitudes = modal_sum_ * scale;
      for (std::size_t d = 0; d < site_sum_.size(); ++d) {
        const std::complex<double> y = site_sum_[d] * scale, force_hat = bed_force_sum_[d] * scale;
        ss.site_amplitudes_m.push_back(y);
        ss.site_amplitude_per_excitation.push_back(std::abs(y) / amplitude_);
        ss.bed_force_amplitudes_n.push_back(force_hat);
        detail::bed_measures(force_hat, y, kTwoPi * frequency_hz_, bed_masses_kg_[d], ss.bed_reduced_loss_factor,
                             ss.bed_apparent_mass_fraction);
      }
    }
  }

  std::string_view stage() const override { return analysing_ ? "analysis" : "transient"; }

 private:
  std::int64_t steps_per_period_;
  std::int64_t transient_steps_;
  std::int64_t min_transient_steps_;  ///< settle_until_stable: the transient lasts at least this
  std::int64_t analysed_periods_;
  bool settle_until_stable_;
  double stable_tolerance_;
  double amplitude_;
  double frequency_hz_;
  std::vector<double> bed_masses_kg_;
  std::complex<double> period_sum_{0.0, 0.0};  ///< this period's sum for the first site
  std::vector<std::complex<double>> site_sum_, bed_force_sum_;  ///< over the analysed periods
  Eigen::VectorXcd modal_sum_;
  bool analysing_;
  std::int64_t analysis_start_;  ///< the step the analysis started at, −1 before
  CosimulationSteadyState steady_;  ///< the per-period amplitudes and `stable` so far
};

/// A linear sweep (docs/cosimulation.md §6a): per drive cycle (ψ − φ from 2πk to 2π(k + 1))
/// the first harmonic Ŷ = (i/π)∫y e^{−iψ}dψ with each step's exact dψ, and the beds' measures.
class SweepCycleMeasure final : public RunMeasure {
 public:
  SweepCycleMeasure(double f0_hz, double rate_hz_s, double start_time_s, double amplitude,
                    std::vector<double> bed_masses_kg)
      : f0_hz_(f0_hz),
        rate_hz_s_(rate_hz_s),
        start_time_s_(start_time_s),
        amplitude_(amplitude),
        bed_masses_kg_(std::move(bed_masses_kg)),
        cycle_site_(bed_masses_kg_.size(), {0.0, 0.0}),
        cycle_force_(bed_masses_kg_.size(), {0.0, 0.0}) {}

  void after_step(const StepView& s, std::int64_t&) override {
    // (1/π)·i·e^{−iψ} dψ over the step, dψ exact; a cycle closes once ψ − φ passes 2π(k + 1).
    const double dpsi = s.after.phase - s.before.phase;
    const std::complex<double> kernel(s.after.s * dpsi, s.after.c * dpsi);
    for (std::size_t d = 0; d < cycle_site_.size(); ++d)
      cycle_site_[d] += s.site_y[d] * kernel, cycle_force_[d] += s.force[d] * kernel;
    if (s.after.phase >= cycle_end_phase_ * (1.0 - 1e-14)) close_cycle();  // the sweep's last step ends one to round-off
  }

  void write(CosimulationResult& result, std::int64_t) const override { result.sweep_cycles = cycles_; }

  std::string_view stage() const override { return "sweep"; }

 private:
  void close_cycle() {
    const double k = cycle_end_phase_ / kTwoPi;  // cycles ended
    const double t_a = detail::sweep_cycle_time(f0_hz_, rate_hz_s_, k - 1.0);
    const double t_b = detail::sweep_cycle_time(f0_hz_, rate_hz_s_, k);
    CosimulationSweepCycle cycle;
    cycle.time_s = start_time_s_ + 0.5 * (t_a + t_b);
    cycle.frequency_hz = 1.0 / (t_b - t_a);
    for (std::size_t d = 0; d < cycle_site_.size(); ++d) {
      const std::complex<double> y = cycle_site_[d] / std::numbers::pi, force_hat = cycle_force_[d] / std::numbers::pi;
      cycle.site_amplitudes_m.push_back(y);
      cycle.site_amplitude_per_excitation.push_back(std::abs(y) / amplitude_);
      cycle.bed_force_amplitudes_n.push_back(force_hat);
      detail::bed_measures(force_hat, y, kTwoPi * cycle.frequency_hz, bed_masses_kg_[d], cycle.bed_reduced_loss_factor,
                           cycle.bed_apparent_mass_fraction);
      cycle_site_[d] = cycle_force_[d] = {0.0, 0.0};
    }
    cycles_.push_back(std::move(cycle));
    cycle_end_phase_ += kTwoPi;
  }

  double f0_hz_, rate_hz_s_, start_time_s_, amplitude_;
  std::vector<double> bed_masses_kg_;
  std::vector<std::complex<double>> cycle_site_, cycle_force_;  ///< the current cycle's sums
  double cycle_end_phase_ = kTwoPi;  ///< ψ − φ where the current cycle ends, rad
  std::vector<CosimulationSweepCycle> cycles_;
};

/// Reads the clock between the stages of a timed step (CosimulationStageTimes): on the
/// others it reads nothing.
class StageClock {
 public:
  explicit StageClock(bool timed) : timed_(timed), last_(timed ? Clock::now() : Clock::time_point{}) {}
  /// Adds the time since the last lap, times the timing stride, to `stage_s`.
  void lap(double& stage_s) {
    if (!timed_) return;
    const auto now = Clock::now();
    stage_s += static_cast<double>(kCosimulationTimingStride) * std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  bool timed_;
  Clock::time_point last_;
};

}  // namespace

struct Cosimulation::Impl {
  /// A fresh run (`state` and `earlier` null), a continuation of `state`, or a restored free
  /// decay (`state` and `earlier` from a checkpoint). Throws before it takes `state`.
  Impl(const ModalModel& model, const std::vector<CosimulationDamper>& dampers, const detail::RunOptions& options,
       CosimulationState* state, const CosimulationResult* earlier, base::RunHooks& hooks);

  // --- Construction, in order.
  void check_inputs(const ModalModel& model, const CosimulationState* state, const CosimulationResult* earlier) const;
  void plan(const ModalModel& model, const CosimulationState* state, const CosimulationResult* earlier);
  void plan_length();
  void tabulate_drive();
  void place_containers();
  void build_and_settle_worlds();
  void open_ledger();
  void open_measures(const CosimulationResult* earlier);
  void open_snapshots(const CosimulationResult* earlier);

  // --- A coupled step: the stages in order (docs/cosimulation.md §3). Inlined into step():
  // out of line, their calls and a view of the state built per step cost about 170
  // instructions a step, 8% of a step of a lone sphere on 8 modes (cachegrind, and timed).
  bool step();
  [[gnu::always_inline]] void kick_and_drift();
  [[gnu::always_inline]] bool step_beds();
  [[gnu::always_inline]] void closing_kick();
  [[gnu::always_inline]] void account_energy();
  bool force_start(std::size_t d, const std::function<void(std::int64_t)>& observe);
  /// Steps of the forced start (0 without one): whole periods rounded to whole steps.
  std::int64_t forced_start_steps() const {
    if (options_.forced_start_periods <= 0) return 0;
    return std::max<std::int64_t>(1, std::llround(options_.forced_start_periods / (options_.forced_start_frequency_hz * dt_)));
  }
  [[gnu::always_inline]] void commit_step();
  [[gnu::always_inline]] void feed_measures();
  void report_progress();
  /// Every bed's particles and container now (CosimulationSettings::snapshots): at the
  /// planned steps only, so the copy is outside the step loop's allocation-free path.
  void take_snapshots();
  std::int64_t snapshot_step(std::size_t s) const {
    return static_cast<std::int64_t>((static_cast<double>(s) + 1.0) * static_cast<double>(planned_steps_) /
                                     options_.snapshots);
  }

  // --- Kinematics, loads and energies.
  double time_at(std::int64_t k) const { return static_cast<double>(steps0_ + k) * dt_; }
  Drive drive_at(std::int64_t k) const;
  /// The factor of load_shape: sin ψ for a force, −ü_b/U = ψ̇² sin ψ − ψ̈ cos ψ for the base.
  double load_factor(const Drive& a) const { return is_base_ ? a.rate * a.rate * a.s - a.acceleration * a.c : a.s; }
  [[gnu::always_inline]] void site_state(std::size_t d, const Eigen::VectorXd& qq, double base, double base_velocity,
                                         const Eigen::VectorXd& qdot, dem::ContainerState& s);
  void read_load(std::size_t d, const dem::ContainerLoad& load);
  void modal_load(double factor, const Eigen::VectorXd& qq, Eigen::VectorXd& out) const;
  double structure_kinetic(const Eigen::VectorXd& vv, double base_velocity, Eigen::VectorXd& scratch) const;
  double structure_potential(const Eigen::VectorXd& qq) const { return 0.5 * qq.dot(modal_.K.cwiseProduct(qq)); }
  double base_power(const Eigen::VectorXd& accel, double base_velocity) const;
  CosimulationEnergy ledger(double work, double damping, double kinetic_start, double potential_start,
                            const std::vector<dem::EnergyAccount>& start, double kinetic_end, double potential_end) const;
  /// T' and V of the structure at the run's present step.
  std::pair<double, double> structure_energy_now() const;

  std::int64_t advance(std::int64_t steps);
  bool finished() const { return outcome_ != dem::Outcome::kCompleted || step_ >= end_step_; }
  /// The run so far; `release`: the measures' large parts moved out (the run is spent).
  CosimulationResult result(bool release);
  void sync_state();

  // --- Inputs.
  std::vector<CosimulationDamper> dampers_;
  detail::RunOptions options_;
  base::RunHooks* hooks_;
  int stop_signal_ = 0;  ///< the stop request that ended advance() early
  bool continuation_ = false;  ///< continues a CosimulationState (no settling)
  bool restored_ = false;      ///< a free decay restored from its checkpoint
  bool is_harmonic_ = false, is_sweep_ = false, is_base_ = false, periodic_ = false;
  Eigen::Index n_ = 0;
  std::size_t dcount_ = 0;

  // --- The plan: modal arrays, step, drive.
  detail::Prepared modal_;  ///< the modal arrays with the containers, the excitation's shapes
  std::vector<dem::WorldOptions> world_options_;  ///< a fresh run's worlds
  std::vector<dem::Vec3> across_axis_;  ///< the container axis that follows t_d = z × n_d: c = k × a
  Eigen::MatrixXd A_inv_;               ///< (M + ½dt C)⁻¹
  double dt_ = 0.0, half_dt_ = 0.0;
  std::int64_t steps_per_period_ = 0;
  double f_run_ = 0.0, f_plan_ = 0.0;
  double phase0_ = 0.0;            ///< the drive's phase φ at the run's start, rad
  double sweep_rate_ = 0.0;        ///< Hz/s
  std::int64_t steps0_ = 0;        ///< steps since the first run's start at this run's step 0
  std::int64_t planned_steps_ = 0, sample_every_ = 1, max_samples_ = 0;
  std::vector<double> sin_table_, cos_table_;  ///< sin ψ, cos ψ at the steps of a period (one frequency)

  // --- The run's state: modes, containers, loads, drive.
  std::int64_t step_ = 0, end_step_ = 0;
  Eigen::VectorXd q_, v_, acc_;                             ///< q, q̇, q̈ at step_
  Eigen::VectorXd vh_, q_new_, v_new_, acc_new_, g_, tmp_;  ///< the step's (preallocated)
  std::vector<double> site_y_, site_across_, site_theta_;
  std::vector<dem::ContainerState> containers_;
  /// Bed loads on the structure: F_d along a, G_d along c (across) and M_d about k, what the
  /// container applies to the bed.
  std::vector<double> force_, force_across_, moment_;
  Drive drive_now_, drive_next_;
  double t_next_ = 0.0, base_next_ = 0.0, base_velocity_next_ = 0.0;

  // --- The energy ledger (docs/cosimulation.md §4).
  double power_ = 0.0;  ///< base reaction power at step_, W
  double work_ = 0.0, damping_ = 0.0;  ///< this run's sums (a restored run's since the first start)
  double work_since_start_ = 0.0, damping_since_start_ = 0.0;
  double kinetic0_ = 0.0, potential0_ = 0.0;
  std::vector<dem::EnergyAccount> opening_;
  CosimulationState state_;  ///< the worlds; the rest is brought up to date by sync_state()

  // --- Measures and the result's own fields.
  std::vector<std::unique_ptr<RunMeasure>> measures_;  ///< the kind's measure first, the histories last
  /// What they read after each step.
  const StepView view_{step_, t_next_, drive_now_, drive_next_, q_, site_y_, site_theta_, force_, moment_};
  std::vector<std::vector<BedSnapshot>> snapshots_;
  std::int64_t next_snapshot_step_ = -1;  ///< -1: no more snapshots
  std::int64_t untimed_steps_ = 0;  ///< steps until the next timed one (CosimulationStageTimes)
  dem::Outcome outcome_ = dem::Outcome::kCompleted;
  std::string message_;
  std::vector<std::string> warnings_;
  std::int64_t settling_steps_ = 0;
  double start_time_s_ = 0.0;
  bool continued_ = false;
  Eigen::VectorXd frequencies_with_containers_hz_;
  double wall_s_ = 0.0;  ///< wall time of construction and advance() calls (a restored run's since the first start)
  CosimulationStageTimes stage_times_;
  Clock::time_point last_report_;
  std::int64_t last_report_step_ = 0;
};

Cosimulation::Impl::Impl(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                         const detail::RunOptions& options, CosimulationState* state,
                         const CosimulationResult* earlier, base::RunHooks& hooks)
    : dampers_(dampers), options_(options), hooks_(&hooks) {
  const auto wall_start = Clock::now();
  continuation_ = state != nullptr && earlier == nullptr;
  restored_ = earlier != nullptr;
  const auto& exc = options_.excitation;
  is_harmonic_ = detail::harmonic(exc);
  is_sweep_ = detail::sweeping(options_);
  is_base_ = exc.kind == CosimulationExcitationKind::kBaseTranslation;
  periodic_ = is_harmonic_ && !is_sweep_;  // one frequency, whole periods
  n_ = model.mode_count();
  dcount_ = dampers_.size();

  check_inputs(model, state, earlier);
  plan(model, state, earlier);
  plan_length();
  tabulate_drive();
  if (state) state_ = std::move(*state);  // the last throw is behind: the state is taken over
  place_containers();
  if (!continuation_ && !restored_) build_and_settle_worlds();
  open_ledger();
  open_measures(earlier);
  open_snapshots(earlier);
  wall_s_ = (earlier ? earlier->wall_time_s : 0.0) + seconds_since(wall_start);
  last_report_ = Clock::now();
}

// Every violation, one per line; a restored decay also fits its checkpoint to the options.
void Cosimulation::Impl::check_inputs(const ModalModel& model, const CosimulationState* state,
                                      const CosimulationResult* earlier) const {
  detail::validate_inputs(model, dampers_, options_, continuation_);
  if (continuation_) detail::validate_state(model, dampers_, options_, *state);
  if (!restored_) return;
  std::vector<std::string> p;
  const std::string at = "cosimulation checkpoint: ";
  if (is_harmonic_)
    p.push_back(at + "continues a free decay only (a harmonic run's measures are not in a checkpoint: continue its "
                     "CosimulationState with a new run)");
  if (state->excitation.kind != options_.excitation.kind)
    p.push_back(at + "excitation.kind: a run of another excitation");
  for (std::size_t d = 0; d < state->worlds.size(); ++d)
    if (state->worlds[d].status().outcome != dem::Outcome::kCompleted)
      p.push_back(at + "world " + std::to_string(d) + " stopped (" + state->worlds[d].status().message +
                  "): it cannot be continued");
  if (earlier->outcome != dem::Outcome::kCompleted) p.push_back(at + "outcome: the run had stopped: " + earlier->message);
  if (earlier->steps > state->steps)
    p.push_back(at + "steps = " + std::to_string(earlier->steps) + " in the result, " + std::to_string(state->steps) +
                " in the state: must not be more");
  if (!p.empty()) throw std::invalid_argument(detail::join(p));
}

// Frequency, step and steps per period, the modal arrays with the containers and the warnings.
// A continuation keeps the worlds' step: the period takes the nearest whole number of them
// (the frequency run is 1/(N dt)). A restored decay plans as its fresh start did and must find
// the checkpoint's step.
void Cosimulation::Impl::plan(const ModalModel& model, const CosimulationState* state,
                              const CosimulationResult* earlier) {
  const auto& exc = options_.excitation;
  const Eigen::VectorXd q_start = continuation_ ? state->modal_displacements
                                                : detail::start_vector(options_.initial_modal_displacements, n_);
  const Eigen::VectorXd v_start = continuation_ ? state->modal_velocities
                                                : detail::start_vector(options_.initial_modal_velocities, n_);
  f_run_ = is_harmonic_ ? exc.frequency_hz : 0.0;
  // A sweep plans its step at its highest frequency (the drive's step rule is per period).
  f_plan_ = is_sweep_ ? std::max(exc.frequency_hz, options_.sweep_end_frequency_hz) : f_run_;
  if (continuation_) {
    dt_ = state->time_step_s;
    if (periodic_) {
      steps_per_period_ = std::max<std::int64_t>(1, std::llround(1.0 / (exc.frequency_hz * dt_)));
      if (steps_per_period_ < 8)
        throw std::invalid_argument("cosimulation.excitation.frequency_hz = " + format_number(exc.frequency_hz, 12) +
                                    ": a period of the state's step " + format_number(dt_, 12) + " s is only " +
                                    std::to_string(steps_per_period_) + " steps (at least 8)");
      const double whole = 1.0 / (static_cast<double>(steps_per_period_) * dt_);
      if (std::abs(whole - exc.frequency_hz) > 1e-12 * exc.frequency_hz) f_run_ = whole;
      if (std::abs(whole - exc.frequency_hz) > detail::kFrequencyChangeWarning * exc.frequency_hz)
        warnings_.push_back("frequency " + format_number(exc.frequency_hz, 12) + " Hz run as " +
                            format_number(whole, 12) + " Hz: " + std::to_string(steps_per_period_) +
                            " whole steps of the carried-over step " + format_number(dt_, 12) + " s per period");
    }
  }
  modal_ = detail::prepare(model, dampers_, options_, f_run_, q_start, v_start);
  if (!restored_) warnings_.insert(warnings_.end(), modal_.warnings.begin(), modal_.warnings.end());
  if (continuation_) {
    // The step this frequency would take on its own: a warning if the carried one is longer.
    detail::RunOptions automatic = options_;
    automatic.time_step_s = 0.0;
    const detail::StepPlan own = detail::plan_step(modal_, dampers_, automatic, f_plan_);
    if (dt_ > own.dt * (1.0 + detail::kCarriedStepMargin))
      warnings_.push_back("the carried-over step " + format_number(dt_, 12) + " s is above the automatic step " +
                          format_number(own.dt, 12) + " s" +
                          (is_harmonic_ ? " at " + format_number(f_plan_, 12) + " Hz" : std::string()) +
                          ": contacts are resolved more coarsely (plan the sweep's step with "
                          "cosimulation_time_step at its most demanding frequency)");
    if (modal_.w.maxCoeff() * dt_ > detail::kStructureStepLimit)
      throw std::invalid_argument("cosimulation state: time_step_s = " + format_number(dt_, 12) +
                                  ": the highest mode needs ω·dt <= 0.2");
  } else {
    detail::StepPlan plan = detail::plan_step(modal_, dampers_, options_, f_plan_);
    dt_ = plan.dt;
    steps_per_period_ = is_sweep_ ? 0 : plan.steps_per_period;
    if (restored_) {
      if (state->time_step_s != dt_)
        throw std::invalid_argument("cosimulation checkpoint: time_step_s = " + format_number(state->time_step_s, 12) +
                                    ": this run's step is " + format_number(dt_, 12) +
                                    " s (a checkpoint of other settings)");
      warnings_ = earlier->warnings;
    } else {
      for (auto& wline : plan.warnings) warnings_.push_back(std::move(wline));
      world_options_ = std::move(plan.world_options);
      for (auto& wo : world_options_) wo.integration.time_step_s = dt_;
    }
  }
  half_dt_ = 0.5 * dt_;
  across_axis_.resize(dcount_);
  for (std::size_t d = 0; d < dcount_; ++d) {
    const dem::Vec3& k = dampers_[d].container_rotation_axis;
    const dem::Vec3& a = dampers_[d].container_drive_axis;
    across_axis_[d] = {k[1] * a[2] - k[2] * a[1], k[2] * a[0] - k[0] * a[2], k[0] * a[1] - k[1] * a[0]};
  }
  frequencies_with_containers_hz_ = natural_frequencies_with_containers_hz(modal_.coupled);
  // The drive's phase at the start: a harmonic continuation goes on where the last run ended.
  phase0_ = continuation_ ? state->excitation_phase_rad : (is_harmonic_ ? options_.excitation_phase_rad : 0.0);
  // Times are whole steps since the first run's start, (steps0 + k)·dt: a run continued in
  // segments samples the same instants, to the bit, as one run (its dt never changes). A
  // restored decay counts its steps from its own start, which is the state's steps before.
  steps0_ = continuation_ ? state->steps : restored_ ? state->steps - earlier->steps : 0;
  step_ = restored_ ? earlier->steps : 0;
  start_time_s_ = restored_ ? earlier->start_time_s : time_at(0);
  continued_ = restored_ ? earlier->continued : continuation_;
  if (restored_) settling_steps_ = earlier->settling_steps;
  q_ = state ? state->modal_displacements : q_start;
  v_ = state ? state->modal_velocities : v_start;
}

// The planned length and the history's sampling.
void Cosimulation::Impl::plan_length() {
  const std::int64_t transient_steps = periodic_ ? options_.transient_periods * steps_per_period_ : 0;
  planned_steps_ = periodic_ ? transient_steps + options_.analysed_periods * steps_per_period_
                             : static_cast<std::int64_t>(std::llround(options_.duration_s / dt_));
  end_step_ = planned_steps_;
  double interval = options_.sample_interval_s;
  if (interval == 0.0) interval = is_harmonic_ ? 1.0 / (64.0 * f_plan_) : options_.duration_s / 2000.0;
  sample_every_ = std::max<std::int64_t>(1, std::llround(interval / dt_));
  max_samples_ = planned_steps_ / sample_every_ + 1;
}

// sin ψ and cos ψ, ψ = 2πk/N + φ, at the steps of a period (one frequency), tabulated once.
void Cosimulation::Impl::tabulate_drive() {
  if (!periodic_) {
    sweep_rate_ = is_sweep_ ? (options_.sweep_end_frequency_hz - options_.excitation.frequency_hz) / options_.duration_s
                            : 0.0;
    return;
  }
  sin_table_.resize(static_cast<std::size_t>(steps_per_period_));
  cos_table_.resize(static_cast<std::size_t>(steps_per_period_));
  for (std::int64_t k = 0; k < steps_per_period_; ++k) {
    const double phase = kTwoPi * static_cast<double>(k) / static_cast<double>(steps_per_period_) + phase0_;
    sin_table_[static_cast<std::size_t>(k)] = std::sin(phase);
    cos_table_[static_cast<std::size_t>(k)] = std::cos(phase);
  }
}

// The drive at step k of this run (a sweep: ψ = φ + 2π(f₀τ + ½rτ²), τ = k dt, computed per
// step; its cost is nothing next to a DEM step).
Drive Cosimulation::Impl::drive_at(std::int64_t k) const {
  if (!is_harmonic_) return {};
  if (!is_sweep_) {
    const auto i = static_cast<std::size_t>(k % steps_per_period_);
    return {sin_table_[i], cos_table_[i], modal_.omega, 0.0, 0.0};
  }
  const double f0 = options_.excitation.frequency_hz;
  const double tau = static_cast<double>(k) * dt_;
  const double phase = kTwoPi * tau * (f0 + 0.5 * sweep_rate_ * tau);
  return {std::sin(phase0_ + phase), std::cos(phase0_ + phase), kTwoPi * (f0 + sweep_rate_ * tau),
          kTwoPi * sweep_rate_, phase};
}

// Container kinematics of damper d for modal state qq (§2): position a·y + c·x, orientation
// Rodrigues(k, θ), velocities from qdot; leaves y, x, θ in site_y_, site_across_, site_theta_.
inline void Cosimulation::Impl::site_state(std::size_t d, const Eigen::VectorXd& qq, double base,
                                           double base_velocity, const Eigen::VectorXd& qdot,
                                           dem::ContainerState& s) {
  const auto col = static_cast<Eigen::Index>(d);
  const auto& cd = dampers_[d];
  const double y = modal_.B.col(col).dot(qq) + modal_.drive_dot_e[d] * base;
  const double ydot = modal_.B.col(col).dot(qdot) + modal_.drive_dot_e[d] * base_velocity;
  const double x = modal_.T.col(col).dot(qq) + modal_.across_dot_e[d] * base;  // across the drive
  const double xdot = modal_.T.col(col).dot(qdot) + modal_.across_dot_e[d] * base_velocity;
  const double theta = modal_.R.col(col).dot(qq);
  const double theta_dot = modal_.R.col(col).dot(qdot);
  for (int a = 0; a < 3; ++a) {
    s.position_m[a] = cd.container_drive_axis[a] * y + across_axis_[d][a] * x;
    s.velocity_m_s[a] = cd.container_drive_axis[a] * ydot + across_axis_[d][a] * xdot;
    s.angular_velocity_rad_s[a] = cd.container_rotation_axis[a] * theta_dot;
  }
  s.orientation = theta == 0.0 ? dem::kIdentity : rotation_about(cd.container_rotation_axis, theta);
  site_y_[d] = y;
  site_across_[d] = x;
  site_theta_[d] = theta;
}

void Cosimulation::Impl::read_load(std::size_t d, const dem::ContainerLoad& load) {
  force_[d] = dot3(load.force_n, dampers_[d].container_drive_axis);
  force_across_[d] = dot3(load.force_n, across_axis_[d]);
  moment_[d] = dot3(load.moment_nm, dampers_[d].container_rotation_axis);
}

// The containers at the start pose and velocity.
void Cosimulation::Impl::place_containers() {
  site_y_.assign(dcount_, 0.0);
  site_across_.assign(dcount_, 0.0);
  site_theta_.assign(dcount_, 0.0);
  containers_.assign(dcount_, dem::ContainerState{});
  drive_now_ = drive_at(0);
  const double base0 = modal_.U * drive_now_.s;                              // u_b = U sin ψ
  const double base_velocity0 = modal_.U * drive_now_.rate * drive_now_.c;  // u̇_b = Uψ̇ cos ψ
  for (std::size_t d = 0; d < dcount_; ++d) site_state(d, q_, base0, base_velocity0, v_, containers_[d]);
}

// A fresh run's worlds, built at the start pose, and the beds settled with the structure held.
void Cosimulation::Impl::build_and_settle_worlds() {
  const auto settling_start = Clock::now();
  auto& worlds = state_.worlds;
  worlds.clear();
  worlds.reserve(dcount_);
  for (std::size_t d = 0; d < dcount_; ++d) worlds.emplace_back(world_options_[d], containers_[d]);
  for (std::size_t d = 0; d < dcount_; ++d) {
    const double settling = options_.bed_settling_time_s >= 0.0 ? options_.bed_settling_time_s
                                                                : dem::automatic_settling_time_s(world_options_[d]);
    const auto steps = static_cast<std::int64_t>(std::llround(settling / dt_));
    settling_steps_ = std::max(settling_steps_, steps + forced_start_steps());
    const double end_s = static_cast<double>(planned_steps_) * dt_;
    hooks_->progress({"", "settling", 0.0, end_s, false, 0.0, NAN});
    // A big bed settles for hours: a "settling" report about every progress_interval_s, and
    // a stop request met within kStopPollSteps steps. No consistent state exists yet, so a
    // stop ends the run without one.
    auto last = Clock::now();
    const auto observe = [&](std::int64_t k) {
      if ((k + 1) % Cosimulation::kStopPollSteps != 0) return;
      if (const int signal = hooks_->stop_requested(); signal != 0)
        throw base::Interrupted(signal, "the co-simulation stopped while its beds settled, before its coupled steps: "
                                        "nothing was kept");
      const auto now = Clock::now();
      const double since = std::chrono::duration<double>(now - last).count();
      if (since < options_.progress_interval_s) return;
      last = now;
      hooks_->progress({"", "settling", 0.0, end_s, false, static_cast<double>(Cosimulation::kStopPollSteps) / since, NAN});
    };
    if (!dem::settle(worlds[d], containers_[d], steps, observe)) {
      outcome_ = worlds[d].status().outcome;
      message_ = "damper " + dampers_[d].name + " (settling): " + worlds[d].status().message;
    } else if (options_.forced_start_periods > 0 && !force_start(d, observe)) {
      outcome_ = worlds[d].status().outcome;
      message_ = "damper " + dampers_[d].name + " (forced start): " + worlds[d].status().message;
    }
  }
  stage_times_.settling_s = seconds_since(settling_start);
}

// The forced start (CosimulationSettings::forced_start_periods): the container of bed d moves
// as its start pose times a(t)·cos φ(t), t from the settled bed (at rest at the start pose) to
// the same pose at rest again. φ advances 2π·periods·k/steps (the last step lands on a whole
// period, the step need not divide it); a = 1 + (P − 1)·sin²(πk/steps) rises to the peak
// factor P half-way and eases back to 1 with zero slope at both ends. The last state is the
// start pose itself.
bool Cosimulation::Impl::force_start(std::size_t d, const std::function<void(std::int64_t)>& observe) {
  dem::World& world = state_.worlds[d];
  const dem::ContainerState& start = containers_[d];
  const auto& cd = dampers_[d];
  const double pi = std::acos(-1.0);
  const std::int64_t steps = forced_start_steps();
  const double n = static_cast<double>(steps);
  const double angle_per_step = 2.0 * pi * options_.forced_start_periods / n;
  const double omega = angle_per_step / dt_;
  const double rise = options_.forced_start_peak_factor - 1.0;
  dem::ContainerState s = start;
  for (std::int64_t k = 0; k < steps; ++k) {
    if (k + 1 == steps) {
      s = start;
    } else {
      const double step = static_cast<double>(k + 1);
      const double c = std::cos(angle_per_step * step), sn = std::sin(angle_per_step * step);
      const double envelope = 1.0 + rise * std::pow(std::sin(pi * step / n), 2);
      const double envelope_rate = rise * std::sin(2.0 * pi * step / n) * pi / (n * dt_);
      const double scale = envelope * c, rate = envelope_rate * c - envelope * omega * sn;
      for (int a = 0; a < 3; ++a) {
        s.position_m[a] = start.position_m[a] * scale;
        s.velocity_m_s[a] = start.position_m[a] * rate;
        s.angular_velocity_rad_s[a] = cd.container_rotation_axis[a] * site_theta_[d] * rate;
      }
      s.orientation =
          site_theta_[d] == 0.0 ? dem::kIdentity : rotation_about(cd.container_rotation_axis, site_theta_[d] * scale);
    }
    world.step(s);
    if (world.status().outcome != dem::Outcome::kCompleted) return false;
    observe(k);
  }
  return true;
}

// The loads and energies at the start, q̈(0), and the ledger's opening: this run's, or for a
// restored decay the first start's (its sums continue).
void Cosimulation::Impl::open_ledger() {
  force_.assign(dcount_, 0.0);
  force_across_.assign(dcount_, 0.0);
  moment_.assign(dcount_, 0.0);
  for (std::size_t d = 0; d < dcount_; ++d) read_load(d, state_.worlds[d].load());
  for (const auto& world : state_.worlds) opening_.push_back(world.energy());

  // The step's vectors, preallocated (the step loop allocates nothing).
  for (auto* x : {&g_, &tmp_, &acc_, &vh_, &q_new_, &v_new_, &acc_new_}) x->resize(n_);
  A_inv_ = (modal_.M + 0.5 * dt_ * Eigen::MatrixXd(modal_.C.asDiagonal())).inverse();
  const double base_velocity0 = modal_.U * drive_now_.rate * drive_now_.c;
  kinetic0_ = structure_kinetic(v_, base_velocity0, tmp_);
  potential0_ = structure_potential(q_);
  modal_load(load_factor(drive_now_), q_, g_);
  tmp_ = g_ - modal_.C.cwiseProduct(v_);
  if (restored_) {
    // The closing kick's own product: q̈ to the bit of the step that ended at the checkpoint.
    acc_.noalias() = modal_.M_inv.lazyProduct(tmp_);
  } else {
    acc_.noalias() = modal_.M_inv * tmp_;
  }
  power_ = is_base_ ? base_power(acc_, base_velocity0) : 0.0;
  // The same sums since the first run's start (CosimulationState::energy_since_start).
  if (continuation_ || restored_) {
    work_since_start_ = state_.energy_since_start.excitation_work_j;
    damping_since_start_ = state_.energy_since_start.structural_damping_j;
  } else {
    state_.start_structure_kinetic_j = kinetic0_;
    state_.start_structure_potential_j = potential0_;
    state_.start_world_energy = opening_;
  }
  if (restored_) {
    work_ = work_since_start_;
    damping_ = damping_since_start_;
    kinetic0_ = state_.start_structure_kinetic_j;
    potential0_ = state_.start_structure_potential_j;
    opening_ = state_.start_world_energy;
  }
}

// The kind's measure first (it names the progress stage), then the histories, whose first
// sample is the start (a restored decay has its samples so far).
void Cosimulation::Impl::open_measures(const CosimulationResult* earlier) {
  std::vector<double> bed_masses_kg;
  for (const auto& world : state_.worlds) bed_masses_kg.push_back(world.bed_mass_kg());
  if (periodic_) {
    measures_.push_back(
        std::make_unique<SteadyStateMeasure>(options_, steps_per_period_, f_run_, std::move(bed_masses_kg), n_));
  } else if (is_sweep_) {
    measures_.push_back(std::make_unique<SweepCycleMeasure>(options_.excitation.frequency_hz, sweep_rate_, time_at(0),
                                                            options_.excitation.amplitude, std::move(bed_masses_kg)));
  }
  auto history = std::make_unique<SampledHistory>(sample_every_, max_samples_, n_, dcount_,
                                                  earlier ? &earlier->history : nullptr);
  if (!earlier) history->record(time_at(0), q_, site_y_, site_theta_, force_, moment_);
  measures_.push_back(std::move(history));
}

// The snapshots taken so far (a restored run's from its checkpoint), the next one's step.
void Cosimulation::Impl::open_snapshots(const CosimulationResult* earlier) {
  if (options_.snapshots <= 0) return;
  if (options_.snapshots > planned_steps_)
    throw std::invalid_argument("cosimulation.snapshots = " + std::to_string(options_.snapshots) +
                                ": more than the run's " + std::to_string(planned_steps_) + " steps");
  if (earlier) snapshots_ = earlier->bed_snapshots;
  if (snapshots_.size() < static_cast<std::size_t>(options_.snapshots)) next_snapshot_step_ = snapshot_step(snapshots_.size());
}

void Cosimulation::Impl::take_snapshots() {
  std::vector<BedSnapshot> beds;
  for (std::size_t d = 0; d < dcount_; ++d)
    beds.push_back({dem::particle_snapshot(state_.worlds[d], t_next_), state_.worlds[d].container().position_m});
  snapshots_.push_back(std::move(beds));
  next_snapshot_step_ =
      snapshots_.size() < static_cast<std::size_t>(options_.snapshots) ? snapshot_step(snapshots_.size()) : -1;
}

std::int64_t Cosimulation::Impl::advance(std::int64_t steps) {
  const auto wall_start = Clock::now();
  std::int64_t taken = 0;
  stop_signal_ = 0;
  while (taken < steps && step_ < end_step_ && outcome_ == dem::Outcome::kCompleted && step()) {
    ++taken;
    if (taken % kStopPollSteps == 0 && (stop_signal_ = hooks_->stop_requested()) != 0) break;
  }
  wall_s_ += seconds_since(wall_start);
  return taken;
}

// One coupled step, t_k → t_{k+1} (docs/cosimulation.md §3): false when a World stopped (the
// step then does not count).
bool Cosimulation::Impl::step() {
  const bool timed = untimed_steps_-- == 0;
  if (timed) untimed_steps_ = kCosimulationTimingStride - 1;
  StageClock clock(timed);
  kick_and_drift();
  clock.lap(stage_times_.modal_kick_drift_s);
  if (!step_beds()) return false;
  clock.lap(stage_times_.bed_steps_s);
  closing_kick();
  clock.lap(stage_times_.closing_kick_s);
  account_energy();
  commit_step();
  clock.lap(stage_times_.ledger_s);
  feed_measures();
  drive_now_ = drive_next_;
  clock.lap(stage_times_.measures_s);
  report_progress();
  return true;
}

// Kick and drift of the modes (velocity Verlet): v_{k+½} = v_k + ½dt q̈_k,
// q_{k+1} = q_k + dt v_{k+½}; the drive and the base at t_{k+1}.
inline void Cosimulation::Impl::kick_and_drift() {
  vh_ = v_ + half_dt_ * acc_;
  q_new_ = q_ + dt_ * vh_;
  const std::int64_t next = step_ + 1;
  t_next_ = time_at(next);
  drive_next_ = drive_at(next);
  base_next_ = modal_.U * drive_next_.s;
  base_velocity_next_ = modal_.U * drive_next_.rate * drive_next_.c;
}

// The beds: each container at its new state, its World stepped, its load read back. The
// container's velocities are the half-step rates (y_{k+1} − y_k)/dt, the Verlet ones, which
// is what the World's leapfrog takes for its walls (§2).
inline bool Cosimulation::Impl::step_beds() {
  auto& worlds = state_.worlds;
  for (std::size_t d = 0; d < dcount_; ++d) {
    const double y_old = site_y_[d], x_old = site_across_[d], theta_old = site_theta_[d];
    dem::ContainerState& s = containers_[d];
    site_state(d, q_new_, base_next_, 0.0, vh_, s);
    const double y_rate = (site_y_[d] - y_old) / dt_, x_rate = (site_across_[d] - x_old) / dt_;
    const double theta_rate = (site_theta_[d] - theta_old) / dt_;
    for (int a = 0; a < 3; ++a) {
      s.velocity_m_s[a] = dampers_[d].container_drive_axis[a] * y_rate + across_axis_[d][a] * x_rate;
      s.angular_velocity_rad_s[a] = dampers_[d].container_rotation_axis[a] * theta_rate;
    }
    const dem::ContainerLoad& load = worlds[d].step(s);
    if (worlds[d].status().outcome != dem::Outcome::kCompleted) {
      outcome_ = worlds[d].status().outcome;
      message_ =
          "damper " + dampers_[d].name + " at t = " + format_number(t_next_, 12) + " s: " + worlds[d].status().message;
    }
    read_load(d, load);
  }
  return outcome_ == dem::Outcome::kCompleted;
}

// The closing kick with the new loads: (M + dt/2 C) v_{k+1} = M v_{k+½} + dt/2 g_{k+1}, then
// q̈_{k+1} = M⁻¹(g_{k+1} − C v_{k+1}). Lazy (coefficient-wise) products: a few modes make the
// blocked GEMV's dispatch the larger cost, measurable next to a small bed's step
// (bench_cosimulation).
inline void Cosimulation::Impl::closing_kick() {
  modal_load(load_factor(drive_next_), q_new_, g_);
  tmp_.noalias() = modal_.M.lazyProduct(vh_);
  tmp_ += half_dt_ * g_;
  v_new_.noalias() = A_inv_.lazyProduct(tmp_);
  tmp_ = g_ - modal_.C.cwiseProduct(v_new_);
  acc_new_.noalias() = modal_.M_inv.lazyProduct(tmp_);
}

// The ledger over the step, trapezoidal (the worlds account their work the same way, §4):
// structural damping ½(Cq̇_k + Cq̇_{k+1})·Δq, the force's work ½F(sin ψ_k + sin ψ_{k+1})Φ_pᵀe·Δq,
// or the base reaction's ½dt(R_k u̇_k + R_{k+1} u̇_{k+1}).
inline void Cosimulation::Impl::account_energy() {
  tmp_ = q_new_ - q_;
  const double damped = 0.5 * (modal_.C.cwiseProduct(v_) + modal_.C.cwiseProduct(v_new_)).dot(tmp_);
  damping_ += damped;
  damping_since_start_ += damped;
  double worked = 0.0;
  if (options_.excitation.kind == CosimulationExcitationKind::kPointForce) {
    worked = 0.5 * options_.excitation.amplitude * (drive_now_.s + drive_next_.s) * modal_.force_shape.dot(tmp_);
  } else if (is_base_) {
    const double power_next = base_power(acc_new_, base_velocity_next_);
    worked = half_dt_ * (power_ + power_next);
    power_ = power_next;
  }
  work_ += worked;
  work_since_start_ += worked;
}

// The new state becomes the present one.
inline void Cosimulation::Impl::commit_step() {
  q_.swap(q_new_);
  v_.swap(v_new_);
  acc_.swap(acc_new_);
  ++step_;
}

inline void Cosimulation::Impl::feed_measures() {
  for (const auto& measure : measures_) measure->after_step(view_, end_step_);
  if (step_ == next_snapshot_step_) [[unlikely]] take_snapshots();
}

// About every progress_interval_s of wall time, read every kProgressStride steps.
void Cosimulation::Impl::report_progress() {
  if (step_ % kProgressStride != 0) return;
  const auto now = Clock::now();
  const double since = std::chrono::duration<double>(now - last_report_).count();
  if (since < options_.progress_interval_s) return;
  hooks_->progress({"", std::string(measures_.front()->stage()), static_cast<double>(step_) * dt_,
                    static_cast<double>(end_step_) * dt_, false, static_cast<double>(step_ - last_report_step_) / since,
                    NAN});
  last_report_ = now;
  last_report_step_ = step_;
}

// g = f_exc − Kq − Σ(b_d F_d + t_d G_d + r_d M_d) (§3).
void Cosimulation::Impl::modal_load(double factor, const Eigen::VectorXd& qq, Eigen::VectorXd& out) const {
  out = factor * modal_.load_shape - modal_.K.cwiseProduct(qq);
  for (std::size_t d = 0; d < dcount_; ++d) {
    const auto col = static_cast<Eigen::Index>(d);
    out -= force_[d] * modal_.B.col(col);
    if (force_across_[d] != 0.0) out -= force_across_[d] * modal_.T.col(col);
    if (moment_[d] != 0.0) out -= moment_[d] * modal_.R.col(col);
  }
}

// Structural kinetic energy in the inertial frame (without ½m_rigid u̇_b², §4):
// T' = ½q̇ᵀMq̇ + u̇_b P_eᵀq̇.
double Cosimulation::Impl::structure_kinetic(const Eigen::VectorXd& vv, double base_velocity,
                                             Eigen::VectorXd& scratch) const {
  scratch.noalias() = modal_.M * vv;
  return 0.5 * vv.dot(scratch) + base_velocity * modal_.base_shape.dot(vv);
}

// Base reaction power R'·u̇_b = u̇_b (P_eᵀq̈ + Σ F_d n_d·e + G_d t_d·e) (§4).
double Cosimulation::Impl::base_power(const Eigen::VectorXd& accel, double base_velocity) const {
  double r = modal_.base_shape.dot(accel);
  for (std::size_t d = 0; d < dcount_; ++d) r += force_[d] * modal_.drive_dot_e[d] + force_across_[d] * modal_.across_dot_e[d];
  return r * base_velocity;
}

std::pair<double, double> Cosimulation::Impl::structure_energy_now() const {
  Eigen::VectorXd scratch(n_);
  const double base_velocity_end = modal_.U * drive_now_.rate * drive_now_.c;
  return {structure_kinetic(v_, base_velocity_end, scratch), structure_potential(q_)};
}

// W, D_s and the changes of the structure's and the beds' energies from the given start (§4).
CosimulationEnergy Cosimulation::Impl::ledger(double work, double damping, double kinetic_start,
                                              double potential_start, const std::vector<dem::EnergyAccount>& start,
                                              double kinetic_end, double potential_end) const {
  CosimulationEnergy e;
  e.excitation_work_j = work;
  e.structural_damping_j = damping;
  e.delta_structure_kinetic_j = kinetic_end - kinetic_start;
  e.delta_structure_potential_j = potential_end - potential_start;
  for (std::size_t d = 0; d < dcount_; ++d) {
    const dem::EnergyAccount now = state_.worlds[d].energy();
    e.dem_normal_damping_j += now.normal_damping_j - start[d].normal_damping_j;
    e.dem_friction_j += now.friction_j - start[d].friction_j;
    e.dem_rolling_j += now.rolling_j - start[d].rolling_j;
    e.delta_bed_kinetic_j += now.kinetic_j - start[d].kinetic_j;
    e.delta_bed_potential_j += now.potential_j - start[d].potential_j;
    e.delta_bed_elastic_j += now.elastic_j - start[d].elastic_j;
    e.container_work_j += now.container_work_j - start[d].container_work_j;
  }
  e.relative_error = detail::ledger_error(e);
  return e;
}

CosimulationResult Cosimulation::Impl::result(bool release) {
  CosimulationResult r;
  r.outcome = outcome_;
  r.message = message_;
  r.time_step_s = dt_;
  r.steps = step_;
  r.steps_per_period = steps_per_period_;
  r.settling_steps = settling_steps_;
  r.simulated_time_s = static_cast<double>(step_) * dt_;
  r.start_time_s = start_time_s_;
  r.continued = continued_;
  r.frequencies_with_containers_hz = frequencies_with_containers_hz_;
  r.final_modal_displacements = q_;
  r.final_modal_velocities = v_;
  for (const auto& measure : measures_) {
    if (release) {
      measure->release(r, step_);
    } else {
      measure->write(r, step_);
    }
  }
  r.bed_snapshots = release ? std::move(snapshots_) : snapshots_;
  const auto [kinetic_end, potential_end] = structure_energy_now();
  r.energy = ledger(work_, damping_, kinetic0_, potential0_, opening_, kinetic_end, potential_end);
  for (const auto& world : state_.worlds) {
    r.world_status.push_back(world.status());
    r.final_container_states.push_back(world.container());
  }
  r.warnings = warnings_;
  r.wall_time_s = wall_s_;
  r.stage_times = stage_times_;
  return r;
}

// The state for the next run: q, q̇, the clock, the excitation with the drive's phase at the
// end, and the ledger since the first start.
void Cosimulation::Impl::sync_state() {
  if (state_.worlds.empty()) return;  // handed over
  state_.modal_displacements = q_;
  state_.modal_velocities = v_;
  state_.time_s = time_at(step_);
  state_.steps = steps0_ + step_;
  state_.time_step_s = dt_;
  state_.excitation = options_.excitation;
  state_.excitation.frequency_hz = is_sweep_ ? drive_now_.rate / kTwoPi : f_run_;
  state_.excitation_phase_rad = 0.0;
  if (is_sweep_) {
    const double phase = std::fmod(phase0_ + drive_now_.phase, kTwoPi);
    state_.excitation_phase_rad = phase < 0.0 ? phase + kTwoPi : phase;
  } else if (is_harmonic_) {
    const double phase = std::fmod(phase0_ + kTwoPi * static_cast<double>(step_ % steps_per_period_) /
                                                 static_cast<double>(steps_per_period_), kTwoPi);
    state_.excitation_phase_rad = phase < 0.0 ? phase + kTwoPi : phase;
  }
  const auto [kinetic_end, potential_end] = structure_energy_now();
  state_.energy_since_start = ledger(work_since_start_, damping_since_start_, state_.start_structure_kinetic_j,
                                     state_.start_structure_potential_j, state_.start_world_energy, kinetic_end,
                                     potential_end);
}

// ------------------------------------------------------------------ the public face

Cosimulation::Cosimulation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Cosimulation::Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                           const CosimulationRun& run, base::RunHooks& hooks)
    : impl_(std::make_unique<Impl>(model, dampers, detail::run_options(run), nullptr, nullptr, hooks)) {}

Cosimulation::Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                           const CosimulationRun& run, CosimulationState&& state, base::RunHooks& hooks)
    : impl_(std::make_unique<Impl>(model, dampers, detail::run_options(run), state.started() ? &state : nullptr, nullptr,
                                   hooks)) {}

Cosimulation Cosimulation::restore(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                   const DecayRun& run, dem::StateReader& in, base::RunHooks& hooks) {
  const detail::RunOptions options = detail::run_options(run);
  detail::validate_inputs(model, dampers, options, false);
  CosimulationState state = restore_cosimulation_state(model, dampers, in);
  const CosimulationResult earlier = restore_cosimulation_result(in, model.mode_count(), dampers.size());
  return Cosimulation(std::make_unique<Impl>(model, dampers, options, &state, &earlier, hooks));
}

Cosimulation::Cosimulation(Cosimulation&&) noexcept = default;
Cosimulation& Cosimulation::operator=(Cosimulation&&) noexcept = default;
Cosimulation::~Cosimulation() = default;

std::int64_t Cosimulation::advance(std::int64_t steps) {
  if (impl_->state_.worlds.empty()) throw std::logic_error("Cosimulation::advance: the state was handed over");
  return impl_->advance(steps);
}

int Cosimulation::stop_signal() const { return impl_->stop_signal_; }

bool Cosimulation::finished() const { return impl_->finished(); }
std::int64_t Cosimulation::steps_done() const { return impl_->step_; }
std::int64_t Cosimulation::total_steps() const { return impl_->end_step_; }
double Cosimulation::time_step_s() const { return impl_->dt_; }
CosimulationResult Cosimulation::result() const& {
  if (impl_->state_.worlds.empty()) throw std::logic_error("Cosimulation::result: the state was handed over");
  return impl_->result(false);
}

CosimulationResult Cosimulation::result() && {
  if (impl_->state_.worlds.empty()) throw std::logic_error("Cosimulation::result: the state was handed over");
  return impl_->result(true);
}

const CosimulationState& Cosimulation::state() const {
  impl_->sync_state();
  return impl_->state_;
}

CosimulationState Cosimulation::take_state() && {
  impl_->sync_state();
  return std::move(impl_->state_);
}

void Cosimulation::save(dem::StateWriter& out) const {
  if (impl_->is_harmonic_)
    throw std::logic_error("Cosimulation::save: a harmonic run's measures are not in a checkpoint (save its state)");
  save_cosimulation_state(state(), out);
  save_cosimulation_result(result(), out);
}

// ------------------------------------------------------------------ the free functions

CosimulationTimeStep cosimulation_time_step(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                            const CosimulationRun& run) {
  const detail::RunOptions options = detail::run_options(run);
  detail::validate_inputs(model, dampers, options, false);
  const Eigen::Index n = model.mode_count();
  const double f = options.excitation.frequency_hz;
  const detail::Prepared P = detail::prepare(model, dampers, options, f,
                                             detail::start_vector(options.initial_modal_displacements, n),
                                             detail::start_vector(options.initial_modal_velocities, n));
  detail::StepPlan plan = detail::plan_step(P, dampers, options, f);
  return {plan.dt, plan.steps_per_period, std::move(plan.warnings)};
}

CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationRun& run, base::RunHooks& hooks) {
  CosimulationState state;
  return cosimulate(model, dampers, run, state, hooks);
}

CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationRun& run, CosimulationState& state, base::RunHooks& hooks) {
  Cosimulation cosimulation(model, dampers, run, std::move(state), hooks);
  cosimulation.advance(std::numeric_limits<std::int64_t>::max());
  if (const int signal = cosimulation.stop_signal(); signal != 0)
    throw base::Interrupted(signal, "the co-simulation stopped; it had no checkpoint, so nothing was kept");
  CosimulationResult result = std::move(cosimulation).result();
  state = std::move(cosimulation).take_state();
  return result;
}

}  // namespace pdamp::structure
