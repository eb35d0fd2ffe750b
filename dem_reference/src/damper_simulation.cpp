// Harmonic DEM run of one damper: settling, transient, analysed periods, and the
// measures (complex power, energy balance, motion mode).
#include "pdamp/dem_reference/damper_simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/formulas/complex_power.hpp"
#include "initial_state.hpp"
#include "walls.hpp"
#include "world_data.hpp"

namespace pdamp::dem_reference {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

/// Inner extent of a compartment along gravity (g_norm = |g| > 0), m.
double extent_along_gravity(const CompartmentOptions& c, const Vec3& gravity, double g_norm) {
  double h = 0.0;
  for (int a = 0; a < 3; ++a) h += std::abs(gravity[static_cast<std::size_t>(a)]) / g_norm * c.container.inner_length(a);
  return h;
}

/// The inner extent of the tallest compartment along gravity, m (the settling time of a
/// random placement).
double fall_height(const WorldOptions& w) {
  const double g = norm(w.gravity_m_s2);
  if (g == 0.0) return 0.0;
  double height = 0.0;
  for (const auto& c : w.compartments) height = std::max(height, extent_along_gravity(c, w.gravity_m_s2, g));
  return height;
}

/// Largest free fall of a sphere, m: per compartment, its inner extent H along gravity
/// less the smallest sphere diameter 2r_min, the largest of these (0 without gravity).
/// A sphere's centre moves between r from the floor and r from the ceiling, so it falls
/// at most H − 2r (from rest at the ceiling onto the floor). Not H − h_bed: a sphere
/// thrown up from a multi-layer bed can land beside it, in the clearance of a collected
/// bed; for one layer (h_bed = 2r) the two agree. The drive's own speed is in 2XΩ.
double free_fall_height(const WorldOptions& w) {
  const double g = norm(w.gravity_m_s2);
  if (g == 0.0) return 0.0;
  double height = 0.0;
  for (const auto& c : w.compartments) {
    const double h = extent_along_gravity(c, w.gravity_m_s2, g);
    double r_min = std::numeric_limits<double>::infinity();
    for (const auto& p : c.particles) r_min = std::min(r_min, p.radius_m * (1.0 - p.radius_spread));
    if (!std::isfinite(r_min)) r_min = 0.0;
    height = std::max(height, std::max(0.0, h - 2.0 * r_min));
  }
  return height;
}

/// Mean Pearson correlation of consecutive periods of a periodically sampled signal.
double period_correlation(const std::vector<double>& signal, int samples, int periods) {
  if (periods < 2) return 1.0;
  double sum = 0.0;
  for (int p = 1; p < periods; ++p) {
    const double* a = signal.data() + static_cast<std::ptrdiff_t>((p - 1) * samples);
    const double* b = signal.data() + static_cast<std::ptrdiff_t>(p * samples);
    double ma = 0.0, mb = 0.0;
    for (int k = 0; k < samples; ++k) {
      ma += a[k];
      mb += b[k];
    }
    ma /= samples;
    mb /= samples;
    double sab = 0.0, saa = 0.0, sbb = 0.0;
    for (int k = 0; k < samples; ++k) {
      sab += (a[k] - ma) * (b[k] - mb);
      saa += (a[k] - ma) * (a[k] - ma);
      sbb += (b[k] - mb) * (b[k] - mb);
    }
    // A bed at rest in the container repeats itself exactly: count it as synchronous.
    sum += (saa > 0.0 && sbb > 0.0) ? sab / std::sqrt(saa * sbb) : 1.0;
  }
  return sum / (periods - 1);
}

/// Thresholds of the motion-mode labels (docs/dem.md "Motion modes" derives them from
/// the mode definitions of PHYSICS.md and the ideal orbits of §2-3).
struct ModeThresholds {
  /// solid_like: the bed uses under a tenth of its clearance and carries over 80% of the
  /// rigidly attached bed's inertial force (m_f = 1).
  static constexpr double kSolidStroke = 0.1;
  static constexpr double kSolidMass = 0.8;
  /// decoupled: under 10% of the rigid inertial force and under 10% of the plastic
  /// block's η* (the container moves around a bed at rest: m_f = η* = 0).
  static constexpr double kDecoupledMass = 0.1;
  static constexpr double kDecoupledEta = 0.1;
  /// collect-and-collide: the ideal orbits (plastic block, bouncing or rolling, from the
  /// onset to X = 10h) cross the clearance once per half period (crossing fraction 1),
  /// with a phase-locked stroke of 0.98-1.26, a lag behind the container from 149° (the
  /// onset orbit, the latest impact that still repeats) down to 37°, and m_f in
  /// [−0.56, 1.12]. Accepted: at least every other half period crosses, at least half
  /// the ideal locked stroke, a lag in [0°, 150°] (a bed left behind lags 180°; an
  /// elastic bed's rebound makes it lead), and m_f <= 1.5 (a collected bed never moves
  /// faster than the walls; a bed rebounding elastically off walls at ±V leaves at up
  /// to (1 + 2ε)V, m_f ≈ 2.5-3).
  static constexpr double kCrossing = 0.5;
  static constexpr double kLockedStroke = 0.5;
  static constexpr double kMinLag_deg = 0.0;
  static constexpr double kMaxLag_deg = 150.0;
  static constexpr double kMaxMass = 1.5;
  /// rolling: the bed keeps at least half of its settled base contacts, on average over
  /// the analysed periods (most of it rolls on its base, PHYSICS.md §3); otherwise
  /// bouncing (airborne: spheres hopping after the wall impacts, or no gravity).
  static constexpr double kRollingBase = 0.5;
  /// A sphere is mobile when its rms speed relative to the bed's mean velocity exceeds
  /// V/2: walls moving at ±V drive a granular gas at fluctuations of order V, a
  /// collected block only by its internal rearrangement.
  static constexpr double kMobileSpeed = 0.5;
  /// Fluidisation (high intensity, Γ > 1): all of the bed mobile (>= 90%, a few spheres
  /// may stay wedged) is global, a part (>= 10%) local.
  static constexpr double kGlobalMobile = 0.9;
  static constexpr double kLocalMobile = 0.1;
};

/// The labels of PHYSICS.md from the indicators (docs/dem.md "Motion modes"); the first
/// that applies.
MotionMode classify(const MotionIndicators& m, double eta_star, double intensity) {
  using T = ModeThresholds;
  if (m.relative_stroke_over_clearance < T::kSolidStroke && m.apparent_mass_fraction > T::kSolidMass) {
    return MotionMode::kSolidLike;
  }
  if (std::abs(m.apparent_mass_fraction) < T::kDecoupledMass && eta_star < T::kDecoupledEta) {
    return MotionMode::kDecoupled;
  }
  if (m.crossing_fraction >= T::kCrossing && m.phase_locked_stroke >= T::kLockedStroke &&
      m.phase_lag_deg >= T::kMinLag_deg && m.phase_lag_deg <= T::kMaxLag_deg &&
      m.apparent_mass_fraction <= T::kMaxMass) {
    const bool rolling = m.settled_base_contact_fraction > 0.0 &&
                         m.base_contact_fraction >= T::kRollingBase * m.settled_base_contact_fraction;
    return rolling ? MotionMode::kRollingCollectAndCollide : MotionMode::kBouncingCollectAndCollide;
  }
  if (intensity > 1.0 && m.mobile_fraction >= T::kGlobalMobile) return MotionMode::kGlobalFluidisation;
  if (intensity > 1.0 && m.mobile_fraction >= T::kLocalMobile) return MotionMode::kLocalFluidisation;
  return MotionMode::kScattering;
}

/// Fills the phase-locked indicators from x_r (relative to the container centre) sampled
/// at times t (`samples` per period, `periods` periods) of the drive X sin Ωt, clearance h.
void phase_indicators(const std::vector<double>& rel, const std::vector<double>& time_s, int samples, int periods,
                      double omega, double h, MotionIndicators& m) {
  if (!(h > 0.0) || rel.empty()) {
    m.phase_locked_stroke = m.phase_coherence = m.phase_lag_deg = m.crossing_fraction = kNaN;
    return;
  }
  double re_all = 0.0, im_all = 0.0, abs_sum = 0.0;
  for (int p = 0; p < periods; ++p) {
    double re = 0.0, im = 0.0;
    for (int k = p * samples; k < (p + 1) * samples; ++k) {
      const auto i = static_cast<std::size_t>(k);
      re += rel[i] * std::cos(omega * time_s[i]);
      im -= rel[i] * std::sin(omega * time_s[i]);
    }
    re *= 2.0 / samples;  // x_r ≈ Re(c e^{iΩt}), c = re + i·im
    im *= 2.0 / samples;
    re_all += re / periods;
    im_all += im / periods;
    abs_sum += std::hypot(re, im) / periods;
  }
  const double c_abs = std::hypot(re_all, im_all);
  m.phase_locked_stroke = 2.0 * c_abs / h;
  m.phase_coherence = abs_sum > 0.0 ? c_abs / abs_sum : 0.0;
  // The container position X sin Ωt has the coefficient −iX: lag = arg(−i / c).
  m.phase_lag_deg = c_abs > 0.0 ? std::atan2(-re_all, -im_all) * 180.0 / kPi : 0.0;
  if (m.phase_lag_deg <= -180.0) m.phase_lag_deg += 360.0;
  // Crossings: transits between the outer quarters at either wall (x_r < −h/4, x_r > h/4).
  int side = 0, crossings = 0;
  for (const double x : rel) {
    const int now = x < -0.25 * h ? -1 : (x > 0.25 * h ? 1 : 0);
    if (now != 0 && side != 0 && now != side) ++crossings;
    if (now != 0) side = now;
  }
  m.crossing_fraction = static_cast<double>(crossings) / (2.0 * periods);
}

/// Reports progress about twice a second. The clock is read every `stride` steps, a
/// power of two with stride × particles ≈ 65,536 particle-steps (every step from 65,536
/// particles on, every 2048th for 36): one read costs ~20 ns, a step of a large world
/// milliseconds, so that the first report of a 1e6-particle run comes after 0.5 s and
/// not after 4096 steps (minutes), as with a fixed stride.
class ProgressReporter {
 public:
  ProgressReporter(const ProgressCallback& callback, double end_time_s, int particles)
      : callback_(callback), end_time_s_(end_time_s), start_(Clock::now()), last_(start_) {
    std::int64_t stride = 1;
    while (stride < 4096 && stride * 2 * std::max(particles, 1) <= 65536) stride *= 2;
    mask_ = stride - 1;
  }
  /// Reports now (the set-up stages, before any step).
  void report_now(std::string_view stage, double time_s, double eta_s) {
    if (!callback_) return;
    Progress p;
    p.stage = stage;
    p.simulated_time_s = time_s;
    p.end_time_s = end_time_s_;
    p.eta_s = eta_s;
    callback_(p);
    last_ = Clock::now();
  }
  /// The stepping starts: the rate is measured from here.
  void start_stepping() { start_ = Clock::now(); }
  void maybe_report(std::string_view stage, std::int64_t step, std::int64_t total_steps, double time_s) {
    if (!callback_ || (step & mask_) != 0) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_).count() < 0.5) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0.0 ? static_cast<double>(step) / elapsed : 0.0;
    Progress p;
    p.stage = stage;
    p.simulated_time_s = time_s;
    p.end_time_s = end_time_s_;
    p.steps_per_s = rate;
    p.eta_s = rate > 0.0 ? static_cast<double>(total_steps - step) / rate : 0.0;
    callback_(p);
  }

 private:
  const ProgressCallback& callback_;
  double end_time_s_;
  Clock::time_point start_;
  Clock::time_point last_;
  std::int64_t mask_ = 0;
};

