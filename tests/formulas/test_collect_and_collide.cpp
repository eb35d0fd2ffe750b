// Tests of the collect-and-collide closed forms against analytic values and an event-driven impact map.
#include "pdamp/formulas/collect_and_collide.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace fm = pdamp::formulas;
using Catch::Matchers::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
const double kOnsetRadius = std::sqrt(kPi * kPi + 4.0);  // √(π²+4), derived in the docs
const double kOnsetAngle = std::atan(2.0 / kPi);         // α = atan(2/π)

/// φ − sin φ in long double: an 18-term series below 0.5 (where the difference
/// cancels), the direct difference above (relative error ~1e-18 there).
long double phi_minus_sin_ld(long double phi) {
  if (phi >= 0.5L) return phi - std::sin(phi);
  long double term = phi * phi * phi / 6.0L;
  long double sum = 0.0L;
  for (int k = 0; k < 18; ++k) {
    sum += term;
    term *= -phi * phi / static_cast<long double>((2 * k + 4) * (2 * k + 5));
  }
  return sum;
}

/// Independent root of φ − sin φ = r on [0, π]: plain bisection in long double, down
/// to a relative width of 1e-21 (about 1100 halvings for r = 1e-300).
long double reference_impact_phase(long double r) {
  long double lo = 0.0L;
  long double hi = static_cast<long double>(kPi);
  for (int i = 0; i < 2000 && hi - lo > 1e-21L * hi; ++i) {
    const long double mid = 0.5L * (lo + hi);
    if (phi_minus_sin_ld(mid) < r) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return 0.5L * (lo + hi);
}

template <class Call>
void require_invalid_argument(Call&& call, const std::string& key) {
  REQUIRE_THROWS_AS(call(), std::invalid_argument);
  REQUIRE_THROWS_WITH(call(), Contains(key));
}

bool has_warning(const fm::LossResult& result, const std::string& text) {
  return std::any_of(result.warnings.begin(), result.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// ---------------------------------------------------------------------------------------
// Independent reference: event-driven simulation of one bed element in a container
// x_c = X sin(Ωt) with walls at x = 0 and x = h (x is the free travel of the element).
//  - friction = 0: a point block (bouncing model). In flight it keeps its velocity,
//    so its relative acceleration is −a_c.
//  - friction > 0: a sphere of inertia κ m r² on the base with Coulomb friction μ:
//    rolling (relative acceleration −a_c/(1+κ), needs friction <= μ m g), slipping
//    (friction ∓μ m g on translation and spin), held at a wall (sliding until the
//    spin is gone). The wall is frictionless, so the spin survives the impact.
// Wall impacts are plastic (relative velocity to zero); after an impact or a release the
// element rides with the wall while the wall's force would be compressive. Between
// events every mode has an analytic solution, and events are found by scanning each
// cycle in 2048 steps and bisecting to a relative time of 4e-16, so event phases are
// accurate to ~1e-13 rad (the scan could only miss a pair of crossings within 3e-3 rad,
// i.e. a grazing contact). Energy: container work on the element (impulses J·v_c and
// forces F·v_c), impact losses ½ m u² and friction losses μ m g ∫|w| dt; bed mass 1 kg.
struct ImpactMapSetup {
  double clearance_m = 0.05;
  double stroke_m = 0.02;
  double frequency_hz = 2.0;
  double friction = 0.0;        ///< μ on the base; 0 = point block without spin
  double inertia_factor = 0.4;  ///< κ of the sphere (used when friction > 0)
};

struct Impact {
  double time_s = 0.0;
  int wall = 0;  ///< −1: wall at x = 0, +1: wall at x = h
};

class ImpactMap {
 public:
  explicit ImpactMap(const ImpactMapSetup& setup)
      : setup_(setup),
        omega_(2.0 * kPi * setup.frequency_hz),
        velocity_(setup.stroke_m * omega_),
        acceleration_(velocity_ * omega_),
        friction_acceleration_(setup.friction * fm::kStandardGravity) {}

  double period_s() const { return 1.0 / setup_.frequency_hz; }
  double omega() const { return omega_; }
  double velocity_amplitude() const { return velocity_; }

  /// Element at rest relative to the container against the wall at x = 0, phase Ωt.
  void start_collected(double phase_rad) {
    begin(Mode::kHeldStick, phase_rad / omega_, 0.0, 0.0, 0.0);
    enter_wall(-1);
  }

  void run_until(double t_end) {
    const double step = period_s() / kScanStepsPerCycle;
    while (t_now_ < t_end) {
      double t_a = t_now_;
      bool fired = false;
      for (bool first = true; t_a < t_end && !fired; first = false) {
        const double t_b = std::min(t_a + step, t_end);
        int which = -1;
        const double t_event = find_event(t_a, t_b, first, which);
        if (which >= 0) {
          apply_event(t_event, which);
          fired = true;
        } else {
          require_inside(t_b);
          t_a = t_b;
        }
      }
      if (!fired) t_now_ = t_end;
      if (++events_ > kMaxEvents) throw std::runtime_error("impact map: too many events");
    }
  }

  double container_work() const { return work_ + mode_work(t_now_); }
  double losses() const { return impact_loss_ + friction_loss_ + mode_friction_loss(t_now_); }
  double kinetic_energy() const {
    const State state = state_at(t_now_);
    const double v = state.u + velocity_ * std::cos(omega_ * t_now_);
    const double spin = setup_.friction > 0.0 ? setup_.inertia_factor * state.spin * state.spin : 0.0;
    return 0.5 * (v * v + spin);
  }
  const std::vector<Impact>& impacts() const { return impacts_; }
  /// Times the sphere could not roll because friction was short (μ < κ|a_c|/((1+κ)g)).
  int roll_failures() const { return roll_failures_; }

 private:
  static constexpr int kScanStepsPerCycle = 2048;
  static constexpr int kMaxEvents = 1000000;
  enum class Mode { kFlight, kRoll, kSlip, kHeldSlip, kHeldStick };
  /// Relative position x, relative velocity u, spin expressed as σ = ωr (slip w = u + σ).
  struct State {
    double x, u, spin;
  };
  /// u' = cu·a_c + du and σ' = cs·a_c + ds in the current mode.
  struct Rates {
    double cu = 0.0, du = 0.0, cs = 0.0, ds = 0.0;
  };

  Rates rates() const {
    const double k = setup_.inertia_factor;
    Rates r;
    switch (mode_) {
      case Mode::kFlight: r.cu = -1.0; break;
      case Mode::kRoll: r.cu = -1.0 / (1.0 + k); r.cs = 1.0 / (1.0 + k); break;
      case Mode::kSlip:
        r.cu = -1.0;
        r.du = -friction_acceleration_ * slip_;
        r.ds = -friction_acceleration_ * slip_ / k;
        break;
      case Mode::kHeldSlip: r.ds = -friction_acceleration_ * slip_ / k; break;
      case Mode::kHeldStick: break;
    }
    return r;
  }
  double container_acceleration(double t) const { return -acceleration_ * std::sin(omega_ * t); }
  double container_velocity(double t) const { return velocity_ * std::cos(omega_ * t); }
  double container_position(double t) const { return setup_.stroke_m * std::sin(omega_ * t); }

  State state_at(double t) const {
    const Rates r = rates();
    const double tau = t - t0_;
    const double dv = container_velocity(t) - vc0_;
    const double dx = container_position(t) - xc0_ - vc0_ * tau;
    return State{x0_ + u0_ * tau + r.cu * dx + 0.5 * r.du * tau * tau, u0_ + r.cu * dv + r.du * tau,
                 spin0_ + r.cs * dv + r.ds * tau};
  }
  /// ∫ F·v_c dt since the mode began, F = m(u' + a_c) the container's force on the bed.
  double mode_work(double t) const {
    const Rates r = rates();
    const double vc = container_velocity(t);
    return (r.cu + 1.0) * 0.5 * (vc * vc - vc0_ * vc0_) + r.du * (container_position(t) - xc0_);
  }
  /// μ m g ∫|w| dt since the mode began (w keeps its sign within a slip mode).
  double mode_friction_loss(double t) const {
    if (mode_ != Mode::kSlip && mode_ != Mode::kHeldSlip) return 0.0;
    const double tau = t - t0_;
    const double spin_integral = spin0_ * tau + 0.5 * rates().ds * tau * tau;
    return friction_acceleration_ * slip_ * (state_at(t).x - x0_ + spin_integral);
  }

  int event_count() const {
    switch (mode_) {
      case Mode::kFlight: return 2;
      case Mode::kRoll:
      case Mode::kSlip: return 3;
      case Mode::kHeldSlip: return 2;
      case Mode::kHeldStick: return 1;
    }
    return 0;
  }
  /// Event functions: positive while the mode lasts.
  double event_value(int i, double t) const {
    const State s = state_at(t);
    const double ac = container_acceleration(t);
    const double k = setup_.inertia_factor;
    switch (mode_) {
      case Mode::kFlight:
      case Mode::kRoll:
      case Mode::kSlip:
        if (i == 0) return s.x;
        if (i == 1) return setup_.clearance_m - s.x;
        if (mode_ == Mode::kRoll) return friction_acceleration_ - k / (1.0 + k) * std::abs(ac);
        return slip_ * (s.u + s.spin);
      case Mode::kHeldSlip:
        // Wall force N = m(a_c + μ g·slip) must push the bed away from the wall.
        if (i == 0) return slip_ * s.spin;
        return -wall_ * (ac + friction_acceleration_ * slip_);
      case Mode::kHeldStick: return -wall_ * ac;
    }
    return 1.0;
  }

  /// Earliest event in (t_a, t_b]; on the first step of a mode the functions count as
  /// positive at t_a (they may start at zero, e.g. x = 0 when leaving a wall).
  double find_event(double t_a, double t_b, bool first, int& which) const {
    which = -1;
    double earliest = t_b;
    for (int i = 0; i < event_count(); ++i) {
      if (event_value(i, t_b) > 0.0) continue;
      if (!first && event_value(i, t_a) <= 0.0) continue;
      double lo = t_a;
      double hi = t_b;
      for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        if (event_value(i, mid) > 0.0) {
          lo = mid;
        } else {
          hi = mid;
        }
      }
      if (which < 0 || hi < earliest) {
        earliest = hi;
        which = i;
      }
    }
    return earliest;
  }

  void require_inside(double t) const {
    const double x = state_at(t).x;
    if (x < -1e-9 * setup_.clearance_m || x > (1.0 + 1e-9) * setup_.clearance_m) {
      throw std::runtime_error("impact map: the element left the container");
    }
  }

  void begin(Mode mode, double t, double x, double u, double spin) {
    mode_ = mode;
    t0_ = t;
    t_now_ = t;
    x0_ = x;
    u0_ = u;
    spin0_ = spin;
    vc0_ = container_velocity(t);
    xc0_ = container_position(t);
  }

  void apply_event(double t, int which) {
    const State s = state_at(t);
    work_ += mode_work(t);
    friction_loss_ += mode_friction_loss(t);
    const bool free = mode_ == Mode::kFlight || mode_ == Mode::kRoll || mode_ == Mode::kSlip;
    if (free && which <= 1) {  // plastic wall impact: impulse −m u at the wall velocity
      const int wall = which == 0 ? -1 : 1;
      impacts_.push_back({t, wall});
      impact_loss_ += 0.5 * s.u * s.u;
      work_ += -s.u * container_velocity(t);
      begin(Mode::kHeldStick, t, wall < 0 ? 0.0 : setup_.clearance_m, 0.0, s.spin);
      enter_wall(wall);
    } else if (mode_ == Mode::kRoll) {  // friction short: slip in the direction of w'
      ++roll_failures_;
      slip_ = container_acceleration(t) > 0.0 ? -1.0 : 1.0;
      begin(Mode::kSlip, t, s.x, s.u, s.spin);
    } else if (mode_ == Mode::kSlip) {  // w = 0: the sphere may roll
      begin(Mode::kSlip, t, s.x, s.u, -s.u);
      enter_free();
    } else if (mode_ == Mode::kHeldSlip && which == 0) {  // spin gone at the wall
      begin(Mode::kHeldStick, t, s.x, 0.0, 0.0);
      enter_wall(wall_);
    } else {  // the wall force would turn tensile: release
      begin(Mode::kSlip, t, s.x, 0.0, s.spin);
      enter_free();
    }
  }

  /// Chooses the free mode from the state set by begin().
  void enter_free() {
    if (setup_.friction == 0.0) {
      mode_ = Mode::kFlight;
      return;
    }
    const double w = u0_ + spin0_;
    if (std::abs(w) > 1e-12 * velocity_) {
      slip_ = w > 0.0 ? 1.0 : -1.0;
      mode_ = Mode::kSlip;
      return;
    }
    const double ac = container_acceleration(t0_);
    const double k = setup_.inertia_factor;
    spin0_ = -u0_;
    if (k / (1.0 + k) * std::abs(ac) <= friction_acceleration_) {
      mode_ = Mode::kRoll;
    } else {
      ++roll_failures_;
      slip_ = ac > 0.0 ? -1.0 : 1.0;
      mode_ = Mode::kSlip;
    }
  }

  /// At a wall with u = 0: held (sliding off the spin, or sticking) or released.
  void enter_wall(int wall) {
    wall_ = wall;
    const double ac = container_acceleration(t0_);
    if (setup_.friction > 0.0 && std::abs(spin0_) > 1e-12 * velocity_) {
      const double slip = spin0_ > 0.0 ? 1.0 : -1.0;
      if (-wall * (ac + friction_acceleration_ * slip) > 0.0) {
        slip_ = slip;
        mode_ = Mode::kHeldSlip;
        return;
      }
      enter_free();
      return;
    }
    spin0_ = 0.0;
    if (-wall * ac > 0.0) {
      mode_ = Mode::kHeldStick;
      return;
    }
    enter_free();
  }

  ImpactMapSetup setup_;
  double omega_;
  double velocity_;
  double acceleration_;
  double friction_acceleration_;
  Mode mode_ = Mode::kHeldStick;
  double t0_ = 0.0, t_now_ = 0.0, x0_ = 0.0, u0_ = 0.0, spin0_ = 0.0, vc0_ = 0.0, xc0_ = 0.0;
  double slip_ = 1.0;  ///< sign of the slip velocity w in a slip mode
  int wall_ = -1;
  double work_ = 0.0, impact_loss_ = 0.0, friction_loss_ = 0.0;
  int roll_failures_ = 0;
  long events_ = 0;
  std::vector<Impact> impacts_;
};

/// Steady-state measurement over whole cycles after a warm-up.
struct Measurement {
  double eta_star = 0.0;         ///< (W − ΔK)/(cycles·π m V²) = E_diss/(½ m V²)
  double balance_error = 0.0;    ///< (W − ΔK − losses)/losses
  int impacts = 0;               ///< impacts in the measured cycles
  double left_phase = 0.0;       ///< Ωt mod 2π of the impacts on the wall at x = 0
  double right_phase = 0.0;      ///< ... at x = h
  double phase_spread = 0.0;     ///< largest spread of the impact phases at one wall
};

Measurement measure(const ImpactMapSetup& setup, double start_phase_rad, int warm_cycles = 200,
                    int cycles = 20) {
  ImpactMap map(setup);
  map.start_collected(start_phase_rad);
  const double period = map.period_s();
  const double t_begin = (std::ceil(start_phase_rad / (2.0 * kPi)) + warm_cycles) * period;
  map.run_until(t_begin);
  const double work0 = map.container_work();
  const double kinetic0 = map.kinetic_energy();
  const double losses0 = map.losses();
  const std::size_t first = map.impacts().size();
  map.run_until(t_begin + cycles * period);
  const double dissipated = map.container_work() - work0 - (map.kinetic_energy() - kinetic0);
  const double v = map.velocity_amplitude();

  Measurement m;
  m.eta_star = dissipated / (cycles * kPi * v * v);
  m.balance_error = (dissipated - (map.losses() - losses0)) / std::max(map.losses() - losses0, 1e-300);
  double lo[2] = {1e9, 1e9};
  double hi[2] = {-1e9, -1e9};
  for (std::size_t i = first; i < map.impacts().size(); ++i) {
    const Impact& impact = map.impacts()[i];
    const double phase = std::fmod(map.omega() * impact.time_s, 2.0 * kPi);
    const int side = impact.wall < 0 ? 0 : 1;
    lo[side] = std::min(lo[side], phase);
    hi[side] = std::max(hi[side], phase);
    ++m.impacts;
  }
  m.left_phase = lo[0];
  m.right_phase = lo[1];
  m.phase_spread = std::max(hi[0] - lo[0], hi[1] - lo[1]);
  return m;
}

/// Distance of an angle from a target, modulo 2π.
double angle_distance(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 2.0 * kPi);
  return std::min(d, 2.0 * kPi - d);
}

}  // namespace

