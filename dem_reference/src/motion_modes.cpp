// Motion-mode indicators and labels of a driven run (docs/dem.md "Motion modes").
#include "pdamp/dem_reference/motion_modes.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "vec3_ops.hpp"

namespace pdamp::dem_reference {

const base::Fields<MotionIndicators>& MotionIndicators::fields() {
  using M = MotionIndicators;
  static const auto f =
      base::Fields<M>()
          .field("relative_stroke_over_clearance", &M::relative_stroke_over_clearance, "1",
                 "peak-to-peak travel of the bed relative to the container over h")
          .field("period_correlation", &M::period_correlation, "1", "correlation of consecutive periods' motion")
          .field("eta_star_variation", &M::eta_star_variation, "1", "coefficient of variation of the periods' eta*")
          .field("apparent_mass_fraction", &M::apparent_mass_fraction, "1", "apparent mass over bed mass")
          .field("base_contact_fraction", &M::base_contact_fraction, "1", "particles on the wall gravity presses on")
          .field("airborne_fraction", &M::airborne_fraction, "1", "particles touching nothing")
          .field("spread_over_packed", &M::spread_over_packed, "1", "the bed's extent along the drive over its packed extent")
          .field("phase_locked_stroke", &M::phase_locked_stroke, "1", "2 |x_r at Omega| / h")
          .field("phase_coherence", &M::phase_coherence, "1", "how alike the periods' phase at Omega is, [0, 1]")
          .field("phase_lag_deg", &M::phase_lag_deg, "deg", "lag of the bed's motion behind the container's")
          .field("crossing_fraction", &M::crossing_fraction, "1", "crossings of the clearance per half period")
          .field("settled_base_contact_fraction", &M::settled_base_contact_fraction, "1",
                 "base contact of the settled bed before the drive")
          .field("mobile_fraction", &M::mobile_fraction, "1", "spheres faster than V/2 relative to the bed");
  return f;
}

namespace {

using detail::dot;

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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
/// the mode definitions of docs/theory.md §8.1 and the ideal orbits of §2-3).
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
  /// the analysed periods (most of it rolls on its base, docs/theory.md §3); otherwise
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

MotionMode classify_motion(const MotionIndicators& m, double eta_star, double intensity) {
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

MotionModeAccumulator::MotionModeAccumulator(const World& world, const WorldOptions& world_options,
                                             const Vec3& drive_axis)
    : axis_(drive_axis),
      gravity_m_s2_(world_options.gravity_m_s2),
      bed_mass_kg_(world.bed_mass_kg()),
      clearance_m_(world.clearance_m(0)),
      packed_extent_m_(world_options.compartments.front().container.inner_length(
                           world_options.compartments.front().collect_axis) -
                       clearance_m_),
      centre_m_(dot(world_options.compartments.front().offset_m, drive_axis)),
      settled_base_fraction_(static_cast<double>(world.contact_census(world_options.gravity_m_s2).touching_base) /
                             world.particle_count()),
      fluctuation_sum_(static_cast<std::size_t>(world.particle_count()), 0.0) {}

void MotionModeAccumulator::save(StateWriter& out) const {
  out.f64(settled_base_fraction_);
  out.i64(blocks_);
  for (double v : {base_sum_, airborne_sum_, spread_sum_}) out.f64(v);
  out.f64s(fluctuation_sum_);
}

void MotionModeAccumulator::restore(StateReader& in) {
  settled_base_fraction_ = in.finite("motion_modes.settled_base_fraction");
  blocks_ = in.i64("motion_modes.blocks");
  if (blocks_ < 0) in.fail("motion_modes.blocks", "must not be negative");
  for (double* v : {&base_sum_, &airborne_sum_, &spread_sum_}) *v = in.finite("motion_modes.sums");
  fluctuation_sum_ = in.finite_f64s("motion_modes.fluctuation_sum", fluctuation_sum_.size());
}

void MotionModeAccumulator::sample_block(const World& world) {
  const int n = world.particle_count();
  ++blocks_;
  const ContactCensus census = world.contact_census(gravity_m_s2_);
  base_sum_ += static_cast<double>(census.touching_base) / n;
  airborne_sum_ += static_cast<double>(census.airborne) / n;
  // Extent of compartment 0's bed along the drive over its packed extent.
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int i = 0; i < n; ++i) {
    if (world.compartment(i) != 0) continue;
    const double along = dot(world.position(i), axis_);
    lo = std::min(lo, along - world.radius(i));
    hi = std::max(hi, along + world.radius(i));
  }
  spread_sum_ += packed_extent_m_ > 0.0 ? (hi - lo) / packed_extent_m_ : kNaN;
  // Velocity of each sphere relative to the bed's mean velocity (the fluctuation).
  const Vec3 p_bed = world.bed_momentum();
  for (int i = 0; i < n; ++i) {
    const Vec3 v = world.velocity(i);
    double d2 = 0.0;
    for (std::size_t a = 0; a < 3; ++a) d2 += (v[a] - p_bed[a] / bed_mass_kg_) * (v[a] - p_bed[a] / bed_mass_kg_);
    fluctuation_sum_[static_cast<std::size_t>(i)] += d2;
  }
}

MotionIndicators MotionModeAccumulator::indicators(const BlockRecorder& recorder, const DriveBinMeasures& measures,
                                                   const MotionReference& drive) const {
  MotionIndicators mi;
  const int samples = recorder.options().blocks_per_period;
  const int periods = static_cast<int>(recorder.recorded_blocks() / samples);
  const auto blocks = static_cast<double>(blocks_);
  const auto& rel = recorder.series().bed_relative_position_m;
  if (!rel.empty()) {
    const auto [lo_it, hi_it] = std::minmax_element(rel.begin(), rel.end());
    mi.relative_stroke_over_clearance = clearance_m_ > 0.0 ? (*hi_it - *lo_it) / clearance_m_ : kNaN;
  } else {
    mi.relative_stroke_over_clearance = kNaN;
  }
  mi.period_correlation = period_correlation(rel, samples, periods);
  mi.eta_star_variation = measures.eta_star_variation;
  mi.apparent_mass_fraction = measures.apparent_mass_kg / bed_mass_kg_;
  mi.base_contact_fraction = base_sum_ / blocks;
  mi.airborne_fraction = airborne_sum_ / blocks;
  mi.spread_over_packed = spread_sum_ / blocks;
  mi.settled_base_contact_fraction = settled_base_fraction_;
  // x_r about the container centre (compartment 0's offset along the drive).
  std::vector<double> rel_mid(rel.size());
  for (std::size_t k = 0; k < rel.size(); ++k) rel_mid[k] = rel[k] - centre_m_;
  // Mobile spheres: rms speed relative to the bed's mean velocity above V/2.
  int mobile = 0;
  for (const double sum : fluctuation_sum_) {
    mobile += std::sqrt(sum / blocks) > ModeThresholds::kMobileSpeed * drive.velocity_amplitude_m_s ? 1 : 0;
  }
  mi.mobile_fraction = static_cast<double>(mobile) / static_cast<double>(fluctuation_sum_.size());
  phase_indicators(rel_mid, recorder.sample_times_s(), samples, periods, drive.angular_frequency_rad_s, clearance_m_,
                   mi);
  return mi;
}

}  // namespace pdamp::dem_reference