/// The drive's largest impact speed: a collected bed leaving one wall at the drive's
/// peak velocity V meets the other wall coming at V (2V), plus the largest free fall of
/// a sphere, √(2|g|H_free) with H_free = H − 2r_min (free_fall_height), m/s.
double drive_impact_speed(const DamperSimulationOptions& o) {
  const double v_amp = o.amplitude_m * 2.0 * kPi * o.frequency_hz;
  return 2.0 * v_amp + std::sqrt(2.0 * norm(o.world.gravity_m_s2) * free_fall_height(o.world));
}

/// Fewest steps per contact at the impact speed that a user time step may give
/// (docs/dem.md "Integration and time step"): the single-impact restitution error of
/// the leapfrog with the half-step damping velocity follows −(0.6 ln²ε + 0.1)/N from
/// here on for every ε >= 0.05; below it heavily damped contacts overshoot (ε = 0.05
/// realises up to 0.11 at 10 steps, ε = 0.01 up to 1.0 at 20).
constexpr double kMinStepsPerContact = 20.0;

/// The largest relative restitution error of one impact at N steps per contact, for
/// the target ε: (0.6 ln²ε + 0.1)/N (measured bound, tests/dem_reference/test_measures.cpp).
double restitution_error_bound(double restitution, double steps_per_contact) {
  const double l = std::log(restitution);
  return (0.6 * l * l + 0.1) / steps_per_contact;
}

