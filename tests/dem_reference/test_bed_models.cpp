// The bed models of docs/theory.md §3.1 (the rebounding bed) and §3.3 (the nested bed)
// against short DEM runs of beds that no case ships: a one-sphere-high layer at two
// restitutions and a nested two-high bed at two frictions. Softened contacts (the
// landmarks of a rolling layer depend on ε and μ, not on the stiffness, once contacts are
// much shorter than a period) and few periods, so each case runs in seconds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"

namespace {

namespace dr = pdamp::dem_reference;
namespace fm = pdamp::formulas;
constexpr double kPi = dem_test::kPi;
constexpr double kRadius = 0.0025;

/// A one-high layer: `slabs` slabs of 4 steel spheres r = 2.5 mm across y, one high, collected
/// at −x in a box slabs·5 mm + h long, 20.2 mm wide, 6 mm high; gravity −z, drive along x at
/// 3.6 Hz, stroke X = x_over_h·h; restitution ε, friction μ = 0.3, E = 206 GPa/1000.
dr::DamperSimulationOptions one_high(int slabs, double clearance_m, double x_over_h, double restitution) {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.container.box_inner_size_m = {slabs * 2.0 * kRadius + clearance_m, 4 * 2.0 * kRadius + 2e-4, 0.006};
  c.particles = {dr::ParticleGroupOptions{slabs * 4, kRadius, 0.0, 0}};
  c.particles.front().lot_diameter_variation_m = 0.0;
  c.lattice_counts = {slabs, 4, 1};
  o.world.materials.front().material.youngs_modulus_pa = 206e9 / 1000.0;
  o.world.default_pair.restitution.constant = restitution;
  o.world.default_pair.friction = 0.3;
  o.world.default_pair.rolling_friction = 0.0;
  o.frequency_hz = 3.6;
  o.amplitude_m = x_over_h * clearance_m;
  o.samples_per_period = 64;
  return o;
}

/// A nested bed: a lattice 4 slabs × 2 lanes × 2 high (16 steel spheres r = 2.5 mm) in a box
/// 28 × 10.2 × 12 mm: each lane's 8 spheres settle into 5 on the base and 3 resting on two
/// others (formulas::LatticeBed: 6 upper spheres, settled h = 3 mm). Gravity −z, drive
/// along x at 3.6 Hz and intensity Γ; restitution 0.8, friction μ, E = 206 GPa/1000.
dr::DamperSimulationOptions nested(double gamma, double friction) {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.container.box_inner_size_m = {0.028, 2 * 2.0 * kRadius + 2e-4, 0.012};
  c.particles = {dr::ParticleGroupOptions{16, kRadius, 0.0, 0}};
  c.particles.front().lot_diameter_variation_m = 0.0;
  c.lattice_counts = {4, 2, 2};
  o.world.materials.front().material.youngs_modulus_pa = 206e9 / 1000.0;
  o.world.default_pair.restitution.constant = 0.8;
  o.world.default_pair.friction = friction;
  o.world.default_pair.rolling_friction = 0.0;
  o.frequency_hz = 3.6;
  const double omega = 2.0 * kPi * o.frequency_hz;
  o.amplitude_m = gamma * fm::kStandardGravity / (omega * omega);
  o.samples_per_period = 64;
  return o;
}

dr::DamperResult run(dr::DamperSimulationOptions o, int transient, int analysed) {
  o.transient_periods = transient;
  o.analysed_periods = analysed;
  auto r = dr::run_harmonic(o);
  REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
  return r;
}

bool collected(const dr::DamperResult& r) {
  return r.motion_mode == dr::MotionMode::kRollingCollectAndCollide ||
         r.motion_mode == dr::MotionMode::kBouncingCollectAndCollide;
}

/// The jump and the peak of a one-high layer's η*(X) on a grid of strokes.
struct Landmarks {
  double jump_over_h = 0.0;     ///< midway between the last scattered and the first collected stroke
  double resolution_over_h = 0.0;  ///< half the grid step there
  double last_scattered_over_h = 0.0, first_collected_over_h = 0.0;  ///< the grid strokes around the jump
  double peak = 0.0, peak_stderr = 0.0, peak_over_h = 0.0;
  /// The largest η* lies between smaller ones (not at either end of the grid): a peak, not a
  /// curve still rising or falling where the grid stops.
  bool peak_bracketed = false;
};

Landmarks sweep(double restitution, const std::vector<double>& strokes_over_h, double clearance_m, int slabs = 3,
                int transient = 5) {
  Landmarks l;
  double last_scattered = 0.0;
  bool jumped = false;
  for (const double s : strokes_over_h) {
    const auto r = run(one_high(slabs, clearance_m, s, restitution), transient, 10);
    std::printf("one-high layer (%d slabs) eps %.2f X/h %.2f: eta* %.3f +- %.3f (%s)\n", slabs, restitution, s, r.eta_star,
                r.eta_star_stderr, std::string(dr::to_string(r.motion_mode)).c_str());
    if (!jumped && collected(r)) {
      jumped = true;
      l.jump_over_h = 0.5 * (last_scattered + s);
      l.resolution_over_h = 0.5 * (s - last_scattered);
      l.last_scattered_over_h = last_scattered;
      l.first_collected_over_h = s;
    }
    if (!jumped) last_scattered = s;
    if (r.eta_star > l.peak) {
      l.peak = r.eta_star;
      l.peak_stderr = r.eta_star_stderr;
      l.peak_over_h = s;
    }
  }
  l.peak_bracketed = l.peak_over_h != strokes_over_h.front() && l.peak_over_h != strokes_over_h.back();
  return l;
}

/// The ranges of e_b a sweep's landmarks give (fit_bed_restitution): from the jump at either
/// end of its interval, from the peak at ±2 standard errors. A largest η* at the grid's end
/// is no peak: the jump alone gives e_b (the range from the peak is then the whole [0, 1]).
struct RestitutionRanges {
  double onset_lo, onset_hi, peak_lo, peak_hi;
};
RestitutionRanges restitution_ranges(const Landmarks& l, double kappa, double h) {
  const auto at = [&](double jump_over_h, double peak) { return fm::fit_bed_restitution(kappa, h, jump_over_h * h, peak); };
  return {at(l.jump_over_h + l.resolution_over_h, l.peak).from_onset,
          at(l.jump_over_h - l.resolution_over_h, l.peak).from_onset,
          l.peak_bracketed ? at(l.jump_over_h, l.peak - 2.0 * l.peak_stderr).from_peak : 0.0,
          l.peak_bracketed ? at(l.jump_over_h, l.peak + 2.0 * l.peak_stderr).from_peak : 1.0};
}

}  // namespace

