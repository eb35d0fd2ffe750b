// Tests of complex_power against synthetic signals whose complex power is known in closed form.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pdamp/formulas/complex_power.hpp"

namespace {

using pdamp::formulas::complex_power;
using pdamp::formulas::ComplexPower;

constexpr double kPi = 3.14159265358979323846;
constexpr double kFrequency = 5.0;                 // Hz
constexpr double kOmega = 2.0 * kPi * kFrequency;  // rad/s
constexpr int kSamplesPerPeriod = 200;
constexpr double kDt = 1.0 / (kFrequency * kSamplesPerPeriod);  // s
constexpr double kVelocityAmplitude = 0.3;                      // |V*|, m/s
constexpr double kVelocityPhase = 0.4;                          // arg V*, rad
constexpr double kBedMass = 0.2;                                // kg

using Signal = std::function<double(double)>;

struct Record {
  std::vector<double> force;
  std::vector<double> velocity;
};

Record sample(const Signal& force, const Signal& velocity, int periods, double t0 = 0.0) {
  Record record;
  const int n = periods * kSamplesPerPeriod;
  record.force.resize(n);
  record.velocity.resize(n);
  for (int i = 0; i < n; ++i) {
    const double t = t0 + i * kDt;
    record.force[i] = force(t);
    record.velocity[i] = velocity(t);
  }
  return record;
}

ComplexPower analyse(const Record& record) {
  return complex_power(record.force, record.velocity, kDt, kFrequency);
}

// Container motion with V* = 0.3·e^{0.4i}: v = Re(V* e^{iΩt}), x = ∫v, a = dv/dt.
double velocity(double t) { return kVelocityAmplitude * std::cos(kOmega * t + kVelocityPhase); }
double displacement(double t) { return kVelocityAmplitude / kOmega * std::sin(kOmega * t + kVelocityPhase); }
double acceleration(double t) { return -kVelocityAmplitude * kOmega * std::sin(kOmega * t + kVelocityPhase); }

// Content orthogonal to the bin at Ω over whole periods: a DC offset and harmonics 2Ω, 3Ω.
double other_content(double t, double scale) {
  return scale * (0.8 + 0.6 * std::cos(2.0 * kOmega * t + 1.1) + 0.35 * std::sin(3.0 * kOmega * t - 0.3));
}

// The force of a linear element F = c·v + m·a + k·x has F* = (c + iΩm − ik/Ω)·V*, hence
// Re(F* conj V*) = c|V*|² and Im(F* conj V*) = (Ωm − k/Ω)|V*|²: η* = c/(m_bed Ω) and
// m_app = m − k/Ω² (derived by hand, not by the code under test).
struct LinearElement {
  double c = 0.0;  // N s/m
  double m = 0.0;  // kg
  double k = 0.0;  // N/m
  double force(double t) const { return c * velocity(t) + m * acceleration(t) + k * displacement(t); }
  double eta_star() const { return c / (kBedMass * kOmega); }
  double apparent_mass() const { return m - k / (kOmega * kOmega); }
};

// Round-off bound for the exact cases: the DFT of N = 2400 samples carries relative
// errors of order ε·log N ≈ 1e-15 of the signal's largest component; 1e-11 of the
// force scale leaves a wide margin and still fails for any real leakage (which would be
// of order the harmonic amplitude, ~1).
constexpr double kRoundOff = 1e-11;

// Checks η*, m_app and V* of a record whose first sample is at t0 (V* = V*(0)·e^{iΩt0}).
void check_element(const LinearElement& element, const ComplexPower& result, double t0 = 0.0) {
  const double force_scale = std::abs(result.force_amplitude);
  // η* and m_app are Re and Im of F*/V* divided by Ω m_bed and Ω: their round-off is
  // that of F* relative to |V*|.
  const double eta_tolerance = kRoundOff * force_scale / (kVelocityAmplitude * kOmega * kBedMass);
  const double mass_tolerance = kRoundOff * force_scale / (kVelocityAmplitude * kOmega);
  CHECK(result.reduced_loss_factor(kBedMass) == Approx(element.eta_star()).margin(eta_tolerance));
  CHECK(result.apparent_mass_kg == Approx(element.apparent_mass()).margin(mass_tolerance));
  CHECK(std::abs(result.velocity_amplitude - std::polar(kVelocityAmplitude, kVelocityPhase + kOmega * t0)) <
        kRoundOff * kVelocityAmplitude);
}

}  // namespace

