// Tests of the scattered-state fit: recovery of a known law, weighting, samples, coefficient file.
#include <unistd.h>

#include <catch2/catch.hpp>

#include "support/temp_dir.hpp"
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <vector>

#include "pdamp/surrogate/scattered_fit.hpp"
#include "surrogate/hostile_files.hpp"

namespace {

using namespace pdamp::surrogate;
namespace fm = pdamp::formulas;
namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;
/// η*_onset of the bouncing block, 4π/(π²+4) (docs/theory.md §2).
const double kBouncingOnset = 4 * kPi / (kPi * kPi + 4);

using pdamp::test::TempDir;

/// Samples of η* = J·η*_onset·s^p at n strokes in [0.2, 0.95], with Gaussian noise of
/// standard deviation σ_i (given as the stderr) when `noisy`.
std::vector<ScatteredSample> synthetic(double jump, double exponent, int n, bool noisy, unsigned seed = 1) {
  std::mt19937_64 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<ScatteredSample> samples;
  for (int i = 0; i < n; ++i) {
    const double s = 0.2 + 0.75 * i / (n - 1);
    const double eta = jump * kBouncingOnset * std::pow(s, exponent);
    const double sigma = 0.005 + 0.05 * eta;  // heteroscedastic, as DEM scatter grows with η*
    samples.push_back({s, eta + (noisy ? sigma * normal(random) : 0.0), sigma, kBouncingOnset});
  }
  return samples;
}

/// Independent reference: χ² minimised by profiling. For fixed p the best J is linear
/// least squares, J*(p) = Σ w a η / Σ w a², a = η*_onset s^p; golden-section search on p.
std::pair<double, double> profiled_minimum(const std::vector<ScatteredSample>& samples) {
  auto best_jump = [&](double p) {
    double num = 0, den = 0;
    for (const auto& x : samples) {
      const double w = 1 / (x.eta_star_stderr * x.eta_star_stderr), a = x.eta_star_onset * std::pow(x.s, p);
      num += w * a * x.eta_star;
      den += w * a * a;
    }
    return num / den;
  };
  auto chi2 = [&](double p) {
    const double j = best_jump(p);
    double sum = 0;
    for (const auto& x : samples) {
      const double r = (x.eta_star - j * x.eta_star_onset * std::pow(x.s, p)) / x.eta_star_stderr;
      sum += r * r;
    }
    return sum;
  };
  double lo = 0.0, hi = 10.0;
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < 200; ++i) {
    const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
    if (chi2(a) < chi2(b)) {
      hi = b;
    } else {
      lo = a;
    }
  }
  const double p = 0.5 * (lo + hi);
  return {best_jump(p), p};
}

}  // namespace

TEST_CASE("the fit recovers a noise-free law exactly", "[surrogate]") {
  const auto samples = synthetic(0.42, 1.7, 15, false);
  const ScatteredFitResult r = fit_scattered_law(samples, "synthetic");
  // Reference: the law the samples were made from; exact data, so only the optimiser's
  // tolerance (xtol 1e-12) and rounding remain.
  CHECK(r.fit.jump_fraction == Approx(0.42).epsilon(1e-8));
  CHECK(r.fit.exponent == Approx(1.7).epsilon(1e-8));
  CHECK(r.fit.reduced_chi_squared < 1e-12);
  CHECK(r.fit.s_min == Approx(0.2));
  CHECK(r.fit.s_max == Approx(0.95));
  CHECK(r.fit.points == 15);
  CHECK_FALSE(r.fit.provisional);
  CHECK(r.fit.source == "synthetic");
  CHECK(r.fit.validate().empty());
}

TEST_CASE("the weighted fit of noisy points is the chi-square minimum and within its error bars", "[surrogate]") {
  const auto samples = synthetic(0.35, 2.4, 40, true, 2024);
  const ScatteredFitResult r = fit_scattered_law(samples, "synthetic noisy");
  const auto [jump, exponent] = profiled_minimum(samples);
  // Same minimum as the profiled golden-section search (its bracket shrinks to 1e-12).
  CHECK(r.fit.jump_fraction == Approx(jump).epsilon(1e-6));
  CHECK(r.fit.exponent == Approx(exponent).epsilon(1e-6));
  // The truth lies within 4 reported standard errors (a 4σ band fails with p < 1e-4).
  CHECK(std::abs(r.fit.jump_fraction - 0.35) < 4 * r.fit.jump_fraction_stderr);
  CHECK(std::abs(r.fit.exponent - 2.4) < 4 * r.fit.exponent_stderr);
  // Reduced χ² of correctly weighted data: mean 1, standard deviation √(2/38) ≈ 0.23.
  CHECK(r.fit.reduced_chi_squared > 0.3);
  CHECK(r.fit.reduced_chi_squared < 2.0);
}

