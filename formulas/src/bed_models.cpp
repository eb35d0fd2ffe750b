// The beds the closed forms of §2-3 leave out: the rebounding bed (collective restitution
// e_b, docs/theory.md §3.1), the plastic block's impact map below the onset (§4.2) and the
// nested bed as a Coulomb block (§3.3).
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdamp/base/checks.hpp"
#include "pdamp/base/one_dimensional.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"

namespace pdamp::formulas {
namespace {

constexpr double kTwoPi = 2.0 * kPi;
/// R = √(π²+4) and α = atan(2/π) of the plastic orbit (e_b = 0), as collect_and_collide.cpp has them.
constexpr double kOnsetRadius = 3.724191778237173;

using base::require;
using base::require_positive;

void require_inertia_factor(double inertia_factor) { base::require_in("inertia_factor", inertia_factor, 0.0, 1.0); }
void require_bed_restitution(double bed_restitution) {
  base::require_in("bed_restitution", bed_restitution, 0.0, kMaxBedRestitution);
}

// ---- Impact map ------------------------------------------------------------------------

/// The plastic block in units X = V = Ω = 1 (phase φ = Ωt as time): the container is at
/// sin φ, the block's relative acceleration is −a_c = sin φ, the walls are at 0 and H = h/X.
/// In flight from φ0 at x0 with relative velocity u0: u = a − cos φ, x = x0 + a(φ − φ0) −
/// sin φ + sin φ0 with a = u0 + cos φ0 (exact). Impacts are plastic: the block takes the
/// wall's velocity and rides with the wall while the wall pushes (wall 0 while sin φ < 0,
/// wall H while sin φ > 0), then leaves at the container's velocity extreme.
class PlasticBlock {
 public:
  explicit PlasticBlock(double clearance_over_stroke) : clearance_(clearance_over_stroke) {}

  /// Runs from the collected start (leaving wall 0 at φ = 0) and measures over
  /// [2π warm, 2π (warm + cycles)].
  ImpactMapPoint measure(int warm_cycles, int cycles) {
    const double begin = kTwoPi * warm_cycles;
    const double end = begin + kTwoPi * cycles;
    double phase = 0.0;
    double x0 = 0.0;
    double a = 1.0;       // leaves wall 0 at the velocity maximum: u = 0, a = u + cos 0
    int leaving = -1;     // the wall the flight starts from (−1: 0, +1: H)
    double losses = 0.0;
    int impacts = 0;
    std::complex<double> harmonic = 0.0;  // ∫ u e^{−iφ} dφ over the measured flights
    while (phase < end) {
      int wall = 0;
      const double hit = next_impact(phase, x0, a, leaving, wall);
      const double lo = std::max(phase, begin), hi = std::min(hit, end);
      if (hi > lo) harmonic += flight_integral(a, hi) - flight_integral(a, lo);
      const double u = a - std::cos(hit);
      if (hit > begin && hit <= end) {
        losses += 0.5 * u * u;
        ++impacts;
      }
      // At the wall with the wall's velocity: held while the wall pushes, else away at once.
      const double s = std::sin(hit);
      double leave = hit;
      if (wall < 0 && s < 0.0) leave = kTwoPi * (std::floor(hit / kTwoPi) + 1.0);
      if (wall > 0 && s > 0.0) leave = kPi + kTwoPi * std::floor(hit / kTwoPi);
      if (leave < hit) leave += kTwoPi;
      phase = leave;
      x0 = wall < 0 ? 0.0 : clearance_;
      a = std::cos(leave);  // u = 0 on leaving
      leaving = wall;
    }
    ImpactMapPoint point;
    point.eta_star = losses / (cycles * kPi);  // E/(π m V²) with m = V = 1
    point.impacts_per_cycle = static_cast<double>(impacts) / cycles;
    point.apparent_mass_fraction = 1.0 + harmonic.real() / (cycles * kPi);
    return point;
  }

 private:
  double position(double x0, double a, double phase0, double phase) const {
    return x0 + a * (phase - phase0) - std::sin(phase) + std::sin(phase0);
  }
  /// ∫ (a − cos φ) e^{−iφ} dφ, an antiderivative: a·i e^{−iφ} − (φ/2 + i e^{−2iφ}/4).
  static std::complex<double> flight_integral(double a, double phase) {
    const std::complex<double> i(0.0, 1.0);
    return a * i * std::exp(-i * phase) - (0.5 * phase + 0.25 * i * std::exp(-2.0 * i * phase));
  }