TEST_CASE("a viscous damper gives eta* = c/(m_bed Omega) and no apparent mass", "[formulas]") {
  const LinearElement damper{2.5, 0.0, 0.0};
  const auto force = [&](double t) { return damper.force(t); };
  const ComplexPower clean = analyse(sample(force, velocity, 12));
  check_element(damper, clean);
  CHECK(clean.periods == 12);
  CHECK(clean.samples_per_period == kSamplesPerPeriod);
  CHECK(clean.angular_frequency == Approx(kOmega).epsilon(1e-15));

  // Independent reference for the energy: the work c∫v²dt over the record per period,
  // summed sample by sample (the rectangle rule is exact over whole periods for a
  // product of two components at Ω sampled 200 times per period).
  const Record record = sample(force, velocity, 12);
  double work = 0.0;
  for (std::size_t i = 0; i < record.force.size(); ++i) work += record.force[i] * record.velocity[i] * kDt;
  CHECK(clean.energy_per_cycle_j == Approx(work / 12.0).epsilon(1e-12));
  CHECK(clean.e_diss_j ==
        Approx(damper.c * kVelocityAmplitude * kVelocityAmplitude / (2.0 * kOmega)).epsilon(1e-12));

  SECTION("a DC offset and harmonics at 2 and 3 Omega on both signals change nothing") {
    const auto force_plus = [&](double t) { return damper.force(t) + other_content(t, 1.0); };
    const auto velocity_plus = [&](double t) { return velocity(t) + other_content(t, 0.2); };
    const ComplexPower loaded = analyse(sample(force_plus, velocity_plus, 12));
    check_element(damper, loaded);
    CHECK(std::abs(loaded.power - clean.power) < kRoundOff * std::abs(clean.power));
  }
}

TEST_CASE("a rigid mass gives Re(P) = 0 and an apparent mass equal to the mass", "[formulas]") {
  const LinearElement mass{0.0, 0.7, 0.0};
  const auto force = [&](double t) { return mass.force(t); };
  const ComplexPower clean = analyse(sample(force, velocity, 8));
  check_element(mass, clean);
  CHECK(std::abs(clean.power.real()) < kRoundOff * std::abs(clean.power));

  SECTION("with a DC offset and harmonics") {
    const auto force_plus = [&](double t) { return mass.force(t) + other_content(t, 2.0); };
    const auto velocity_plus = [&](double t) { return velocity(t) + other_content(t, 0.1); };
    const ComplexPower loaded = analyse(sample(force_plus, velocity_plus, 8));
    check_element(mass, loaded);
    CHECK(std::abs(loaded.power.real()) < kRoundOff * std::abs(loaded.power));
  }
}

TEST_CASE("a spring gives an apparent mass of -k/Omega^2 and no dissipation", "[formulas]") {
  const LinearElement spring{0.0, 0.0, 1500.0};
  const auto force = [&](double t) { return spring.force(t); };
  const ComplexPower clean = analyse(sample(force, velocity, 5));
  check_element(spring, clean);
  CHECK(clean.apparent_mass_kg < 0.0);

  SECTION("with a DC offset (a preload) and harmonics") {
    const auto force_plus = [&](double t) { return spring.force(t) + other_content(t, 3.0); };
    const auto velocity_plus = [&](double t) { return velocity(t) + other_content(t, 0.5); };
    check_element(spring, analyse(sample(force_plus, velocity_plus, 5)));
  }
}

TEST_CASE("the apparent mass and eta* do not depend on the time origin", "[formulas]") {
  // Starting the record at t0 multiplies F* and V* by the same factor e^{iΩt0}, so
  // F*·conj(V*) is unchanged (docs/theory.md §1); F* itself must rotate by exactly that factor.
  const LinearElement element{1.3, 0.45, 800.0};
  const auto force = [&](double t) { return element.force(t); };
  const ComplexPower origin = analyse(sample(force, velocity, 6));
  for (const double t0 : {0.37 / kFrequency, 0.5 / kFrequency, 0.913 / kFrequency, 3.2e-4}) {
    CAPTURE(t0);
    const ComplexPower shifted = analyse(sample(force, velocity, 6, t0));
    check_element(element, shifted, t0);
    const std::complex<double> rotation = std::polar(1.0, kOmega * t0);
    CHECK(std::abs(shifted.force_amplitude - origin.force_amplitude * rotation) <
          kRoundOff * std::abs(origin.force_amplitude));
  }
}

