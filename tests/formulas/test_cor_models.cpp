// Tests of the restitution models, the impact CSV, the fits and the Hertz damping calibration.
#include "pdamp/formulas/cor_models.hpp"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace pf = pdamp::formulas;
using Catch::Matchers::Contains;
using std::numbers::pi;

namespace {

// Steel (pdamp's default "steel" material, docs/cases.md) and the 5 mm sphere of the reference cases.
constexpr double kSteelModulus = 210e9;
constexpr double kSteelPoisson = 0.3;
constexpr double kSteelDensity = 7850.0;
constexpr double kSphereRadius = 0.005;
const double kSphereMass = 4.0 / 3.0 * pi * std::pow(kSphereRadius, 3) * kSteelDensity;
// Sphere on a steel plate (both elastic, the plate massive), as in the shipped CSV.
const double kSteelPairModulus = kSteelModulus / (2.0 * (1.0 - kSteelPoisson * kSteelPoisson));

std::string data_path(const std::string& name) {
  return std::string(PDAMP_SOURCE_DIR) + "/tests/data/" + name;
}

// Thornton (1997), Eq. for e with r = V_y/V_i, typed from the paper's form
// e = (6√3/5)^{1/2}[1 − (1/6)r²]^{1/2}{r/[r + 2((6/5) − (1/5)r²)^{1/2}]}^{1/4}.
double thornton_paper(double r) {
  return std::pow(6.0 * std::sqrt(3.0) / 5.0, 0.5) * std::pow(1.0 - r * r / 6.0, 0.5) *
         std::pow(r / (r + 2.0 * std::pow(6.0 / 5.0 - r * r / 5.0, 0.5)), 0.25);
}

// Writes `text` to a fresh file in the temporary directory and returns its path.
std::string write_temp_csv(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("pdamp_test_cor_" + name + ".csv");
  std::ofstream(path) << text;
  return path.string();
}

// Independent integrator for the impact tests: classical RK4 in τ = (t/t_s)^{1/4}.
// δ^{1/4} is not smooth in t at first touch (Runge-Kutta in t converges only as
// h^{5/4} there), but the solution is a power series in τ, so RK4 in τ converges as
// h⁴. Integrates δ'' = acceleration(δ, δ') from δ = 0, δ' = impact speed until
// end(δ, δ') <= 0 with δ' < 0 (located by bisection of the last step) and returns
// the rebound speed −δ'.
template <class Acceleration, class End>
double rebound_speed(Acceleration acceleration, End end, double impact_speed, double time_scale,
                     int steps_per_unit_tau) {
  const double h = 1.0 / steps_per_unit_tau;
  struct State {
    double x, v;
  };
  auto derivative = [&](double tau, const State& s) {
    const double dt_dtau = 4.0 * time_scale * tau * tau * tau;
    return State{dt_dtau * s.v, dt_dtau * acceleration(s.x, s.v)};
  };
  auto rk4 = [&](double tau, const State& s, double step) {
    const State k1 = derivative(tau, s);
    const State k2 = derivative(tau + step / 2, {s.x + step / 2 * k1.x, s.v + step / 2 * k1.v});
    const State k3 = derivative(tau + step / 2, {s.x + step / 2 * k2.x, s.v + step / 2 * k2.v});
    const State k4 = derivative(tau + step, {s.x + step * k3.x, s.v + step * k3.v});
    return State{s.x + step / 6 * (k1.x + 2 * k2.x + 2 * k3.x + k4.x),
                 s.v + step / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v)};
  };
  State state{0.0, impact_speed};
  double tau = 0.0;
  for (int i = 0; i < 100 * steps_per_unit_tau; ++i) {
    const State next = rk4(tau, state, h);
    if (next.v < 0.0 && end(next.x, next.v) <= 0.0) {
      double lo = 0.0, hi = h;
      for (int j = 0; j < 60; ++j) {
        const double mid = 0.5 * (lo + hi);
        const State at = rk4(tau, state, mid);
        (at.v < 0.0 && end(at.x, at.v) <= 0.0 ? hi : lo) = mid;
      }
      return -rk4(tau, state, hi).v;
    }
    state = next;
    tau += h;
  }
  FAIL("rebound_speed: the contact did not end");
  return 0.0;
}

// The dimensionless damped Hertz impact with contact end at zero total force.
double dimensionless_rebound(double damping, int steps_per_unit_tau = 4000) {
  auto acceleration = [&](double x, double v) {
    const double quarter = std::sqrt(std::sqrt(std::abs(x)));
    return -x * quarter * quarter - damping * quarter * v;
  };
  auto total_force_over_quarter = [&](double x, double v) {
    return x * std::sqrt(std::sqrt(std::abs(x))) + damping * v;
  };
  return rebound_speed(acceleration, total_force_over_quarter, 1.0, 1.0, steps_per_unit_tau);
}

double textbook_beta(double restitution) {
  const double log_e = std::log(restitution);
  return log_e / std::sqrt(log_e * log_e + pi * pi);
}

// Standard error of ln p_y from the linearised least squares at the true p_y:
// σ/√Σ(∂ε_i/∂ln p_y)², the derivative by central differences of the paper's form.
double thornton_log_pressure_standard_error(const std::vector<double>& speeds, double pressure,
                                            double sigma) {
  double sum = 0.0;
  for (double v : speeds) {
    auto eps = [&](double p) {
      const double r = pf::yield_speed(p, kSteelPairModulus, kSphereRadius, kSphereMass) / v;
      return r >= 1.0 ? 1.0 : thornton_paper(r);
    };
    const double derivative =
        (eps(pressure * std::exp(1e-5)) - eps(pressure * std::exp(-1e-5))) / 2e-5;
    sum += derivative * derivative;
  }
  return sigma / std::sqrt(sum);
}
}  // namespace