TEST_CASE("impact_phase solves phi - sin(phi) = r to a few ulp over [0, pi]", "[formulas]") {
  std::vector<double> ratios = {1e-300, 1e-12, 1e-9, 1e-6, 1e-3, kPi - 1e-6, kPi - 1e-12, kPi};
  for (int i = 1; i <= 2000; ++i) ratios.push_back(kPi * i / 2000.0);
  double previous_phase = 0.0;
  std::sort(ratios.begin(), ratios.end());
  for (const double r : ratios) {
    const double phase = fm::impact_phase(r);
    const long double reference = reference_impact_phase(r);
    const long double residual = phi_minus_sin_ld(phase) - static_cast<long double>(r);
    CAPTURE(r, phase, static_cast<double>(reference));
    // The root is well conditioned (relative condition r/(φ(1 − cos φ)) <= 1/2 on
    // [0, π]), so a correct solver lands within a few ulp of the long-double bisection.
    REQUIRE(std::abs(phase - reference) <= 4.0 * kEpsilon * reference);
    REQUIRE(std::abs(static_cast<double>(residual)) < 1e-12);
    // Relative residual: 3·(relative error of φ) at small φ, so 16 ε covers 4 ulp.
    REQUIRE(std::abs(static_cast<double>(residual)) <= 16.0 * kEpsilon * r);
    REQUIRE(phase >= previous_phase);  // monotone in r
    previous_phase = phase;
  }
  REQUIRE(fm::impact_phase(0.0) == 0.0);
  REQUIRE(fm::impact_phase(kPi) == kPi);
  REQUIRE_THROWS_AS(fm::impact_phase(-1e-3), std::domain_error);
  REQUIRE_THROWS_AS(fm::impact_phase(kPi + 1e-9), std::domain_error);
  REQUIRE_THROWS_AS(fm::impact_phase(std::nan("")), std::domain_error);
}