/// The smallest restitution the pairs can give (constant or table nodes); NaN when a
/// pair uses a model.
double smallest_restitution(const WorldOptions& w) {
  double e = 1.0;
  bool model = false;
  const auto consider = [&](const ContactPairOptions& p) {
    const auto& r = p.restitution;
    if (r.model) {
      model = true;
    } else if (!r.table_values.empty()) {
      e = std::min(e, *std::min_element(r.table_values.begin(), r.table_values.end()));
    } else {
      e = std::min(e, r.constant);
    }
  };
  consider(w.default_pair);
  for (const auto& p : w.pairs) consider(p);
  return model ? kNaN : e;
}

/// What run_harmonic and estimate_run derive from the options before building a world.
struct RunPlan {
  WorldOptions world;  ///< with the raised max_impact_speed_m_s and the chosen time step
  TimeStepBound bound;
  double dt = 0.0;
  std::int64_t steps_per_block = 0;
  std::int64_t steps_per_period = 0;
  std::int64_t settle_steps = 0;
  std::int64_t transient_steps = 0;
  std::int64_t analysed_steps = 0;
  std::int64_t total_steps = 0;
  int particles = 0;
  double impact_speed_m_s = 0.0;   ///< the speed the bound is taken at (before any lowering below)
  double stability_limit_s = 0.0;  ///< min(T_R, t_c/kMinStepsPerContact): the largest user step accepted
  double steps_per_contact = 0.0;  ///< t_c(impact speed)/dt
  std::vector<std::string> warnings;
};

