// Harmonic damper runs — complex power against the energy balance,
// the low-intensity rolling sweep and the high-intensity bouncing sweep ([long]) — and
// the error paths and result files of run_harmonic.
#include <catch2/catch.hpp>
#include <cstdint>
#include <iterator>
#include <cstring>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/result_files.hpp"

namespace {

namespace dr = pdamp::dem_reference;
constexpr double kPi = 3.14159265358979323846;

/// Low-intensity case of docs/theory.md §8 (cases/low_intensity_36_spheres.json): 36 steel
/// spheres r = 5 mm, 6 × 6 × 1 lattice collected against −x in a 160 × 61 × 40 mm box
/// (h_roll = 0.1 m), 2 Hz along x, gravity −z. Young's modulus divided by `softening`.
dr::DamperSimulationOptions low_intensity(double stroke_over_clearance, double softening) {
  auto o = dem_test::shipped_layer(stroke_over_clearance, 0.8, 0.3, 0.0, softening);
  o.transient_periods = 3;
  o.analysed_periods = 4;
  return o;
}

/// High-intensity case (cases/high_intensity_cylinder.json) without gravity: 260 steel
/// spheres r = 2.5 mm collected in a cylinder R = 12.5 mm, L = 110 mm along x (20 slabs
/// of 13, h = 10 mm), 50 Hz along the axis, ε = 0.5, μ = 0.3.
dr::DamperSimulationOptions high_intensity(double stroke_over_clearance, double softening) {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.container.shape = pdamp::formulas::ContainerShape::kCylinder;
  c.container.cylinder_inner_radius_m = 0.0125;
  c.container.cylinder_inner_length_m = 0.110;
  c.container.cylinder_axis = 0;
  c.particles = {dr::ParticleGroupOptions{260, 0.0025, 0.0, 0}};
  c.lattice_counts.clear();
  o.world.gravity_m_s2 = {0.0, 0.0, 0.0};
  o.world.materials.front().material.youngs_modulus_pa = 210e9 / softening;
  o.world.default_pair.restitution.constant = 0.5;
  o.world.default_pair.friction = 0.3;
  o.frequency_hz = 50.0;
  o.amplitude_m = stroke_over_clearance * 0.010;
  o.transient_periods = 8;
  o.analysed_periods = 6;
  return o;
}

/// Ideal bouncing η* = (1 − cos φ*)²/π with φ* − sin φ* = h/X (docs/theory.md §2), X >= h/π.
double ideal_bouncing(double stroke_over_clearance) {
  double lo = 0.0, hi = kPi;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (mid - std::sin(mid) < 1.0 / stroke_over_clearance ? lo : hi) = mid;
  }
  return std::pow(1.0 - std::cos(lo), 2) / kPi;
}

void print_point(std::FILE* out, double x_over_h, const dr::DamperResult& r, double ideal) {
  std::fprintf(out, "%.3f,%.4f,%.4f,%.4f,%.3f,%s,%.2e\n", x_over_h, r.eta_star, r.eta_star_stderr, ideal,
               r.apparent_mass_kg / r.bed_mass_kg, std::string(dr::to_string(r.motion_mode)).c_str(),
               r.energy_balance_error);
}

}  // namespace

// Reference: conservation of energy. Over whole periods the container's work equals
// 2π·E_diss per period from the complex power (the drive velocity is a pure harmonic),
// and it must equal the dissipation counted in the contacts plus the change of the
// bed's energy. 2% is the DEM's target (docs/dem.md); both sides use the same steps, so what is left
// is the time discretisation of the contact work (measured ~1e-3).
TEST_CASE("complex-power eta* and the energy balance agree on damper cases", "[dem_reference]") {
  for (const auto& options : {low_intensity(0.45, 100.0), high_intensity(0.35, 100.0)}) {
    auto o = options;
    o.transient_periods = 2;
    o.analysed_periods = 2;
    const auto r = dr::run_harmonic(o);
    REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
    INFO("eta* " << r.eta_star << " (complex power) vs " << r.eta_star_energy_balance << " (energy balance), error "
                 << r.energy_balance_error);
    CHECK(r.eta_star > 0.3);
    CHECK(r.eta_star_energy_balance == Approx(r.eta_star).epsilon(0.02));
    CHECK(r.energy_balance_error < 0.02);
    CHECK(r.series.time_s.size() == static_cast<std::size_t>(o.analysed_periods * o.samples_per_period));
  }
}