TEST_CASE("the fit refuses samples it cannot weight or fit", "[surrogate]") {
  auto samples = synthetic(0.4, 2.0, 5, false);
  samples[2].eta_star_stderr = 0.0;
  CHECK_THROWS_WITH(fit_scattered_law(samples, ""), Catch::Contains("sample 2 (s = 0.575): eta_star_stderr = 0"));
  samples = synthetic(0.4, 2.0, 5, false);
  samples[0].s = 1.0;
  CHECK_THROWS_WITH(fit_scattered_law(samples, ""), Catch::Contains("sample 0: s = 1: must be in (0, 1)"));
  samples.resize(2);
  CHECK_THROWS_WITH(fit_scattered_law(samples, ""), Catch::Contains("2 samples below the onset; need at least 3"));
}

TEST_CASE("samples are the ok field points below the onset of the family in use", "[surrogate]") {
  const double h = 0.1;
  EffectiveField field;
  field.grid = Grid::from_ranges(GridAxes::kIntensityStrokeOverClearance, {0.5, 2.0, 2, AxisSpacing::kLinear},
                                 {0.1, 0.4, 4, AxisSpacing::kLinear});
  field.clearance_m = h;
  field.bed_mass_kg = 1.0;
  field.provenance = make_provenance(FieldSource::kDem, "c", 1);
  for (std::size_t k = 0; k < field.grid.size(); ++k) {
    field.points.push_back({0.1, 0.01, 1.0, FieldPoint::kUnknown, FieldPoint::kUnknown, "", PointStatus::kOk});
  }
  // Reference onsets (docs/theory.md §2-3): X_onset = (1+κ)h/√(π²+4), κ = 0.4 rolling, 0 bouncing.
  const double rolling_onset = 1.4 * h / std::sqrt(kPi * kPi + 4), bouncing_onset = h / std::sqrt(kPi * kPi + 4);
  const auto automatic = scattered_samples(field);
  // Γ = 0.5 (rolling): X/h = 0.1, 0.2, 0.3 below 0.376; Γ = 2 > Γ_slip = 1.05 (spheres
  // sliding, κ_eff = μ/(Γ − μ) = 0.3/1.7): 0.1, 0.2, 0.3 below (1 + κ_eff)/√(π²+4) = 0.316.
  const double sliding = 0.3 / 1.7, sliding_onset = (1.0 + sliding) * h / std::sqrt(kPi * kPi + 4);
  REQUIRE(automatic.size() == 6);
  CHECK(automatic[0].s == Approx(0.1 * h / rolling_onset).epsilon(1e-12));
  CHECK(automatic[0].eta_star_onset == Approx(4 * kPi / ((kPi * kPi + 4) * 1.4)).epsilon(1e-12));
  CHECK(automatic[4].s == Approx(0.2 * h / sliding_onset).epsilon(1e-12));
  CHECK(automatic[4].eta_star_onset == Approx(4 * kPi / ((kPi * kPi + 4) * (1.0 + sliding))).epsilon(1e-12));
  // Without a base both intensities are the free-flight block: 0.1 and 0.2 below 0.268.
  fm::ModelOptions weightless;
  weightless.gravity_across_drive = false;
  const auto floating = scattered_samples(field, fm::DamperModel::kAuto, weightless);
  REQUIRE(floating.size() == 4);
  CHECK(floating[3].s == Approx(0.2 * h / bouncing_onset).epsilon(1e-12));
  CHECK(floating[3].eta_star_onset == Approx(kBouncingOnset).epsilon(1e-12));
  CHECK(scattered_samples(field, fm::DamperModel::kBouncing).size() == 4);
  field.points[0].status = PointStatus::kFailed;
  field.points[0].eta_star = FieldPoint::kUnknown;
  field.points[0].e_diss_j = FieldPoint::kUnknown;
  CHECK(scattered_samples(field).size() == 5);  // the failed point is left out
}