// The rebounding bed (docs/theory.md §3.1) in a one-high layer of 12 spheres (not a shipped
// bed) at ε = 0.3 and 0.9, κ = 2/5: its front sphere at a frictionless wall gives e_b = 0 and
// 0.357 (the spheres behind it lower that; one sphere at most ε/(1+κ) = 0.214, 0.643). The DEM's
// jump (the first collected stroke on a grid 0.04 h apart) and peak give e_b. The tolerances
// are the DEM's own: the jump is known to half a grid step, the peak to twice its standard
// error over the ten analysed periods (2-12 % of η*); each becomes a range of e_b through
// X_on(e_b) and η*_pk(e_b). A largest η* at the grid's end is no peak (the curve still rises
// there): the jump alone gives e_b then. Checked: the two ranges overlap (one e_b describes
// both), the range reaches below the frictionless-wall value, and the more elastic layer jumps
// earlier by more than the grid's resolution (the two jump intervals do not overlap).
// Measured (DEM physics version 4): ε = 0.3: jump 0.34-0.38 h (plastic onset 0.376 h), η*
// still rising at 0.46 h (0.983 ± 0.016; version 3 had its largest, 1.02 ± 0.12, at 0.42 h),
// e_b from the jump 0-0.068; ε = 0.9: jump 0.30-0.34 h, peak 1.134 ± 0.047 at 0.34 h, e_b
// 0.068-0.146 from the jump and 0.067-0.149 from the peak, frictionless wall 0.357.
TEST_CASE("a one-high layer's jump and peak give a bed restitution below its front sphere's at a frictionless wall",
          "[dem_reference]") {
  const double h = 0.006, kappa = 0.4;
  const std::vector<double> grid = {0.22, 0.26, 0.30, 0.34, 0.38, 0.42, 0.46};
  Landmarks found[2];
  int k = 0;
  for (const double eps : {0.3, 0.9}) {
    const Landmarks l = sweep(eps, grid, h);
    REQUIRE(l.jump_over_h > 0.0);
    const auto fit = fm::fit_bed_restitution(kappa, h, l.jump_over_h * h, l.peak);
    const auto [onset_lo, onset_hi, peak_lo, peak_hi] = restitution_ranges(l, kappa, h);
    std::printf("eps %.2f: jump %.2f h (+- %.2f), %s %.3f +- %.3f at %.2f h; e_b %.3f, from the jump [%.3f, %.3f], "
                "from the peak [%.3f, %.3f]; frictionless wall %.3f\n",
                eps, l.jump_over_h, l.resolution_over_h, l.peak_bracketed ? "peak" : "largest (grid end)", l.peak,
                l.peak_stderr, l.peak_over_h, fit.bed_restitution,
                onset_lo, onset_hi, peak_lo, peak_hi, fm::frictionless_wall_restitution(eps, kappa));
    CAPTURE(eps, l.jump_over_h, l.peak, fit.bed_restitution, onset_lo, onset_hi, peak_lo, peak_hi);
    CHECK(std::max(onset_lo, peak_lo) <= std::min(onset_hi, peak_hi));
    CHECK(std::max(onset_lo, peak_lo) <= fm::frictionless_wall_restitution(eps, kappa));
    found[k++] = l;
  }
  // Each jump lies between two observed strokes (the last scattered, the first collected);
  // the more elastic layer jumps earlier when its first collected stroke is at most the
  // other's last scattered one (clang 14 with sanitizers: 0.30-0.34 h against 0.34-0.38 h,
  // the chaotic states differing from GCC's run to run, not in the ordering).
  CHECK(found[1].first_collected_over_h <= found[0].last_scattered_over_h);
  // The elastic layer peaks right after its jump and falls as 1/X (the test below): its peak
  // is inside the grid, so both ranges are checked on it.
  CHECK(found[1].peak_bracketed);
}