  /// Phase of the next wall contact after phase0 and the wall hit (−1: 0, +1: H). The step
  /// is safe far from the walls (|u'| <= 1, so within t the block moves at most |u|t + t²/2,
  /// which stays below the distance d to the nearer wall for t < √(u² + 2d) − |u|); near a
  /// wall, steps of π/16 with the bounds
  /// x(φ + t) ∈ x + u t ± t²/2 (|x''| <= 1) decide whether a step can touch it, subdividing
  /// where they cannot tell (a grazing flight is followed to 1e-12 rad).
  double next_impact(double phase0, double x0, double a, int leaving, int& wall) const {
    double phase = phase0;
    for (int guard = 0; guard < 100000000; ++guard) {
      const double x = position(x0, a, phase0, phase);
      const double distance = std::min(x, clearance_ - x);
      // Within t the block moves at most |u|t + t²/2 (|u'| <= 1): safe while that stays below d.
      const double speed = std::abs(a - std::cos(phase));
      const double safe = distance / (speed + std::sqrt(speed * speed + 2.0 * distance));  // = −|u| + √(u² + 2d)
      // Just off the wall being left the distance is ~0: step with the bounds.
      if (safe > kNearStep) {
        phase += safe;
        continue;
      }
      const double next = phase + kNearStep;
      double hit = 0.0;
      if (touches(x0, a, phase0, leaving, phase, next, 0, hit, wall)) return hit;
      phase = next;
    }
    throw std::runtime_error("impact map: no impact found");
  }

  /// Whether [p, q] holds a wall contact; if so its phase and wall.
  bool touches(double x0, double a, double phase0, int leaving, double p, double q, int depth, double& hit,
               int& wall) const {
    const double xp = position(x0, a, phase0, p), xq = position(x0, a, phase0, q);
    const double up = a - std::cos(p), t = q - p;
    // Bounds of x'' = sin φ on [p, q]: the end values, or ±1 where the step holds an extremum.
    const double sp = std::sin(p), sq = std::sin(q);
    const bool holds_max = std::floor((q - 0.5 * kPi) / kTwoPi) > std::floor((p - 0.5 * kPi) / kTwoPi);
    const bool holds_min = std::floor((q - 1.5 * kPi) / kTwoPi) > std::floor((p - 1.5 * kPi) / kTwoPi);
    const double acceleration_min = holds_min ? -1.0 : std::min(sp, sq);
    const double acceleration_max = holds_max ? 1.0 : std::max(sp, sq);
    bool found = false;
    for (const int w : {-1, 1}) {
      // g >= 0 inside. g(q) <= 0: a crossing in (p, q] (bisection); else one is possible
      // only where the lower bound g(p) + g'(p) s + g''_min s²/2 reaches 0 for s in [0, t].
      const double gp = w < 0 ? xp : clearance_ - xp;
      const double gq = w < 0 ? xq : clearance_ - xq;
      const double slope = w < 0 ? up : -up;
      const double curvature = w < 0 ? acceleration_min : -acceleration_max;
      const bool just_left = w == leaving && p == phase0;
      if (gq <= 0.0) {
        // Newton on g (g' = ±u) kept inside the bracket [lo, hi] with g(lo) > 0 >= g(hi),
        // bisection where a step leaves it; the root is the bracket's right end.
        double lo = just_left ? p + 1e-12 : p, hi = q, trial = q;
        for (int k = 0; k < 100 && hi - lo > 1e-15 * hi; ++k) {
          const double xm = position(x0, a, phase0, trial);
          const double g = w < 0 ? xm : clearance_ - xm;
          (g > 0.0 ? lo : hi) = trial;
          const double dg = w < 0 ? a - std::cos(trial) : std::cos(trial) - a;
          const double newton = dg != 0.0 ? trial - g / dg : lo;
          trial = newton > lo && newton < hi ? newton : 0.5 * (lo + hi);
          if (std::abs(newton - trial) == 0.0 && std::abs(g) <= 1e-15 * clearance_) {
            (g > 0.0 ? lo : hi) = trial;
            break;
          }
        }
        if (!found || hi < hit) {
          hit = hi;
          wall = w;
          found = true;
        }
        continue;
      }
      if (just_left) continue;  // it moves away from the wall it left: x ~ t³/6 or faster
      double lowest = std::min(gp, gp + slope * t + 0.5 * curvature * t * t);
      if (curvature > 0.0 && slope < 0.0 && -slope / curvature < t)
        lowest = std::min(lowest, gp - 0.5 * slope * slope / curvature);
      if (lowest > 0.0 || depth > kMaxDepth) continue;
      const double mid = 0.5 * (p + q);
      double h1 = 0.0;
      int w1 = 0;
      if (touches(x0, a, phase0, leaving, p, mid, depth + 1, h1, w1) ||
          touches(x0, a, phase0, leaving, mid, q, depth + 1, h1, w1)) {
        if (!found || h1 < hit) {
          hit = h1;
          wall = w1;
          found = true;
        }
      }
    }
    return found;
  }

