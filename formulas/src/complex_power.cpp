// Complex power P = ½F*·conj(V*) from sampled force and velocity: period folding and an FFTW r2c transform.
#include "pdamp/formulas/complex_power.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <mutex>
#include <new>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "pdamp/formulas/collect_and_collide.hpp"  // kPi

namespace pdamp::formulas {
namespace {

constexpr double kTwoPi = 2.0 * kPi;
/// Relative tolerance on T/dt being an integer (the DEM picks dt = T/n exactly, so
/// only round-off of 1/(f·dt) is expected).
constexpr double kWindowTolerance = 1e-9;
/// |V*| below this fraction of the period-averaged velocity's largest value counts as
/// "no component at Ω": the bin is then round-off of the other components (DC,
/// harmonics) and m_app, η* would be noise.
constexpr double kZeroVelocityFraction = 1e-12;

using base::format_number;

[[noreturn]] void reject(const std::string& what) { throw std::invalid_argument("complex_power: " + what); }

/// FFTW plans cached per transform length. FFTW's planner is not thread-safe, so plan
/// creation (and destruction) is serialised here; fftw_execute_dft_r2c on other arrays
/// of the same alignment is thread-safe, so callers execute without the lock. Plans are
/// made with FFTW_ESTIMATE: cheap to create (no timing runs, so the same algorithm and
/// the same round-off on every run), and they leave the planning arrays untouched.
class PlanCache {
 public:
  PlanCache() = default;
  PlanCache(const PlanCache&) = delete;
  PlanCache& operator=(const PlanCache&) = delete;
  ~PlanCache() {
    for (auto& entry : plans_) fftw_destroy_plan(entry.second);
  }

  fftw_plan plan_for(int n) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (const auto found = plans_.find(n); found != plans_.end()) return found->second;
    // The arrays only fix the plan's alignment and out-of-place layout: fftw_malloc
    // gives the same SIMD alignment as the per-thread workspaces used at execution.
    auto* in = static_cast<double*>(fftw_malloc(sizeof(double) * static_cast<std::size_t>(n)));
    auto* out =
        static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * (static_cast<std::size_t>(n) / 2 + 1)));
    fftw_plan plan = (in && out) ? fftw_plan_dft_r2c_1d(n, in, out, FFTW_ESTIMATE) : nullptr;
    fftw_free(in);
    fftw_free(out);
    if (!plan)
      throw base::NumericalError("complex_power: FFTW could not plan a transform of length " +
                               std::to_string(n));
    plans_.emplace(n, plan);
    return plan;
  }

 private:
  std::mutex mutex_;
  std::unordered_map<int, fftw_plan> plans_;
};

PlanCache& plan_cache() {
  static PlanCache cache;
  return cache;
}

/// Per-thread input/output arrays (fftw_malloc-aligned), grown on demand and reused, so
/// repeated calls allocate nothing.
class Workspace {
 public:
  Workspace() = default;
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;
  ~Workspace() {
    fftw_free(in_);
    fftw_free(out_);
  }

  void reserve(std::size_t n) {
    if (n <= capacity_) return;
    fftw_free(in_);
    fftw_free(out_);
    capacity_ = 0;
    in_ = static_cast<double*>(fftw_malloc(sizeof(double) * n));
    out_ = static_cast<fftw_complex*>(fftw_malloc(sizeof(fftw_complex) * (n / 2 + 1)));
    if (!in_ || !out_) throw std::bad_alloc();
    capacity_ = n;
  }
  double* in() { return in_; }
  fftw_complex* out() { return out_; }

 private:
  double* in_ = nullptr;
  fftw_complex* out_ = nullptr;
  std::size_t capacity_ = 0;
};

struct FundamentalAmplitude {
  std::complex<double> amplitude;  ///< S* = (2/N)·X_N[k]
  double max_abs_average = 0.0;    ///< max over the period-averaged signal, |s̄ₘ|
};

/// S* of a signal of k whole periods of M samples (N = kM). With n = pM + m the bin-k
/// twiddle e^{−2πi kn/N} = e^{−2πi m/M} does not depend on the period p, so
///   X_N[k] = Σₘ (Σₚ s_{pM+m}) e^{−2πi m/M} = k·Ȳ[1],
/// where Ȳ is the length-M DFT of the period-averaged signal s̄ₘ = (1/k)Σₚ s_{pM+m}, and
/// S* = (2/N)·X_N[k] = (2/M)·Ȳ[1] exactly. Why: the fold costs N additions and the
/// FFT M log M, against N log N for the length-N transform (15x faster at N = 1e5, M = 1000).
FundamentalAmplitude fundamental(std::span<const double> signal, const char* name, int samples_per_period,
                                 fftw_plan plan, Workspace& workspace) {
  const std::size_t m_count = static_cast<std::size_t>(samples_per_period);
  const std::size_t periods = signal.size() / m_count;
  double* folded = workspace.in();
  std::copy_n(signal.data(), m_count, folded);
  for (std::size_t p = 1; p < periods; ++p) {
    const double* period = signal.data() + p * m_count;
    for (std::size_t m = 0; m < m_count; ++m) folded[m] += period[m];
  }
  const double inverse_periods = 1.0 / static_cast<double>(periods);
  double max_abs_average = 0.0;
  bool finite = true;
  for (std::size_t m = 0; m < m_count; ++m) {
    folded[m] *= inverse_periods;
    finite = finite && std::isfinite(folded[m]);
    max_abs_average = std::max(max_abs_average, std::abs(folded[m]));
  }
  // A non-finite sample makes its folded sum non-finite: only then search for it.
  if (!finite) {
    for (std::size_t i = 0; i < signal.size(); ++i) {
      if (!std::isfinite(signal[i])) {
        reject(std::string(name) + "[" + std::to_string(i) + "] = " + format_number(signal[i], 12) +
               ": samples must be finite");
      }
    }
    reject(std::string(name) + ": the sum over " + std::to_string(periods) +
           " periods overflows: samples must be finite and far below 1e308");
  }
  fftw_execute_dft_r2c(plan, folded, workspace.out());
  const fftw_complex& y = workspace.out()[1];
  const double scale = 2.0 / static_cast<double>(samples_per_period);
  return {{scale * y[0], scale * y[1]}, max_abs_average};
}