namespace {

// White noise of standard deviation σ on the N force samples puts on F* = (2/N)·Σ sₙe^{−iθₙ}
// independent errors of variance (4/N²)·σ²·(N/2) = 2σ²/N in its real and imaginary parts.
// With V* exact, η* = Re(F*/V*)/(Ω m_bed) and m_app = Im(F*/V*)/Ω, so
//   sd(η*) = σ√(2/N)/(|V*| Ω m_bed),   sd(m_app) = σ√(2/N)/(|V*| Ω).
struct NoiseCase {
  LinearElement element{2.5, 0.7, 1500.0};
  double sigma = 1.0;  // N: about the force amplitude itself (|F*| ≈ 1.36 N)
  int periods = 50;    // N = 10 000 samples
  double n() const { return static_cast<double>(periods * kSamplesPerPeriod); }
  double eta_sd() const { return sigma * std::sqrt(2.0 / n()) / (kVelocityAmplitude * kOmega * kBedMass); }
  double mass_sd() const { return sigma * std::sqrt(2.0 / n()) / (kVelocityAmplitude * kOmega); }
  ComplexPower run(std::mt19937_64& rng) const {
    std::normal_distribution<double> noise(0.0, sigma);
    Record record =
        sample([&](double t) { return element.force(t) + other_content(t, 1.0); }, velocity, periods);
    for (double& f : record.force) f += noise(rng);
    return analyse(record);
  }
};

}  // namespace

TEST_CASE("noise on the force moves eta* and m_app by the expected few sigma", "[formulas]") {
  const NoiseCase noisy;
  std::mt19937_64 rng(20240611);
  const ComplexPower result = noisy.run(rng);
  // sd(η*) ≈ 0.0048 and sd(m_app) ≈ 9.5e-4 kg for σ = 1 N, N = 10 000: allow 4 sd
  // (a 6e-5 chance of a false failure for an arbitrary seed; the seed is fixed).
  CHECK(result.reduced_loss_factor(kBedMass) ==
        Approx(noisy.element.eta_star()).margin(4.0 * noisy.eta_sd()));
  CHECK(result.apparent_mass_kg == Approx(noisy.element.apparent_mass()).margin(4.0 * noisy.mass_sd()));
}

TEST_CASE("the scatter of eta* over noisy records matches sigma*sqrt(2/N)/(|V*| Omega m_bed)", "[formulas]") {
  const NoiseCase noisy;
  std::mt19937_64 rng(7);
  constexpr int kRecords = 400;
  double sum_eta = 0.0, sum_eta2 = 0.0, sum_mass = 0.0, sum_mass2 = 0.0;
  for (int i = 0; i < kRecords; ++i) {
    const ComplexPower result = noisy.run(rng);
    const double d_eta = result.reduced_loss_factor(kBedMass) - noisy.element.eta_star();
    const double d_mass = result.apparent_mass_kg - noisy.element.apparent_mass();
    sum_eta += d_eta;
    sum_eta2 += d_eta * d_eta;
    sum_mass += d_mass;
    sum_mass2 += d_mass * d_mass;
  }
  // The sample sd of 400 Gaussian draws has a relative sd of 1/√(2·400) = 3.5%: allow
  // 15% (> 4 of those). The means must be unbiased within 4 standard errors.
  CHECK(std::sqrt(sum_eta2 / kRecords) == Approx(noisy.eta_sd()).epsilon(0.15));
  CHECK(std::sqrt(sum_mass2 / kRecords) == Approx(noisy.mass_sd()).epsilon(0.15));
  CHECK(std::abs(sum_eta / kRecords) < 4.0 * noisy.eta_sd() / std::sqrt(kRecords));
  CHECK(std::abs(sum_mass / kRecords) < 4.0 * noisy.mass_sd() / std::sqrt(kRecords));
}