TEST_CASE("bouncing landmarks: 4/pi at h/pi, 1.069 at h/2, 0.585 at h, 0.906 at the onset",
          "[formulas]") {
  const double h = 0.04;
  // Reference values from 30-digit roots of φ − sin φ = h/X (mpmath), independent of
  // the solver: φ*(2) = 2.55419595283704303783, φ*(1) = 1.93456321075202426756.
  // Tolerance 1e-13: the root is well conditioned and η* is a smooth function of it.
  const fm::IdealOrbit peak = fm::ideal_orbit(0.0, h, h / kPi);
  REQUIRE(peak.regime == fm::MotionRegime::kCollectAndCollide);
  REQUIRE(peak.eta_star == Approx(4.0 / kPi).epsilon(1e-14));
  REQUIRE(peak.impact_phase_rad == Approx(kPi).epsilon(1e-15));

  const fm::IdealOrbit half = fm::ideal_orbit(0.0, h, h / 2.0);
  REQUIRE(half.eta_star == Approx(1.06876978910505817788).epsilon(1e-13));
  REQUIRE(half.eta_star == Approx(1.069).margin(5e-4));  // docs/theory.md §2, stated digits
  REQUIRE(half.impact_phase_rad == Approx(2.55419595283704303783).epsilon(1e-14));

  const fm::IdealOrbit full = fm::ideal_orbit(0.0, h, h);
  REQUIRE(full.eta_star == Approx(0.58511274012118979578).epsilon(1e-13));
  REQUIRE(full.eta_star == Approx(0.585).margin(5e-4));
  REQUIRE(full.impact_phase_rad == Approx(1.93456321075202426756).epsilon(1e-14));

  const fm::OptimumStroke landmarks = fm::optimum_stroke(fm::DamperModel::kBouncing, h);
  REQUIRE(landmarks.x_opt_ideal_m == Approx(h / kPi).epsilon(1e-15));
  REQUIRE(landmarks.x_opt_m == Approx(h / kPi).epsilon(1e-15));  // c = 1
  REQUIRE(landmarks.x_onset_m == Approx(h / kOnsetRadius).epsilon(1e-15));
  REQUIRE(landmarks.x_onset_m / h == Approx(0.2685).margin(5e-5));
  REQUIRE(landmarks.eta_star_peak == Approx(4.0 / kPi).epsilon(1e-15));
  // At the onset ψ = α: η* = 4cos²α/π = 4π/(π²+4) ≈ 0.906.
  REQUIRE(landmarks.eta_star_onset == Approx(4.0 * kPi / (kPi * kPi + 4.0)).epsilon(1e-15));
  const fm::IdealOrbit onset = fm::ideal_orbit(0.0, h, landmarks.x_onset_m);
  REQUIRE(onset.regime == fm::MotionRegime::kSubPeak);
  // acos is ill-conditioned at 1 (the saddle-node), so one ulp in X moves ψ by ~1e-8.
  REQUIRE(onset.eta_star == Approx(0.9060367009005804).epsilon(1e-7));
  REQUIRE(onset.eta_star == Approx(0.906).margin(5e-4));
  REQUIRE(onset.impact_phase_rad == Approx(kPi + kOnsetAngle).epsilon(1e-7));
  REQUIRE(fm::ideal_orbit(0.0, h, landmarks.x_onset_m * (1.0 - 1e-12)).regime ==
          fm::MotionRegime::kScattered);
}

