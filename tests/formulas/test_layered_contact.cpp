// Tests of the bonded-layer contact law: kernel, exact (Nyström) solution, its limits, the table, impacts.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "pdamp/formulas/layered_contact.hpp"

namespace {

namespace fm = pdamp::formulas;

constexpr double kInf = std::numeric_limits<double>::infinity();

// Independent derivation of the kernel: Love's strain function φ = f(z) J₀(ξr),
// f = (A + Bz)e^{z} + (C + Dz)e^{−z} (ξ = 1, layer 0 <= z <= u), with
//   σ_z = (1−ν)f''' − (2−ν)f',  τ_rz ∝ νf'' + (1−ν)f,
//   2G u_z = (1−2ν)f'' − 2(1−ν)f,  2G u_r ∝ f'
// (Timoshenko & Goodier §139); σ_z(0) = −1, τ(0) = 0, u_r(u) = u_z(u) = 0, solved as a
// 4×4 linear system; L = G u_z(0)/(1 − ν) (the half-space value is (1 − ν)/G).
double kernel_from_boundary_value_problem(double u, double nu) {
  auto basis = [](double z, int d, std::array<double, 4>& b) {
    const double e = std::exp(z), m = std::exp(-z), sign = d % 2 ? -1.0 : 1.0;
    b = {e, (z + d) * e, sign * m, sign * (z - d) * m};
  };
  std::array<std::array<double, 5>, 4> a{};
  std::array<double, 4> b0, b1, b2, b3;
  basis(0.0, 0, b0);
  basis(0.0, 1, b1);
  basis(0.0, 2, b2);
  basis(0.0, 3, b3);
  for (int j = 0; j < 4; ++j) {
    a[0][j] = (1 - nu) * b3[j] - (2 - nu) * b1[j];
    a[1][j] = nu * b2[j] + (1 - nu) * b0[j];
  }
  a[0][4] = -1.0;
  const std::array<double, 4> surface = [&] {
    std::array<double, 4> s;
    for (int j = 0; j < 4; ++j) s[j] = (1 - 2 * nu) * b2[j] - 2 * (1 - nu) * b0[j];
    return s;
  }();
  basis(u, 0, b0);
  basis(u, 1, b1);
  basis(u, 2, b2);
  for (int j = 0; j < 4; ++j) {
    a[2][j] = b1[j];
    a[3][j] = (1 - 2 * nu) * b2[j] - 2 * (1 - nu) * b0[j];
  }
  for (int c = 0; c < 4; ++c) {
    int p = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
    std::swap(a[c], a[p]);
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = a[r][c] / a[c][c];
      for (int k = 0; k < 5; ++k) a[r][k] -= f * a[c][k];
    }
  }
  double uz = 0.0;
  for (int j = 0; j < 4; ++j) uz += a[j][4] / a[j][j] * surface[j];
  return uz / (2.0 * (1.0 - nu));
}

double overlap_of(const fm::LayerIndentation& s, double thickness, double radius) {
  return s.overlap_parameter * s.overlap_parameter * thickness * thickness / radius;
}

}  // namespace

TEST_CASE("the bonded-layer kernel equals the layer's boundary-value solution", "[formulas]") {
  // Reference: the 4x4 Love-function solve above (an independent derivation). The closed
  // form agrees to rounding: 1e-10 relative (the 4x4 elimination carries e^{±u} terms).
  for (double nu : {0.0, 0.3, 0.45, 0.49, 0.5}) {
    for (double u : {0.01, 0.1, 0.5, 1.0, 2.0, 5.0, 12.0}) {
      INFO("nu = " << nu << ", u = " << u);
      CHECK(fm::bonded_layer_kernel(u, nu) ==
            Approx(kernel_from_boundary_value_problem(u, nu)).epsilon(1e-9));
      CHECK(fm::bonded_layer_kernel_complement(u, nu) ==
            Approx(1.0 - kernel_from_boundary_value_problem(u, nu)).epsilon(1e-8).margin(1e-12));
    }
    CHECK(fm::bonded_layer_kernel(60.0, nu) == Approx(1.0).epsilon(1e-15));
    CHECK(std::isfinite(fm::bonded_layer_kernel(1e4, nu)));
  }
}