TEST_CASE("the amplitudes equal the DFT bin at k periods for arbitrary signals", "[formulas]") {
  // Independent reference: the single DFT bin S* = (2/N)·Σₙ sₙ e^{−2πi kn/N} summed
  // directly in long double, for white noise (no periodicity the code could rely on).
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  constexpr int kPeriods = 7;
  constexpr int kN = kPeriods * kSamplesPerPeriod;
  std::vector<double> force(kN), speed(kN);
  for (int i = 0; i < kN; ++i) {
    force[i] = uniform(rng);
    speed[i] = uniform(rng) + 0.5 * std::cos(kOmega * i * kDt);
  }
  const auto direct_bin = [&](const std::vector<double>& s) {
    long double re = 0.0L, im = 0.0L;
    const long double pi = 3.141592653589793238462643383279502884L;
    for (int n = 0; n < kN; ++n) {
      const long double angle =
          -2.0L * pi * static_cast<long double>((static_cast<long long>(kPeriods) * n) % kN) / kN;
      re += s[n] * std::cos(angle);
      im += s[n] * std::sin(angle);
    }
    return std::complex<double>(static_cast<double>(2.0L * re / kN), static_cast<double>(2.0L * im / kN));
  };
  const ComplexPower result = complex_power(force, speed, kDt, kFrequency);
  // The sums run over 1400 terms of size ~1: round-off ~1e-15 absolute on S* ~ 0.04.
  CHECK(std::abs(result.force_amplitude - direct_bin(force)) < 1e-13);
  CHECK(std::abs(result.velocity_amplitude - direct_bin(speed)) < 1e-13);
}

TEST_CASE("complex_power is safe to call from several threads with different period lengths", "[formulas]") {
  // Eight period lengths M no other test uses, so the threads race to create their
  // FFTW plans (the planner is not thread-safe: the cache must serialise it).
  const LinearElement element{2.5, 0.7, 1500.0};
  struct Job {
    std::vector<double> force, velocity;
    double dt = 0.0;
  };
  std::vector<Job> jobs;
  for (int j = 0; j < 8; ++j) {
    const int samples_per_period = 101 + 17 * j;
    Job job;
    job.dt = 1.0 / (kFrequency * samples_per_period);
    for (int i = 0; i < 3 * samples_per_period; ++i) {
      job.force.push_back(element.force(i * job.dt));
      job.velocity.push_back(velocity(i * job.dt));
    }
    jobs.push_back(std::move(job));
  }
  const auto run = [&](const Job& job) { return complex_power(job.force, job.velocity, job.dt, kFrequency); };

  std::vector<std::vector<ComplexPower>> parallel(4);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int repeat = 0; repeat < 5; ++repeat) {
        for (std::size_t i = 0; i < jobs.size(); ++i) parallel[t].push_back(run(jobs[(i + t) % jobs.size()]));
      }
    });
  }
  for (auto& thread : threads) thread.join();
  // Afterwards, serially: every concurrent result must equal it bit for bit (one plan
  // per length, and FFTW's output for one plan and input is deterministic).
  for (int t = 0; t < 4; ++t) {
    REQUIRE(parallel[t].size() == 5 * jobs.size());
    for (std::size_t j = 0; j < parallel[t].size(); ++j) {
      const ComplexPower serial = run(jobs[(j % jobs.size() + t) % jobs.size()]);
      CHECK(parallel[t][j].power == serial.power);
      CHECK(parallel[t][j].apparent_mass_kg == serial.apparent_mass_kg);
    }
  }
  CHECK(run(jobs[3]).apparent_mass_kg == Approx(element.apparent_mass()).margin(1e-12));
}

TEST_CASE("complex_power rejects records that are not whole periods", "[formulas]") {
  const Record record = sample(velocity, velocity, 4);
  SECTION("T/dt not an integer") {
    const double dt = 1.0 / (kFrequency * 200.5);
    CHECK_THROWS_MATCHES(
        complex_power(record.force, record.velocity, dt, kFrequency), std::invalid_argument,
        Catch::Message("complex_power: dt_s = 0.000997506234414, frequency_hz = 5: T/dt = 200.5 "
                       "must be an integer (within 1e-9 relative)"));
  }
  SECTION("T/dt off an integer by more than 1e-9 relative") {
    const double dt = kDt * (1.0 + 1e-8);
    CHECK_THROWS_AS(complex_power(record.force, record.velocity, dt, kFrequency), std::invalid_argument);
  }
  SECTION("T/dt within round-off of an integer is accepted") {
    const double dt = kDt * (1.0 + 1e-12);
    CHECK(complex_power(record.force, record.velocity, dt, kFrequency).samples_per_period ==
          kSamplesPerPeriod);
  }
  SECTION("N not a multiple of T/dt") {
    const std::span<const double> f(record.force.data(), 750);
    const std::span<const double> v(record.velocity.data(), 750);
    CHECK_THROWS_WITH(complex_power(f, v, kDt, kFrequency), Catch::Contains("N = 750 samples, T/dt = 200") &&
                                                                Catch::Contains("whole number of periods"));
  }
  SECTION("shorter than one period") {
    const std::span<const double> f(record.force.data(), 150);
    const std::span<const double> v(record.velocity.data(), 150);
    CHECK_THROWS_AS(complex_power(f, v, kDt, kFrequency), std::invalid_argument);
  }
  SECTION("fewer than 3 samples per period") {
    CHECK_THROWS_WITH(complex_power(record.force, record.velocity, 0.5 / kFrequency, kFrequency),
                      Catch::Contains("T/dt = 2 samples per period, must be >= 3"));
  }
}