TEST_CASE("the sub-peak orbit solves pi cos(psi) + 2 sin(psi) = h/X on the branch joined to the peak",
          "[formulas]") {
  const double h = 0.03;
  double previous_eta = 0.0;
  for (int i = 0; i <= 200; ++i) {
    // Strokes from the onset h/R up to just below the peak h/π.
    const double x = h / kOnsetRadius + (h / kPi - h / kOnsetRadius) * i / 200.0 * (1.0 - 1e-12);
    const fm::IdealOrbit orbit = fm::ideal_orbit(0.0, h, x);
    REQUIRE(orbit.regime == fm::MotionRegime::kSubPeak);
    const double psi = orbit.impact_phase_rad - kPi;
    CAPTURE(x / h, psi);
    REQUIRE(psi >= 0.0);
    REQUIRE(psi <= kOnsetAngle + 1e-15);
    // The orbit equation of the symmetric orbit (left at ψ, arrives at π + ψ), written
    // directly; its residual is set by the ill-conditioned acos near the onset only.
    REQUIRE(kPi * std::cos(psi) + 2.0 * std::sin(psi) == Approx(h / x).epsilon(1e-12));
    // Relative speed 2V cos ψ at two impacts per cycle: η* = 4cos²ψ/π.
    REQUIRE(orbit.eta_star == Approx(4.0 * std::cos(psi) * std::cos(psi) / kPi).epsilon(1e-14));
    REQUIRE(orbit.eta_star >= previous_eta);  // η* rises from the onset to the peak
    previous_eta = orbit.eta_star;
  }
}

TEST_CASE("eta* and the impact phase are continuous at X = h/pi between the two branches",
          "[formulas]") {
  const double h = 0.05;
  const fm::IdealOrbit below = fm::ideal_orbit(0.0, h, h / kPi * (1.0 - 1e-9));
  const fm::IdealOrbit above = fm::ideal_orbit(0.0, h, h / kPi * (1.0 + 1e-9));
  REQUIRE(below.regime == fm::MotionRegime::kSubPeak);
  REQUIRE(above.regime == fm::MotionRegime::kCollectAndCollide);
  // Both branches have zero slope at the peak: ψ ~ √(δX) on the sub-peak side, so the
  // difference is O(1e-9) for a 1e-9 offset; the phase moves by O(√1e-9) = 3e-5 on the
  // sub-peak side and O(1e-9^(1/2)) on the other.
  REQUIRE(below.eta_star == Approx(4.0 / kPi).epsilon(1e-8));
  REQUIRE(above.eta_star == Approx(4.0 / kPi).epsilon(1e-8));
  REQUIRE(below.impact_phase_rad == Approx(kPi).epsilon(1e-4));
  REQUIRE(above.impact_phase_rad == Approx(kPi).epsilon(1e-4));
}

TEST_CASE("rolling landmarks: peak 20/(7 pi) at 7h/(5 pi), onset 0.376 h, design stroke 0.4 h",
          "[formulas]") {
  const double h = 0.05;
  const fm::OptimumStroke rolling = fm::optimum_stroke(fm::DamperModel::kRolling, h);
  REQUIRE(rolling.model == fm::DamperModel::kRolling);
  REQUIRE(rolling.clearance_m == h);
  REQUIRE(rolling.x_opt_ideal_m == Approx(7.0 * h / (5.0 * kPi)).epsilon(1e-15));
  REQUIRE(rolling.x_onset_m == Approx(1.4 * h / kOnsetRadius).epsilon(1e-15));
  REQUIRE(rolling.x_onset_m / h == Approx(0.376).margin(5e-4));
  // c = 0.8976 has four digits: 0.8976·7/(5π) = 0.4000009.
  REQUIRE(rolling.x_opt_m / h == Approx(0.4).epsilon(1e-5));
  REQUIRE(rolling.calibration_factor == 0.8976);
  REQUIRE(rolling.eta_star_peak == Approx(20.0 / (7.0 * kPi)).epsilon(1e-15));
  REQUIRE(rolling.eta_star_onset == Approx(4.0 * kPi / (1.4 * (kPi * kPi + 4.0))).epsilon(1e-15));
  REQUIRE(rolling.eta_star_onset == Approx(0.647).margin(5e-4));

  const fm::IdealOrbit peak = fm::ideal_orbit(0.4, h, rolling.x_opt_ideal_m);
  REQUIRE(peak.eta_star == Approx(20.0 / (7.0 * kPi)).epsilon(1e-14));
  REQUIRE(peak.eta_star == Approx(0.909).margin(5e-4));
  // The design stroke 0.4 h sits on the sub-peak branch, between onset and peak.
  const fm::IdealOrbit design = fm::ideal_orbit(0.4, h, rolling.x_opt_m);
  REQUIRE(design.regime == fm::MotionRegime::kSubPeak);
  REQUIRE(design.eta_star > rolling.eta_star_onset);
  REQUIRE(design.eta_star < rolling.eta_star_peak);

  // A thin-walled hollow sphere (κ = 2/3) moves the landmarks by (1+κ).
  fm::ModelOptions hollow;
  hollow.rolling_inertia_factor = 2.0 / 3.0;
  const fm::OptimumStroke hollow_landmarks = fm::optimum_stroke(fm::DamperModel::kRolling, h, hollow);
  REQUIRE(hollow_landmarks.x_opt_ideal_m == Approx(5.0 * h / (3.0 * kPi)).epsilon(1e-15));
  REQUIRE(hollow_landmarks.eta_star_peak == Approx(12.0 / (5.0 * kPi)).epsilon(1e-15));
}

TEST_CASE("clearance_for_stroke inverts optimum_stroke for both models and any calibration",
          "[formulas]") {
  fm::ModelOptions options;
  for (const double c : {0.5, 0.8976, 1.0, 1.7}) {
    options.rolling_calibration = c;
    options.bouncing_calibration = c;
    for (const auto model : {fm::DamperModel::kRolling, fm::DamperModel::kBouncing}) {
      for (const double h : {1e-4, 0.0123, 0.05, 3.0}) {
        const double stroke = fm::optimum_stroke(model, h, options).x_opt_m;
        // Three roundings each way: 4 ulp.
        REQUIRE(fm::clearance_for_stroke(model, stroke, options) == Approx(h).epsilon(4 * kEpsilon));
      }
    }
  }
  // Source-study numbers: a 0.02 m design stroke needs h_roll = 0.05 m (to c's digits).
  REQUIRE(fm::clearance_for_stroke(fm::DamperModel::kRolling, 0.02) == Approx(0.05).epsilon(1e-5));
  REQUIRE(fm::clearance_for_stroke(fm::DamperModel::kBouncing, 0.01) == Approx(0.01 * kPi).epsilon(1e-15));
}