/// P, E_diss, energy per cycle and m_app from F* and V* (V* non-zero).
void finish_measures(ComplexPower& result, double frequency_hz) {
  const double omega = kTwoPi * frequency_hz;
  const double v_norm = std::norm(result.velocity_amplitude);
  const std::complex<double> f_conj_v = result.force_amplitude * std::conj(result.velocity_amplitude);
  result.power = 0.5 * f_conj_v;
  result.angular_frequency = omega;
  result.e_diss_j = result.power.real() / omega;
  result.energy_per_cycle_j = kTwoPi * result.e_diss_j;
  result.apparent_mass_kg = f_conj_v.imag() / (omega * v_norm);
}

}  // namespace

double ComplexPower::reduced_loss_factor(double bed_mass_kg) const {
  if (!(bed_mass_kg > 0.0) || !std::isfinite(bed_mass_kg)) {
    throw std::invalid_argument("reduced_loss_factor: bed_mass_kg = " + format_number(bed_mass_kg, 12) +
                                ": must be > 0 and finite");
  }
  return e_diss_j / (0.5 * bed_mass_kg * std::norm(velocity_amplitude));
}

ComplexPower complex_power(std::span<const double> force_n, std::span<const double> velocity_m_s, double dt_s,
                           double frequency_hz) {
  if (force_n.empty() || velocity_m_s.empty()) {
    reject("force has " + std::to_string(force_n.size()) + " samples, velocity " +
           std::to_string(velocity_m_s.size()) + ": both must be non-empty");
  }
  if (force_n.size() != velocity_m_s.size()) {
    reject("force has " + std::to_string(force_n.size()) + " samples, velocity " +
           std::to_string(velocity_m_s.size()) + ": lengths must be equal");
  }
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) reject("dt_s = " + format_number(dt_s, 12) + ": must be > 0 and finite");
  if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz)) {
    reject("frequency_hz = " + format_number(frequency_hz, 12) + ": must be > 0 and finite");
  }
  if (force_n.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
    reject("N = " + std::to_string(force_n.size()) + " samples: at most " +
           std::to_string(std::numeric_limits<int>::max()));
  }
  const int n = static_cast<int>(force_n.size());

  const double period_over_dt = 1.0 / (frequency_hz * dt_s);
  const double nearest = std::round(period_over_dt);
  if (std::abs(period_over_dt - nearest) > kWindowTolerance * period_over_dt) {
    reject("dt_s = " + format_number(dt_s, 12) + ", frequency_hz = " + format_number(frequency_hz, 12) +
           ": T/dt = " + format_number(period_over_dt, 12) + " must be an integer (within 1e-9 relative)");
  }
  // Below 3 samples per period Ω sits at or above Nyquist, where (2/N)·X[k] is not
  // the amplitude (at M = 2 a sine of any amplitude samples to zero).
  if (nearest < 3.0) {
    reject("dt_s = " + format_number(dt_s, 12) + ", frequency_hz = " + format_number(frequency_hz, 12) +
           ": T/dt = " + format_number(nearest, 12) + " samples per period, must be >= 3");
  }
  if (nearest > static_cast<double>(n) || n % static_cast<int>(nearest) != 0) {
    reject("N = " + std::to_string(n) + " samples, T/dt = " + format_number(nearest, 12) +
           ": N must be a positive multiple of T/dt (a whole number of periods)");
  }
  const int samples_per_period = static_cast<int>(nearest);
  const int periods = n / samples_per_period;

  const fftw_plan plan = plan_cache().plan_for(samples_per_period);
  thread_local Workspace workspace;
  workspace.reserve(static_cast<std::size_t>(samples_per_period));

  ComplexPower result;
  result.force_amplitude = fundamental(force_n, "force_n", samples_per_period, plan, workspace).amplitude;
  const FundamentalAmplitude velocity =
      fundamental(velocity_m_s, "velocity_m_s", samples_per_period, plan, workspace);
  result.velocity_amplitude = velocity.amplitude;

  const double v_norm = std::norm(result.velocity_amplitude);
  if (!(std::sqrt(v_norm) > kZeroVelocityFraction * velocity.max_abs_average)) {
    reject("|V*| = " + format_number(std::sqrt(v_norm), 12) +
           " m/s with max|v| = " + format_number(velocity.max_abs_average, 12) +
           " m/s over the period-averaged velocity: it has no component at the drive frequency " +
           format_number(frequency_hz, 12) + " Hz, so m_app and eta* are undefined");
  }

  finish_measures(result, frequency_hz);
  result.periods = periods;
  result.samples_per_period = samples_per_period;
  return result;
}