// ---------------------------------------------------------------------------
// Constant, linear and tabulated laws.

TEST_CASE("constant restitution is the same at every speed", "[formulas][cor]") {
  const auto model = pf::make_constant_restitution(0.8);
  CHECK(model->restitution(0.0) == 0.8);
  CHECK(model->restitution(7.5) == 0.8);
  CHECK_THAT(model->describe(), Contains("constant 0.8"));
}

TEST_CASE("constant restitution rejects values outside the interval from 0 to 1",
          "[formulas][cor]") {
  CHECK_THROWS_WITH(pf::make_constant_restitution(0.0),
                    Contains("restitution = 0: must be in (0, 1]"));
  CHECK_THROWS_AS(pf::make_constant_restitution(1.01), std::invalid_argument);
  CHECK_THROWS_AS(pf::make_constant_restitution(std::nan("")), std::invalid_argument);
  CHECK_NOTHROW(pf::make_constant_restitution(1.0));
}

TEST_CASE("every law rejects a negative or non-finite impact speed", "[formulas][cor]") {
  const auto model = pf::make_constant_restitution(0.5);
  CHECK_THROWS_WITH(model->restitution(-0.1), Contains("impact_speed_m_s = -0.1"));
  CHECK_THROWS_AS(model->restitution(std::nan("")), std::invalid_argument);
  const auto thornton =
      pf::make_thornton_restitution(1e9, kSteelPairModulus, kSphereRadius, kSphereMass);
  CHECK_THROWS_AS(thornton->restitution(-1.0), std::invalid_argument);
}

TEST_CASE("linear restitution follows the line and is clamped between its floor and 1",
          "[formulas][cor]") {
  const auto model = pf::make_linear_restitution(0.9, 0.05);
  CHECK(model->restitution(0.0) == Approx(0.9).margin(1e-15));
  CHECK(model->restitution(2.0) == Approx(0.8).margin(1e-15));
  CHECK(model->restitution(100.0) == pf::kMinLinearRestitution);  // the line is negative there
  const auto rising = pf::make_linear_restitution(0.9, -0.5);
  CHECK(rising->restitution(1.0) == 1.0);
  CHECK_THROWS_AS(pf::make_linear_restitution(0.0, 0.1), std::invalid_argument);
  CHECK_THROWS_AS(pf::make_linear_restitution(0.9, INFINITY), std::invalid_argument);
}

TEST_CASE("tabulated restitution is exact at the nodes and clamped outside the table",
          "[formulas][cor]") {
  const std::vector<double> speeds{0.05, 0.1, 0.3, 1.0, 2.0};
  const std::vector<double> values{0.95, 0.9, 0.8, 0.7, 0.68};
  const auto model = pf::make_tabulated_restitution(speeds, values);
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    CHECK(model->restitution(speeds[i]) == Approx(values[i]).margin(1e-15));
  }
  CHECK(model->restitution(0.0) == 0.95);
  CHECK(model->restitution(10.0) == 0.68);
  CHECK_THAT(model->describe(), Contains("5 points"));
}

TEST_CASE("tabulated restitution reproduces a linear table exactly", "[formulas][cor]") {
  // Non-uniform spacing on purpose: the three-point slopes are exact for a line.
  const std::vector<double> speeds{0.0, 0.1, 0.35, 0.4, 1.2, 3.0};
  std::vector<double> values;
  for (double v : speeds) values.push_back(0.92 - 0.04 * v);
  const auto model = pf::make_tabulated_restitution(speeds, values);
  for (double v = 0.0; v <= 3.0; v += 0.01) {
    // Rounding only: a few ulps of values ~0.9.
    CHECK(model->restitution(v) == Approx(0.92 - 0.04 * v).margin(1e-14));
  }
}

TEST_CASE("tabulated restitution of monotone data is monotone without overshoot",
          "[formulas][cor]") {
  // A flat start, a sharp drop and a long tail: an unlimited cubic spline rings here.
  const std::vector<double> speeds{0.0, 0.1, 0.2, 0.25, 0.3, 1.0, 3.0, 5.0};
  const std::vector<double> values{1.0, 1.0, 0.99, 0.75, 0.7, 0.65, 0.64, 0.3};
  const auto model = pf::make_tabulated_restitution(speeds, values);
  double previous = model->restitution(0.0);
  for (int i = 1; i <= 50000; ++i) {
    const double v = 5.0 * i / 50000;
    const double value = model->restitution(v);
    CHECK(value <= previous);  // exact monotonicity: no tolerance
    // No overshoot: inside the bracketing nodes' values.
    const auto k = static_cast<std::size_t>(std::upper_bound(speeds.begin(), speeds.end(), v) -
                                            speeds.begin());
    if (k < speeds.size()) {
      CHECK(value <= values[k - 1]);
      CHECK(value >= values[k]);
    }
    previous = value;
  }
}