TEST_CASE("the thin-layer expansion of the kernel gives the constrained and squeeze moduli", "[formulas]") {
  for (double nu : {0.3, 0.45, 0.49, 0.5}) {
    const fm::ThinLayerModuli m = fm::thin_layer_moduli(1.0, nu, 1.0);
    // Reference: the kernel itself at small u; the next term is O(u⁵): at u = 1e-2 the
    // remainders of (L − c₃u³)/u and (L − c₁u)/u³ are c₅u⁴ (|c₅| ≈ 1.2 at ν = 0.5) and O(u²).
    const double u = 1e-2;
    const double l = fm::bonded_layer_kernel(u, nu);
    CHECK((l - m.cubic_coefficient * u * u * u) / u == Approx(m.linear_coefficient).epsilon(1e-6).margin(3e-8));
    CHECK((l - m.linear_coefficient * u) / (u * u * u) == Approx(m.cubic_coefficient).epsilon(1e-3));
    if (nu < 0.5) {
      // M = E(1−ν)/((1+ν)(1−2ν)) by hand.
      CHECK(m.constrained_modulus_pa == Approx((1 - nu) / ((1 + nu) * (1 - 2 * nu))).epsilon(1e-14));
    } else {
      CHECK(std::isinf(m.constrained_modulus_pa));
      CHECK(m.cubic_coefficient == Approx(2.0 / 3.0).epsilon(1e-14));
      CHECK(m.squeeze_modulus_pa == Approx(1.0).epsilon(1e-14));  // E₃ = E: the lubrication result
    }
  }
}

TEST_CASE("the exact layered solution is converged in its quadrature", "[formulas]") {
  // Reference: the same solve with twice the nodes. Observed differences 1e-9 (small a/t)
  // to 3e-7 (a/t = 34, ν = 0.5); tolerance 1e-6.
  for (double nu : {0.3, 0.45, 0.49, 0.5}) {
    for (double lambda : {0.5, 3.0, 12.0, 34.0}) {
      const auto coarse = fm::solve_layer_indentation(lambda, nu);
      const auto fine = fm::solve_layer_indentation(lambda, nu, 1.0, 2 * (24 + static_cast<int>(7 * lambda)) + 2);
      INFO("nu = " << nu << ", a/t = " << lambda);
      CHECK(coarse.force_over_hertz == Approx(fine.force_over_hertz).epsilon(1e-6));
      CHECK(coarse.overlap_over_hertz == Approx(fine.overlap_over_hertz).epsilon(1e-6));
    }
  }
}

TEST_CASE("a thick layer is a Hertz half-space", "[formulas]") {
  // Reference: Hertz (a/t -> 0): g = Rδ/a² = 1 and F/F_H = 1 at a/t = 0 exactly; the
  // first correction is linear in χ: at χ = 1e-3 the ratio is within 1.2e-3 of 1.
  for (double nu : {0.3, 0.45, 0.49, 0.5}) {
    const auto zero = fm::solve_layer_indentation(0.0, nu);
    CHECK(zero.force_over_hertz == 1.0);
    const auto s = fm::solve_layer_indentation(1e-3, nu);
    CHECK(s.force_over_hertz == Approx(1.0).epsilon(1.2e-3));
    CHECK(s.overlap_over_hertz == Approx(1.0).epsilon(1e-3));
    // Second order, derived in the docs: with β = slope·χ the exact expansion is
    // G = 1 + β + (7/6)β² + O(χ³). Slope from χ = 1e-4 (its own O(χ) error 1e-4),
    // check at χ ≈ 0.01: the O(χ³) remainder ~1e-6, tolerance 5e-6 absolute.
    const auto tiny = fm::solve_layer_indentation(1e-4, nu);
    const double slope = (tiny.force_over_hertz - 1.0) / tiny.overlap_parameter;
    const auto small = fm::solve_layer_indentation(1e-2, nu);
    const double beta = slope * small.overlap_parameter;
    CHECK(small.force_over_hertz == Approx(1.0 + beta + 7.0 / 6.0 * beta * beta).margin(5e-6));
  }
}