DriveBinAccumulator::DriveBinAccumulator(std::int64_t steps_per_period, StepForce force_model)
    : steps_per_period_(steps_per_period) {
  if (steps_per_period < 3) {
    reject("DriveBinAccumulator: steps_per_period = " + std::to_string(steps_per_period) + ": must be >= 3");
  }
  const double half_step = kPi / static_cast<double>(steps_per_period);  // Ωdt/2
  const double sinc = std::sin(half_step) / half_step;
  weight_ = force_model == StepForce::kConstant ? sinc : sinc * sinc;
  rotor_ = std::polar(1.0, -2.0 * half_step);
}

void DriveBinAccumulator::add(std::int64_t step, double force_n, double velocity_m_s) {
  // e^{−2πi k/M} depends on k mod M only; recomputed from it every 64 steps (and after a
  // jump in k), rotated by e^{−2πi/M} in between.
  const std::int64_t m = ((step % steps_per_period_) + steps_per_period_) % steps_per_period_;
  if (!started_ || step != next_step_ || (m & 63) == 0) {
    phase_ = std::polar(1.0, -kTwoPi * static_cast<double>(m) / static_cast<double>(steps_per_period_));
  }
  started_ = true;
  next_step_ = step + 1;
  force_sum_ += force_n * phase_;
  velocity_sum_ += velocity_m_s * phase_;
  max_abs_velocity_ = std::max(max_abs_velocity_, std::abs(velocity_m_s));
  ++samples_;
  phase_ *= rotor_;
}

void DriveBinAccumulator::merge(const DriveBinAccumulator& other) {
  if (other.steps_per_period_ != steps_per_period_ || other.weight_ != weight_) {
    reject("DriveBinAccumulator::merge: steps_per_period " + std::to_string(other.steps_per_period_) + " vs " +
           std::to_string(steps_per_period_) + ": must be equal, with the same force model");
  }
  force_sum_ += other.force_sum_;
  velocity_sum_ += other.velocity_sum_;
  max_abs_velocity_ = std::max(max_abs_velocity_, other.max_abs_velocity_);
  samples_ += other.samples_;
}

void DriveBinAccumulator::restore_sums(const Sums& sums) {
  force_sum_ = sums.force;
  velocity_sum_ = sums.velocity;
  max_abs_velocity_ = sums.max_abs_velocity;
  samples_ = sums.samples;
  phase_ = sums.phase;
  next_step_ = sums.next_step;
  started_ = sums.started;
}

void DriveBinAccumulator::clear() {
  force_sum_ = velocity_sum_ = {0.0, 0.0};
  max_abs_velocity_ = 0.0;
  samples_ = 0;
  started_ = false;
}

ComplexPower DriveBinAccumulator::result(double frequency_hz) const {
  if (!(frequency_hz > 0.0) || !std::isfinite(frequency_hz)) {
    reject("frequency_hz = " + format_number(frequency_hz, 12) + ": must be > 0 and finite");
  }
  if (samples_ <= 0 || samples_ % steps_per_period_ != 0) {
    reject("N = " + std::to_string(samples_) + " samples, T/dt = " + std::to_string(steps_per_period_) +
           ": N must be a positive multiple of T/dt (a whole number of periods)");
  }
  if (!std::isfinite(std::abs(force_sum_)) || !std::isfinite(std::abs(velocity_sum_))) {
    reject("the sums over " + std::to_string(samples_) + " samples are not finite: samples must be finite");
  }
  ComplexPower result;
  const double scale = 2.0 / static_cast<double>(samples_);
  result.force_amplitude = scale * weight_ * force_sum_;
  result.velocity_amplitude = scale * velocity_sum_;
  const double v_abs = std::abs(result.velocity_amplitude);
  if (!(v_abs > kZeroVelocityFraction * max_abs_velocity_)) {
    reject("|V*| = " + format_number(v_abs, 12) + " m/s with max|v| = " + format_number(max_abs_velocity_, 12) +
           " m/s: the velocity has no component at the drive frequency " + format_number(frequency_hz, 12) +
           " Hz, so m_app and eta* are undefined");
  }
  finish_measures(result, frequency_hz);
  result.periods = static_cast<int>(std::min<std::int64_t>(samples_ / steps_per_period_, std::numeric_limits<int>::max()));
  result.samples_per_period = static_cast<int>(std::min<std::int64_t>(steps_per_period_, std::numeric_limits<int>::max()));
  return result;
}

}  // namespace pdamp::formulas