TEST_CASE("auto rolls while the base friction holds the spheres and slides continuously toward free flight",
          "[formulas]") {
  const double f = 10.0;
  const double omega = 2.0 * kPi * f;
  const double x_unit = fm::kStandardGravity / (omega * omega);  // stroke of Γ = 1
  const fm::ModelOptions options;                                // μ = 0.3, κ = 2/5, gravity across
  // Γ_slip = μ(1+κ)/κ = 1.05: a sphere rolling on a base accelerating at A needs the
  // friction force κ/(1+κ)·mA <= μmg.
  REQUIRE(fm::slip_intensity(options) == Approx(0.3 * 1.4 / 0.4).epsilon(1e-15));
  const double h = 0.5 * x_unit;  // X/h ≈ 2: on the main branch
  // Nothing happens at Γ = 1 under a horizontal drive: both sides roll.
  const auto below = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, x_unit * (1 - 1e-9), f, options);
  const auto above = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, x_unit * (1 + 1e-9), f, options);
  REQUIRE(below.model_used == fm::DamperModel::kRolling);
  REQUIRE(above.model_used == fm::DamperModel::kRolling);
  REQUIRE(above.eta_star == Approx(below.eta_star).epsilon(1e-6));
  REQUIRE(below.eta_star == Approx(fm::ideal_orbit(0.4, h, 2.0 * h).eta_star).epsilon(1e-8));
  REQUIRE(below.warnings.empty());
  // Across Γ_slip the block changes continuously: κ_eff = μ/(Γ − μ) = κ at Γ_slip.
  const double x_slip = 1.05 * x_unit;
  const auto at = fm::reduced_loss_factor(fm::DamperModel::kAuto, 0.5 * x_slip, x_slip * (1 + 1e-9), f, options);
  REQUIRE(at.inertia_factor == Approx(0.4).epsilon(1e-7));
  // In the band the relative acceleration is 1 − μ/Γ (Γ = 3: κ_eff = 0.3/2.7), with a warning.
  const auto band = fm::reduced_loss_factor(fm::DamperModel::kAuto, 1.5 * x_unit, 3.0 * x_unit, f, options);
  REQUIRE(band.inertia_factor == Approx(0.3 / 2.7).epsilon(1e-12));
  REQUIRE(band.eta_star == Approx(fm::ideal_orbit(0.3 / 2.7, 1.5 * x_unit, 3.0 * x_unit).eta_star).epsilon(1e-8));
  REQUIRE(has_warning(band, "slide on the base"));
  // Far above (Γ = 100 > 20μ) it is the free-flight block within 0.3%, without warning.
  const auto fast = fm::reduced_loss_factor(fm::DamperModel::kAuto, 50.0 * x_unit, 100.0 * x_unit, f, options);
  REQUIRE(fast.model_used == fm::DamperModel::kBouncing);
  REQUIRE(fast.eta_star == Approx(fm::ideal_orbit(0.0, 50.0 * x_unit, 100.0 * x_unit).eta_star).epsilon(3e-3));
  REQUIRE(!has_warning(fast, "slide on the base"));
  // Without gravity across the drive there is no base: free flight at any Γ.
  fm::ModelOptions weightless;
  weightless.gravity_across_drive = false;
  const auto floating = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.5 * x_unit, f, weightless);
  REQUIRE(floating.model_used == fm::DamperModel::kBouncing);
  REQUIRE(floating.inertia_factor == 0.0);
  // A rule that switched at Γ = 1 made η* at h = 8.28 mm and 10 Hz jump six-fold between
  // Γ = 0.99 and 1.01.
  const double jump_h = 0.00828;
  const double eta_099 = fm::reduced_loss_factor(fm::DamperModel::kAuto, jump_h, 0.99 * x_unit, f).eta_star;
  const double eta_101 = fm::reduced_loss_factor(fm::DamperModel::kAuto, jump_h, 1.01 * x_unit, f).eta_star;
  REQUIRE(eta_101 == Approx(eta_099).epsilon(0.05));
}

TEST_CASE("below the onset every model gives the scattered-state fit", "[formulas]") {
  const double h = 0.05;
  const double f = 2.0;
  fm::ModelOptions options;
  options.scattered.jump_fraction = 0.6;
  options.scattered.exponent = 3.0;
  options.scattered.s_min = 0.2;
  options.scattered.provisional = false;
  options.scattered.source = "test fit";
  for (const auto model : {fm::DamperModel::kAuto, fm::DamperModel::kRolling,
                           fm::DamperModel::kScattered}) {
    const double onset = 1.4 * h / kOnsetRadius;  // rolling family (Γ < 1 at 2 Hz)
    const double s = 0.7;
    const fm::LossResult r = fm::reduced_loss_factor(model, h, s * onset, f, options);
    CAPTURE(fm::to_string(model));
    REQUIRE(r.regime == fm::MotionRegime::kScattered);
    REQUIRE(r.model_used == fm::DamperModel::kRolling);
    REQUIRE(std::isnan(r.impact_phase_rad));
    REQUIRE(r.stroke_over_onset == Approx(s).epsilon(1e-14));
    // docs/theory.md §4 form with η*_onset = 4π/((π²+4)(1+κ)).
    const double expected = 0.6 * 4.0 * kPi / ((kPi * kPi + 4.0) * 1.4) * std::pow(s, 3.0);
    REQUIRE(r.eta_star == Approx(expected).epsilon(1e-14));
    REQUIRE(has_warning(r, "does not exist") == (model == fm::DamperModel::kRolling));
    REQUIRE_FALSE(has_warning(r, "provisional"));
    REQUIRE_FALSE(has_warning(r, "outside its range"));
  }
  // Bouncing family below its own onset h/R, Γ >= 1 (60 Hz).
  const fm::LossResult bouncing = fm::reduced_loss_factor(fm::DamperModel::kBouncing, h, 0.5 * h / kOnsetRadius, 60.0);
  REQUIRE(bouncing.regime == fm::MotionRegime::kScattered);
  REQUIRE(bouncing.eta_star == Approx(0.5 * 4.0 * kPi / (kPi * kPi + 4.0) * 0.25).epsilon(1e-14));
  REQUIRE(has_warning(bouncing, "does not exist"));
  REQUIRE(has_warning(bouncing, "provisional"));  // default coefficients
  // The jump: just above the onset the orbit gives η*_onset, just below the fit gives
  // jump_fraction·η*_onset (the free-flight block: no base under the bed).
  const double onset = h / kOnsetRadius;
  fm::ModelOptions weightless;
  weightless.gravity_across_drive = false;
  const double up = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, onset * (1 + 1e-12), 60.0, weightless).eta_star;
  const double down = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, onset * (1 - 1e-12), 60.0, weightless).eta_star;
  REQUIRE(up == Approx(4.0 * kPi / (kPi * kPi + 4.0)).epsilon(1e-5));
  REQUIRE(down == Approx(0.5 * 4.0 * kPi / (kPi * kPi + 4.0)).epsilon(1e-10));
  // kScattered above the onset and below s_min: the fit, flagged as extrapolated.
  const fm::LossResult forced = fm::reduced_loss_factor(fm::DamperModel::kScattered, h, 2.0 * onset, 60.0, options);
  REQUIRE(forced.regime == fm::MotionRegime::kScattered);
  REQUIRE(has_warning(forced, "outside the range it was fitted on"));
  REQUIRE(has_warning(fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.1 * onset, 60.0, options),
                      "outside the range it was fitted on"));
  // Fitted on [s_min, s_max] = [0.3, 0.85]: s = 0.9, between the data and the cliff, is
  // an extrapolation and says so with the fit's quality; s = 0.6 is inside.
  fm::ModelOptions fitted = options;
  fitted.scattered.s_min = 0.3;
  fitted.scattered.s_max = 0.85;
  fitted.scattered.points = 12;
  fitted.scattered.reduced_chi_squared = 1.3;
  fitted.scattered.jump_fraction_stderr = 0.04;
  const auto near_cliff = fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.9 * onset, 60.0, fitted);
  REQUIRE(has_warning(near_cliff, "[0.3, 0.85]: extrapolated (fitted on 12 points, reduced chi^2 = 1.3"));
  REQUIRE(!has_warning(fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.6 * onset, 60.0, fitted), "extrapolated"));
  // A jump fraction above 1 is a fit result the DEM shows (1.10 at s = 0.93), not an error.
  fitted.scattered.jump_fraction = 1.1;
  REQUIRE(fitted.validate().empty());
}