TEST_CASE("the exact layered solution agrees with Dimitriadis et al. (2002) for small chi", "[formulas]") {
  // Reference: Dimitriadis et al. 2002 (Biophys. J. 82:2798), bonded sample. Their first-order
  // coefficient −2α₀/π is a quadratic fit in ν to 4 digits: the exact slope agrees within 0.5%.
  // Their χ² coefficient (2α₀/π)² differs from the exact (7/6)(2α₀/π)² (docs), so the series
  // departs by ~(1/6)β²: within 1% at χ <= 0.2 (observed 0.5–0.9%), not beyond.
  for (double nu : {0.3, 0.45, 0.49}) {
    const auto tiny = fm::solve_layer_indentation(1e-3, nu);
    const double slope = (tiny.force_over_hertz - 1.0) / tiny.overlap_parameter;
    const double alpha = -(1.2876 - 1.4678 * nu + 1.3442 * nu * nu) / (1.0 - nu);
    CHECK(slope == Approx(-2.0 * alpha / 3.14159265358979323846).epsilon(5e-3));
    for (double lambda : {0.05, 0.1, 0.2}) {
      const auto s = fm::solve_layer_indentation(lambda, nu);
      INFO("nu = " << nu << ", chi = " << s.overlap_parameter);
      CHECK(s.force_over_hertz == Approx(fm::dimitriadis_force_ratio(s.overlap_parameter, nu)).epsilon(0.01));
    }
  }
}

TEST_CASE("a thin compressible layer is an elastic foundation of the constrained modulus", "[formulas]") {
  // Reference: foundation p = M(δ − r²/2R)/t, F = πMRδ²/t, a² = 2Rδ. The exact solution's
  // edge zone of width ~t gives an O((t/a)²) correction at ν = 0.3: observed 0.6% at
  // a/t = 5, 0.2% at 10, 0.02% at 34; tolerances 1%, 0.3%, 0.05%.
  const double radius = 1.0, thickness = 1.0, modulus = 1.0, nu = 0.3;
  const std::array<std::pair<double, double>, 3> cases{{{5.0, 0.01}, {10.0, 3e-3}, {34.0, 5e-4}}};
  for (const auto& [lambda, tolerance] : cases) {
    const auto s = fm::solve_layer_indentation(lambda, nu);
    const double delta = overlap_of(s, thickness, radius);
    const double hertz = 4.0 / 3.0 * modulus / (1 - nu * nu) * std::sqrt(radius) * std::pow(delta, 1.5);
    INFO("a/t = " << lambda);
    CHECK(s.force_over_hertz * hertz ==
          Approx(fm::foundation_force(delta, radius, modulus, nu, thickness)).epsilon(tolerance));
  }
  // At ν = 0.45 and 0.49 the foundation is the a/ℓ -> ∞ limit only: a/t = 60 gives
  // a/ℓ = 41 and 16, exact/foundation = 0.998 and 0.983 (the squeeze correction ~2ℓ/a... docs).
  for (const auto& [nu2, tolerance] : std::array<std::pair<double, double>, 2>{{{0.45, 5e-3}, {0.49, 0.025}}}) {
    const auto s = fm::solve_layer_indentation(60.0, nu2);
    const double delta = overlap_of(s, thickness, radius);
    const double hertz = 4.0 / 3.0 * modulus / (1 - nu2 * nu2) * std::sqrt(radius) * std::pow(delta, 1.5);
    CHECK(s.force_over_hertz * hertz ==
          Approx(fm::foundation_force(delta, radius, modulus, nu2, thickness)).epsilon(tolerance));
  }
}

TEST_CASE("a thin incompressible layer follows the squeeze-film law", "[formulas]") {
  // Reference: ν = 0.5, thin-film equation −(t³/E)∇²p = δ − r²/2R with p(a) = p'(a) = 0:
  // p = E(a² − r²)²/(32Rt³), a² = 4Rδ, F = (2π/3)ER²δ³/t³. Edge correction O(t/a):
  // exact/thin observed 1.043 (a/t = 20), 1.016 (34), 1.0055 (60): tolerances 5%, 2%, 0.7%.
  const double radius = 1.0, thickness = 1.0, modulus = 1.0;
  for (const auto& [lambda, tolerance] :
       std::array<std::pair<double, double>, 3>{{{20.0, 0.05}, {34.0, 0.02}, {60.0, 7e-3}}}) {
    const auto s = fm::solve_layer_indentation(lambda, 0.5);
    const double delta = overlap_of(s, thickness, radius);
    const double hertz = 16.0 / 9.0 * modulus * std::sqrt(radius) * std::pow(delta, 1.5);
    INFO("a/t = " << lambda);
    CHECK(s.force_over_hertz * hertz ==
          Approx(fm::incompressible_thin_layer_force(delta, radius, modulus, thickness)).epsilon(tolerance));
    // Contact radius: a² = 4Rδ, i.e. g = Rδ/a² -> 1/4, O(t/a): observed 0.67–0.71 t/a.
    CHECK(s.overlap_over_hertz == Approx(0.25).margin(0.8 / lambda));
  }
}