  static constexpr double kNearStep = kPi / 16.0;
  /// Subdivisions of a near step before a grazing flight is taken as missing the wall:
  /// 24 halvings of π/16 leave 1e-8 rad, where the bound s²/2 is 6e-17 X.
  static constexpr int kMaxDepth = 24;
  double clearance_;
};

ImpactMapTable build_impact_map_table() {
  ImpactMapTable table;
  const int n = kImpactMapPoints;
  const double onset = 1.0 / kOnsetRadius;
  for (int i = 1; i <= n; ++i) {
    const double xi = onset * i / n;
    table.stroke_over_clearance.push_back(xi);
    table.eta_star_raw.push_back(simulate_impact_map(xi).eta_star);
  }
  // Moving average over kImpactMapSmoothingPoints neighbours, the window shrinking
  // symmetrically at both ends (so the ends stay averages of their own neighbourhood).
  const int half = kImpactMapSmoothingPoints / 2;
  for (int i = 0; i < n; ++i) {
    const int w = std::min({half, i, n - 1 - i});
    double sum = 0.0;
    for (int k = i - w; k <= i + w; ++k) sum += table.eta_star_raw[static_cast<std::size_t>(k)];
    table.eta_star.push_back(sum / (2 * w + 1));
  }
  return table;
}

// ---- Coulomb block ----------------------------------------------------------------------

/// ∫ from p0 to p of u e^{−iφ} dφ for u = c0 − cos φ − r(φ − p0): antiderivatives
/// ∫e^{−iφ} = i e^{−iφ}, ∫cos φ e^{−iφ} = φ/2 + i e^{−2iφ}/4, ∫φ e^{−iφ} = (iφ + 1) e^{−iφ}.
std::complex<double> slide_integral(double c0, double r, double p0, double p) {
  const std::complex<double> i(0.0, 1.0);
  const auto antiderivative = [&](double q) {
    const std::complex<double> e = std::exp(-i * q);
    return (c0 + r * p0) * i * e - (0.5 * q + 0.25 * i * std::exp(-2.0 * i * q)) - r * (i * q + 1.0) * e;
  };
  return antiderivative(p) - antiderivative(p0);
}

/// Root of f on [lo, hi] with f(lo) > 0 >= f(hi) by bisection to the last bits.
template <class F>
double bisect(const F& f, double lo, double hi) {
  for (int k = 0; k < 200 && hi - lo > 4e-16 * std::abs(hi); ++k) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

// ---- The rebounding bed ------------------------------------------------------------------

double rebound_factor(double bed_restitution) {
  require(bed_restitution >= 0.0 && bed_restitution < 1.0, "bed_restitution", bed_restitution, "in [0, 1)");
  return (1.0 + bed_restitution) / (1.0 - bed_restitution);
}

double onset_stroke_m(double inertia_factor, double clearance_m, double bed_restitution) {
  if (bed_restitution == 0.0) return onset_stroke_m(inertia_factor, clearance_m);
  const double k = rebound_factor(bed_restitution);
  return (1.0 + inertia_factor) * clearance_m / std::sqrt(kPi * kPi * k * k + 4.0);
}

double onset_reduced_loss_factor(double inertia_factor, double bed_restitution) {
  if (bed_restitution == 0.0) return onset_reduced_loss_factor(inertia_factor);
  const double k = rebound_factor(bed_restitution);
  return 4.0 * kPi * k * k * k / ((kPi * kPi * k * k + 4.0) * (1.0 + inertia_factor));
}

double peak_stroke_m(double inertia_factor, double clearance_m, double bed_restitution) {
  return (1.0 + inertia_factor) * clearance_m / (kPi * rebound_factor(bed_restitution));
}

double peak_reduced_loss_factor(double inertia_factor, double bed_restitution) {
  return 4.0 * rebound_factor(bed_restitution) / (kPi * (1.0 + inertia_factor));
}

ReboundingOrbit rebounding_orbit(double inertia_factor, double bed_restitution, double clearance_m,
                                 double stroke_m) {
  require_inertia_factor(inertia_factor);
  require_bed_restitution(bed_restitution);
  require_positive("clearance_m", clearance_m);
  require_positive("stroke_m", stroke_m);
  const double c = 1.0 / (1.0 + inertia_factor);
  const double k = rebound_factor(bed_restitution);
  const double radius = std::sqrt(kPi * kPi * k * k + 4.0);
  const double angle = std::atan2(2.0, kPi * k);
  // X = onset_stroke_m(...) exactly may round to a ratio a few ulp above 1: still the onset.
  const double ratio = std::min(clearance_m / (c * stroke_m * radius), 1.0 + 1e-12);
  ReboundingOrbit orbit;
  if (ratio > 1.0 + 4e-16 * 8) return orbit;  // below the onset
  const double psi = angle - std::acos(std::min(ratio, 1.0));
  // The relative velocity cK cos ψ − c cos φ (in V) keeps its sign through the flight
  // while K cos ψ >= 1.
  if (k * std::cos(psi) < 1.0 && psi < 0.0) return orbit;
  orbit.exists = true;
  orbit.psi_rad = psi;
  orbit.eta_star = 4.0 * c * k * std::cos(psi) * std::cos(psi) / kPi;
  orbit.apparent_mass_fraction = inertia_factor * c - 2.0 * c * k * std::sin(2.0 * psi) / kPi;
  return orbit;
}

double frictionless_wall_restitution(double particle_restitution, double inertia_factor) {
  require(particle_restitution > 0.0 && particle_restitution <= 1.0, "particle_restitution", particle_restitution,
          "in (0, 1]");
  require_inertia_factor(inertia_factor);
  return std::max(0.0, (particle_restitution - inertia_factor) / (1.0 + inertia_factor));
}

double bed_restitution_bound(double particle_restitution, double inertia_factor) {
  require(particle_restitution > 0.0 && particle_restitution <= 1.0, "particle_restitution", particle_restitution,
          "in (0, 1]");
  require_inertia_factor(inertia_factor);
  return particle_restitution / (1.0 + inertia_factor);
}

BedRestitutionFit fit_bed_restitution(double inertia_factor, double clearance_m, double onset_stroke,
                                      double peak_eta_star) {
  require_inertia_factor(inertia_factor);
  require_positive("clearance_m", clearance_m);
  require_positive("onset_stroke_m", onset_stroke);
  require_positive("peak_eta_star", peak_eta_star);
  const double c = 1.0 / (1.0 + inertia_factor);
  const auto from_k = [](double k) { return std::clamp((k - 1.0) / (k + 1.0), 0.0, kMaxBedRestitution); };
  const double q = clearance_m / (c * onset_stroke);
  BedRestitutionFit fit;
  fit.from_onset = q * q > 4.0 ? from_k(std::sqrt(q * q - 4.0) / kPi) : 0.0;
  fit.from_peak = from_k(kPi * peak_eta_star / (4.0 * c));
  const auto misfit = [&](double e) {
    const double a = std::log(onset_stroke_m(inertia_factor, clearance_m, e) / onset_stroke);
    const double b = std::log(peak_reduced_loss_factor(inertia_factor, e) / peak_eta_star);
    return a * a + b * b;
  };
  // Golden section on [0, e_max]: the misfit is a sum of two squares of monotone functions of
  // e_b (the onset falls, the peak rises), unimodal there.
  base::GoldenSectionOptions search;
  search.max_iterations = 200;
  search.min_width = 1e-13;
  search.ties_keep_lower = true;
  double best = base::golden_section(misfit, 0.0, kMaxBedRestitution, search).middle();
  for (const double end : {0.0, kMaxBedRestitution})
    if (misfit(end) < misfit(best)) best = end;
  fit.bed_restitution = best;
  fit.onset_misfit = onset_stroke_m(inertia_factor, clearance_m, best) / onset_stroke - 1.0;
  fit.peak_misfit = peak_reduced_loss_factor(inertia_factor, best) / peak_eta_star - 1.0;
  return fit;
}

// ---- Impact map ------------------------------------------------------------------------

ImpactMapPoint simulate_impact_map(double stroke_over_clearance, int warm_cycles, int cycles) {
  require(stroke_over_clearance > 0.0 && stroke_over_clearance <= 1.0 / kOnsetRadius * (1.0 + 1e-12),
          "stroke_over_clearance", stroke_over_clearance, "in (0, 1/sqrt(pi^2 + 4)]");
  require(warm_cycles >= 0, "warm_cycles", warm_cycles, ">= 0");
  require(cycles >= 1, "cycles", cycles, ">= 1");
  ImpactMapPoint point = PlasticBlock(1.0 / stroke_over_clearance).measure(warm_cycles, cycles);
  point.stroke_over_clearance = stroke_over_clearance;
  return point;
}

const ImpactMapTable& impact_map_table() {
  static const ImpactMapTable table = build_impact_map_table();  // thread-safe initialisation
  return table;
}

double impact_map_reduced_loss_factor(double xi) {
  require(xi >= 0.0 && std::isfinite(xi), "stroke_over_effective_clearance", xi, ">= 0 and finite");
  const ImpactMapTable& table = impact_map_table();
  const auto& x = table.stroke_over_clearance;
  const auto& y = table.eta_star;
  if (xi <= x.front()) return y.front() * xi / x.front();
  if (xi >= x.back()) return y.back();
  // Uniform grid: x_i = (i + 1)·x_0.
  const double position = xi / x.front() - 1.0;
  const auto i = std::min(static_cast<std::size_t>(position), x.size() - 2);
  const double t = position - static_cast<double>(i);
  return y[i] + t * (y[i + 1] - y[i]);
}

double impact_map_reduced_loss_factor_slope(double xi) {
  require(xi >= 0.0 && std::isfinite(xi), "stroke_over_effective_clearance", xi, ">= 0 and finite");
  const ImpactMapTable& table = impact_map_table();
  const auto& x = table.stroke_over_clearance;
  const auto& y = table.eta_star;
  if (xi <= x.front()) return y.front() / x.front();
  if (xi >= x.back()) return 0.0;
  const auto i = std::min(static_cast<std::size_t>(xi / x.front() - 1.0), x.size() - 2);
  return (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
}

// ---- Coulomb block ----------------------------------------------------------------------

namespace {

/// coulomb_block for checked inputs; h = +inf: no wall is ever reached (the wall-free slide).
CoulombBlock block_orbit(double friction, double intensity, double clearance_over_stroke) {
  CoulombBlock block;
  const double r = friction / intensity;
  if (r >= 1.0) return block;  // the base holds it: carried, η* = 0, m_app = m_bed
  block.regime = MotionRegime::kSliding;
  const double h = clearance_over_stroke;
  // Released from rest at sin φ_d = r (the friction can no longer hold it), relative
  // velocity u(φ) = cos φ_d − cos φ − r(φ − φ_d) and travel x(φ), both in units of V and X.
  const double pd = std::asin(r);
  const double cd = std::cos(pd);
  const auto velocity = [&](double p) { return cd - std::cos(p) - r * (p - pd); };
  const auto travel = [&](double p) { return cd * (p - pd) - std::sin(p) + std::sin(pd) - 0.5 * r * (p - pd) * (p - pd); };
  // Where u returns to 0 after its maximum at π − φ_d: in (π − φ_d, π + φ_d] the base holds
  // it again (stick-slip); beyond, it slides on (the first zero is searched up to 2π + φ_d).
  double stop = 0.0;
  {
    double lo = kPi - pd, hi = lo;
    const double limit = kTwoPi + pd;
    while (hi < limit && velocity(hi) > 0.0) hi = std::min(hi + 0.05, limit);
    stop = velocity(hi) > 0.0 ? limit : bisect(velocity, lo, hi);
  }
  const double free_slide = travel(stop);
  std::complex<double> harmonic;  // ∫ over one half cycle of u e^{−iφ} dφ (the other half mirrors it)
  if (free_slide >= h) {
    // Wall to wall: the first point of the slide where the travel reaches h.
    double lo = pd, hi = pd;
    while (travel(hi) < h) hi += 0.01;
    const double ph = bisect([&](double p) { return h - travel(p); }, lo, hi);
    const double uh = velocity(ph);
    block.wall_to_wall = true;
    // Held at the far wall only if it arrives before the drive reverses at π + φ_d.
    block.outside_domain = ph > kPi + pd;
    block.slide_over_stroke = h;
    block.eta_star = 2.0 / kPi * r * h + uh * uh / kPi;
    harmonic = slide_integral(cd, r, pd, ph);
  } else if (stop <= kPi + pd) {
    block.slide_over_stroke = free_slide;
    block.eta_star = 2.0 / kPi * r * free_slide;
    harmonic = slide_integral(cd, r, pd, stop);
  } else {
    // Den Hartog's sliding without sticking: u > 0 on (φ_1, φ_1 + π), cos φ_1 = πr/2, the
    // travel per half cycle 2 sin φ_1.
    const double c1 = 0.5 * kPi * r;
    const double p1 = std::acos(c1);
    block.slide_over_stroke = 2.0 * std::sin(p1);
    block.eta_star = 4.0 / kPi * r * std::sin(p1);
    block.outside_domain = block.slide_over_stroke > h;
    harmonic = slide_integral(c1, r, p1, p1 + kPi);
  }
  // Half-wave symmetry u(φ + π) = −u(φ): û = (2/π)·(the half cycle's integral);
  // m_app/m_bed = 1 + Re(û)/V (the bed moves at v_c + u, docs/theory.md §1).
  block.apparent_mass_fraction = 1.0 + 2.0 / kPi * harmonic.real();
  return block;
}

}  // namespace

CoulombBlock coulomb_block(double friction, double intensity, double clearance_over_stroke) {
  require(friction >= 0.0 && std::isfinite(friction), "friction", friction, ">= 0 and finite");
  require_positive("intensity", intensity);
  require_positive("clearance_over_stroke", clearance_over_stroke);
  return block_orbit(friction, intensity, clearance_over_stroke);
}

CoulombBlock coulomb_slide_without_walls(double friction, double intensity) {
  require(friction >= 0.0 && std::isfinite(friction), "friction", friction, ">= 0 and finite");
  require_positive("intensity", intensity);
  return block_orbit(friction, intensity, std::numeric_limits<double>::infinity());
}

RollingTail rolling_tail(double inertia_factor, double rolling_resistance, double intensity) {
  require(inertia_factor > 0.0 && inertia_factor <= 1.0, "inertia_factor", inertia_factor, "in (0, 1]");
  // U = (1+κ)u slides as the Coulomb block of friction μ_r; the force on the bed is
  // (κ m a_c + F_block)/(1+κ), F_block = m(a_c + U̇) the block's friction force
  // (docs/theory.md §3.4), so η* and the block's part of m_app are divided by 1+κ.
  require(rolling_resistance >= 0.0 && std::isfinite(rolling_resistance), "rolling_resistance", rolling_resistance,
          ">= 0 and finite");
  require_positive("intensity", intensity);
  RollingTail tail;
  const double scale = 1.0 + inertia_factor;
  if (rolling_resistance == 0.0) {
    // The frictionless block's wall-free orbit u = −V sin... carries no force: η* = 0, m_block = 0
    // (the general path gives the same to rounding; this one is exact and allocation-free).
    tail.apparent_mass_fraction = inertia_factor / scale;
    return tail;
  }
  const CoulombBlock block = coulomb_slide_without_walls(rolling_resistance, intensity);
  tail.regime = block.regime == MotionRegime::kStuck ? MotionRegime::kStuck : MotionRegime::kRollingTail;
  tail.eta_star = block.eta_star / scale;
  tail.apparent_mass_fraction = (inertia_factor + block.apparent_mass_fraction) / scale;
  return tail;
}

}  // namespace pdamp::formulas