/// Validates (std::invalid_argument: all violations) and plans: the automatic bound at
/// the drive's largest impact speed, the time step reduced so that a period is a whole
/// number of blocks of whole steps, the settling time, the step counts.
RunPlan plan_run(const DamperSimulationOptions& options) {
  if (const auto errors = options.validate(); !errors.empty()) throw std::invalid_argument(join_lines(errors));
  RunPlan plan;
  plan.world = options.world;
  auto& integ = plan.world.integration;
  integ.max_impact_speed_m_s = std::max(integ.max_impact_speed_m_s, drive_impact_speed(options));
  const double user_step = integ.time_step_s;
  integ.time_step_s = 0.0;
  plan.bound = time_step_bound(plan.world);
  const TimeStepBound& bound = plan.bound;
  plan.impact_speed_m_s = integ.max_impact_speed_m_s;
  // Stability limit: the Rayleigh time (the explicit critical step of the wave through a
  // sphere, Li, Xu & Thornton 2005) and kMinStepsPerContact at the impact speed.
  plan.stability_limit_s = std::min(bound.rayleigh_time_s, bound.contact_time_s / kMinStepsPerContact);
  if (user_step > plan.stability_limit_s) {
    std::ostringstream msg;
    msg << "dem.integration.time_step_s = " << user_step << ": must be <= " << plan.stability_limit_s
        << " s, the stability limit: the Rayleigh time " << bound.rayleigh_time_s << " s or "
        << kMinStepsPerContact << " steps of the contact time " << bound.contact_time_s << " s at "
        << integ.max_impact_speed_m_s << " m/s (the automatic step is " << bound.max_time_step_s << " s: "
        << integ.steps_per_contact << " steps per contact or " << integ.rayleigh_fraction << " of the Rayleigh time)";
    throw std::invalid_argument(msg.str());
  }
  // The automatic bound of metre-sized soft spheres can exceed the largest step the
  // integration takes (limits::kMaxTimeStep_s): the run then steps at that limit.
  const double target_step = user_step > 0.0 ? user_step : std::min(bound.max_time_step_s, limits::kMaxTimeStep_s);
  const double period = 1.0 / options.frequency_hz;
  const int samples = options.samples_per_period;
  plan.steps_per_block = static_cast<std::int64_t>(std::ceil(period / (samples * target_step) - 1e-9));
  plan.steps_per_period = plan.steps_per_block * samples;
  plan.dt = period / static_cast<double>(plan.steps_per_period);
  integ.time_step_s = plan.dt;
  plan.steps_per_contact = bound.contact_time_s / plan.dt;
  if (plan.dt > bound.max_time_step_s) {
    // A user step between the automatic bound and the stability limit: accepted, with
    // what it costs. The world checks its step against its own bound at
    // max_impact_speed_m_s, so it is built at the (lower) speed whose bound this step
    // is: t_c ∝ v^{−1/5}, v_w = v·(t_c(v)/(N_c·dt))^5. That speed only sets the world's
    // bound and its energy-growth threshold (½m_bed v_w²); restitution laws were
    // validated up to v above.
    std::ostringstream w;
    w << "dem.integration.time_step_s = " << user_step << " s is above the automatic bound "
      << bound.max_time_step_s << " s: " << plan.steps_per_contact << " steps per contact at the impact speed "
      << plan.impact_speed_m_s << " m/s (automatic: " << integ.steps_per_contact << ")";
    const double e_min = smallest_restitution(plan.world);
    if (std::isfinite(e_min)) {
      w << "; one impact then realises a restitution low by up to (0.6 ln^2(e) + 0.1)/N = "
        << 100.0 * restitution_error_bound(e_min, plan.steps_per_contact) << "% at e = " << e_min;
    } else {
      w << "; one impact then realises a restitution low by up to (0.6 ln^2(e) + 0.1)/N of e";
    }
    w << " (docs/dem.md)";
    plan.warnings.push_back(w.str());
    const double ratio = bound.contact_time_s / (integ.steps_per_contact * plan.dt);
    integ.max_impact_speed_m_s = plan.impact_speed_m_s * std::pow(ratio, 5.0);
    integ.rayleigh_fraction = std::min(1.0, std::max(integ.rayleigh_fraction, plan.dt / bound.rayleigh_time_s));
    for (int k = 0; k < 8 && time_step_bound(plan.world).max_time_step_s < plan.dt; ++k) {
      integ.max_impact_speed_m_s *= 1.0 - 1e-9 * (1 << (2 * k));
      if (integ.rayleigh_fraction < 1.0) integ.rayleigh_fraction = std::min(1.0, integ.rayleigh_fraction * (1.0 + 1e-12));
    }
  }

  // Settling: automatic = long enough for the bed to come to rest under gravity.
  double settling = options.settling_time_s;
  if (settling < 0.0) {
    bool random = false;
    for (const auto& c : plan.world.compartments) random = random || c.placement == InitialPlacement::kRandom;
    const double g_norm = norm(plan.world.gravity_m_s2);
    settling = g_norm == 0.0 ? 0.0
                             : (random ? 2.0 * std::sqrt(2.0 * fall_height(plan.world) / g_norm) + 0.02 : 0.01);
  }
  plan.settle_steps = static_cast<std::int64_t>(std::ceil(settling / plan.dt));
  plan.transient_steps = plan.steps_per_period * options.transient_periods;
  plan.analysed_steps = plan.steps_per_period * options.analysed_periods;
  plan.total_steps = plan.settle_steps + plan.transient_steps + plan.analysed_steps;
  for (const auto& c : plan.world.compartments) {
    for (const auto& g : c.particles) plan.particles += g.count;
  }
  return plan;
}

ParticleSnapshot snapshot_of(const World& world, double time_s) {
  ParticleSnapshot s;
  s.time_s = time_s;
  const int n = world.particle_count();
  for (int i = 0; i < n; ++i) {
    s.positions_m.push_back(world.position(i));
    s.velocities_m_s.push_back(world.velocity(i));
    s.angular_velocities_rad_s.push_back(world.angular_velocity(i));
    s.radii_m.push_back(world.radius(i));
    s.compartments.push_back(world.compartment(i));
  }
  return s;
}

}  // namespace

std::string_view to_string(MotionMode mode) {
  switch (mode) {
    case MotionMode::kSolidLike:
      return "solid_like";
    case MotionMode::kRollingCollectAndCollide:
      return "rolling_collect_and_collide";
    case MotionMode::kBouncingCollectAndCollide:
      return "bouncing_collect_and_collide";
    case MotionMode::kScattering:
      return "scattering";
    case MotionMode::kLocalFluidisation:
      return "local_fluidisation";
    case MotionMode::kGlobalFluidisation:
      return "global_fluidisation";
    case MotionMode::kDecoupled:
      return "decoupled";
  }
  return "scattering";
}