TEST_CASE("the thin-layer law bridges the compressible and incompressible limits at nu near 0.5", "[formulas]") {
  // Reference: the exact solution. The thin-layer closed form (x = a/ℓ, ℓ = t√(c₃/c₁) ≈
  // t/√(3(1−2ν))) holds for a ≫ t whatever a/ℓ: its error is the O((t/a)²) edge zone
  // (ν = 0.3, 0.45, 0.49 at a/t = 34: observed 3e-5, 2e-4, 1.1e-3) and O(t/a) as ν -> 0.5
  // (6e-3 at ν = 0.499, 0.016 at 0.5). Tolerances about twice those.
  const double radius = 1.0, thickness = 1.0, modulus = 1.0;
  for (const auto& [nu, tolerance] : std::array<std::pair<double, double>, 5>{
           {{0.3, 1e-4}, {0.45, 5e-4}, {0.49, 2.5e-3}, {0.499, 0.012}, {0.5, 0.03}}}) {
    const auto s = fm::solve_layer_indentation(34.0, nu);
    const double delta = overlap_of(s, thickness, radius);
    const double hertz = 4.0 / 3.0 * modulus / (1 - nu * nu) * std::sqrt(radius) * std::pow(delta, 1.5);
    // The thin-layer contact radius at this δ (δ(a) increasing: bisection).
    double lo = 1e-6, hi = 200.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (fm::thin_layer_indentation(mid, radius, modulus, nu, thickness).overlap_m > delta ? hi : lo) = mid;
    }
    INFO("nu = " << nu);
    CHECK(s.force_over_hertz * hertz ==
          Approx(fm::thin_layer_indentation(lo, radius, modulus, nu, thickness).force_n).epsilon(tolerance));
  }
  // The closed form's limits (exact algebra, rounding only).
  const double a = 40.0;
  const auto incompressible = fm::thin_layer_indentation(a, radius, modulus, 0.5, thickness);
  CHECK(incompressible.overlap_m == Approx(a * a / (4 * radius)).epsilon(1e-14));
  CHECK(incompressible.force_n ==
        Approx(fm::incompressible_thin_layer_force(incompressible.overlap_m, radius, modulus, thickness))
            .epsilon(1e-13));
  const auto compressible = fm::thin_layer_indentation(1e5, radius, modulus, 0.3, thickness);
  CHECK(compressible.force_n ==
        Approx(fm::foundation_force(compressible.overlap_m, radius, modulus, 0.3, thickness)).epsilon(1e-4));
}