TEST_CASE("run_harmonic refuses bad options naming each violation", "[dem_reference]") {
  auto o = low_intensity(0.4, 100.0);
  o.amplitude_m = -0.01;
  o.analysed_periods = 0;
  o.world.compartments.front().particles.front().radius_m = 0.0;
  try {
    dr::run_harmonic(o);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::Contains("dem.compartments[0].particles[0].radius_m = 0: must be in [1e-05, 1] m"));
    CHECK_THAT(what, Catch::Contains("dem.amplitude_m = -0.01: must be in (0, 10] m"));
    CHECK_THAT(what, Catch::Contains("dem.analysed_periods = 0: must be in [1, 100000]"));
  }
  auto step = low_intensity(0.4, 100.0);
  step.world.integration.time_step_s = 1e-3;
  CHECK_THROWS_WITH(dr::run_harmonic(step), Catch::Contains("dem.integration.time_step_s = 0.001: must be <="));
}

TEST_CASE("result files are complete CSV and VTK written atomically", "[dem_reference]") {
  auto o = low_intensity(0.4, 100.0);
  o.transient_periods = 0;
  o.analysed_periods = 1;
  o.samples_per_period = 64;
  o.snapshots = 2;
  const auto r = dr::run_harmonic(o);
  REQUIRE(r.snapshots.size() == 2);
  const auto dir = std::filesystem::temp_directory_path() / "pdamp_dem_test_files";
  std::filesystem::create_directories(dir);
  const auto csv = (dir / "series.csv").string();
  const auto vtp = (dir / "particles.vtp").string();
  dr::write_time_series_csv(csv, r.series);
  dr::write_vtp_snapshot(vtp, r.snapshots.back());
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  CHECK(line.rfind("time_s,container_position_m,", 0) == 0);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  CHECK(rows == 64);
  // The VTK XML layout: its header, one vertex per particle, the appended block whose
  // first array (radius_m) is a UInt64 byte count then the radii as stored.
  std::ifstream v(vtp, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(v)), std::istreambuf_iterator<char>());
  CHECK(file.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\"", 0) == 0);
  const std::size_t n = r.snapshots.back().radii_m.size();
  CHECK_THAT(file, Catch::Contains("NumberOfPoints=\"" + std::to_string(n) + "\" NumberOfVerts=\"" + std::to_string(n) + "\""));
  const auto block = file.find("<AppendedData encoding=\"raw\">\n   _");
  REQUIRE(block != std::string::npos);
  const std::size_t at = block + std::string("<AppendedData encoding=\"raw\">\n   _").size();
  std::uint64_t bytes = 0;
  std::memcpy(&bytes, file.data() + at, sizeof bytes);
  CHECK(bytes == n * sizeof(double));
  double first_radius = 0.0;
  std::memcpy(&first_radius, file.data() + at + sizeof bytes, sizeof first_radius);
  CHECK(first_radius == r.snapshots.back().radii_m.front());
  CHECK_FALSE(std::filesystem::exists(csv + ".tmp"));
  CHECK_THROWS_AS(dr::write_time_series_csv((dir / "missing" / "x.csv").string(), r.series), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// References: the rolling model of docs/theory.md §3 — onset of the
// collect-and-collide orbit (7/5)h/√(π²+4) = 0.376 h_roll, ideal peak 0.446 h_roll,
// design value ≈ 0.4 h_roll from the source study — and the no-slip rolling bed's
// apparent mass 2/7 of m_bed at small strokes (rigid-body mechanics). The test asks for
// the maximum in [0.35, 0.50] h_roll, a jump from the scattered state, and m_app/m_bed
// near 2/7 (±25%: the bed is not all rolling without slip). Young's modulus is divided by
// 100 (contact time still < 0.1% of the period); the stiffness check at the end shows η*
// does not depend on it.
TEST_CASE("low-intensity sweep shows the jump to rolling collect-and-collide near 0.4 h_roll",
          "[dem_reference][long]") {
  const std::vector<double> strokes{0.15, 0.2, 0.25, 0.3, 0.33, 0.36, 0.38, 0.4, 0.42, 0.45, 0.5, 0.6, 0.7};
  std::FILE* out = std::fopen("dem_sweep_low_intensity.csv", "w");
  REQUIRE(out != nullptr);
  std::fprintf(out, "x_over_h,eta_star,eta_star_stderr,ideal_eta_star,apparent_mass_fraction,motion_mode,energy_balance_error\n");
  std::vector<double> eta;
  double mass_fraction_small = 0.0;
  for (const double x : strokes) {
    const auto r = dr::run_harmonic(low_intensity(x, 100.0));
    REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
    print_point(out, x, r, std::nan(""));
    print_point(stdout, x, r, std::nan(""));
    eta.push_back(r.eta_star);
    if (x == strokes.front()) mass_fraction_small = r.apparent_mass_kg / r.bed_mass_kg;
  }
  std::fclose(out);
  const auto peak = std::max_element(eta.begin(), eta.end());
  const double x_peak = strokes[static_cast<std::size_t>(peak - eta.begin())];
  CHECK(x_peak >= 0.35);
  CHECK(x_peak <= 0.50);
  // The jump: below the onset the scattered state dissipates far less than the peak.
  CHECK(eta[1] < 0.5 * *peak);
  CHECK(mass_fraction_small == Approx(2.0 / 7.0).epsilon(0.25));
  // Stiffness: E/100 against E/20 at the design stroke, each the mean of four seeds, within
  // 10%. One seed is no measure here: at 0.42 h the bed's orbit differs from seed to seed
  // (η* 0.66-0.90 at E/100, sd ~0.09, each within a few per cent period to period);
  // the means' standard error is ~0.045 each (measured means 0.798 and 0.819).
  const auto seed_mean = [](double softening) {
    double sum = 0.0;
    for (const std::uint64_t seed : {1, 2, 3, 4}) {
      auto o = low_intensity(0.42, softening);
      o.world.seed = seed;
      sum += dr::run_harmonic(o).eta_star;
    }
    return sum / 4.0;
  };
  const double soft = seed_mean(100.0);
  const double stiff = seed_mean(20.0);
  std::printf("stiffness check at X/h = 0.42, mean of four seeds: eta* %.4f (E/100) vs %.4f (E/20)\n", soft, stiff);
  CHECK(soft == Approx(stiff).epsilon(0.10));
}

// Reference: the ideal bouncing collect-and-collide model of docs/theory.md
// §2 — onset h/√(π²+4) = 0.2685 h where the orbit's η* is 4π/(π²+4) = 0.906, and
// η* = (1 − cos φ*)²/π above X_opt = h/π. The jump is the smallest stroke from which η*
// stays at or above 0.906 for every larger stroke of the sweep, within two standard errors
// of its per-period scatter (at the jump the bed switches between orbits from period to
// period: 0.87 ± 0.23 at 0.28 h); it must lie within 10% of the onset. η* must lie within 15% of the ideal for X in [1, 1.3] h/π; at and
// just above the peak (X < 1.15 h/π) the lattice bed sits higher — its aligned chains of
// spheres pass the impact on like a Newton's cradle, so the bed is not a plastic block
// (docs/theory.md §2: 4/π is not an upper bound with partial rebound; measured +15-22%, independent
// of μ and of ε in 0.2-0.8) — there only the lower bound applies. E/100: docs/dem.md
// records η* at h/π for E, E/10, E/100 (equal within the per-period scatter).
//
// The ideal model is one coherent block, which the perfect lattice of identical spheres
// is (its lanes move as one): the sweep runs it (lot_diameter_variation_m = 0). The
// default bed with the G100 ball-lot tolerance, whose lanes drift apart, jumps a little
// later, between 0.28 and 0.30 h (4-12% above the ideal onset; docs/dem.md records
// its sweep), and follows the same curve above.
TEST_CASE("high-intensity sweep without gravity follows the bouncing collect-and-collide model",
          "[dem_reference][long]") {
  const std::vector<double> strokes{0.2, 0.22, 0.24, 0.26, 0.28, 0.3, 0.318, 0.34, 0.36, 0.38, 0.4, 0.414, 0.45, 0.5};
  std::FILE* out = std::fopen("dem_sweep_high_intensity.csv", "w");
  REQUIRE(out != nullptr);
  std::fprintf(out, "x_over_h,eta_star,eta_star_stderr,ideal_eta_star,apparent_mass_fraction,motion_mode,energy_balance_error\n");
  std::vector<dr::DamperResult> results;
  for (const double x : strokes) {
    auto options = high_intensity(x, 100.0);
    options.world.compartments.front().particles.front().lot_diameter_variation_m = 0.0;
    results.push_back(dr::run_harmonic(options));
    const auto& r = results.back();
    REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
    const double ideal = x >= 1.0 / kPi ? ideal_bouncing(x) : std::nan("");
    print_point(out, x, r, ideal);
    print_point(stdout, x, r, ideal);
  }
  std::fclose(out);
  const double onset = 1.0 / std::sqrt(kPi * kPi + 4.0);
  const double eta_onset = 4.0 * kPi / (kPi * kPi + 4.0);
  std::size_t jump = strokes.size();
  while (jump > 0 && results[jump - 1].eta_star + 2.0 * results[jump - 1].eta_star_stderr >= eta_onset) --jump;
  REQUIRE(jump < strokes.size());
  std::printf("jump at X/h = %.3f, ideal onset %.4f\n", strokes[jump], onset);
  CHECK(strokes[jump] == Approx(onset).epsilon(0.10));
  for (std::size_t k = 0; k < strokes.size(); ++k) {
    if (strokes[k] < 1.0 / kPi - 1e-9 || strokes[k] > 1.3 / kPi + 1e-9) continue;
    INFO("X/h " << strokes[k]);
    const double ideal = ideal_bouncing(strokes[k]);
    CHECK(results[k].eta_star >= 0.85 * ideal);
    if (strokes[k] >= 1.15 / kPi) CHECK(results[k].eta_star <= 1.15 * ideal);
  }
}