TEST_CASE("validity warnings name the violated range with numbers, and none appear inside it",
          "[formulas]") {
  const double h = 0.05;
  // Rolling at Γ = 0.02·(8π)²/g ≈ 1.288 (X = 0.4 h at 4 Hz).
  const fm::LossResult rolling = fm::reduced_loss_factor(fm::DamperModel::kRolling, h, 0.4 * h, 4.0);
  REQUIRE(rolling.intensity > 1.0);
  REQUIRE(has_warning(rolling, "Gamma = 1.28822"));
  REQUIRE(has_warning(rolling, "the spheres slide"));
  REQUIRE(rolling.regime == fm::MotionRegime::kSubPeak);
  // Bouncing at Γ ≈ 0.32.
  const fm::LossResult bouncing = fm::reduced_loss_factor(fm::DamperModel::kBouncing, h, 0.4 * h, 2.0);
  REQUIRE(has_warning(bouncing, "keeps the spheres rolling"));
  REQUIRE(bouncing.regime == fm::MotionRegime::kCollectAndCollide);
  // Gravity along the drive.
  fm::ModelOptions vertical;
  vertical.gravity_along_drive = true;
  REQUIRE(has_warning(fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.4 * h, 2.0, vertical),
                      "gravity along the drive"));
  // X/h > 10: the bed barely separates.
  const fm::LossResult large = fm::reduced_loss_factor(fm::DamperModel::kBouncing, h, 12.0 * h, 60.0);
  REQUIRE(has_warning(large, "X/h = 12"));
  REQUIRE(large.warnings.size() == 1);
  // Gravity across a horizontal drive (the default): below X = h the decoupled state
  // can replace the bouncing orbit (the shipped cylinder case at its optimum: h = 10 mm, X = 3.2 mm, 50 Hz).
  const auto floating = fm::reduced_loss_factor(fm::DamperModel::kAuto, 0.01, 0.0032, 50.0);
  REQUIRE(floating.model_used == fm::DamperModel::kBouncing);
  REQUIRE(has_warning(floating, "decoupled state"));
  REQUIRE(!has_warning(fm::reduced_loss_factor(fm::DamperModel::kBouncing, h, 1.5 * h, 60.0), "decoupled"));
  // Inside every range: no warning (and no allocation on that path); bouncing without
  // gravity across the drive (a vertical drive or a weightless bed).
  fm::ModelOptions weightless;
  weightless.gravity_across_drive = false;
  REQUIRE(fm::reduced_loss_factor(fm::DamperModel::kRolling, h, 0.4 * h, 2.0).warnings.empty());
  REQUIRE(fm::reduced_loss_factor(fm::DamperModel::kBouncing, h, h / kPi, 60.0, weightless).warnings.empty());
  REQUIRE(fm::reduced_loss_factor(fm::DamperModel::kAuto, h, 0.5 * h, 60.0, weightless).warnings.empty());
}

TEST_CASE("reduced_loss_factor_counted gives the same numbers and warning count without the sentences",
          "[formulas]") {
  const double h = 0.05;
  fm::ModelOptions vertical;
  vertical.gravity_along_drive = true;
  fm::ModelOptions weightless;
  weightless.gravity_across_drive = false;
  const fm::ModelOptions defaults;
  for (const fm::ModelOptions* options : std::vector<const fm::ModelOptions*>{&defaults, &vertical, &weightless})
    for (const fm::DamperModel model : {fm::DamperModel::kRolling, fm::DamperModel::kBouncing,
                                        fm::DamperModel::kScattered, fm::DamperModel::kAuto})
      for (const double x_over_h : {0.05, 0.2, 0.37, 0.4, 1.0 / kPi, 1.5, 12.0})
        for (const double f : {2.0, 4.0, 60.0}) {
          const fm::LossResult full = fm::reduced_loss_factor(model, h, x_over_h * h, f, *options);
          const fm::LossResult counted = fm::reduced_loss_factor_counted(model, h, x_over_h * h, f, *options);
          REQUIRE(full.warning_count == full.warnings.size());
          REQUIRE(counted.warnings.empty());
          REQUIRE(counted.warning_count == full.warnings.size());
          REQUIRE(counted.model_used == full.model_used);
          REQUIRE(counted.regime == full.regime);
          // Bit for bit: the same code computes both.
          REQUIRE(counted.eta_star == full.eta_star);
          REQUIRE(counted.inertia_factor == full.inertia_factor);
          REQUIRE(counted.intensity == full.intensity);
          REQUIRE(counted.stroke_over_onset == full.stroke_over_onset);
          REQUIRE((counted.impact_phase_rad == full.impact_phase_rad ||
                   (std::isnan(counted.impact_phase_rad) && std::isnan(full.impact_phase_rad))));
        }
  REQUIRE_THROWS_AS(fm::reduced_loss_factor_counted(fm::DamperModel::kRolling, 0.0, 0.01, 2.0, defaults),
                    std::invalid_argument);
}