TEST_CASE("LayeredContact interpolates the exact solution and keeps force, stiffness and energy consistent",
          "[formulas]") {
  const double radius = 0.0025, thickness = 1e-4, modulus = 60e6;
  for (double nu : {0.3, 0.45, 0.49, 0.5}) {
    const fm::LayeredContact c(radius, modulus, nu, kInf, 0.3, thickness);
    CHECK(c.effective_modulus_pa() == Approx(modulus / (1 - nu * nu)).epsilon(1e-15));
    // Reference: direct solves at a/t between the table's nodes. Interpolation error
    // (two cubic stages) observed < 2e-6; tolerance 1e-5.
    for (double lambda : {0.37, 2.13, 7.71, 19.3, 30.1}) {
      const auto s = fm::solve_layer_indentation(lambda, nu);
      const double delta = overlap_of(s, thickness, radius);
      if (s.overlap_parameter > fm::LayeredContact::kMaxTabulatedOverlapParameter) continue;
      const double hertz = 4.0 / 3.0 * c.effective_modulus_pa() * std::sqrt(radius) * std::pow(delta, 1.5);
      INFO("nu = " << nu << ", a/t = " << lambda);
      CHECK(c.force(delta) == Approx(s.force_over_hertz * hertz).epsilon(1e-5));
      CHECK(c.contact_radius(delta) == Approx(lambda * thickness).epsilon(1e-5));
    }
    // Stiffness against a central difference of the force (h = 1e-5 δ: truncation
    // 1e-10, rounding 1e-11); energy against 64-point Gauss of the force (exact to
    // rounding for the smooth integrand in √δ: substitution δ = s², s uniform).
    for (double delta : {0.02 * thickness, 0.5 * thickness, thickness, 3.0 * thickness, 300.0 * thickness}) {
      const double h = 1e-5 * delta;
      INFO("nu = " << nu << ", delta/t = " << delta / thickness);
      CHECK(c.stiffness(delta) == Approx((c.force(delta + h) - c.force(delta - h)) / (2 * h)).epsilon(1e-6));
      double energy = 0.0;
      const int panels = 400;
      for (int p = 0; p < panels; ++p) {  // Simpson in s = √δ on 400 panels
        const double s0 = std::sqrt(delta) * p / panels, s1 = std::sqrt(delta) * (p + 1) / panels;
        const double sm = 0.5 * (s0 + s1);
        energy += (s1 - s0) / 6.0 *
                  (2 * s0 * c.force(s0 * s0) + 4 * 2 * sm * c.force(sm * sm) + 2 * s1 * c.force(s1 * s1));
      }
      CHECK(c.energy(delta) == Approx(energy).epsilon(2e-6));
    }
    // Continuity at the end of the table (power-law continuation): value and slope.
    const double end = fm::LayeredContact::kMaxTabulatedOverlapParameter;
    CHECK(c.force_over_hertz(end * (1 + 1e-9)) == Approx(c.force_over_hertz(end * (1 - 1e-9))).epsilon(1e-7));
    CHECK(c.force(0.0) == 0.0);
    CHECK(c.force(-1.0) == 0.0);
    CHECK(c.energy(0.0) == 0.0);
    CHECK(c.stiffness(0.0) == 0.0);
  }
}

TEST_CASE("an elastic sphere adds its half-space compliance to the layer's", "[formulas]") {
  // Reference: for a/t -> 0 the law is Hertz with E* from both materials (exact by the
  // construction of the kernel); for a thin layer the sphere's compliance softens it:
  // rigid sphere > elastic sphere > Hertz with the combined E*.
  const double radius = 0.0025, thickness = 1e-4;
  const fm::LayeredContact equal(radius, 60e6, 0.45, 60e6, 0.45, thickness);
  const fm::LayeredContact rigid(radius, 60e6, 0.45, kInf, 0.3, thickness);
  CHECK(equal.effective_modulus_pa() == Approx(0.5 * 60e6 / (1 - 0.45 * 0.45)).epsilon(1e-14));
  CHECK(equal.force_over_hertz(1e-9) == Approx(1.0).epsilon(1e-6));
  const double delta = 0.5 * thickness;
  const double hertz = 4.0 / 3.0 * equal.effective_modulus_pa() * std::sqrt(radius) * std::pow(delta, 1.5);
  CHECK(equal.force(delta) > hertz);
  CHECK(equal.force(delta) < rigid.force(delta));
  // Steel on polyurethane: the sphere carries 3.3e-4 of the half-space compliance, but the
  // thin layer is G ≈ 15 times stiffer than the half-space here, so the sphere's share
  // of the compliance is ≈ 15 × 3.3e-4 = 0.5%: softer than the rigid sphere by 0.2–1.5%.
  const fm::LayeredContact steel(radius, 60e6, 0.45, 210e9, 0.3, thickness);
  const double softening = 1.0 - steel.force(delta) / rigid.force(delta);
  CHECK(softening > 2e-3);
  CHECK(softening < 1.5e-2);
}