std::vector<std::string> DamperSimulationOptions::validate(const std::string& prefix) const {
  std::vector<std::string> errors = world.validate(prefix);
  const auto add = [&](bool ok, const std::string& field, auto value, const std::string& rule) {
    if (ok) return;
    std::ostringstream line;
    line << prefix << field << " = " << value << ": " << rule;
    errors.push_back(line.str());
  };
  const auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  const double axis = norm(drive_axis);
  if (!(std::isfinite(axis) && axis > 0.0)) {
    std::ostringstream line;
    line << prefix << "drive_axis = [" << drive_axis[0] << ", " << drive_axis[1] << ", " << drive_axis[2]
         << "]: must be a finite non-zero vector";
    errors.push_back(line.str());
  }
  std::ostringstream amplitude_rule, frequency_rule;
  amplitude_rule << "must be in (0, " << limits::kMaxAmplitude_m << "] m";
  frequency_rule << "must be in [" << limits::kMinFrequency_hz << ", " << limits::kMaxFrequency_hz << "] Hz";
  const bool amplitude_ok = in(amplitude_m, 0.0, limits::kMaxAmplitude_m) && amplitude_m > 0.0;
  const bool frequency_ok = in(frequency_hz, limits::kMinFrequency_hz, limits::kMaxFrequency_hz);
  add(amplitude_ok, "amplitude_m", amplitude_m, amplitude_rule.str());
  add(frequency_ok, "frequency_hz", frequency_hz, frequency_rule.str());
  add(settling_time_s == -1.0 || in(settling_time_s, 0.0, limits::kMaxSettlingTime_s), "settling_time_s",
      settling_time_s, "must be -1 (automatic) or in [0, " + std::to_string(static_cast<int>(limits::kMaxSettlingTime_s)) + "] s");
  const std::string periods = std::to_string(limits::kMaxPeriods);
  add(transient_periods >= 0 && transient_periods <= limits::kMaxPeriods, "transient_periods", transient_periods,
      "must be in [0, " + periods + "]");
  add(analysed_periods >= 1 && analysed_periods <= limits::kMaxPeriods, "analysed_periods", analysed_periods,
      "must be in [1, " + periods + "]");
  const bool samples_ok =
      samples_per_period >= limits::kMinSamplesPerPeriod && samples_per_period <= limits::kMaxSamplesPerPeriod;
  add(samples_ok, "samples_per_period", samples_per_period,
      "must be in [" + std::to_string(limits::kMinSamplesPerPeriod) + ", " +
          std::to_string(limits::kMaxSamplesPerPeriod) + "]");
  const long long recorded = static_cast<long long>(samples_per_period) * analysed_periods;
  if (samples_ok && analysed_periods >= 1) {
    add(recorded <= limits::kMaxRecordedSamples, "samples_per_period", samples_per_period,
        "samples_per_period x analysed_periods = " + std::to_string(recorded) + " recorded samples must be <= " +
            std::to_string(limits::kMaxRecordedSamples) + " (72 bytes each)");
  }
  const long long max_snapshots =
      samples_ok && analysed_periods >= 1 ? std::min<long long>(limits::kMaxSnapshots, recorded) : limits::kMaxSnapshots;
  add(snapshots >= 0 && snapshots <= max_snapshots, "snapshots", snapshots,
      "must be in [0, " + std::to_string(max_snapshots) + "] (at most one per recorded sample and " +
          std::to_string(limits::kMaxSnapshots) + ")");
  // The run raises integration.max_impact_speed_m_s to the drive's impact speed: that
  // speed must be in range too, and the restitution laws are checked up to it.
  if (errors.empty() && amplitude_ok && frequency_ok) {
    const double drive = drive_impact_speed(*this);
    std::ostringstream rule;
    rule << "the drive's impact speed 2XΩ + √(2|g|(H − 2r_min)) = " << drive << " m/s (frequency_hz = " << frequency_hz
         << ") must be <= " << limits::kMaxImpactSpeed_m_s << " m/s";
    add(drive <= limits::kMaxImpactSpeed_m_s, "amplitude_m", amplitude_m, rule.str());
    if (drive <= limits::kMaxImpactSpeed_m_s && drive > world.integration.max_impact_speed_m_s) {
      WorldOptions raised = world;
      raised.integration.max_impact_speed_m_s = drive;
      errors = raised.validate(prefix);
    }
  }
  return errors;
}

namespace {

/// Bytes of the world's arrays right after construction (World::Impl's reserves).
void estimate_world_bytes(const RunPlan& plan, RunEstimate& e) {
  const auto n = static_cast<std::size_t>(plan.particles);
  // 23 double arrays (state, forces, radii, masses, rebuild positions, scratch) and 5 int
  // arrays (material, compartment, order, index_of, scratch) per particle.
  e.particle_bytes = n * (23 * sizeof(double) + 5 * sizeof(int));
  // Row offsets get 1/8 margin (resize_with_margin); slots as reserved: 4 pair slots and
  // 1 wall slot per particle.
  const std::size_t offsets = 2 * (n + 1 + (n + 1) / 8) * sizeof(int);
  const std::size_t slots = (4 * n + n) * sizeof(detail::Slot);
  // The cell grid: at most max(64, 8n) cells (CellGrid::configure), 3 ints per particle.
  double r_max = 0.0;
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& c : plan.world.compartments) {
    for (const auto& g : c.particles) r_max = std::max(r_max, g.radius_m * (1.0 + g.radius_spread));
    for (int a = 0; a < 3; ++a) {
      const auto k = static_cast<std::size_t>(a);
      lo[k] = std::min(lo[k], c.offset_m[k] - 0.5 * c.container.inner_length(a));
      hi[k] = std::max(hi[k], c.offset_m[k] + 0.5 * c.container.inner_length(a));
    }
  }
  const double cell = (2.0 + plan.world.integration.skin_fraction) * r_max;
  double cells = 1.0;
  for (std::size_t a = 0; a < 3; ++a) cells *= std::max(1.0, std::ceil((hi[a] - lo[a]) / cell));
  cells = std::min(cells, std::max(64.0, 8.0 * static_cast<double>(n)));
  const std::size_t grid = (static_cast<std::size_t>(cells) + 1 + 3 * n) * sizeof(int);
  e.neighbour_bytes = offsets + slots + grid;
  // Contact pools as reserved: 2 pair contacts and n/2 + 16 wall contacts per particle,
  // each a Contact and a key (and a rolling torque with rolling resistance).
  bool rolling = plan.world.default_pair.rolling_friction > 0.0;
  for (const auto& p : plan.world.pairs) rolling = rolling || p.rolling_friction > 0.0;
  const std::size_t entry = sizeof(detail::Contact) + sizeof(detail::ContactKey) + (rolling ? 3 * sizeof(double) : 0);
  e.contact_bytes = (2 * n + n / 2 + 16) * entry;
}