TEST_CASE("bad inputs throw std::invalid_argument naming the quantity, value and range",
          "[formulas]") {
  using M = fm::DamperModel;
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, -0.01, 0.01, 2.0); },
                           "clearance_m = -0.01: must be > 0 and finite");
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, 0.05, 0.0, 2.0); },
                           "stroke_m = 0: must be > 0");
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, 0.05, nan, 2.0); },
                           "stroke_m = nan");
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, 0.05, 0.01, inf); },
                           "frequency_hz = inf");
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, 0.05, 0.01, -2.0); },
                           "frequency_hz = -2");
  require_invalid_argument([&] { return fm::optimum_stroke(M::kRolling, nan); }, "clearance_m = nan");
  require_invalid_argument([&] { return fm::optimum_stroke(M::kAuto, 0.05); }, "model = auto");
  require_invalid_argument([&] { return fm::optimum_stroke(M::kScattered, 0.05); }, "model = scattered");
  require_invalid_argument([&] { return fm::clearance_for_stroke(M::kBouncing, -1.0); }, "stroke_m = -1");
  require_invalid_argument([&] { return fm::clearance_for_stroke(M::kAuto, 1.0); }, "model = auto");
  require_invalid_argument([&] { return fm::ideal_orbit(1.5, 0.05, 0.02); }, "inertia_factor = 1.5");
  require_invalid_argument([&] { return fm::ideal_orbit(0.4, 0.05, -0.02); }, "stroke_m = -0.02");
  require_invalid_argument([&] { return fm::rolling_no_slip_friction(0.0, 0.5); }, "inertia_factor = 0");
  require_invalid_argument([&] { return fm::rolling_no_slip_friction(0.4, nan); }, "intensity = nan");
  require_invalid_argument([&] { return fm::dissipated_energy_measure(-1.0, 1.0, 1.0); }, "eta_star = -1");
  require_invalid_argument([&] { return fm::dissipated_energy_measure(1.0, 0.0, 1.0); }, "bed_mass_kg = 0");
  require_invalid_argument([&] { return fm::dissipated_energy_measure(1.0, 1.0, nan); },
                           "velocity_amplitude_m_s = nan");
  require_invalid_argument([&] { return fm::energy_per_cycle(-2.0); }, "e_diss_j = -2");

  fm::ModelOptions bad;
  bad.rolling_inertia_factor = 1.5;
  require_invalid_argument([&] { return fm::reduced_loss_factor(M::kAuto, 0.05, 0.01, 2.0, bad); },
                           "rolling_inertia_factor = 1.5: must be in (0, 1]");
  require_invalid_argument([&] { return fm::optimum_stroke(M::kBouncing, 0.05, bad); },
                           "rolling_inertia_factor");
  fm::ModelOptions bad_fit;
  bad_fit.scattered.exponent = nan;
  require_invalid_argument([&] { return fm::clearance_for_stroke(M::kRolling, 0.02, bad_fit); },
                           "scattered.exponent = nan: must be in [0, 10]");
}

TEST_CASE("validate() reports every violated option, one line each", "[formulas]") {
  REQUIRE(fm::ModelOptions{}.validate().empty());
  REQUIRE(fm::ScatteredFit{}.validate().empty());
  fm::ModelOptions options;
  options.rolling_inertia_factor = 0.0;
  options.rolling_calibration = 2.5;
  options.bouncing_calibration = -1.0;
  options.scattered.jump_fraction = 2.2;
  options.scattered.exponent = 11.0;
  options.scattered.s_min = 1.0;
  const std::vector<std::string> problems = options.validate();
  REQUIRE(problems == std::vector<std::string>{
                          "rolling_inertia_factor = 0: must be in (0, 1]",
                          "rolling_calibration = 2.5: must be in (0, 2]",
                          "bouncing_calibration = -1: must be in (0, 2]",
                          "scattered.jump_fraction = 2.2: must be in [0, 2]",
                          "scattered.exponent = 11: must be in [0, 10]",
                          "scattered.s_min = 1: must be in [0, 1)",
                      });
  fm::ScatteredFit fit;
  fit.s_min = -0.1;
  REQUIRE(fit.validate() == std::vector<std::string>{"s_min = -0.1: must be in [0, 1)"});
}

TEST_CASE("model and regime names round-trip and unknown names give nullopt", "[formulas]") {
  for (const auto model : {fm::DamperModel::kRolling, fm::DamperModel::kBouncing,
                           fm::DamperModel::kScattered, fm::DamperModel::kAuto}) {
    REQUIRE(fm::damper_model_from_string(fm::to_string(model)) == model);
  }
  REQUIRE(fm::to_string(fm::DamperModel::kRolling) == "rolling");
  REQUIRE_FALSE(fm::damper_model_from_string("Rolling").has_value());
  REQUIRE_FALSE(fm::damper_model_from_string("").has_value());
  REQUIRE(fm::to_string(fm::MotionRegime::kCollectAndCollide) == "collect_and_collide");
  REQUIRE(fm::to_string(fm::MotionRegime::kSubPeak) == "sub_peak");
  REQUIRE(fm::to_string(fm::MotionRegime::kScattered) == "scattered");
}

TEST_CASE("energy measures reproduce a viscous damper's energy per cycle", "[formulas]") {
  // A viscous damper c at amplitude X, frequency Ω dissipates πcΩX² per cycle, and its
  // η* is c/(m Ω) (docs/theory.md §1): independent textbook result.
  const double c = 3.0;
  const double m = 0.7;
  const double omega = 2.0 * kPi * 5.0;
  const double x = 0.01;
  const double eta = c / (m * omega);
  const double e_diss = fm::dissipated_energy_measure(eta, m, x * omega);
  REQUIRE(e_diss == Approx(0.5 * c * omega * x * x).epsilon(1e-14));
  REQUIRE(fm::energy_per_cycle(e_diss) == Approx(kPi * c * omega * x * x).epsilon(1e-14));
  REQUIRE(fm::dissipated_energy_measure(0.0, m, 0.0) == 0.0);
}

TEST_CASE("a plastic block in the event-driven impact map reproduces the bouncing eta* on both branches",
          "[formulas]") {
  // Reference: the event-driven simulation above from a collected start (at rest on the
  // wall at x = 0, two different start phases), 200 warm-up cycles, 20 measured.
  // Tolerance 1e-9: event phases are located to ~1e-13 rad and the slowest transient
  // (sub-peak multiplier (π/2)tan ψ = 0.68 per impact at X = 0.272 h) has decayed below
  // 1e-60; the measured deviations are 1e-12 and below.
  const double h = 0.05;
  for (const double x_over_h : {1.0 / kPi, 0.4, 0.5, 1.0, 2.0, 0.272, 0.28, 0.30}) {
    const fm::IdealOrbit orbit = fm::ideal_orbit(0.0, h, x_over_h * h);
    for (const double start : {0.5, 4.0}) {
      ImpactMapSetup setup;
      setup.clearance_m = h;
      setup.stroke_m = x_over_h * h;
      setup.frequency_hz = 20.0;
      const Measurement m = measure(setup, start);
      CAPTURE(x_over_h, start, m.eta_star, orbit.eta_star, m.right_phase, orbit.impact_phase_rad);
      INFO("impact map eta* = " << m.eta_star << ", closed form " << orbit.eta_star
                                << ", relative difference " << m.eta_star / orbit.eta_star - 1.0);
      REQUIRE(m.impacts == 40);  // two impacts per cycle: period-1
      REQUIRE(m.phase_spread < 1e-9);
      REQUIRE(angle_distance(m.right_phase - m.left_phase, kPi) < 1e-9);  // symmetric
      REQUIRE(angle_distance(m.right_phase, orbit.impact_phase_rad) < 1e-9);
      REQUIRE(m.eta_star == Approx(orbit.eta_star).epsilon(1e-9));
      REQUIRE(std::abs(m.balance_error) < 1e-10);  // container work = impact losses
    }
  }
  // Below the onset the plastic block finds no symmetric period-1 orbit.
  ImpactMapSetup below;
  below.clearance_m = h;
  below.stroke_m = 0.25 * h;
  below.frequency_hz = 20.0;
  const Measurement scattered = measure(below, 0.5);
  INFO("plastic block at X = 0.25 h (s = 0.93): eta* = " << scattered.eta_star);
  REQUIRE((scattered.impacts != 40 || scattered.phase_spread > 1e-6));
}