TEST_CASE("the layered impact reduces to Hertz on a thick layer", "[formulas]") {
  // Reference: the Hertz closed forms (hertz_impact.hpp). A layer 1000x the Hertz
  // penetration has χ ~ 1e-3·√(R/δ): F within ~0.3% of Hertz, δ_max and t_c within 0.2%.
  const double radius = 0.0025, mass = 20 * 7850 * 4.0 / 3.0 * 3.14159265358979 * std::pow(radius, 3);
  const fm::Material steel;
  const fm::Material layer{1200, 60e6, 0.45};
  const fm::HertzContact hertz = fm::sphere_wall_contact(radius, mass, steel, layer);
  const double v = 0.52;
  const double delta_h = fm::max_penetration(hertz, v);
  const fm::LayeredContact thick(radius, 60e6, 0.45, 210e9, 0.3, 1e3 * delta_h);
  const auto impact = fm::layered_impact(thick, mass, v);
  CHECK(impact.max_overlap_m == Approx(delta_h).epsilon(2e-3));
  CHECK(impact.contact_time_s == Approx(fm::contact_time(hertz, v)).epsilon(2e-3));
  // Energy balance at the turning point (bisection to 1e-15 relative).
  CHECK(thick.energy(impact.max_overlap_m) == Approx(0.5 * mass * v * v).epsilon(1e-12));
}

TEST_CASE("the layered impact's contact time matches an integration of the impact", "[formulas]") {
  // Reference: RK4 of m δ'' = −F(δ) written here (step t_c/20000; the contact ends at
  // δ = 0, linear interpolation). Agreement observed 1e-7; tolerance 1e-5 (the quadrature's
  // Hertz-like start, docs).
  const double radius = 0.0025, mass = 0.01, v = 0.5;
  for (double nu : {0.3, 0.49, 0.5}) {
    const fm::LayeredContact c(radius, 60e6, nu, 210e9, 0.3, 1e-4);
    const auto impact = fm::layered_impact(c, mass, v);
    const double h = impact.contact_time_s / 20000;
    double x = 0.0, u = v, time = 0.0, peak = 0.0;
    auto acc = [&](double xx) { return -c.force(xx) / mass; };
    while (true) {
      const double k1x = u, k1v = acc(x);
      const double k2x = u + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x);
      const double k3x = u + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x);
      const double k4x = u + h * k3v, k4v = acc(x + h * k3x);
      const double nx = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      const double nu_ = u + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      if (nx <= 0.0 && time > 0.0) {
        time += h * x / (x - nx);
        break;
      }
      x = nx;
      u = nu_;
      time += h;
      peak = std::max(peak, x);
    }
    INFO("nu = " << nu);
    CHECK(impact.contact_time_s == Approx(time).epsilon(1e-5));
    CHECK(impact.max_overlap_m == Approx(peak).epsilon(1e-6));
  }
}

TEST_CASE("the layered damping reduces to the calibrated Hertz damping on a thick layer", "[formulas]") {
  // Reference: formulas::realised_restitution (the Hertz one-collision solve, 1e-10).
  // With t ≫ δ the layered law is Hertz to ~0.3% in force; the restitution, which depends
  // on the law's shape, within 2e-3. The elastic collision returns ε = 1 (RK4 to 1e-6).
  const double radius = 0.0025, mass = 0.01, v = 0.5;
  const fm::LayeredContact thick(radius, 60e6, 0.45, kInf, 0.3, 1.0);
  CHECK(fm::layered_realised_restitution(thick, mass, v, 0.0) == Approx(1.0).epsilon(1e-6));
  for (double gamma : {0.2, 1.0}) {
    CHECK(fm::layered_realised_restitution(thick, mass, v, gamma) ==
          Approx(fm::realised_restitution(gamma)).epsilon(2e-3));
  }
  // A thin layer realises a different ε for the same γ_n (why the DEM must recalibrate),
  // and the inverse returns the target (|Δε| < 1e-6 by its stopping rule, 1e-5 checked).
  const fm::LayeredContact thin(radius, 60e6, 0.48, kInf, 0.3, 1e-4);
  const double hertz_gamma = fm::damping_for_restitution(0.6);
  const double layered_e = fm::layered_realised_restitution(thin, mass, v, hertz_gamma);
  CHECK(std::abs(layered_e - 0.6) > 0.01);
  const double gamma = fm::layered_damping_for_restitution(thin, mass, v, 0.6);
  CHECK(fm::layered_realised_restitution(thin, mass, v, gamma) == Approx(0.6).margin(1e-5));
}