// Above its peak the rebounding layer (ε = 0.9) follows η*_pk·X_pk/X = 4h/(π²X) whatever e_b
// (docs/theory.md §3.1), an observation: the DEM lies 6-13 % below it at X/h = 0.55-1.0
// (0.691, 0.546, 0.351 against 0.737, 0.579, 0.405; standard errors 2-4 %). Checked within
// 15 %, the spread the peak itself has between neighbouring strokes and restitutions here.
TEST_CASE("above its peak a rebounding layer follows eta*_pk X_pk / X", "[dem_reference][long]") {
  const double h = 0.006;
  for (const double s : {0.55, 0.7, 1.0}) {
    const auto r = run(one_high(3, h, s, 0.9), 5, 10);
    fm::ModelOptions o;
    o.bed_restitution = 0.08;
    const auto model = fm::reduced_loss_factor(fm::DamperModel::kRolling, h, s * h, 3.6, o);
    std::printf("one-high layer eps 0.9 X/h %.2f: DEM eta* %.3f +- %.3f, tail %.3f\n", s, r.eta_star, r.eta_star_stderr,
                model.eta_star);
    CAPTURE(s, r.eta_star, model.eta_star);
    CHECK(model.eta_star == Approx(4.0 / (kPi * kPi * s)).epsilon(1e-12));
    CHECK(r.eta_star == Approx(model.eta_star).epsilon(0.15));
  }
}