TEST_CASE("the coefficient file round-trips and is read strictly", "[surrogate]") {
  TempDir dir("scattered_fit_file");
  const fs::path path = dir.path / "fit.json";
  const ScatteredFitResult r = fit_scattered_law(synthetic(0.35, 2.4, 20, true), "dem field x.json");
  write_scattered_fit(r, path);
  const ScatteredFitResult back = read_scattered_fit(path);
  CHECK(back.fit.jump_fraction == r.fit.jump_fraction);
  CHECK(back.fit.exponent == r.fit.exponent);
  CHECK(back.fit.s_min == r.fit.s_min);
  CHECK(back.fit.s_max == r.fit.s_max);
  CHECK(back.fit.reduced_chi_squared == r.fit.reduced_chi_squared);
  CHECK(back.fit.exponent_stderr == r.fit.exponent_stderr);
  CHECK(back.fit.points == 20);
  CHECK(back.fit.source == "dem field x.json");
  CHECK_FALSE(back.fit.provisional);

  auto write = [&](const std::string& text) {
    std::ofstream(path) << text;
    return path;
  };
  const std::string minimal =
      R"({"jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "source": "hand", "residual": 1.1)";
  CHECK(read_scattered_fit(write(minimal + "}")).fit.jump_fraction == 0.5);
  CHECK_THROWS_WITH(read_scattered_fit(write(minimal + R"(, "offset": 0})")),
                    Catch::Contains("fit.json: /offset: unknown key"));
  CHECK_THROWS_WITH(read_scattered_fit(write(R"({"jump_fraction": 0.5})")), Catch::Contains("/exponent: missing"));
  CHECK_THROWS_WITH(
      read_scattered_fit(
          write(R"({"jump_fraction": 2.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "source": "x", "residual": 1})")),
      Catch::Contains("/jump_fraction: jump_fraction = 2.5"));
  // Above 1: the DEM shows 1.10 just below the cliff (formulas::kMaxJumpFraction).
  CHECK(read_scattered_fit(write(R"({"jump_fraction": 1.1, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "source": "x",
                                     "residual": 1})"))
            .fit.jump_fraction == 1.1);
  CHECK_THROWS_WITH(
      read_scattered_fit(
          write(R"({"jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 1.2, "source": "x", "residual": 1})")),
      Catch::Contains("/s_max: 1.2: must be in [s_min, 1]"));
  CHECK_THROWS_WITH(read_scattered_fit(write(minimal + R"(, "format_version": 2})")),
                    Catch::Contains("/format_version"));
  CHECK_THROWS_WITH(read_scattered_fit(write("{jump")), Catch::StartsWith(path.string() + ": malformed JSON: "));
}

TEST_CASE("a coefficient file outside the law's ranges, repeated keys or too few points is refused", "[surrogate]") {
  TempDir dir("scattered_fit_ranges");
  const fs::path path = dir.path / "fit.json";
  auto read = [&](const std::string& members) {
    std::ofstream(path) << "{" << members << "}";
    return read_scattered_fit(path);
  };
  const std::string base = R"("source": "hand", "residual": 1.1, )";
  auto check = [&](const std::string& members, const std::string& message) {
    INFO(members);
    CHECK_THROWS_WITH(read(base + members), Catch::Equals(path.string() + ": " + message));
  };
  check(R"("jump_fraction": -0.1, "exponent": 2, "s_min": 0.3, "s_max": 0.9)",
        "/jump_fraction: jump_fraction = -0.1: must be in [0, 2]");
  check(R"("jump_fraction": 0.5, "exponent": 12, "s_min": 0.3, "s_max": 0.9)",
        "/exponent: exponent = 12: must be in [0, 10]");
  check(R"("jump_fraction": 0.5, "exponent": -1, "s_min": 0.3, "s_max": 0.9)",
        "/exponent: exponent = -1: must be in [0, 10]");
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 1, "s_max": 1)", "/s_min: s_min = 1: must be in [0, 1)");
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": -0.2, "s_max": 0.9)",
        "/s_min: s_min = -0.2: must be in [0, 1)");
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 0.6, "s_max": 0.5)",
        "/s_max: 0.5: must be in [s_min, 1] = [0.6, 1]");
  // A fit needs 3 samples (2 coefficients and 1 degree of freedom): the old reader took 0.
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "points": 2)",
        "/points: 2 must be in [3, 2147483647]");
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "exponent_stderr": -1)",
        "/exponent_stderr: -1: must be >= 0 or null");
  // nlohmann::json would keep the last jump_fraction silently.
  check(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "jump_fraction": 0.7)",
        "/jump_fraction: duplicate key (each key may appear once in an object)");
  CHECK_THROWS_WITH(read(R"("jump_fraction": 0.5, "exponent": 2, "s_min": 0.3, "s_max": 0.9, "residual": 1, )"
                         R"("source": "dem\u0000x")"),
                    Catch::Equals(path.string() + ": /source: \"dem\\0x\" holds control characters (must be printable "
                                                  "text: it is printed in reports)"));
}

TEST_CASE("a directory or a FIFO given as the coefficient file is refused at once, naming it", "[surrogate]") {
  TempDir dir("scattered_fit_hostile");
  CHECK_THROWS_WITH(read_scattered_fit(dir.path), Catch::Equals(dir.path.string() + ": is a directory, not a file"));
  const fs::path fifo = dir.path / "fit.json";
  pdamp::test::make_fifo(fifo);
  // The old reader (std::ifstream) blocked in open() forever; the guard turns that into a failure.
  CHECK(pdamp::test::invalid_argument_within_timeout([&] { read_scattered_fit(fifo); }, fifo) ==
        fifo.string() + ": is a FIFO (named pipe), not a file");
}