TEST_CASE("the layered damping table realises the target restitution between its nodes", "[formulas]") {
  // Reference: the one-collision solve layered_realised_restitution (20000 RK4 steps,
  // ~1e-6), which the table's inversion must hit at impacts between its ξ nodes and for
  // restitutions between its γ nodes. 1e-3 relative: the DEM's restitution tolerance is
  // 2%; linear inversion on the (ln ξ, ln(1 + γ)) grid stays well inside.
  const double radius = 0.005, mass = 4.1e-3;
  const fm::LayeredContact materials(radius, 100e6, 0.48, 210e9, 0.3, 1.5e-4);
  const fm::LayeredDampingTable table(materials);
  // Also the ratios the DEM uses: force and energy at χ against the dimensional law,
  // and the damping ratio √(S/S_Hertz) against the law's own stiffness.
  const double delta = 3e-5, chi = std::sqrt(radius * delta) / 1.5e-4;
  const auto ratios = materials.hertz_ratios(chi);
  const double k_hertz = 4.0 / 3.0 * materials.effective_modulus_pa() * std::sqrt(radius);
  CHECK(ratios.force * k_hertz * std::pow(delta, 1.5) == Approx(materials.force(delta)).epsilon(1e-12));
  CHECK(ratios.energy * 0.4 * k_hertz * std::pow(delta, 2.5) == Approx(materials.energy(delta)).epsilon(1e-12));
  CHECK(ratios.damping * ratios.damping * 1.5 * k_hertz * std::sqrt(delta) ==
        Approx(materials.stiffness(delta)).epsilon(1e-12));
  for (const double thickness : {3e-3, 3.3e-4, 1.1e-4, 4e-5}) {
    const fm::LayeredContact layer(materials, thickness);
    for (const double v : {0.37, 2.9}) {
      const double xi = fm::LayeredDampingTable::impact_overlap_parameter(layer, mass, v);
      for (const double eps : {0.33, 0.71, 0.93}) {
        const double gamma = table.damping_for_restitution(xi, eps);
        const double realised = fm::layered_realised_restitution(layer, mass, v, gamma);
        INFO("t = " << thickness << " m, v = " << v << " m/s, xi = " << xi << ", target " << eps << ": gamma "
                    << gamma << ", realised " << realised);
        CHECK(realised == Approx(eps).epsilon(1e-3));
      }
    }
  }
  CHECK(table.damping_for_restitution(0.5, 1.0) == 0.0);
}

TEST_CASE("the layered law rejects invalid parameters", "[formulas]") {
  CHECK_THROWS_WITH(fm::LayeredContact(-1.0, 60e6, 0.45, kInf, 0.3, 1e-4),
                    Catch::StartsWith("LayeredContact: effective_radius_m = -1: must be > 0"));
  CHECK_THROWS_WITH(fm::LayeredContact(0.001, 60e6, 0.51, kInf, 0.3, 1e-4),
                    Catch::Contains("layer_poisson_ratio = 0.51: must be in [0, 0.5]"));
  CHECK_THROWS_WITH(fm::LayeredContact(0.001, 60e6, 0.45, kInf, 0.3, 0.0),
                    Catch::Contains("thickness_m = 0: must be > 0"));
  CHECK_THROWS_AS(fm::solve_layer_indentation(-1.0, 0.3), std::invalid_argument);
  CHECK_THROWS_AS(fm::solve_layer_indentation(1.0, 0.3, 1.5), std::invalid_argument);
  CHECK_THROWS_AS(fm::thin_layer_moduli(1.0, 0.6, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(fm::thin_layer_indentation(0.0, 1.0, 1.0, 0.45, 1.0), std::invalid_argument);
  const fm::LayeredContact c(0.001, 60e6, 0.45, kInf, 0.3, 1e-4);
  CHECK_THROWS_AS(fm::layered_impact(c, 0.0, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(fm::layered_realised_restitution(c, 0.01, 1.0, -1.0), std::invalid_argument);
  CHECK_THROWS_AS(fm::layered_damping_for_restitution(c, 0.01, 1.0, 0.0), std::invalid_argument);
}