/// Rates of bench/results/cpp-2core/bench_dem.txt (see RunEstimate::particle_steps_per_s).
double assumed_rate(int particles, int threads) {
  const bool parallel = threads != 1 && particles > 1500;  // World: kParallelParticles
  if (particles < 10'000) return 25e6;
  return parallel ? 21e6 : 11e6;
}

}  // namespace

RunEstimate estimate_run(const DamperSimulationOptions& options) {
  const RunPlan plan = plan_run(options);
  RunEstimate e;
  e.particles = plan.particles;
  e.time_step_s = plan.dt;
  e.impact_speed_m_s = plan.impact_speed_m_s;
  e.steps_per_contact = plan.steps_per_contact;
  e.stability_limit_s = plan.stability_limit_s;
  e.warnings = plan.warnings;
  e.steps_per_period = plan.steps_per_period;
  e.settling_steps = plan.settle_steps;
  e.transient_steps = plan.transient_steps;
  e.analysed_steps = plan.analysed_steps;
  e.total_steps = plan.total_steps;
  e.particle_steps = static_cast<double>(plan.total_steps) * plan.particles;
  e.recorded_samples = static_cast<std::int64_t>(options.analysed_periods) * options.samples_per_period;
  e.snapshots = options.snapshots;
  estimate_world_bytes(plan, e);
  // 7 TimeSeries columns and the 2 block-average signals per sample; η* per period.
  e.signal_bytes = static_cast<std::size_t>(e.recorded_samples) * 9 * sizeof(double) +
                   static_cast<std::size_t>(options.analysed_periods) * sizeof(double);
  // Per particle and snapshot: 3 Vec3, a radius, a compartment.
  e.snapshot_bytes = static_cast<std::size_t>(options.snapshots) * static_cast<std::size_t>(plan.particles) *
                     (3 * sizeof(Vec3) + sizeof(double) + sizeof(int));
  e.memory_bytes = e.particle_bytes + e.neighbour_bytes + e.contact_bytes + e.signal_bytes + e.snapshot_bytes;
  e.particle_steps_per_s = assumed_rate(plan.particles, options.world.threads);
  e.wall_time_s = e.particle_steps / e.particle_steps_per_s;
  return e;
}

void check_initial_placement(const DamperSimulationOptions& options) {
  if (const auto errors = options.validate(); !errors.empty()) throw std::invalid_argument(join_lines(errors));
  // run_harmonic starts the container at rest in its reference orientation, so gravity
  // in the body frame is gravity itself.
  (void)detail::place_particles(options.world, detail::build_walls(options.world), options.world.gravity_m_s2);
}