TEST_CASE("tabulated restitution rejects malformed tables", "[formulas][cor]") {
  const std::vector<double> one{0.1};
  CHECK_THROWS_WITH(pf::make_tabulated_restitution(one, one), Contains("1 points: must have >= 2"));
  const std::vector<double> two{0.1, 0.2};
  const std::vector<double> three{0.1, 0.2, 0.3};
  CHECK_THROWS_WITH(pf::make_tabulated_restitution(two, three), Contains("equal lengths"));
  const std::vector<double> good_values{0.9, 0.8};
  const std::vector<double> repeated{0.2, 0.2};
  CHECK_THROWS_WITH(pf::make_tabulated_restitution(repeated, good_values),
                    Contains("speeds_m_s[1] = 0.2: must be > speeds_m_s[0]"));
  const std::vector<double> negative{-0.1, 0.2};
  CHECK_THROWS_WITH(pf::make_tabulated_restitution(negative, good_values),
                    Contains("speeds_m_s[0] = -0.1"));
  const std::vector<double> not_a_number{0.1, std::nan("")};
  CHECK_THROWS_AS(pf::make_tabulated_restitution(not_a_number, good_values), std::invalid_argument);
  const std::vector<double> too_high{0.9, 1.2};
  CHECK_THROWS_WITH(pf::make_tabulated_restitution(two, too_high),
                    Contains("values[1] = 1.2: must be in (0, 1]"));
  const std::vector<double> zero{0.9, 0.0};
  CHECK_THROWS_AS(pf::make_tabulated_restitution(two, zero), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Yield speed and Thornton's law.

TEST_CASE("the yield speed of a sphere on a flat carries Thornton's constant 1.56",
          "[formulas][cor]") {
  // Reference: Thornton (1997), V_y = 1.56 (p_y⁵/(E*⁴ρ))^{1/2} for m* = (4/3)πR³ρ,
  // R* = R. 1.56 is √(π⁴/40) = 1.5605 rounded: 0.04% apart, tolerance 0.1%.
  for (double pressure : {0.5e9, 1.6e9, 3e9}) {
    const double expected =
        1.56 * std::sqrt(std::pow(pressure, 5) / (std::pow(kSteelPairModulus, 4) * kSteelDensity));
    CHECK(pf::yield_speed(pressure, kSteelPairModulus, kSphereRadius, kSphereMass) ==
          Approx(expected).epsilon(1e-3));
  }
}

TEST_CASE("at the yield speed the Hertz peak pressure equals p_y", "[formulas][cor]") {
  // Reference: docs/theory.md §5, δ_max = (15m*v²/(16E*√R*))^{2/5}, with a = √(R*δ) and
  // p₀ = 2E*a/(πR*) (Hertz; Johnson 1985, ch. 4). Same algebra, so rounding only: 1e-12.
  const double pressure = 1.2e9, modulus = 115e9, radius = 0.003, mass = 2e-3;
  const double v = pf::yield_speed(pressure, modulus, radius, mass);
  const double overlap = std::pow(15.0 * mass * v * v / (16.0 * modulus * std::sqrt(radius)), 0.4);
  const double peak_pressure = 2.0 * modulus * std::sqrt(radius * overlap) / (pi * radius);
  CHECK(peak_pressure == Approx(pressure).epsilon(1e-12));
}

TEST_CASE("Johnson's first-yield speed corresponds to p_y of about 1.6 Y", "[formulas][cor]") {
  // Reference: Johnson (Contact Mechanics, 1985, ch. 11) ρv_y²/Y = 26(Y/E*)⁴, i.e.
  // v_y = √(26 Y⁵/(ρE*⁴)), and p₀ = 1.60 Y at first yield (ch. 6). v_y ∝ p_y^{5/2}, so the ratio c
  // = p_y/Y that reproduces Johnson's speed is 1.6·(v_J/v(1.6Y))^{2/5}; exact value
  // (26·40/π⁴)^{1/5} = 1.606. Johnson's 26 is rounded to 2 digits: tolerance 0.01 on c.
  const double yield_stress = 0.8e9;
  const double johnson = std::sqrt(26.0 * std::pow(yield_stress, 5) /
                                   (kSteelDensity * std::pow(kSteelPairModulus, 4)));
  const double at_1_6 = pf::yield_speed(pf::kLimitingPressurePerYieldStress * yield_stress,
                                        kSteelPairModulus, kSphereRadius, kSphereMass);
  const double ratio = pf::kLimitingPressurePerYieldStress * std::pow(johnson / at_1_6, 0.4);
  CHECK(ratio == Approx(1.6).margin(0.01));
}

TEST_CASE("Thornton's restitution is 1 up to v_y and then continuous and decreasing as v^(-1/4)",
          "[formulas][cor]") {
  const double pressure = 1e9;
  const auto model =
      pf::make_thornton_restitution(pressure, kSteelPairModulus, kSphereRadius, kSphereMass);
  const double vy = pf::yield_speed(pressure, kSteelPairModulus, kSphereRadius, kSphereMass);
  CHECK(model->restitution(0.5 * vy) == 1.0);
  CHECK(model->restitution(vy) == 1.0);
  // Continuity: just above v_y the closed form is 1 to rounding (√(5/6)·3^{-1/4}·√(6√3/5) = 1).
  CHECK(model->restitution(vy * (1.0 + 1e-12)) == Approx(1.0).margin(1e-10));
  double previous = 1.0;
  for (int i = 1; i <= 400; ++i) {
    const double v = vy * std::pow(10.0, 6.0 * i / 400);
    const double value = model->restitution(v);
    CHECK(value < previous);
    previous = value;
  }
  // Large v: ε → √(6√3/5)·(r/(2√(6/5)))^{1/4}, r = v_y/v; slope of ln ε in ln v → −1/4
  // with an O(r) correction: at r = 1e-8 tolerance 1e-6 on the slope and on the constant.
  const double v1 = 1e8 * vy, v2 = 2e8 * vy;
  const double slope = std::log(model->restitution(v2) / model->restitution(v1)) / std::log(2.0);
  CHECK(slope == Approx(-0.25).margin(1e-6));
  const double asymptote =
      std::sqrt(6.0 * std::sqrt(3.0) / 5.0) * std::pow(1e-8 / (2.0 * std::sqrt(1.2)), 0.25);
  CHECK(model->restitution(v1) == Approx(asymptote).epsilon(1e-6));
  // Against the paper's form typed independently (rounding only).
  for (double r : {0.9, 0.5, 0.1, 0.01}) {
    CHECK(model->restitution(vy / r) == Approx(thornton_paper(r)).epsilon(1e-13));
  }
}

TEST_CASE("Thornton's closed form is the energy balance of his force-overlap model",
          "[formulas][cor]") {
  // Reference: Thornton's (1997) contact model itself, integrated here in closed form.
  // Loading: Hertz up to δ_y (p₀ = p_y), then F = F_y + πp_yR*(δ − δ_y). Unloading:
  // Hertz with radius R_p, F_max = (4/3)E*√R_p(δ_max − δ_p)^{3/2}, where the contact
  // radius a_p² = (2F_max + F_y)/(2πp_y) gives R_p = 4E*a_p³/(3F_max). Then
  // ε² = (unloading work)/(½m*v²). Same physics, different algebra: rounding only.
  const double pressure = 0.9e9, modulus = kSteelPairModulus, radius = kSphereRadius,
               mass = kSphereMass;
  const auto model = pf::make_thornton_restitution(pressure, modulus, radius, mass);
  const double overlap_y = radius * std::pow(pi * pressure / (2.0 * modulus), 2);
  const double force_y = 4.0 / 3.0 * modulus * std::sqrt(radius) * std::pow(overlap_y, 1.5);
  const double work_y = 0.4 * force_y * overlap_y;
  const double stiffness = pi * pressure * radius;
  for (double speed : {0.1, 0.5, 2.0, 10.0}) {
    const double kinetic = 0.5 * mass * speed * speed;
    // W_y + F_y·d + ½k·d² = ½m*v², d = δ_max − δ_y.
    const double d =
        (-force_y + std::sqrt(force_y * force_y + 2.0 * stiffness * (kinetic - work_y))) /
        stiffness;
    const double force_max = force_y + stiffness * d;
    const double contact_radius_sq = (2.0 * force_max + force_y) / (2.0 * pi * pressure);
    const double radius_p = 4.0 * modulus * std::pow(contact_radius_sq, 1.5) / (3.0 * force_max);
    const double unload =
        std::pow(3.0 * force_max / (4.0 * modulus * std::sqrt(radius_p)), 2.0 / 3.0);
    const double work_out = 0.4 * force_max * unload;
    CHECK(model->restitution(speed) == Approx(std::sqrt(work_out / kinetic)).epsilon(1e-10));
  }
}

TEST_CASE("Thornton's law from the yield stress uses p_y = 1.6 Y", "[formulas][cor]") {
  const double yield_stress = 0.7e9;
  const auto from_y = pf::make_thornton_restitution_from_yield_stress(
      yield_stress, kSteelPairModulus, kSphereRadius, kSphereMass);
  const auto from_p = pf::make_thornton_restitution(1.6 * yield_stress, kSteelPairModulus,
                                                    kSphereRadius, kSphereMass);
  for (double v : {0.01, 0.3, 3.0}) CHECK(from_y->restitution(v) == from_p->restitution(v));
  CHECK_THAT(from_y->describe(), Contains("p_y = 1.12e+09 Pa"));
}

TEST_CASE("Thornton's law and the yield speed reject non-positive parameters", "[formulas][cor]") {
  CHECK_THROWS_WITH(pf::yield_speed(-1.0, 1e11, 0.01, 0.01),
                    Contains("limiting_pressure_pa = -1: must be > 0 and finite"));
  CHECK_THROWS_WITH(pf::yield_speed(1e9, 0.0, 0.01, 0.01), Contains("effective_modulus_pa = 0"));
  CHECK_THROWS_AS(pf::yield_speed(1e9, 1e11, std::nan(""), 0.01), std::invalid_argument);
  CHECK_THROWS_AS(pf::make_thornton_restitution(1e9, 1e11, 0.01, 0.0), std::invalid_argument);
  CHECK_THROWS_WITH(pf::make_thornton_restitution_from_yield_stress(0.0, 1e11, 0.01, 0.01),
                    Contains("yield_stress_pa = 0"));
}

// ---------------------------------------------------------------------------
// Impact CSV.

TEST_CASE("the shipped impact CSV is read with its columns in any order", "[formulas][cor]") {
  const pf::ImpactData data = pf::read_impact_csv(data_path("cor_impacts_synthetic_thornton.csv"));
  REQUIRE(data.speed_m_s.size() == 40);
  REQUIRE(data.restitution.size() == 40);
  CHECK(data.speed_m_s.front() == 0.1);
  CHECK(data.restitution.front() == 0.909369);  // first column of the file
  CHECK(data.speed_m_s.back() == 3.0);
}

TEST_CASE("impact CSV errors name the file and the line and the problem", "[formulas][cor]") {
  const std::string header = "impact_speed_m_s,restitution\n";
  const auto missing = write_temp_csv("missing", "# c\nspeed,restitution\n0.1,0.9\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(missing),
                    Contains(missing + ":2:") && Contains("no column 'impact_speed_m_s'"));
  const auto text = write_temp_csv("text", header + "0.1,0.9\n0.2,high\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(text),
                    Contains(text + ":3:") && Contains("restitution = 'high': not a number"));
  const auto nan = write_temp_csv("nan", header + "nan,0.9\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(nan), Contains(nan + ":2:") && Contains("must be finite"));
  const auto negative = write_temp_csv("negative", header + "0.1,0.9\n\n-0.5,0.9\n");
  CHECK_THROWS_WITH(
      pf::read_impact_csv(negative),
      Contains(negative + ":4:") && Contains("impact_speed_m_s = -0.5: must be >= 0"));
  const auto above = write_temp_csv("above", header + "0.1,1.2\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(above), Contains("restitution = 1.2: must be in (0, 1]"));
  const auto zero = write_temp_csv("zero", header + "0.1,0\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(zero), Contains("restitution = 0: must be in (0, 1]"));
  const auto short_row = write_temp_csv("short", header + "0.1\n");
  CHECK_THROWS_WITH(pf::read_impact_csv(short_row), Contains(short_row + ":2: 1 columns"));
  const auto empty = write_temp_csv("empty", header);
  CHECK_THROWS_WITH(pf::read_impact_csv(empty), Contains("no data rows"));
  CHECK_THROWS_WITH(pf::read_impact_csv("/nonexistent/impacts.csv"),
                    Catch::Equals("impact CSV /nonexistent/impacts.csv: no such file"));
}

TEST_CASE("a directory, a FIFO or a binary file given as the impact CSV fails at once with one line",
          "[formulas][cor]") {
  const auto dir = std::filesystem::temp_directory_path() / ("pdamp_test_cor_hostile_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // The old reader took a directory for an empty file ("no header line").
  CHECK_THROWS_WITH(pf::read_impact_csv(dir.string()),
                    Catch::Equals("impact CSV " + dir.string() + ": is a directory, not a file"));
  const auto fifo = dir / "impacts.csv";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // The old reader (std::ifstream) blocked in open() until a writer came: run it on a
  // thread and, after 10 s, open the FIFO for writing and close it (end of file) so the
  // test fails instead of hanging.
  auto read = std::async(std::launch::async, [&]() -> std::string {
    try {
      pf::read_impact_csv(fifo.string());
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no exception";
  });
  if (read.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    for (int attempt = 0; attempt < 100 && read.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready;
         ++attempt) {
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (fd >= 0) ::close(fd);
    }
    FAIL("read_impact_csv blocked on a FIFO for more than 10 s");
  }
  CHECK(read.get() == "impact CSV " + fifo.string() + ": is a FIFO (named pipe), not a file");
  // A NUL in a quoted cell is escaped, so the message is not cut at it.
  const auto binary = (dir / "binary.csv").string();
  std::ofstream(binary, std::ios::binary) << std::string("impact_speed_m_s,restitution\n0.1,0.9\0x\n", 39);
  std::string message;
  try {
    pf::read_impact_csv(binary);
  } catch (const std::invalid_argument& e) {
    message = e.what();
  }
  CHECK(message == "impact CSV " + binary + ":2: restitution = '0.9\\0x': not a number");
  std::filesystem::remove_all(dir);
}

TEST_CASE("impact CSV tolerates spaces and CRLF line ends and extra columns", "[formulas][cor]") {
  const auto path =
      write_temp_csv("crlf", "note , restitution , impact_speed_m_s\r\nA, 0.8 ,0.25\r\n");
  const pf::ImpactData data = pf::read_impact_csv(path);
  REQUIRE(data.speed_m_s.size() == 1);
  CHECK(data.speed_m_s[0] == 0.25);
  CHECK(data.restitution[0] == 0.8);
}

// ---------------------------------------------------------------------------
// Fits.

TEST_CASE("the constant fit is the sample mean", "[formulas][cor]") {
  // Reference: least squares of a constant is the mean (closed form).
  const pf::ImpactData data{{0.1, 0.5, 1.0, 2.0}, {0.8, 0.75, 0.7, 0.77}};
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kConstant);
  const double mean = (0.8 + 0.75 + 0.7 + 0.77) / 4.0;
  CHECK(fit.coefficients.at(0) == Approx(mean).margin(1e-9));  // SLSQP xtol 1e-12, f quadratic
  CHECK(fit.points == 4);
  double sum = 0.0;
  for (double e : data.restitution) sum += (e - mean) * (e - mean);
  CHECK(fit.rms_residual == Approx(std::sqrt(sum / 4.0)).epsilon(1e-6));
  CHECK(fit.model->restitution(3.0) == Approx(mean).margin(1e-9));
}

TEST_CASE("the linear fit is ordinary least squares when the line stays inside the valid range",
          "[formulas][cor]") {
  // Reference: the normal equations of ε = ε₀ − k v, solved in closed form here.
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.005);
  pf::ImpactData data;
  for (int i = 0; i < 30; ++i) {
    const double v = 0.05 + 0.1 * i;
    data.speed_m_s.push_back(v);
    data.restitution.push_back(0.85 - 0.03 * v + noise(rng));
  }
  double sv = 0, se = 0, svv = 0, sve = 0;
  const double n = 30.0;
  for (int i = 0; i < 30; ++i) {
    sv += data.speed_m_s[i];
    se += data.restitution[i];
    svv += data.speed_m_s[i] * data.speed_m_s[i];
    sve += data.speed_m_s[i] * data.restitution[i];
  }
  const double slope = (n * sve - sv * se) / (n * svv - sv * sv);  // dε/dv = −k
  const double intercept = (se - slope * sv) / n;
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kLinear);
  // SLSQP on a quadratic converges to the optimum; 1e-8 is far above its xtol.
  CHECK(fit.coefficients.at(0) == Approx(intercept).margin(1e-8));
  CHECK(fit.coefficients.at(1) == Approx(-slope).margin(1e-8));
  // Recovery of the generating line: 3σ of the OLS estimates (σ_k ≈ 0.005/(√30·0.87) ≈ 1e-3).
  CHECK(fit.coefficients.at(1) == Approx(0.03).margin(3e-3));
  CHECK(fit.rms_residual == Approx(0.005).epsilon(0.4));  // sample std of 30 normals: ±13% (1σ)
}

TEST_CASE("the linear fit keeps the line at or below 1 at zero speed", "[formulas][cor]") {
  // Unconstrained OLS would give ε₀ = 1.018 here. With ε₀ held at its bound 1 the
  // best k is Σ(1 − ε_i)v_i / Σv_i² (closed form, the constrained optimum).
  const pf::ImpactData data{{0.1, 0.5, 1.0}, {1.0, 0.9, 0.8}};
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kLinear);
  const double k = (0.0 * 0.1 + 0.1 * 0.5 + 0.2 * 1.0) / (0.01 + 0.25 + 1.0);
  CHECK(fit.coefficients.at(0) == Approx(1.0).margin(1e-9));
  CHECK(fit.coefficients.at(1) == Approx(k).margin(1e-8));
}

TEST_CASE("the Thornton fit recovers p_y from noise-free data", "[formulas][cor]") {
  const double pressure = 1.3e9;
  const auto truth =
      pf::make_thornton_restitution(pressure, kSteelPairModulus, kSphereRadius, kSphereMass);
  pf::ImpactData data;
  for (int i = 0; i < 25; ++i) {
    const double v = 0.02 * std::pow(200.0, i / 24.0);  // 0.02 .. 4 m/s, across v_y = 0.081 m/s
    data.speed_m_s.push_back(v);
    data.restitution.push_back(truth->restitution(v));
  }
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kThornton,
                                                     kSteelPairModulus, kSphereRadius, kSphereMass);
  // Exact data: only the optimiser's tolerance (xtol 1e-12 on ln p_y) limits it.
  CHECK(fit.coefficients.at(0) == Approx(pressure).epsilon(1e-6));
  CHECK(fit.rms_residual < 1e-7);
}

TEST_CASE("the Thornton fit recovers p_y from noisy synthetic data within its standard error",
          "[formulas][cor]") {
  const double pressure = 0.8e9, sigma = 0.005;
  std::mt19937 rng(2024);
  std::normal_distribution<double> noise(0.0, sigma);
  pf::ImpactData data;
  for (int i = 0; i < 60; ++i) {
    const double v = 0.05 * std::pow(60.0, i / 59.0);  // 0.05 .. 3 m/s, v_y = 0.024 m/s
    const double r = pf::yield_speed(pressure, kSteelPairModulus, kSphereRadius, kSphereMass) / v;
    data.speed_m_s.push_back(v);
    data.restitution.push_back(std::min(1.0, thornton_paper(r) + noise(rng)));
  }
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kThornton,
                                                     kSteelPairModulus, kSphereRadius, kSphereMass);
  const double standard_error =
      thornton_log_pressure_standard_error(data.speed_m_s, pressure, sigma);
  // 4 standard errors: a false failure has probability 6e-5.
  CHECK(std::abs(std::log(fit.coefficients.at(0) / pressure)) < 4.0 * standard_error);
  CHECK(fit.rms_residual == Approx(sigma).epsilon(0.35));  // 60 normals: ±9% (1σ)
}

TEST_CASE("the Thornton fit of the shipped CSV recovers the generating p_y", "[formulas][cor]") {
  // The file was generated from p_y = 1.0 GPa with Gaussian noise σ = 0.01 (its header).
  const pf::ImpactData data = pf::read_impact_csv(data_path("cor_impacts_synthetic_thornton.csv"));
  const pf::RestitutionFit fit = pf::fit_restitution(data, pf::RestitutionLaw::kThornton,
                                                     kSteelPairModulus, kSphereRadius, kSphereMass);
  const double standard_error = thornton_log_pressure_standard_error(data.speed_m_s, 1e9, 0.01);
  CHECK(std::abs(std::log(fit.coefficients.at(0) / 1e9)) < 4.0 * standard_error);
  CHECK(fit.rms_residual == Approx(0.01).epsilon(0.35));  // 40 normals: ±11% (1σ)
  CHECK(fit.points == 40);
  CHECK_THAT(fit.model->describe(), Contains("Thornton"));
  // The digressive decay is not a line: the linear law fits clearly worse.
  const pf::RestitutionFit line = pf::fit_restitution(data, pf::RestitutionLaw::kLinear);
  CHECK(line.rms_residual > 2.0 * fit.rms_residual);
}

TEST_CASE("fits reject bad data and missing contact parameters", "[formulas][cor]") {
  const pf::ImpactData unequal{{0.1, 0.2}, {0.9}};
  CHECK_THROWS_WITH(pf::fit_restitution(unequal, pf::RestitutionLaw::kConstant),
                    Contains("must be equal"));
  const pf::ImpactData empty{};
  CHECK_THROWS_WITH(pf::fit_restitution(empty, pf::RestitutionLaw::kConstant),
                    Contains("no points"));
  const pf::ImpactData bad{{0.1, 0.2}, {0.9, 1.5}};
  CHECK_THROWS_WITH(pf::fit_restitution(bad, pf::RestitutionLaw::kConstant),
                    Contains("restitution[1] = 1.5: must be in (0, 1]"));
  const pf::ImpactData one_speed{{0.3, 0.3}, {0.9, 0.8}};
  CHECK_THROWS_WITH(pf::fit_restitution(one_speed, pf::RestitutionLaw::kLinear),
                    Contains("distinct speeds"));
  const pf::ImpactData good{{0.1, 0.2}, {0.9, 0.8}};
  CHECK_THROWS_WITH(pf::fit_restitution(good, pf::RestitutionLaw::kThornton),
                    Contains("effective_modulus_pa = 0"));
  const pf::ImpactData at_rest{{0.0, 0.0}, {1.0, 1.0}};
  CHECK_THROWS_AS(pf::fit_restitution(at_rest, pf::RestitutionLaw::kThornton, 1e11, 0.01, 0.01),
                  std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Hertz damping calibration.

TEST_CASE("realised restitution matches an independent RK4 integration in t^(1/4)",
          "[formulas][cor]") {
  // Reference: rebound_speed() above (RK4 in τ, 4000 steps per unit τ). Its error,
  // from halving the step (h⁴ convergence), is < 3e-11 for these γ; the promise is 1e-10.
  for (double damping : {0.01, 0.3, 1.0, 3.0, 10.6}) {
    CAPTURE(damping);
    CHECK(pf::realised_restitution(damping) ==
          Approx(dimensionless_rebound(damping)).margin(1e-10));
  }
}

TEST_CASE("realised restitution is 1 undamped and falls with slope pi/sqrt(5) at small damping",
          "[formulas][cor]") {
  // Reference: first-order perturbation of the elastic orbit x'² = 1 − (4/5)x^{5/2},
  // x_max = (5/4)^{2/5}. The energy lost is
  //   ΔE = γ∫x^{1/4}x'²dt = 2γ∫₀^{x_max} x^{1/4}(1 − (4/5)x^{5/2})^{1/2} dx
  //      = 2γ·x_max^{5/4}·∫₀¹ u^{1/4}(1 − u^{5/2})^{1/2} du = 2γ·(√5/2)·(2/5)B(1/2, 3/2)
  //      = γπ/√5,
  // and ε² = 1 − 2ΔE, so ε = 1 − (π/√5)γ + O(γ²). The O(γ²) term is ~1.3γ²: at
  // γ = 1e-4 the slope is within 1e-4 relative; tolerance 1e-3.
  CHECK(pf::realised_restitution(0.0) == 1.0);
  const double gamma = 1e-4;
  CHECK((1.0 - pf::realised_restitution(gamma)) / gamma ==
        Approx(pi / std::sqrt(5.0)).epsilon(1e-3));
  CHECK_THROWS_WITH(pf::realised_restitution(-0.1), Contains("damping_coefficient = -0.1"));
  CHECK_THROWS_AS(pf::realised_restitution(INFINITY), std::invalid_argument);
  CHECK_THROWS_WITH(pf::realised_restitution(101.0), Contains("must be in [0, 100]"));
}

TEST_CASE("realised restitution tends to 5/(4 gamma^2) at heavy damping", "[formulas][cor]") {
  // Reference (overdamped asymptote): loading x'' ≈ −γx^{1/4}x' integrates to
  // x' = 1 − (4/5)γx^{5/4}, so the overlap stops at x_m^{5/4} = 5/(4γ); the return then
  // creeps with the force balance x^{3/2} = −γx^{1/4}x', i.e. x' = −x_m^{5/4}/γ, and the
  // contact ends there: ε → 5/(4γ²). Corrections are O(γ^{-2/5})-relative and smaller:
  // 0.2% at γ = 100 (measured), tolerance 0.5%.
  const double gamma = pf::kMaxDampingCoefficient;
  CHECK(pf::realised_restitution(gamma) * gamma * gamma == Approx(1.25).epsilon(5e-3));
}

TEST_CASE("the textbook damping law realises about 0.40 for a target 0.3 without tension",
          "[formulas][cor]") {
  // docs/theory.md §6: γ_n = −√5·β reaches ε only if the contact ends at zero overlap
  // (tension allowed); ending at zero force gives about 0.40 for a target 0.3.
  for (double target : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    CAPTURE(target);
    const double gamma = -std::sqrt(5.0) * textbook_beta(target);
    // Reference for the zero-overlap end: the test's own RK4, ending at x = 0. The
    // textbook law is itself an approximation there (to ~5e-7, measured): 1e-5.
    auto acceleration = [&](double x, double v) {
      const double quarter = std::sqrt(std::sqrt(std::abs(x)));
      return -x * quarter * quarter - gamma * quarter * v;
    };
    const double with_tension = rebound_speed(
        acceleration, [](double x, double) { return x; }, 1.0, 1.0, 4000);
    CHECK(with_tension == Approx(target).margin(1e-5));
    CHECK(pf::realised_restitution(gamma) > target);
  }
  CHECK(pf::realised_restitution(-std::sqrt(5.0) * textbook_beta(0.3)) ==
        Approx(0.40).margin(0.005));
}

TEST_CASE("damping_for_restitution inverts the realised restitution to 1e-9", "[formulas][cor]") {
  for (double target :
       {pf::kMinCalibratedRestitution, 0.01, 0.05, 0.2, 0.3, 0.5, 0.8, 0.95, 0.999, 1.0 - 1e-9}) {
    CAPTURE(target);
    const double gamma = pf::damping_for_restitution(target);
    // The forward map is checked against an independent integration above.
    CHECK(std::abs(pf::realised_restitution(gamma) - target) < 1e-9);
  }
  CHECK(pf::damping_for_restitution(1.0) == 0.0);
  CHECK_THROWS_WITH(pf::damping_for_restitution(0.0),
                    Contains("restitution = 0: must be in [0.001, 1]"));
  CHECK_THROWS_AS(pf::damping_for_restitution(5e-4), std::invalid_argument);
  CHECK_THROWS_AS(pf::damping_for_restitution(1.5), std::invalid_argument);
  CHECK_THROWS_AS(pf::damping_for_restitution(std::nan("")), std::invalid_argument);
}

TEST_CASE("the damping table realises every restitution from 0.01 to 1 within 1e-5",
          "[formulas][cor]") {
  // Linear interpolation of γ(ε) on a uniform grid (h = 4.95e-4): the error in ε is
  // ≈ (h²/8)·|γ''/γ'| ≈ (h²/8)·3/(2ε) (γ ≈ 1.1 ε^{-1/2} at small ε), 4.6e-6 at ε = 0.01.
  // Checked on the grid nodes and the midpoints, where interpolation is worst.
  const pf::DampingTable table;
  constexpr int kChecks = 2 * (pf::DampingTable::kPoints - 1);
  double worst = 0.0;
  for (int i = 0; i <= kChecks; ++i) {
    const double target = 0.01 + 0.99 * i / kChecks;
    worst = std::max(
        worst, std::abs(pf::realised_restitution(table.damping_for_restitution(target)) - target));
  }
  CHECK(worst < 1e-5);
  CHECK(table.damping_for_restitution(1.0) == 0.0);
  CHECK_THROWS_WITH(table.damping_for_restitution(0.005),
                    Contains("restitution = 0.005: must be in [0.01, 1]"));
  CHECK_THROWS_AS(table.damping_for_restitution(1.0001), std::invalid_argument);
  CHECK_THROWS_AS(table.damping_for_restitution(std::nan("")), std::invalid_argument);
}

TEST_CASE(
    "a steel sphere hitting a rigid wall rebounds with the calibrated restitution at any speed",
    "[formulas][cor]") {
  // Reference: the dimensional contact m*δ'' = −Kδ^{3/2} − γ_n√(m*K)δ^{1/4}δ' (K = (4/3)E*√R*,
  // sphere r = 5 mm on a rigid wall: E* = E/(1−ν²), R* = r, m* = m), integrated in SI
  // units by the test's RK4 to zero total force. It checks the scaling to the
  // dimensionless problem (ε independent of speed, mass and stiffness).
  const double modulus = kSteelModulus / (1.0 - kSteelPoisson * kSteelPoisson);
  const double stiffness = 4.0 / 3.0 * modulus * std::sqrt(kSphereRadius);
  const pf::DampingTable table;
  for (double target : {0.3, 0.7}) {
    CAPTURE(target);
    const double accurate = pf::damping_for_restitution(target);
    const double tabulated = table.damping_for_restitution(target);
    std::vector<double> rebound_accurate;
    for (double speed : {0.1, 2.0}) {
      CAPTURE(speed);
      // Time scale of the contact: docs/theory.md §5, t_c ≈ 2.87(m*²/(R*E*²v))^{1/5}.
      const double time_scale =
          2.87 *
          std::pow(kSphereMass * kSphereMass / (kSphereRadius * modulus * modulus * speed), 0.2);
      auto rebound = [&](double gamma) {
        const double viscous = gamma * std::sqrt(kSphereMass * stiffness);
        auto acceleration = [&](double x, double v) {
          const double quarter = std::sqrt(std::sqrt(std::abs(x)));
          return -(stiffness * x * quarter * quarter + viscous * quarter * v) / kSphereMass;
        };
        auto force_over_quarter = [&](double x, double v) {
          return stiffness * x * std::sqrt(std::sqrt(std::abs(x))) + viscous * v;
        };
        return rebound_speed(acceleration, force_over_quarter, speed, time_scale, 4000) / speed;
      };
      // RK4 error ~1e-11 (as in the dimensionless check): 1e-8 against the 1e-9 inverse.
      rebound_accurate.push_back(rebound(accurate));
      CHECK(rebound_accurate.back() == Approx(target).margin(1e-8));
      // The table promises 1e-5.
      CHECK(rebound(tabulated) == Approx(target).margin(1e-5));
    }
    // Speed independence, to the integrator's error.
    CHECK(rebound_accurate[0] == Approx(rebound_accurate[1]).margin(1e-9));
  }
}