TEST_CASE("complex_power rejects malformed signals and parameters with the numbers", "[formulas]") {
  const Record record = sample(velocity, velocity, 2);
  const std::vector<double> empty;
  CHECK_THROWS_WITH(complex_power(empty, empty, kDt, kFrequency), Catch::Contains("must be non-empty"));
  const std::span<const double> shorter(record.velocity.data(), 399);
  CHECK_THROWS_WITH(complex_power(record.force, shorter, kDt, kFrequency),
                    Catch::Contains("force has 400 samples, velocity 399: lengths must be equal"));
  CHECK_THROWS_WITH(complex_power(record.force, record.velocity, 0.0, kFrequency),
                    Catch::Contains("dt_s = 0: must be > 0"));
  CHECK_THROWS_WITH(complex_power(record.force, record.velocity, -kDt, kFrequency),
                    Catch::Contains("dt_s = -0.001: must be > 0"));
  CHECK_THROWS_WITH(complex_power(record.force, record.velocity, kDt, -5.0),
                    Catch::Contains("frequency_hz = -5: must be > 0"));
  CHECK_THROWS_WITH(complex_power(record.force, record.velocity, kDt, std::nan("")),
                    Catch::Contains("frequency_hz = nan"));

  Record bad = record;
  bad.force[17] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(complex_power(bad.force, bad.velocity, kDt, kFrequency),
                    Catch::Contains("force_n[17] = nan: samples must be finite"));
  bad = record;
  bad.velocity[399] = std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(complex_power(bad.force, bad.velocity, kDt, kFrequency),
                    Catch::Contains("velocity_m_s[399] = inf"));
}

TEST_CASE("complex_power rejects a velocity without a component at the drive frequency", "[formulas]") {
  const auto no_fundamental = [](double t) { return other_content(t, 1.0); };
  const Record harmonics_only = sample(velocity, no_fundamental, 3);
  CHECK_THROWS_WITH(complex_power(harmonics_only.force, harmonics_only.velocity, kDt, kFrequency),
                    Catch::Contains("no component at the drive frequency 5 Hz"));
  const std::vector<double> zeros(600, 0.0);
  CHECK_THROWS_WITH(complex_power(harmonics_only.force, zeros, kDt, kFrequency),
                    Catch::Contains("|V*| = 0 m/s"));
}

TEST_CASE("the reduced loss factor needs a positive bed mass", "[formulas]") {
  const Record record = sample(velocity, velocity, 1);
  const ComplexPower result = analyse(record);
  CHECK_THROWS_WITH(result.reduced_loss_factor(0.0), Catch::Contains("bed_mass_kg = 0: must be > 0"));
  CHECK_THROWS_AS(result.reduced_loss_factor(-1.0), std::invalid_argument);
}

// ---- Step-by-step drive bin (measures that do not alias) ----