TEST_CASE("a rolling sphere with strong base friction reproduces the rolling eta*", "[formulas]") {
  // Reference: the event-driven sphere (rolling with 1/(1+κ) of the relative
  // acceleration, spin kept through a frictionless wall impact, then slid off against
  // the base with friction μ while the wall holds the sphere). The ideal model removes
  // the spin instantly; the simulation takes Δφ = Ω κ u_imp/(μ g) to do it. Above the
  // peak the spin is gone before the detachment at the velocity extreme, so η* agrees to
  // the event accuracy (1e-9). On the sub-peak branch a first-order analysis of the
  // orbit with the departure delayed by Δφ gives d ln η*/dΔφ = −tan ψ (1+m)/(1−m),
  // m = (π/2) tan ψ: the simulation must match the closed form within 1.3 times that
  // bound (the measured deviation equals it to within 2% at μ = 1e3).
  const double h = 0.05;
  const double kappa = 0.4;
  for (const double x_over_heff : {0.4, 0.5, 0.7, 0.272, 0.28, 0.30}) {
    ImpactMapSetup setup;
    setup.clearance_m = h;
    setup.stroke_m = x_over_heff * (1.0 + kappa) * h;
    setup.frequency_hz = 2.0;
    setup.friction = 1e3;
    setup.inertia_factor = kappa;
    const fm::IdealOrbit orbit = fm::ideal_orbit(kappa, h, setup.stroke_m);
    const Measurement m = measure(setup, 4.0);
    const double deviation = m.eta_star / orbit.eta_star - 1.0;
    CAPTURE(x_over_heff, m.eta_star, orbit.eta_star, deviation);
    REQUIRE(m.impacts == 40);
    REQUIRE(m.phase_spread < 1e-9);
    REQUIRE(angle_distance(m.right_phase - m.left_phase, kPi) < 1e-9);
    REQUIRE(std::abs(m.balance_error) < 1e-10);
    if (orbit.regime == fm::MotionRegime::kCollectAndCollide) {
      REQUIRE(m.eta_star == Approx(orbit.eta_star).epsilon(1e-9));
      REQUIRE(angle_distance(m.right_phase, orbit.impact_phase_rad) < 1e-9);
    } else {
      const double psi = orbit.impact_phase_rad - kPi;
      const double multiplier = 0.5 * kPi * std::tan(psi);
      const double intensity = setup.stroke_m * std::pow(2.0 * kPi * setup.frequency_hz, 2) /
                               fm::kStandardGravity;
      const double delay = kappa * 2.0 * std::cos(psi) * intensity / ((1.0 + kappa) * setup.friction);
      const double bound = std::tan(psi) * (1.0 + multiplier) / (1.0 - multiplier) * delay;
      CAPTURE(bound);
      REQUIRE(std::abs(deviation) <= 1.3 * bound);
    }
  }
  // Ten times the friction, a tenth of the sub-peak deviation: the ideal model is the
  // limit μ → ∞ of the sphere.
  ImpactMapSetup setup;
  setup.clearance_m = h;
  setup.stroke_m = 0.28 * (1.0 + kappa) * h;
  setup.inertia_factor = kappa;
  const double eta = fm::ideal_orbit(kappa, h, setup.stroke_m).eta_star;
  setup.friction = 1e3;
  const double deviation_1e3 = measure(setup, 4.0).eta_star / eta - 1.0;
  setup.friction = 1e4;
  const double deviation_1e4 = measure(setup, 4.0).eta_star / eta - 1.0;
  REQUIRE(deviation_1e3 / deviation_1e4 == Approx(10.0).epsilon(0.05));
}

TEST_CASE("rolling without slip holds exactly when mu >= kappa Gamma / (1 + kappa)", "[formulas]") {
  // Reference: the sphere's Coulomb friction law in the simulation. Collected start at
  // phase 4 rad: the sphere rides with the wall to the detachment at Ωt = 2π and rolls
  // across the container through |a_c| = Γ g at Ωt = 5π/2 before its first impact (X =
  // 0.5 h_eff: impact at 2π + 2.55). Below the bound it must start to slip there.
  const double h = 0.05;
  const double kappa = 0.4;
  ImpactMapSetup setup;
  setup.clearance_m = h;
  setup.stroke_m = 0.5 * (1.0 + kappa) * h;
  setup.inertia_factor = kappa;
  const double intensity = setup.stroke_m * std::pow(2.0 * kPi * setup.frequency_hz, 2) / fm::kStandardGravity;
  const double mu_min = fm::rolling_no_slip_friction(kappa, intensity);
  REQUIRE(mu_min == Approx(kappa * intensity / (1.0 + kappa)).epsilon(1e-15));
  for (const double factor : {1.02, 0.98}) {
    setup.friction = factor * mu_min;
    ImpactMap map(setup);
    map.start_collected(4.0);
    map.run_until((2.0 * kPi + 2.0) / map.omega());  // first flight, before the impact
    REQUIRE(map.impacts().empty());
    REQUIRE((map.roll_failures() > 0) == (factor < 1.0));
    map.run_until(30.0 * map.period_s());
    REQUIRE((map.roll_failures() > 0) == (factor < 1.0));
  }
}

TEST_CASE("at realistic base friction the sphere's energy balance closes and the spin-down delays "
          "detachment", "[formulas]") {
  // Demonstration of what the ideal rolling model assumes (docs/collect_and_collide.md,
  // "What the ideal model neglects"): at μ = 0.1-0.3 the spin-down after an impact lasts
  // κΓ(1 − cos φ*)/((1+κ)μ) = 0.3-1 rad, so the sphere leaves the wall late. Checked
  // here: the simulation's own energy balance (container work = impact + friction
  // losses, a conservation law, to 1e-9); the η* values are reported, not asserted.
  const double h = 0.05;
  const double kappa = 0.4;
  for (const double mu : {0.3, 0.1}) {
    for (const double x_over_heff : {0.5, 0.7}) {
      ImpactMapSetup setup;
      setup.clearance_m = h;
      setup.stroke_m = x_over_heff * (1.0 + kappa) * h;
      setup.friction = mu;
      setup.inertia_factor = kappa;
      const Measurement m = measure(setup, 4.0);
      const double ideal = fm::ideal_orbit(kappa, h, setup.stroke_m).eta_star;
      INFO("mu = " << mu << ", X/h_eff = " << x_over_heff << ": sphere eta* = " << m.eta_star
                   << ", ideal " << ideal);
      REQUIRE(std::abs(m.balance_error) < 1e-9);
      REQUIRE(m.eta_star > 0.0);
    }
  }
}