DamperResult run_harmonic(const DamperSimulationOptions& options, const ProgressCallback& progress) {
  const auto wall_start = Clock::now();
  const RunPlan plan = plan_run(options);
  const HarmonicMotion motion(options.drive_axis, options.amplitude_m, options.frequency_hz);
  const Vec3& axis = motion.axis();
  const double v_amp = motion.velocity_amplitude_m_s();
  const Vec3& g = options.world.gravity_m_s2;
  const double g_norm = norm(g);
  const WorldOptions& world_options = plan.world;
  const double dt = plan.dt;
  const int samples = options.samples_per_period;
  const std::int64_t steps_per_block = plan.steps_per_block;
  const std::int64_t steps_per_period = plan.steps_per_period;
  const std::int64_t settle_steps = plan.settle_steps;
  const std::int64_t drive_steps = plan.transient_steps + plan.analysed_steps;
  const std::int64_t total_steps = plan.total_steps;
  ProgressReporter reporter(progress, static_cast<double>(drive_steps) * dt, plan.particles);
  // Before the world is built (placement, lists and first forces take seconds for a
  // million spheres) and after: the estimate's wall time is the best ETA there is.
  const double eta_s = static_cast<double>(plan.particles) * static_cast<double>(total_steps) /
                       assumed_rate(plan.particles, options.world.threads);
  reporter.report_now("setup", -static_cast<double>(settle_steps) * dt, eta_s);

  const ContainerState start = motion.state(0.0);
  ContainerState rest = start;
  rest.velocity_m_s = {0.0, 0.0, 0.0};
  World world(world_options, rest);
  reporter.report_now("setup", -static_cast<double>(settle_steps) * dt, eta_s);
  reporter.start_stepping();

  DamperResult result;
  result.bed_mass_kg = world.bed_mass_kg();
  result.velocity_amplitude_m_s = v_amp;
  result.intensity = motion.intensity();
  result.time_step_s = dt;
  result.steps_per_period = static_cast<int>(steps_per_period);
  for (int c = 0; c < world.compartment_count(); ++c) result.compartment_clearances_m.push_back(world.clearance_m(c));
  result.clearance_m = result.compartment_clearances_m.front();
  const int n = world.particle_count();

  const auto finish = [&](Outcome outcome, const std::string& message) {
    auto& s = result.summary;
    s.outcome = outcome;
    s.message = message;
    s.steps = world.step_count();
    s.particle_steps = s.steps * n;
    s.neighbour_rebuilds = world.neighbour_rebuilds();
    s.particles = n;
    s.time_step_s = dt;
    s.simulated_time_s = world.time_s();
    s.wall_time_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
    s.stage_times = world.stage_times();
    result.particle_steps_per_s = s.wall_time_s > 0.0 ? static_cast<double>(s.particle_steps) / s.wall_time_s : 0.0;
  };
  // The world stops on an instability (kUnstable) or a failed step (kFailed).
  const auto unstable = [&]() { return world.status().outcome != Outcome::kCompleted; };

  for (std::int64_t k = 0; k < settle_steps; ++k) {
    world.step(rest);
    if (unstable()) {
      finish(world.status().outcome, world.status().message);
      return result;
    }
    reporter.maybe_report("settling", k, total_steps, (k - settle_steps) * dt);
  }

  const double settled_base = static_cast<double>(world.contact_census(g).touching_base) / n;
  // The drive starts with the bed at rest relative to the container: collected against
  // its wall and riding with it, as on the collect-and-collide orbit at detachment.
  world.add_velocity(start.velocity_m_s);
  const std::int64_t transient_steps = steps_per_period * options.transient_periods;
  for (std::int64_t k = 1; k <= transient_steps; ++k) {
    world.step(motion.state(static_cast<double>(k) * dt));
    if (unstable()) {
      finish(world.status().outcome, world.status().message);
      return result;
    }
    reporter.maybe_report("transient", settle_steps + k, total_steps, static_cast<double>(k) * dt);
  }

  // Analysis: the drive bin (Fourier coefficient at Ω) of the force and the container
  // velocity along the drive, accumulated every step and per period (the measures; no
  // aliasing, whatever samples_per_period), block averages of both (the recorded series,
  // for plots), and instantaneous samples of the bed at block ends.
  const int periods = options.analysed_periods;
  const std::int64_t blocks = static_cast<std::int64_t>(periods) * samples;
  TimeSeries& series = result.series;
  std::vector<double> force_blocks, velocity_blocks;
  force_blocks.reserve(static_cast<std::size_t>(blocks));
  velocity_blocks.reserve(static_cast<std::size_t>(blocks));
  for (auto* v : {&series.time_s, &series.container_position_m, &series.container_velocity_m_s, &series.force_n,
                  &series.bed_relative_position_m, &series.bed_momentum_kg_m_s, &series.kinetic_energy_j}) {
    v->reserve(static_cast<std::size_t>(blocks));
  }
  std::vector<double> rel_time_s;  // block ends, where the bed's x_r is sampled
  rel_time_s.reserve(static_cast<std::size_t>(blocks));
  const EnergyAccount e_start = world.energy();
  double base_sum = 0.0, airborne_sum = 0.0, spread_sum = 0.0;
  std::vector<double> fluctuation_sum(static_cast<std::size_t>(n), 0.0);  // Σ over blocks of |v_i − v_bed|², m²/s²
  const double packed_extent =
      world_options.compartments.front().container.inner_length(world_options.compartments.front().collect_axis) -
      result.clearance_m;
  std::vector<std::int64_t> snapshot_blocks;
  for (int s = 0; s < options.snapshots; ++s) {
    snapshot_blocks.push_back(static_cast<std::int64_t>((s + 1.0) * static_cast<double>(blocks) / options.snapshots) - 1);
  }
  // F_k of a step is the leapfrog impulse F_k·dt over [t_k − dt/2, t_k + dt/2]: held
  // constant there (formulas::StepForce::kConstant).
  formulas::DriveBinAccumulator period_bin(steps_per_period), all_bin(steps_per_period);
  const double m_bed = result.bed_mass_kg;
  std::int64_t step = transient_steps;
  for (std::int64_t b = 0; b < blocks; ++b) {
    double force_sum = 0.0, velocity_sum = 0.0;
    for (std::int64_t k = 0; k < steps_per_block; ++k) {
      ++step;
      const ContainerState state = motion.state(static_cast<double>(step) * dt);
      const ContainerLoad& load = world.step(state);
      if (unstable()) {
        finish(world.status().outcome, world.status().message);
        return result;
      }
      const double force_along = dot(load.force_n, axis);
      const double velocity_along = dot(state.velocity_m_s, axis);
      force_sum += force_along;
      velocity_sum += velocity_along;
      period_bin.add(step, force_along, velocity_along);
      reporter.maybe_report("analysis", settle_steps + step, total_steps, static_cast<double>(step) * dt);
    }
    const double t_mid = (static_cast<double>(step - steps_per_block) + 0.5 * static_cast<double>(steps_per_block + 1)) * dt;
    force_blocks.push_back(force_sum / static_cast<double>(steps_per_block));
    velocity_blocks.push_back(velocity_sum / static_cast<double>(steps_per_block));
    const ContainerState now = motion.state(static_cast<double>(step) * dt);
    series.time_s.push_back(t_mid);
    series.container_position_m.push_back(dot(motion.state(t_mid).position_m, axis));
    series.container_velocity_m_s.push_back(velocity_blocks.back());
    series.force_n.push_back(force_blocks.back());
    const Vec3 com = world.bed_centre_of_mass();
    series.bed_relative_position_m.push_back(dot(com, axis) - dot(now.position_m, axis));
    rel_time_s.push_back(static_cast<double>(step) * dt);
    series.bed_momentum_kg_m_s.push_back(dot(world.bed_momentum(), axis));
    const EnergyAccount e = world.energy();
    series.kinetic_energy_j.push_back(e.kinetic_j);
    const ContactCensus census = world.contact_census(g);
    base_sum += static_cast<double>(census.touching_base) / n;
    airborne_sum += static_cast<double>(census.airborne) / n;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int i = 0; i < n; ++i) {
      if (world.compartment(i) != 0) continue;
      const double along = dot(world.position(i), axis);
      lo = std::min(lo, along - world.radius(i));
      hi = std::max(hi, along + world.radius(i));
    }
    spread_sum += packed_extent > 0.0 ? (hi - lo) / packed_extent : kNaN;
    // Velocity of each sphere relative to the bed's mean velocity (the fluctuation).
    const Vec3 p_bed = world.bed_momentum();
    for (int i = 0; i < n; ++i) {
      const Vec3 v = world.velocity(i);
      double d2 = 0.0;
      for (std::size_t a = 0; a < 3; ++a) d2 += (v[a] - p_bed[a] / m_bed) * (v[a] - p_bed[a] / m_bed);
      fluctuation_sum[static_cast<std::size_t>(i)] += d2;
    }
    if (std::find(snapshot_blocks.begin(), snapshot_blocks.end(), b) != snapshot_blocks.end()) {
      result.snapshots.push_back(snapshot_of(world, static_cast<double>(step) * dt));
    }
    if ((b + 1) % samples == 0) {
      result.eta_star_per_period.push_back(period_bin.result(options.frequency_hz).reduced_loss_factor(m_bed));
      all_bin.merge(period_bin);
      period_bin.clear();
    }
  }
  const EnergyAccount e_end = world.energy();

  // Complex power over all analysed periods (PHYSICS.md §1): the sum of the periods' bins.
  const auto cp = all_bin.result(options.frequency_hz);
  result.eta_star = cp.reduced_loss_factor(m_bed);
  result.e_diss_j = cp.e_diss_j;
  result.energy_per_cycle_j = cp.energy_per_cycle_j;
  result.apparent_mass_kg = cp.apparent_mass_kg;
  const auto& per = result.eta_star_per_period;
  const double mean = std::accumulate(per.begin(), per.end(), 0.0) / periods;
  double var = 0.0;
  for (const double e : per) var += (e - mean) * (e - mean);
  var = periods > 1 ? var / (periods - 1) : 0.0;
  result.eta_star_stderr = periods > 1 ? std::sqrt(var / periods) : kNaN;

  // Energy balance over the analysed periods.
  EnergyBalance& eb = result.energy;
  eb.container_work_j = e_end.container_work_j - e_start.container_work_j;
  eb.normal_damping_j = e_end.normal_damping_j - e_start.normal_damping_j;
  eb.friction_j = e_end.friction_j - e_start.friction_j;
  eb.rolling_j = e_end.rolling_j - e_start.rolling_j;
  eb.delta_kinetic_j = e_end.kinetic_j - e_start.kinetic_j;
  eb.delta_potential_j = e_end.potential_j - e_start.potential_j;
  eb.delta_elastic_j = e_end.elastic_j - e_start.elastic_j;
  const double dissipated = eb.normal_damping_j + eb.friction_j + eb.rolling_j;
  const double delta_e = eb.delta_kinetic_j + eb.delta_potential_j + eb.delta_elastic_j;
  const double scale = std::max(std::abs(eb.container_work_j), dissipated);
  eb.relative_error = scale > 0.0 ? std::abs(eb.container_work_j - dissipated - delta_e) / scale : 0.0;
  result.energy_balance_error = eb.relative_error;
  result.eta_star_energy_balance = (dissipated + delta_e) / (periods * kPi * m_bed * v_amp * v_amp);

  // Motion mode.
  MotionIndicators& mi = result.indicators;
  const auto& rel = series.bed_relative_position_m;
  const auto [lo_it, hi_it] = std::minmax_element(rel.begin(), rel.end());
  mi.relative_stroke_over_clearance = result.clearance_m > 0.0 ? (*hi_it - *lo_it) / result.clearance_m : kNaN;
  mi.period_correlation = period_correlation(rel, samples, periods);
  mi.eta_star_variation = mean != 0.0 ? std::sqrt(var) / std::abs(mean) : 0.0;
  mi.apparent_mass_fraction = result.apparent_mass_kg / m_bed;
  mi.base_contact_fraction = base_sum / static_cast<double>(blocks);
  mi.airborne_fraction = airborne_sum / static_cast<double>(blocks);
  mi.spread_over_packed = spread_sum / static_cast<double>(blocks);
  mi.settled_base_contact_fraction = settled_base;
  // x_r about the container centre (compartment 0's offset along the drive).
  const double middle = dot(world_options.compartments.front().offset_m, axis);
  std::vector<double> rel_mid(rel.size());
  for (std::size_t k = 0; k < rel.size(); ++k) rel_mid[k] = rel[k] - middle;
  // Mobile spheres: rms speed relative to the bed's mean velocity above V/2.
  int mobile = 0;
  for (const double sum : fluctuation_sum) {
    mobile += std::sqrt(sum / static_cast<double>(blocks)) > ModeThresholds::kMobileSpeed * v_amp ? 1 : 0;
  }
  mi.mobile_fraction = static_cast<double>(mobile) / n;
  phase_indicators(rel_mid, rel_time_s, samples, periods, motion.angular_frequency_rad_s(), result.clearance_m, mi);
  result.motion_mode = classify(mi, result.eta_star, result.intensity);

  // Validity remarks.
  auto& warn = result.warnings;
  warn.insert(warn.end(), plan.warnings.begin(), plan.warnings.end());
  if (g_norm > 0.0 && std::abs(dot(g, axis)) > 1e-6 * g_norm) {
    warn.push_back("gravity has a component along the drive: the ideal collect-and-collide models do not apply");
  }
  if (result.energy_balance_error > 0.02) {
    std::ostringstream w;
    w << "energy balance error " << result.energy_balance_error
      << " exceeds 0.02: lower integration.time_step_s (raise steps_per_contact)";
    warn.push_back(w.str());
  }
  if (periods > 1 && result.eta_star_stderr > 0.1 * std::abs(result.eta_star)) {
    std::ostringstream w;
    w << "eta_star varies from period to period (standard error " << result.eta_star_stderr
      << "): the motion is irregular; analyse more periods";
    warn.push_back(w.str());
  }
  if (periods == 1) warn.push_back("one analysed period: eta_star_stderr is undefined (NaN)");
  finish(Outcome::kCompleted, "");
  return result;
}

}  // namespace pdamp::dem_reference