namespace {

using pdamp::formulas::DriveBinAccumulator;
using pdamp::formulas::StepForce;

constexpr int kBlocks = 16;          // the smallest samples_per_period the DEM allows
constexpr int kStepsPerBlock = 50;
constexpr int kSteps = kBlocks * kStepsPerBlock;  // steps per period, M
constexpr double kStepDt = 1.0 / (kFrequency * kSteps);
const std::complex<double> kF1 = std::polar(2.0, 0.7);    // force at Ω, N
const std::complex<double> kF15 = std::polar(5.0, -1.1);  // at 15Ω: folds into bin 1 of 16 blocks
const std::complex<double> kF17 = std::polar(4.0, 2.3);   // at 17Ω: likewise

/// Force sample of step k: DC + harmonics 1, 15, 17 at t_k = k·dt.
double aliasing_force(double t) {
  return 0.3 + std::real(kF1 * std::polar(1.0, kOmega * t)) + std::real(kF15 * std::polar(1.0, 15.0 * kOmega * t)) +
         std::real(kF17 * std::polar(1.0, 17.0 * kOmega * t));
}
double step_velocity(double t) { return std::real(std::polar(kVelocityAmplitude, kVelocityPhase) * std::polar(1.0, kOmega * t)); }

/// Independent reference: (2/T_total)∫ F(t) e^{−iΩt} dt of the step-held force, by
/// composite Simpson quadrature with 200 intervals per step in long double (no sinc;
/// error ~(Ωh)⁴/2880 ≈ 1e-21). kConstant: F_k over [t_k − dt/2, t_k + dt/2]; kLinear:
/// F linear from t_k to t_{k+1}.
std::complex<long double> integrated_bin(int periods, StepForce model) {
  const long double dt = kStepDt, omega = kOmega;
  const int sub = 200;
  const long double h = dt / sub;
  std::complex<long double> sum = 0.0L;
  const int n = periods * kSteps;
  for (int k = 0; k < n; ++k) {
    const long double fk = aliasing_force(k * kStepDt);
    const long double fk1 = aliasing_force((k + 1) * kStepDt);
    const long double start = model == StepForce::kConstant ? (k - 0.5L) * dt : k * dt;
    for (int j = 0; j <= sub; ++j) {
      const long double u = static_cast<long double>(j) / sub;
      const long double f = model == StepForce::kConstant ? fk : fk + (fk1 - fk) * u;
      const long double w = (j == 0 || j == sub) ? 1.0L : (j % 2 == 1 ? 4.0L : 2.0L);
      sum += w * f * std::polar(1.0L, -omega * (start + u * dt)) * (h / 3.0L);
    }
  }
  return sum * (2.0L / (n * dt));
}

}  // namespace

// Reference: the Fourier coefficient of the force as the DEM step holds it, integrated
// by brute force (above), and in closed form: Σ_k e^{ijΩt_k}e^{−iΩt_k} over a period of
// M = 800 steps vanishes unless j ≡ ±1 (mod 800), so harmonics 15 and 17 and the DC do
// not reach the bin and F* = F₁·sinc(π/M) (constant) or F₁·sinc²(π/M) (linear). Block
// averages over 16 blocks fold 15Ω and 17Ω into bin 1 (15 ≡ −1, 17 ≡ 1 mod 16): the old
// measure is off by 0.30 N here (15% of |F₁|; the boxcar passes 15Ω and 17Ω at
// sinc(15π/16) and sinc(17π/16) ≈ 0.067, −0.059 of the fundamental's gain). Tolerance
// 1e-12 N: round-off of 2400 sums; the quadrature reference agrees to ~1e-13.
TEST_CASE("the step-by-step drive bin is exact for a force with harmonics at 15 and 17 times the drive",
          "[formulas]") {
  constexpr int periods = 3;
  for (const StepForce model : {StepForce::kConstant, StepForce::kLinear}) {
    DriveBinAccumulator bin(kSteps, model);
    std::vector<double> force_blocks, velocity_blocks;
    for (int k = 0; k < periods * kSteps; ++k) {
      bin.add(k, aliasing_force(k * kStepDt), step_velocity(k * kStepDt));
    }
    const ComplexPower cp = bin.result(kFrequency);
    const double sinc = std::sin(kPi / kSteps) / (kPi / kSteps);
    const std::complex<double> expected = kF1 * (model == StepForce::kConstant ? sinc : sinc * sinc);
    const std::complex<long double> brute = integrated_bin(periods, model);
    INFO("F* = " << cp.force_amplitude << ", closed form " << expected << ", quadrature " << std::complex<double>(brute));
    CHECK(std::abs(cp.force_amplitude - expected) < 1e-12);
    CHECK(std::abs(std::complex<double>(brute) - expected) < 1e-12);
    CHECK(std::abs(cp.velocity_amplitude - std::polar(kVelocityAmplitude, kVelocityPhase)) < 1e-14);
    CHECK(cp.periods == periods);
    CHECK(cp.samples_per_period == kSteps);
  }
  // The block measure on the same force: 16 block averages per period.
  std::vector<double> force_blocks, velocity_blocks;
  for (int b = 0; b < periods * kBlocks; ++b) {
    double f = 0.0, v = 0.0;
    for (int k = b * kStepsPerBlock; k < (b + 1) * kStepsPerBlock; ++k) {
      f += aliasing_force(k * kStepDt);
      v += step_velocity(k * kStepDt);
    }
    force_blocks.push_back(f / kStepsPerBlock);
    velocity_blocks.push_back(v / kStepsPerBlock);
  }
  const ComplexPower blocks = complex_power(force_blocks, velocity_blocks, kStepDt * kStepsPerBlock, kFrequency);
  // Undo the boxcar's common factor on F* and V*: what is left is the fold.
  const std::complex<double> block_force = blocks.force_amplitude * (std::polar(kVelocityAmplitude, kVelocityPhase) /
                                                                    blocks.velocity_amplitude);
  INFO("block-average F* = " << block_force << " against F1 = " << kF1);
  CHECK(std::abs(block_force - kF1) > 0.2);
}

