// Harmonic DEM run of one damper: settling, transient, analysed periods, and the
// measures (complex power, energy balance, motion mode), assembled from the run
// machinery that other drivers share (docs/dem.md "Run machinery").
#include "pdamp/dem_reference/damper_simulation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/drive_time_step.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "initial_state.hpp"
#include "vec3_ops.hpp"
#include "walls.hpp"
#include "world_data.hpp"

namespace pdamp::dem_reference {

const base::Fields<DamperResult>& DamperResult::fields() {
  using R = DamperResult;
  static const auto f =
      base::Fields<R>()
          .field("eta_star", &R::eta_star, "1", "reduced loss factor from the complex power")
          .field("eta_star_stderr", &R::eta_star_stderr, "1", "standard error of the periods' mean")
          .field("eta_star_energy_balance", &R::eta_star_energy_balance, "1", "eta* from the energy balance instead")
          .field("e_diss_j", &R::e_diss_j, "J", "Re(P)/Omega")
          .field("energy_per_cycle_j", &R::energy_per_cycle_j, "J", "2 pi E_diss")
          .field("apparent_mass_kg", &R::apparent_mass_kg, "kg", "Im(F* conj V*)/(Omega |V*|^2)")
          .derived("apparent_mass_fraction", [](const R& r) { return r.apparent_mass_kg / r.bed_mass_kg; }, "1",
                   "apparent mass over bed mass")
          .field("energy_balance_error", &R::energy_balance_error, "1", "the energy ledger's relative error")
          .field("particle_steps_per_s", &R::particle_steps_per_s, "1/s", "particle steps per wall-clock second")
          .field("motion_mode", &R::motion_mode, "", "the bed's motion mode")
          .field("clearance_m", &R::clearance_m, "m", "h of the collected bed")
          .field("bed_mass_kg", &R::bed_mass_kg, "kg", "particle mass")
          .field("intensity", &R::intensity, "1", "X Omega^2 / g")
          .field("velocity_amplitude_m_s", &R::velocity_amplitude_m_s, "m/s", "X Omega")
          .field("time_step_s", &R::time_step_s, "s", "the integration step")
          .field("steps_per_period", &R::steps_per_period, "", "steps per drive period")
          .field("eta_star_per_period", &R::eta_star_per_period, "1", "eta* of each analysed period")
          .field("energy", &R::energy, "", "the energy ledger over the analysed periods")
          .field("motion_indicators", &R::indicators, "", "what the motion mode was read from")
          .group("run", "the run",
                 base::Fields<R>()
                     .derived("outcome", [](const R& r) { return r.summary.outcome; }, "", "completed, unstable or failed")
                     .derived("steps", [](const R& r) { return r.summary.steps; }, "", "integration steps")
                     .derived("particles", [](const R& r) { return r.summary.particles; }, "", "spheres")
                     .derived("wall_time_s", [](const R& r) { return r.summary.wall_time_s; }, "s", "wall time")
                     .derived("neighbour_rebuilds", [](const R& r) { return r.summary.neighbour_rebuilds; }, "",
                              "Verlet-list rebuilds"));
  return f;
}

namespace {

using detail::dot;
using detail::norm;
using Clock = std::chrono::steady_clock;
constexpr double kPi = 3.14159265358979323846;

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

/// Reports progress to the hooks about twice a second. The clock is read every `stride`
/// steps, a power of two with stride × particles ≈ 65,536 particle-steps (every step from
/// 65,536 particles on, every 2048th for 36): one read costs ~20 ns, a step of a large
/// world milliseconds, so that the first report of a 1e6-particle run comes after 0.5 s and
/// not after 4096 steps (minutes), as with a fixed stride.
class ProgressReporter {
 public:
  ProgressReporter(base::RunHooks& hooks, double end_time_s, int particles)
      : hooks_(hooks), end_time_s_(end_time_s), start_(Clock::now()), last_(start_) {
    std::int64_t stride = 1;
    while (stride < 4096 && stride * 2 * std::max(particles, 1) <= 65536) stride *= 2;
    mask_ = stride - 1;
  }
  /// Reports now (the set-up stages, before any step: no rate yet).
  void report_now(const char* stage, double time_s, double eta_s) {
    base::Progress p;
    p.stage = stage;
    p.done = time_s;
    p.total = end_time_s_;
    p.eta_s = eta_s;
    hooks_.progress(p);
    last_ = Clock::now();
  }
  /// The stepping starts: the rate is measured from here.
  void start_stepping() { start_ = Clock::now(); }
  void maybe_report(const char* stage, std::int64_t step, std::int64_t total_steps, double time_s) {
    if ((step & mask_) != 0) return;
    const auto now = Clock::now();
    if (std::chrono::duration<double>(now - last_).count() < 0.5) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0.0 ? static_cast<double>(step) / elapsed : 0.0;
    base::Progress p;
    p.stage = stage;
    p.done = time_s;
    p.total = end_time_s_;
    p.steps_per_s = rate;
    p.eta_s = rate > 0.0 ? static_cast<double>(total_steps - step) / rate : 0.0;
    hooks_.progress(p);
  }