// The nested bed (docs/theory.md §3.3): 16 spheres settling into 5 + 3 per lane, 6 of them
// resting on two others (not a shipped bed), at μ = 0.1 and 0.2. The Coulomb block holds it
// for Γ <= μ: the DEM is held there too (solid_like, η* < 1e-3 against 0.2-0.4 once it moves:
// the threshold is the check, not a tolerance). At Γ = 3μ both move (DEM η* 0.26 and 0.24,
// block 0.31 and 0.15: the block is an estimate above μ, the closed forms warn). Measured
// besides: at Γ = 1.5μ = 0.15 with μ = 0.1 the DEM is still held where the block slides
// (η* 0.23); with μ = 0.35 and 0.5 the DEM bed moves from Γ <= 0.28 < μ (η* 0.30-0.37),
// and with μ = 0.5 from Γ = 0.1 (the [long] case below): the block's threshold holds only
// at low friction.
TEST_CASE("a nested bed is held by its base up to Gamma = mu at low friction", "[dem_reference]") {
  for (const double mu : {0.1, 0.2}) {
    for (const double g : {0.5, 0.8, 3.0}) {
      const auto o = nested(g * mu, mu);
      const auto r = run(o, 10, 10);
      const auto block = fm::coulomb_block(mu, g * mu, 0.003 / o.amplitude_m);
      std::printf("nested bed mu %.2f Gamma %.3f: DEM eta* %.4f +- %.4f (%s), block %.4f\n", mu, g * mu, r.eta_star,
                  r.eta_star_stderr, std::string(dr::to_string(r.motion_mode)).c_str(), block.eta_star);
      CAPTURE(mu, g, r.eta_star, block.eta_star);
      REQUIRE(r.clearance_m == Approx(0.003).margin(1e-12));
      if (g < 1.0) {
        CHECK(block.eta_star == 0.0);
        CHECK(r.eta_star < 1e-3);
      } else {
        CHECK(block.eta_star > 0.1);
        CHECK(r.eta_star > 0.1);
      }
    }
  }
}

TEST_CASE("a nested bed at high friction moves below Gamma = mu, outside the Coulomb block",
          "[dem_reference][long]") {
  for (const double g : {0.1, 0.25}) {
    const auto r = run(nested(g, 0.5), 10, 10);
    std::printf("nested bed mu 0.50 Gamma %.3f: DEM eta* %.4f +- %.4f (%s)\n", g, r.eta_star, r.eta_star_stderr,
                std::string(dr::to_string(r.motion_mode)).c_str());
    CHECK(r.eta_star > 0.1);
  }
}

// One sphere per lane (the same box with 1 slab of 4 spheres, not a bed) at ε = 0.3 and 0.5:
// the lone sphere rebounds more than at a frictionless wall, (ε − κ)/(1+κ) = 0 and 0.071,
// and at most as it would without spin, ε/(1+κ) = 0.214 and 0.357 (docs/theory.md §3.1):
// the walls (μ = 0.3) brake the spin at each impact. Each e_b is the closed form's from the
// jump (its grid interval, 0.02 h) and from the peak (±2 standard errors; the periodic orbit
// scatters < 0.2 %). Measured (GCC 12): ε = 0.3 jump 0.27-0.29 h, peak 1.279 at 0.31 h, e_b
// 0.17-0.21 and 0.17; ε = 0.5 jump 0.21-0.23 h, peak 1.822 at 0.23 h, e_b 0.29-0.34 and 0.33.
// Checked: each range meets (frictionless, bound] and the peak's lies above the
// frictionless value; 10 transient periods, as a lone sphere takes longer to lock in.
TEST_CASE("a lone sphere per lane rebounds between a frictionless wall's e_b and eps/(1 + kappa)", "[dem_reference]") {
  const double h = 0.006, kappa = 0.4;
  std::vector<double> grid;
  for (int k = 0; k <= 9; ++k) grid.push_back(0.17 + 0.02 * k);
  for (const double eps : {0.3, 0.5}) {
    const Landmarks l = sweep(eps, grid, h, 1, 10);
    REQUIRE(l.jump_over_h > 0.0);
    const auto [onset_lo, onset_hi, peak_lo, peak_hi] = restitution_ranges(l, kappa, h);
    const double frictionless = fm::frictionless_wall_restitution(eps, kappa), bound = fm::bed_restitution_bound(eps, kappa);
    std::printf("lone sphere eps %.2f: jump %.2f h, peak %.3f at %.2f h; e_b from the jump [%.3f, %.3f], from the peak "
                "[%.3f, %.3f]; frictionless wall %.3f, bound %.3f\n",
                eps, l.jump_over_h, l.peak, l.peak_over_h, onset_lo, onset_hi, peak_lo, peak_hi, frictionless, bound);
    CAPTURE(eps, onset_lo, onset_hi, peak_lo, peak_hi, frictionless, bound);
    CHECK(onset_hi > frictionless);
    CHECK(onset_lo <= bound);
    CHECK(peak_lo > frictionless);
    CHECK(peak_lo <= bound);
  }
}