// Reference: a viscous damper c and a rigid mass m (docs/complex_power.md) with the
// step index starting anywhere: η* = c/(m_bed Ω), m_app = m exactly, the time origin
// drops out of F*·conj V*. Tolerance 1e-12 relative (round-off), and the per-period
// sums merged equal one accumulator over all periods.
TEST_CASE("the drive bin accumulator gives the closed forms from any step origin and merges periods",
          "[formulas]") {
  constexpr double c = 1.7, m = 0.05;
  const auto force = [&](double t) {
    const std::complex<double> v = std::polar(kVelocityAmplitude, kVelocityPhase) * std::polar(1.0, kOmega * t);
    return std::real(c * v + m * std::complex<double>(0.0, kOmega) * v);
  };
  for (const std::int64_t origin : {0LL, 37LL, 123456789LL}) {
    DriveBinAccumulator all(kSteps), period(kSteps), merged(kSteps);
    for (std::int64_t k = origin; k < origin + 4 * kSteps; ++k) {
      const double t = static_cast<double>(k) * kStepDt;
      all.add(k, force(t), step_velocity(t));
      period.add(k, force(t), step_velocity(t));
      if (period.samples() == kSteps) {
        merged.merge(period);
        period.clear();
      }
    }
    const double sinc = std::sin(kPi / kSteps) / (kPi / kSteps);
    const ComplexPower cp = all.result(kFrequency);
    INFO("origin " << origin);
    CHECK(cp.reduced_loss_factor(kBedMass) == Approx(sinc * c / (kBedMass * kOmega)).epsilon(1e-12));
    CHECK(cp.apparent_mass_kg == Approx(sinc * m).epsilon(1e-12));
    const ComplexPower cm = merged.result(kFrequency);
    CHECK(cm.reduced_loss_factor(kBedMass) == Approx(cp.reduced_loss_factor(kBedMass)).epsilon(1e-13));
    CHECK(cm.apparent_mass_kg == Approx(cp.apparent_mass_kg).epsilon(1e-13));
  }
}

TEST_CASE("the drive bin accumulator rejects partial periods, short periods and a missing fundamental",
          "[formulas]") {
  CHECK_THROWS_WITH(DriveBinAccumulator(2), Catch::Contains("steps_per_period = 2: must be >= 3"));
  DriveBinAccumulator bin(kSteps);
  CHECK_THROWS_WITH(bin.result(kFrequency), Catch::Contains("N = 0 samples"));
  for (int k = 0; k < kSteps + 5; ++k) bin.add(k, 1.0, step_velocity(k * kStepDt));
  CHECK_THROWS_WITH(bin.result(kFrequency), Catch::Contains("whole number of periods"));
  DriveBinAccumulator flat(kSteps);
  for (int k = 0; k < kSteps; ++k) flat.add(k, 1.0, 0.2);
  CHECK_THROWS_WITH(flat.result(kFrequency), Catch::Contains("no component at the drive frequency"));
  DriveBinAccumulator other(kSteps + 1);
  CHECK_THROWS_WITH(bin.merge(other), Catch::Contains("must be equal"));
  DriveBinAccumulator nan(kSteps);
  for (int k = 0; k < kSteps; ++k) nan.add(k, k == 7 ? std::nan("") : 1.0, step_velocity(k * kStepDt));
  CHECK_THROWS_WITH(nan.result(kFrequency), Catch::Contains("not finite"));
}