 private:
  base::RunHooks& hooks_;
  double end_time_s_;
  Clock::time_point start_;
  Clock::time_point last_;
  std::int64_t mask_ = 0;
};

/// The harmonic drive's peak container speed V = X·2πf, m/s (in this order of operations:
/// the impact speed, and so the time step, depend on its last bit).
/// The drive's largest velocity amplitude: XΩ, or X_aΩ when the run approaches from X_a > X.
/// (The ramp's A' sin Ωt adds at most (X_a − X)/(N_ramp T) < X_aΩ/(2π N_ramp): 1.6 % of X_aΩ
/// for the default 10 ramp periods, inside the margin of the contact's steps.)
double harmonic_peak_speed(const DamperSimulationOptions& o) {
  return std::max(o.amplitude_m, o.approach_amplitude_m) * 2.0 * kPi * o.frequency_hz;
}

/// Steps of the approach from above (DamperSimulationOptions::approach_amplitude_m).
std::int64_t approach_periods(const DamperSimulationOptions& o) {
  return o.approach_amplitude_m > 0.0 ? o.approach_hold_periods + o.approach_ramp_periods : 0;
}

/// What run_harmonic and estimate_run derive from the options before building a world.
struct RunPlan {
  DriveTimeStep step;  ///< time step, step counts per block and period, the world options to build
  std::int64_t settle_steps = 0;
  std::int64_t approach_steps = 0;
  std::int64_t transient_steps = 0;
  std::int64_t analysed_steps = 0;
  std::int64_t total_steps = 0;
  int particles = 0;
};

/// Spheres of every compartment of `world`.
int particle_count(const WorldOptions& world) {
  int particles = 0;
  for (const auto& c : world.compartments)
    for (const auto& g : c.particles) particles += g.count;
  return particles;
}

/// Validates (std::invalid_argument: all violations) and plans: the drive's time step
/// (drive_time_step: the bound at the drive's largest impact speed, a period of whole
/// blocks of whole steps), the settling time, the step counts.
RunPlan plan_run(const DamperSimulationOptions& options) {
  if (const auto errors = options.validate(); !errors.empty()) throw std::invalid_argument(join_lines(errors));
  RunPlan plan;
  DriveTiming timing;
  timing.period_s = 1.0 / options.frequency_hz;
  timing.blocks_per_period = options.samples_per_period;
  timing.impact_speed_m_s = drive_impact_speed(options.world, harmonic_peak_speed(options));
  plan.step = drive_time_step(options.world, timing);
  const double settling =
      options.settling_time_s < 0.0 ? automatic_settling_time_s(plan.step.world) : options.settling_time_s;
  plan.settle_steps = static_cast<std::int64_t>(std::ceil(settling / plan.step.time_step_s));
  plan.approach_steps = plan.step.steps_per_period * approach_periods(options);
  plan.transient_steps = plan.step.steps_per_period * options.transient_periods;
  plan.analysed_steps = plan.step.steps_per_period * options.analysed_periods;
  plan.total_steps = plan.settle_steps + plan.approach_steps + plan.transient_steps + plan.analysed_steps;
  plan.particles = particle_count(plan.step.world);
  return plan;
}

}  // namespace

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
  add(approach_amplitude_m == 0.0 || (in(approach_amplitude_m, 0.0, limits::kMaxAmplitude_m) &&
                                      (!amplitude_ok || approach_amplitude_m > amplitude_m)),
      "approach_amplitude_m", approach_amplitude_m,
      "must be 0 (from rest) or > amplitude_m and <= " + std::to_string(static_cast<int>(limits::kMaxAmplitude_m)) + " m");
  add(approach_hold_periods >= 0 && approach_hold_periods <= limits::kMaxPeriods, "approach_hold_periods",
      approach_hold_periods, "must be in [0, " + periods + "]");
  add(approach_ramp_periods >= 1 && approach_ramp_periods <= limits::kMaxPeriods, "approach_ramp_periods",
      approach_ramp_periods, "must be in [1, " + periods + "]");
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
    const double drive = drive_impact_speed(world, harmonic_peak_speed(*this));
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
void estimate_world_bytes(const WorldOptions& world, int particles, RunEstimate& e) {
  const auto n = static_cast<std::size_t>(particles);
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
  for (const auto& c : world.compartments) {
    for (const auto& g : c.particles) r_max = std::max(r_max, g.radius_m * (1.0 + g.radius_spread));
    for (int a = 0; a < 3; ++a) {
      const auto k = static_cast<std::size_t>(a);
      lo[k] = std::min(lo[k], c.offset_m[k] - 0.5 * c.container.inner_length(a));
      hi[k] = std::max(hi[k], c.offset_m[k] + 0.5 * c.container.inner_length(a));
    }
  }
  const double cell = (2.0 + world.integration.skin_fraction) * r_max;
  double cells = 1.0;
  for (std::size_t a = 0; a < 3; ++a) cells *= std::max(1.0, std::ceil((hi[a] - lo[a]) / cell));
  cells = std::min(cells, std::max(64.0, 8.0 * static_cast<double>(n)));
  const std::size_t grid = (static_cast<std::size_t>(cells) + 1 + 3 * n) * sizeof(int);
  e.neighbour_bytes = offsets + slots + grid;
  // Contact pools as reserved: 2 pair contacts and n/2 + 16 wall contacts per particle,
  // each a Contact and a key (and a rolling torque with rolling resistance).
  bool rolling = world.default_pair.rolling_friction > 0.0;
  for (const auto& p : world.pairs) rolling = rolling || p.rolling_friction > 0.0;
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
  e.time_step_s = plan.step.time_step_s;
  e.impact_speed_m_s = plan.step.impact_speed_m_s;
  e.steps_per_contact = plan.step.steps_per_contact;
  e.stability_limit_s = plan.step.stability_limit_s;
  e.warnings = plan.step.warnings;
  e.steps_per_period = plan.step.steps_per_period;
  e.settling_steps = plan.settle_steps;
  e.approach_steps = plan.approach_steps;
  e.transient_steps = plan.transient_steps;
  e.analysed_steps = plan.analysed_steps;
  e.total_steps = plan.total_steps;
  e.particle_steps = static_cast<double>(plan.total_steps) * plan.particles;
  e.recorded_samples = static_cast<std::int64_t>(options.analysed_periods) * options.samples_per_period;
  e.snapshots = options.snapshots;
  estimate_world_bytes(plan.step.world, plan.particles, e);
  // Per sample: the 7 TimeSeries columns and the block-end times of BlockRecorder, and
  // the centred copy of x_r the motion indicators take at the end; η* per period.
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

WorldEstimate estimate_world(const WorldOptions& world) {
  WorldEstimate w;
  w.particles = particle_count(world);
  RunEstimate e;
  estimate_world_bytes(world, w.particles, e);
  w.memory_bytes = e.particle_bytes + e.neighbour_bytes + e.contact_bytes;
  w.particle_steps_per_s = assumed_rate(w.particles, world.threads);
  return w;
}

void check_initial_placement(const DamperSimulationOptions& options) {
  if (const auto errors = options.validate(); !errors.empty()) throw std::invalid_argument(join_lines(errors));
  // run_harmonic starts the container at rest in its reference orientation, so gravity
  // in the body frame is gravity itself.
  (void)detail::place_particles(options.world, detail::build_walls(options.world), options.world.gravity_m_s2);
}

namespace {

/// The approach from above (DamperSimulationOptions::approach_amplitude_m): hold periods at
/// X_a, then the stroke lowered linearly to X over the ramp periods, x_c = A(t) sin Ωt. It
/// ends after whole periods, at x_c = 0 with velocity XΩ: the state the transient's
/// x_c = X sin Ωt starts from, so the drive is continuous there. False when the world halted.
bool approach(World& world, const DamperSimulationOptions& o, const RunPlan& plan,
              const std::function<void(std::int64_t)>& report) {
  const HarmonicMotion unit(o.drive_axis, 1.0, o.frequency_hz);
  const Vec3& axis = unit.axis();
  const double omega = unit.angular_frequency_rad_s();
  const double dt = plan.step.time_step_s;
  const std::int64_t hold_steps = plan.step.steps_per_period * o.approach_hold_periods;
  const std::int64_t ramp_steps = plan.approach_steps - hold_steps;
  const double slope_m_s = (o.amplitude_m - o.approach_amplitude_m) / (static_cast<double>(ramp_steps) * dt);  // A'
  for (std::int64_t k = 1; k <= plan.approach_steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    const bool ramping = k > hold_steps;
    const double a = ramping ? o.approach_amplitude_m + slope_m_s * static_cast<double>(k - hold_steps) * dt
                             : o.approach_amplitude_m;
    const double x = a * std::sin(omega * t);
    const double v = a * omega * std::cos(omega * t) + (ramping ? slope_m_s * std::sin(omega * t) : 0.0);
    ContainerState state;
    for (std::size_t i = 0; i < 3; ++i) {
      state.position_m[i] = x * axis[i];
      state.velocity_m_s[i] = v * axis[i];
    }
    world.step(state);
    if (world.status().outcome != Outcome::kCompleted) return false;
    report(k);
  }
  return true;
}

}  // namespace

DamperResult run_harmonic(const DamperSimulationOptions& options, base::RunHooks& hooks,
                          const CheckpointStorage& checkpoints) {
  const auto wall_start = Clock::now();
  const RunPlan plan = plan_run(options);
  const HarmonicMotion motion(options.drive_axis, options.amplitude_m, options.frequency_hz);
  const Vec3& axis = motion.axis();
  const double v_amp = motion.velocity_amplitude_m_s();
  const Vec3& g = options.world.gravity_m_s2;
  const double g_norm = norm(g);
  const double dt = plan.step.time_step_s;
  const std::int64_t steps_per_period = plan.step.steps_per_period;
  const std::int64_t settle_steps = plan.settle_steps;
  const std::int64_t transient_steps = plan.transient_steps;
  const std::int64_t total_steps = plan.total_steps;
  const int periods = options.analysed_periods;
  ProgressReporter reporter(hooks, static_cast<double>(transient_steps + plan.analysed_steps) * dt, plan.particles);
  // Before the world is built (placement, lists and first forces take seconds for a
  // million spheres) and after: the estimate's wall time is the best ETA there is.
  const double eta_s = static_cast<double>(plan.particles) * static_cast<double>(total_steps) /
                       assumed_rate(plan.particles, options.world.threads);
  reporter.report_now("setup", -static_cast<double>(settle_steps) * dt, eta_s);

  const ContainerState start = motion.state(0.0);
  ContainerState rest = start;
  rest.velocity_m_s = {0.0, 0.0, 0.0};
  World world(plan.step.world, rest);
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
  const double m_bed = result.bed_mass_kg;

  // The analysed periods' parts: the series (block averages of the force and the
  // container velocity along the drive, the bed at block ends, snapshots) and the drive
  // bin accumulated every step and per period (the measures; no aliasing, whatever
  // samples_per_period).
  BlockRecorderOptions recording;
  recording.drive_axis = axis;
  recording.time_step_s = dt;
  recording.steps_per_block = plan.step.steps_per_block;
  recording.blocks_per_period = options.samples_per_period;
  recording.periods = periods;
  recording.start_step = transient_steps;
  recording.snapshots = options.snapshots;
  recording.prescribed_motion = &motion;
  BlockRecorder recorder(recording);
  DriveBinMeasure drive_bin(steps_per_period, options.frequency_hz, m_bed);

  double wall_before_s = 0.0;  // of the runs before a resume (CheckpointStorage::resume_state)
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
    s.wall_time_s = wall_before_s + std::chrono::duration<double>(Clock::now() - wall_start).count();
    s.stage_times = world.stage_times();
    result.particle_steps_per_s = s.wall_time_s > 0.0 ? static_cast<double>(s.particle_steps) / s.wall_time_s : 0.0;
  };
  // The world halts on an instability (kUnstable) or a failed step (kFailed): the result
  // keeps what was recorded so far, the measures stay unset.
  const auto halted = [&]() {
    if (world.status().outcome == Outcome::kCompleted) return false;
    result.eta_star_per_period = drive_bin.eta_star_per_period();
    result.series = recorder.take_series();
    result.snapshots = recorder.take_snapshots();
    finish(world.status().outcome, world.status().message);
    return true;
  };

  // A stop asked while the bed settles or approaches (no checkpoint can hold those phases)
  // ends the run at once without one: a big bed's settling can take hours.
  struct StoppedBeforeDrive {};
  const auto stop_asked = [&](std::int64_t k) { return k % kStopPollSteps == 0 && hooks.stop_requested() != 0; };
  const auto report_settling = [&](std::int64_t k) {
    reporter.maybe_report("settling", k, total_steps, static_cast<double>(k - settle_steps) * dt);
    if (stop_asked(k + 1)) throw StoppedBeforeDrive{};
  };
  // A resumed run starts where its checkpoint was written; a new one settles first.
  const bool resuming = !checkpoints.resume_state.empty();
  std::optional<StateReader> saved;
  std::int64_t first_step = 1;  // the next drive step
  bool analysing = false;
  if (resuming) {
    saved.emplace(checkpoints.resume_state, "harmonic run state");
    saved->expect_tag("harmonic run 3");  // 2: the drive bins and the block in progress; 3: snapshots' contacts
    analysing = saved->i32_in("phase", 1, 2) == 2;
    first_step = saved->i64("step") + 1;
    // Checkpoints are written inside the transient (phase 1) or the analysis (phase 2): at
    // period ends, or at any step when a stop was asked.
    const std::int64_t done = first_step - 1;
    if (done < 1 || done >= transient_steps + plan.analysed_steps || analysing != (done > transient_steps))
      saved->fail("step", std::to_string(done) + " in phase " + (analysing ? "2" : "1") +
                              ": not a checkpoint of this run's " +
                              std::to_string(transient_steps + plan.analysed_steps) + " drive steps");
    wall_before_s = saved->finite("wall_time_s");
    world.restore_state(*saved);
  } else {
    // The settled bed starts with the drive's velocity at t = 0 (X_aΩ when it approaches from X_a).
    const ContainerState drive_start =
        plan.approach_steps > 0 ? HarmonicMotion(axis, options.approach_amplitude_m, options.frequency_hz).state(0.0)
                                : start;
    try {
      if (!settle(world, drive_start, settle_steps, report_settling) && halted()) return result;  // false exactly when halted
      if (plan.approach_steps > 0 && !approach(world, options, plan, [&](std::int64_t k) {
            reporter.maybe_report("approach", settle_steps + k, total_steps,
                                  static_cast<double>(k - plan.approach_steps) * dt);
            if (stop_asked(k)) throw StoppedBeforeDrive{};
          }) && halted())
        return result;
    } catch (const StoppedBeforeDrive&) {
      result.stopped = true;
      finish(Outcome::kCompleted, "stopped before the drive started (no checkpoint)");
      return result;
    }
  }
  // Built on the settled bed: its base contacts are the rolling criterion's reference.
  MotionModeAccumulator motion_modes(world, plan.step.world, axis);
  std::optional<EnergyLedger> ledger;
  if (resuming) {
    motion_modes.restore(*saved);
    if (analysing) {
      EnergyAccount opening;
      for (double* v : {&opening.container_work_j, &opening.normal_damping_j, &opening.friction_j, &opening.rolling_j,
                        &opening.kinetic_j, &opening.potential_j, &opening.elastic_j})
        *v = saved->finite("ledger.opening");
      ledger.emplace(opening);
      drive_bin.restore(*saved);
      recorder.restore(*saved);
    }
    saved->expect_tag("end of harmonic run");
    saved->finish();
  }
  // A checkpoint at a period end when due, and at any step once a stop is asked (polled
  // every kStopPollSteps steps and at period ends: a period of a big bed can take an hour);
  // the run then ends.
  auto last_checkpoint = wall_start;
  const auto checkpoint = [&](std::int64_t step) {
    const bool period_end = step % steps_per_period == 0;
    const bool stopping = (period_end || step % kStopPollSteps == 0) && hooks.stop_requested() != 0;
    if (!stopping &&
        (!period_end || !hooks.checkpoint_due(std::chrono::duration<double>(Clock::now() - last_checkpoint).count())))
      return false;
    if (checkpoints.sink != nullptr) {
      StateWriter out;
      out.tag("harmonic run 3");
      out.i32(analysing ? 2 : 1);
      out.i64(step);
      out.f64(wall_before_s + std::chrono::duration<double>(Clock::now() - wall_start).count());
      world.save_state(out);
      motion_modes.save(out);
      if (analysing) {
        const EnergyAccount& a = ledger->opening();
        for (double v : {a.container_work_j, a.normal_damping_j, a.friction_j, a.rolling_j, a.kinetic_j, a.potential_j,
                         a.elastic_j})
          out.f64(v);
        drive_bin.save(out);
        recorder.save(out);
      }
      out.tag("end of harmonic run");
      checkpoints.sink->store(out.bytes(), static_cast<double>(step) * dt);
      last_checkpoint = Clock::now();
    }
    return stopping || hooks.stop_requested() != 0;
  };
  const auto stop_here = [&]() {
    result.stopped = true;
    finish(Outcome::kCompleted, "stopped at a checkpoint");
    return result;
  };
  for (std::int64_t k = first_step; k <= transient_steps; ++k) {
    world.step(motion.state(static_cast<double>(k) * dt));
    if (halted()) return result;
    reporter.maybe_report("transient", settle_steps + k, total_steps, static_cast<double>(k) * dt);
    if (k < transient_steps && checkpoint(k)) return stop_here();
  }

  if (!ledger) ledger.emplace(world.energy());
  analysing = true;
  for (std::int64_t step = std::max(transient_steps + 1, first_step); step <= transient_steps + plan.analysed_steps; ++step) {
    const ContainerState state = motion.state(static_cast<double>(step) * dt);
    const ContainerLoad& load = world.step(state);
    if (halted()) return result;
    drive_bin.add(step, dot(load.force_n, axis), dot(state.velocity_m_s, axis));
    if (recorder.record_step(world)) motion_modes.sample_block(world);
    reporter.maybe_report("analysis", settle_steps + step, total_steps, static_cast<double>(step) * dt);
    if (step < transient_steps + plan.analysed_steps && checkpoint(step)) return stop_here();
  }

  DriveBinMeasures measures = drive_bin.result();
  result.eta_star = measures.eta_star;
  result.eta_star_stderr = measures.eta_star_stderr;
  result.e_diss_j = measures.e_diss_j;
  result.energy_per_cycle_j = measures.energy_per_cycle_j;
  result.apparent_mass_kg = measures.apparent_mass_kg;
  result.energy = ledger->balance(world.energy());
  result.energy_balance_error = result.energy.relative_error;
  result.eta_star_energy_balance = (result.energy.dissipated_j() + result.energy.delta_energy_j()) /
                                   (periods * kPi * m_bed * v_amp * v_amp);
  MotionReference reference;
  reference.angular_frequency_rad_s = motion.angular_frequency_rad_s();
  reference.velocity_amplitude_m_s = v_amp;
  reference.intensity = result.intensity;
  result.indicators = motion_modes.indicators(recorder, measures, reference);
  result.motion_mode = classify_motion(result.indicators, result.eta_star, result.intensity);
  result.eta_star_per_period = std::move(measures.eta_star_per_period);
  result.series = recorder.take_series();
  result.snapshots = recorder.take_snapshots();

  // Validity remarks.
  auto& warn = result.warnings;
  warn.insert(warn.end(), plan.step.warnings.begin(), plan.step.warnings.end());
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
