// Sphere on an elastic layer bonded to a rigid wall: kernel, thin-layer limits, exact Nyström solution, table.
#include "pdamp/formulas/layered_contact.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/one_dimensional.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"  // kPi

namespace pdamp::formulas {
namespace {

using base::positive_finite;
using base::require;
using base::require_positive;

bool layer_poisson_ok(double nu) { return nu >= 0.0 && nu <= 0.5; }

/// Gauss–Legendre nodes and weights on [0, 1] (Newton on P_n from Tricomi's guess), n >= 2.
void gauss_legendre_unit(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double step = p1 / dp;
      z -= step;
      if (std::abs(step) < 1e-16) break;
    }
    const double weight = 2.0 / ((1.0 - z * z) * dp * dp);
    x[i] = 0.5 * (1.0 - z);
    x[n - 1 - i] = 0.5 * (1.0 + z);
    w[i] = w[n - 1 - i] = 0.5 * weight;
  }
}

// ---------------------------------------------------------------------------------------------
// H(c) = k ∫₀^∞ [1 − L(η)] cos(cη) dη and H'(c) on a uniform grid in c, for the Nyström kernel.
// 1 − L decays like 4η²e^{−2η}/κ: truncated at η = 40 (< 1e-30). Composite 8-point Gauss
// panels of width 0.05: c·width <= 3.5 rad per panel at c <= 70, where an 8-point rule
// integrates the oscillation to ~1e-10. c step 0.02 with cubic Hermite (H and H'):
// interpolation error ~ h⁴ max|H''''|/384 < 1e-9 (|H''''| <= ∫η⁴(1−L) ~ 10).
class KernelTransform {
 public:
  KernelTransform(double poisson_ratio, double layer_share, double max_argument) {
    constexpr double kEtaMax = 40.0, kPanel = 0.05;
    step_ = 0.02;
    points_ = static_cast<int>(std::ceil(max_argument / step_)) + 2;
    value_.assign(points_, 0.0);
    slope_.assign(points_, 0.0);
    std::vector<double> gx, gw;
    gauss_legendre_unit(8, gx, gw);
    const int panels = static_cast<int>(kEtaMax / kPanel);
    for (int p = 0; p < panels; ++p) {
      for (int g = 0; g < 8; ++g) {
        const double eta = (p + gx[g]) * kPanel;
        const double weight = gw[g] * kPanel * layer_share * bonded_layer_kernel_complement(eta, poisson_ratio);
        // cos(jhη), sin(jhη) by rotation; 3500 rotations lose < 1e-12.
        const double cr = std::cos(step_ * eta), sr = std::sin(step_ * eta);
        double c = 1.0, s = 0.0;
        for (int j = 0; j < points_; ++j) {
          value_[j] += weight * c;
          slope_[j] -= weight * eta * s;
          const double next = c * cr - s * sr;
          s = s * cr + c * sr;
          c = next;
        }
      }
    }
  }
  double operator()(double c) const {
    c = std::abs(c);  // H is even
    const double position = c / step_;
    int i = static_cast<int>(position);
    if (i >= points_ - 1) i = points_ - 2;
    const double s = position - i, h = step_;
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * value_[i] + (s3 - 2 * s2 + s) * h * slope_[i] +
           (-2 * s3 + 3 * s2) * value_[i + 1] + (s3 - s2) * h * slope_[i + 1];
  }
  double at_zero() const { return value_[0]; }

 private:
  double step_ = 0.0;
  int points_ = 0;
  std::vector<double> value_, slope_;
};

/// Quadrature nodes for the Nyström solve at λ = a/t: the kernel varies over Δx ~ 1/λ.
/// Convergence study (docs): 24 + 7λ nodes give F/F_Hertz and Rδ/a² to < 1e-7.
int default_nodes(double lambda) { return 24 + static_cast<int>(std::ceil(7.0 * lambda)); }

LayerIndentation nystrom(const KernelTransform& h, double lambda, int nodes) {
  LayerIndentation out;
  out.contact_radius_over_thickness = lambda;
  if (lambda == 0.0) {
    out.overlap_over_hertz = 1.0;
    out.force_over_hertz = 1.0;
    return out;
  }
  std::vector<double> x, w;
  gauss_legendre_unit(nodes, x, w);
  const double factor = 2.0 * lambda / kPi;
  Eigen::MatrixXd a(nodes, nodes);
  Eigen::MatrixXd rhs(nodes, 2);
  for (int i = 0; i < nodes; ++i) {
    for (int j = 0; j < nodes; ++j) {
      const double kernel = 0.5 * (h(lambda * (x[i] - x[j])) + h(lambda * (x[i] + x[j])));
      a(i, j) = (i == j ? 1.0 : 0.0) - factor * w[j] * kernel;
    }
    rhs(i, 0) = 1.0;
    rhs(i, 1) = x[i] * x[i];
  }
  const Eigen::MatrixXd psi = a.partialPivLu().solve(rhs);
  // Nyström interpolation to the edge x = 1 and the integrals I_j = ∫₀¹ ψ_j.
  double edge0 = 1.0, edge2 = 1.0, integral0 = 0.0, integral2 = 0.0;
  for (int j = 0; j < nodes; ++j) {
    const double kernel = 0.5 * (h(lambda * (1.0 - x[j])) + h(lambda * (1.0 + x[j])));
    edge0 += factor * w[j] * kernel * psi(j, 0);
    edge2 += factor * w[j] * kernel * psi(j, 1);
    integral0 += w[j] * psi(j, 0);
    integral2 += w[j] * psi(j, 1);
  }
  // φ = (E*/π)[δψ₀ − (a²/R)ψ₂]; φ(a) = 0 gives g = Rδ/a² = ψ₂(1)/ψ₀(1);
  // F = 2E*(a³/R)(g I₀ − I₂) and F_Hertz = (4/3)E*(a³/R) g^{3/2}.
  const double g = edge2 / edge0;
  out.overlap_over_hertz = g;
  out.overlap_parameter = lambda * std::sqrt(g);
  out.force_over_hertz = 1.5 * (g * integral0 - integral2) / (g * std::sqrt(g));
  return out;
}

/// Max a/t the table needs: χ = λ√g with g >= 1/4 (incompressible thin limit), margin.
constexpr double kTableMaxLambda = 2.0 * LayeredContact::kMaxTabulatedOverlapParameter + 2.0;
constexpr double kTableLambdaStep = 0.25;
constexpr double kTableFineLambdaStep = 0.05;
constexpr double kTableFineLambdaEnd = 4.0;
constexpr int kTableIntervals = 256;

/// Fourth-order finite-difference derivative on a uniform grid (one-sided at the ends).
std::vector<double> derivative(const std::vector<double>& f, double h) {
  const int n = static_cast<int>(f.size());
  std::vector<double> d(n);
  for (int i = 0; i < n; ++i) {
    if (i >= 2 && i <= n - 3) {
      d[i] = (f[i - 2] - 8 * f[i - 1] + 8 * f[i + 1] - f[i + 2]) / (12 * h);
    } else if (i < 2) {
      d[i] = (-25 * f[i] + 48 * f[i + 1] - 36 * f[i + 2] + 16 * f[i + 3] - 3 * f[i + 4]) / (12 * h);
    } else {
      d[i] = (25 * f[i] - 48 * f[i - 1] + 36 * f[i - 2] - 16 * f[i - 3] + 3 * f[i - 4]) / (12 * h);
    }
  }
  return d;
}

double hermite(const std::vector<double>& f, const std::vector<double>& d, int i, double s, double h) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * f[i] + (s3 - 2 * s2 + s) * h * d[i] + (-2 * s3 + 3 * s2) * f[i + 1] +
         (s3 - s2) * h * d[i + 1];
}
double hermite_slope(const std::vector<double>& f, const std::vector<double>& d, int i, double s, double h) {
  const double s2 = s * s;
  return ((6 * s2 - 6 * s) * f[i] + (3 * s2 - 4 * s + 1) * h * d[i] + (-6 * s2 + 6 * s) * f[i + 1] +
          (3 * s2 - 2 * s) * h * d[i + 1]) /
         h;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

double bonded_layer_kernel(double u, double nu) {
  const double kappa = 3.0 - 4.0 * nu;
  if (u < 1.0) {
    // sinh 2u − 2u by its series (no cancellation; 2u < 2, 13 terms reach 1e-18).
    const double z = 2.0 * u;
    double term = z * z * z / 6.0, series = 0.0;
    for (int k = 1; k < 14; ++k) {
      series += term;
      term *= z * z / ((2.0 * k + 2.0) * (2.0 * k + 3.0));
    }
    const double numerator = 2.0 * kappa * series + 4.0 * u * (kappa - 1.0);
    const double denominator = 2.0 * kappa * std::cosh(z) + 1.0 + kappa * kappa + 4.0 * u * u;
    return numerator / denominator;
  }
  const double e = std::exp(-2.0 * u);
  return (kappa * (1.0 - e * e) - 4.0 * u * e) / (kappa * (1.0 + e * e) + (1.0 + kappa * kappa + 4.0 * u * u) * e);
}

double bonded_layer_kernel_complement(double u, double nu) {
  if (u < 1.0) return 1.0 - bonded_layer_kernel(u, nu);
  const double kappa = 3.0 - 4.0 * nu;
  const double e = std::exp(-2.0 * u);
  return (2.0 * kappa * e * e + (1.0 + kappa * kappa + 4.0 * u * u + 4.0 * u) * e) /
         (kappa * (1.0 + e * e) + (1.0 + kappa * kappa + 4.0 * u * u) * e);
}

ThinLayerModuli thin_layer_moduli(double youngs_modulus_pa, double nu, double thickness_m) {
  constexpr const char* kFunction = "thin_layer_moduli";
  require_positive("youngs_modulus_pa", youngs_modulus_pa, kFunction);
  require(layer_poisson_ok(nu), "poisson_ratio", nu, "in [0, 0.5]", kFunction);
  require_positive("thickness_m", thickness_m, kFunction);
  const double kappa = 3.0 - 4.0 * nu;
  const double plane = youngs_modulus_pa / (1.0 - nu * nu);
  ThinLayerModuli m;
  m.linear_coefficient = (1.0 - 2.0 * nu) / (2.0 * (1.0 - nu) * (1.0 - nu));
  // c₃ = 8(κ − 2)(κ − 3) / (3(κ + 1)³): the two terms of the expansion combined.
  m.cubic_coefficient = 8.0 * (kappa - 2.0) * (kappa - 3.0) / (3.0 * std::pow(kappa + 1.0, 3));
  const double inf = std::numeric_limits<double>::infinity();
  m.constrained_modulus_pa = m.linear_coefficient > 0.0 ? plane / (2.0 * m.linear_coefficient) : inf;
  m.squeeze_modulus_pa = m.cubic_coefficient > 0.0 ? plane / (2.0 * m.cubic_coefficient) : inf;
  m.spreading_length_m = m.cubic_coefficient <= 0.0 ? 0.0
                         : m.linear_coefficient > 0.0
                             ? thickness_m * std::sqrt(m.cubic_coefficient / m.linear_coefficient)
                             : inf;
  return m;
}

ThinLayerPoint thin_layer_indentation(double a, double radius, double modulus, double nu, double t) {
  constexpr const char* kFunction = "thin_layer_indentation";
  require_positive("contact_radius_m", a, kFunction);
  require_positive("sphere_radius_m", radius, kFunction);
  const ThinLayerModuli m = thin_layer_moduli(modulus, nu, t);
  ThinLayerPoint out;
  if (m.spreading_length_m == 0.0) {
    // ν <= 1/4: c₃ <= 0, no squeeze-flow spreading at this order: the elastic foundation.
    out.overlap_m = a * a / (2.0 * radius);
    out.force_n = kPi * m.constrained_modulus_pa * a * a * a * a / (4.0 * radius * t);
    return out;
  }
  const double x = std::isinf(m.spreading_length_m) ? 0.0 : a / m.spreading_length_m;
  // Dn = 2Rδ/a², Bn = B/x⁴ (see the header): power series in y = x²/4 for x <= 25
  // (all terms positive, no cancellation), the Bessel ratio above.
  double dn = 0.0, bn = 0.0;
  if (x <= 25.0) {
    const double y = 0.25 * x * x;
    // term_k = y^k/(k!(k+1)!); S₁ = Σ term_k; Dn·S₁ = Σ_{k>=1} k² y^{k−1}/(k!(k+1)!),
    // 16·Bn·S₁ = Σ_{k>=2} k(k−1) y^{k−2}/(k!(k+1)!).
    double s1 = 0.0, d_sum = 0.0, b_sum = 0.0;
    double power = 1.0, factorials = 1.0;  // y^{k}, k!(k+1)!
    for (int k = 0; k < 200; ++k) {
      const double term = power / factorials;
      s1 += term;
      d_sum += k * k * term;  // k = 0 adds nothing
      if (k >= 2) b_sum += k * (k - 1.0) * term;
      power *= y;
      factorials *= (k + 1.0) * (k + 2.0);
      if (term < 1e-18 * s1 && k > 4) break;
    }
    // d_sum, b_sum carry y^k; divide by y and y² (limits at y = 0 from the first terms).
    if (y < 1e-8) {  // leading terms (also ν = 0.5, y = 0): Dn = ½(1 + x²/24), Bn = 1/96
      dn = 0.5 * (1.0 + x * x / 24.0);
      bn = 1.0 / 96.0;
    } else {
      dn = d_sum / (y * s1);
      bn = b_sum / (16.0 * y * y * s1);
    }
  } else {
    double ratio;  // I₀(x)/I₁(x)
    if (x < 500.0) {
      ratio = std::cyl_bessel_i(0.0, x) / std::cyl_bessel_i(1.0, x);
    } else {
      ratio = 1.0 / (1.0 - 0.5 / x - 0.125 / (x * x) - 0.125 / (x * x * x));
    }
    dn = 1.0 + 4.0 / (x * x) - 2.0 * ratio / x;
    bn = (2.0 + 0.25 * x * x - x * ratio) / (x * x * x * x);
  }
  out.overlap_m = a * a * dn / (2.0 * radius);
  out.force_n = kPi * m.squeeze_modulus_pa * std::pow(a, 6) * bn / (radius * t * t * t);
  return out;
}

double foundation_force(double overlap, double radius, double modulus, double nu, double t) {
  const ThinLayerModuli m = thin_layer_moduli(modulus, nu, t);
  require_positive("sphere_radius_m", radius, "foundation_force");
  if (!(overlap > 0.0)) return 0.0;
  return kPi * m.constrained_modulus_pa * radius * overlap * overlap / t;
}

double incompressible_thin_layer_force(double overlap, double radius, double modulus, double t) {
  constexpr const char* kFunction = "incompressible_thin_layer_force";
  require_positive("sphere_radius_m", radius, kFunction);
  require_positive("youngs_modulus_pa", modulus, kFunction);
  require_positive("thickness_m", t, kFunction);
  if (!(overlap > 0.0)) return 0.0;
  return 2.0 * kPi / 3.0 * modulus * radius * radius * overlap * overlap * overlap / (t * t * t);
}

double dimitriadis_force_ratio(double chi, double nu) {
  const double alpha = -(1.2876 - 1.4678 * nu + 1.3442 * nu * nu) / (1.0 - nu);
  const double beta = (0.6387 - 1.0277 * nu + 1.5164 * nu * nu) / (1.0 - nu);
  const double pi2 = kPi * kPi;
  return 1.0 - 2.0 * alpha / kPi * chi + 4.0 * alpha * alpha / pi2 * chi * chi -
         8.0 / (pi2 * kPi) * (alpha * alpha * alpha + 4.0 * pi2 * beta / 15.0) * chi * chi * chi +
         16.0 * alpha / (pi2 * pi2) * (alpha * alpha * alpha + 3.0 * pi2 * beta / 5.0) * chi * chi * chi * chi;
}

LayerIndentation solve_layer_indentation(double lambda, double nu, double layer_share, int nodes) {
  constexpr const char* kFunction = "solve_layer_indentation";
  require(lambda >= 0.0 && lambda <= 200.0, "contact_radius_over_thickness", lambda, "in [0, 200]", kFunction);
  require(layer_poisson_ok(nu), "poisson_ratio", nu, "in [0, 0.5]", kFunction);
  require(layer_share > 0.0 && layer_share <= 1.0, "layer_share", layer_share, "in (0, 1]", kFunction);
  require(nodes >= 0 && nodes <= 4000, "nodes", nodes, "in [0, 4000]", kFunction);
  const KernelTransform h(nu, layer_share, 2.0 * lambda + 1.0);
  return nystrom(h, lambda, nodes > 0 ? nodes : default_nodes(lambda));
}

// ---------------------------------------------------------------------------------------------

struct LayeredContact::Table {
  double step = 0.0;                    // χ step
  std::vector<double> g, dg;            // G(χ) = F/F_Hertz and dG/dχ
  std::vector<double> w, dw;            // W(χ) = U/U_Hertz = 5Ψ/χ⁵, Ψ = ∫₀^χ q⁴G dq
  std::vector<double> lam, dlam;        // λ = a/t
  double end_chi = 0.0, end_g = 0.0, end_exponent = 0.0, end_psi = 0.0;
};

namespace {

std::shared_ptr<const LayeredContact::Table> build_table(double nu, double share) {
  auto table = std::make_shared<LayeredContact::Table>();
  const KernelTransform h(nu, share, 2.0 * kTableMaxLambda + 1.0);
  // Exact solutions on a uniform λ grid, then cubic (4-point Lagrange) interpolation in χ
  // onto the uniform χ grid (G and λ are smooth in χ), then cubic Hermite in χ: error
  // < 1e-5 (test: direct solves between the nodes).
  // Finer λ steps below λ = 4: G's Taylor series in χ has a radius of only ~1.5 (G grows
  // like (1 − 2b/3)^{−3/2}, docs), so a 0.25 step there leaves 1e-3 interpolation errors.
  const int fine = static_cast<int>(kTableFineLambdaEnd / kTableFineLambdaStep);
  const int solves = fine + static_cast<int>((kTableMaxLambda - kTableFineLambdaEnd) / kTableLambdaStep) + 1;
  std::vector<double> chi(solves), g(solves), lam(solves);
  for (int i = 0; i < solves; ++i) {
    const double lambda =
        i <= fine ? i * kTableFineLambdaStep : kTableFineLambdaEnd + (i - fine) * kTableLambdaStep;
    const LayerIndentation s = nystrom(h, lambda, default_nodes(lambda));
    chi[i] = s.overlap_parameter;
    g[i] = s.force_over_hertz;
    lam[i] = lambda;
    if (i > 0 && !(chi[i] > chi[i - 1])) {
      throw base::NumericalError("LayeredContact: overlap parameter not increasing with a/t at a/t = " +
                                 base::format_number(lambda, 12));
    }
  }
  if (!(chi.back() > LayeredContact::kMaxTabulatedOverlapParameter)) {
    throw base::NumericalError("LayeredContact: the a/t range does not cover the table");
  }
  const int n = kTableIntervals + 1;
  table->step = LayeredContact::kMaxTabulatedOverlapParameter / kTableIntervals;
  table->g.resize(n);
  table->lam.resize(n);
  int k = 0;
  for (int j = 0; j < n; ++j) {
    const double target = j * table->step;
    while (k + 2 < solves && chi[k + 1] < target) ++k;
    const int first = std::clamp(k - 1, 0, solves - 4);
    double gv = 0.0, lv = 0.0;
    for (int a = first; a < first + 4; ++a) {
      double basis = 1.0;
      for (int b = first; b < first + 4; ++b) {
        if (b != a) basis *= (target - chi[b]) / (chi[a] - chi[b]);
      }
      gv += basis * g[a];
      lv += basis * lam[a];
    }
    table->g[j] = gv;
    table->lam[j] = lv;
  }
  table->g[0] = 1.0;
  table->lam[0] = 0.0;
  table->dg = derivative(table->g, table->step);
  table->dlam = derivative(table->lam, table->step);
  // Ψ(χ) = ∫₀^χ q⁴G dq interval by interval (4-point Gauss on the Hermite interpolant of G:
  // exact for its degree-7 integrand), W = 5Ψ/χ⁵, W' = 5(G − W)/χ.
  std::vector<double> gx, gw;
  gauss_legendre_unit(4, gx, gw);
  table->w.resize(n);
  table->dw.resize(n);
  table->w[0] = 1.0;
  double psi = 0.0;
  for (int j = 1; j < n; ++j) {
    for (int q = 0; q < 4; ++q) {
      const double chi_q = (j - 1 + gx[q]) * table->step;
      psi += gw[q] * table->step * std::pow(chi_q, 4) * hermite(table->g, table->dg, j - 1, gx[q], table->step);
    }
    const double c = j * table->step;
    table->w[j] = 5.0 * psi / std::pow(c, 5);
    table->dw[j] = 5.0 * (table->g[j] - table->w[j]) / c;
  }
  // W ≈ 1 + (5/6)G'(0)χ near 0 (from G ≈ 1 + G'(0)χ).
  table->dw[0] = 5.0 / 6.0 * table->dg[0];
  table->end_chi = LayeredContact::kMaxTabulatedOverlapParameter;
  table->end_g = table->g.back();
  table->end_exponent = table->end_chi * table->dg.back() / table->end_g;
  table->end_psi = psi;
  return table;
}

/// Tables depend on (ν, k) only: the sizing's bisection and a DEM's many contacts of one
/// material pair share one. Small, mutex-guarded, oldest entry dropped beyond 32.
std::shared_ptr<const LayeredContact::Table> shared_table(double nu, double share) {
  struct Entry {
    double nu, share;
    std::shared_ptr<const LayeredContact::Table> table;
  };
  static std::mutex mutex;
  static std::vector<Entry> cache;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (const auto& e : cache) {
      if (e.nu == nu && e.share == share) return e.table;
    }
  }
  auto table = build_table(nu, share);  // outside the lock: ~0.3 s
  const std::lock_guard<std::mutex> lock(mutex);
  if (cache.size() >= 32) cache.erase(cache.begin());
  cache.push_back({nu, share, table});
  return table;
}

}  // namespace

LayeredContact::LayeredContact(double effective_radius_m, double layer_modulus_pa, double layer_poisson_ratio,
                               double sphere_modulus_pa, double sphere_poisson_ratio, double thickness_m) {
  constexpr const char* kFunction = "LayeredContact";
  require_positive("effective_radius_m", effective_radius_m, kFunction);
  require_positive("layer_modulus_pa", layer_modulus_pa, kFunction);
  require(layer_poisson_ok(layer_poisson_ratio), "layer_poisson_ratio", layer_poisson_ratio, "in [0, 0.5]", kFunction);
  require(sphere_modulus_pa > 0.0, "sphere_modulus_pa", sphere_modulus_pa, "> 0 (+inf: rigid)", kFunction);
  require(sphere_poisson_ratio >= 0.0 && sphere_poisson_ratio < 0.5, "sphere_poisson_ratio", sphere_poisson_ratio,
          "in [0, 0.5)", kFunction);
  require_positive("thickness_m", thickness_m, kFunction);
  radius_ = effective_radius_m;
  thickness_ = thickness_m;
  const double layer_compliance = (1.0 - layer_poisson_ratio * layer_poisson_ratio) / layer_modulus_pa;
  const double sphere_compliance =
      std::isinf(sphere_modulus_pa) ? 0.0 : (1.0 - sphere_poisson_ratio * sphere_poisson_ratio) / sphere_modulus_pa;
  effective_modulus_ = 1.0 / (layer_compliance + sphere_compliance);
  hertz_stiffness_ = 4.0 / 3.0 * effective_modulus_ * std::sqrt(radius_);
  layer_poisson_ = layer_poisson_ratio;
  layer_share_ = layer_compliance * effective_modulus_;
  table_ = shared_table(layer_poisson_, layer_share_);
}

LayeredContact::LayeredContact(const LayeredContact& materials, double thickness_m) : LayeredContact(materials) {
  require_positive("thickness_m", thickness_m, "LayeredContact");
  thickness_ = thickness_m;
}

double LayeredContact::force_over_hertz(double chi) const {
  const Table& t = *table_;
  if (chi >= t.end_chi) return t.end_g * std::pow(chi / t.end_chi, t.end_exponent);
  const double position = chi / t.step;
  const int i = static_cast<int>(position);
  return hermite(t.g, t.dg, i, position - i, t.step);
}

double LayeredContact::force(double overlap) const {
  if (!(overlap > 0.0)) return 0.0;
  const double root = std::sqrt(overlap);
  return hertz_stiffness_ * overlap * root * force_over_hertz(std::sqrt(radius_) * root / thickness_);
}

namespace {

/// G(χ) and dG/dχ from the table (or its power-law continuation beyond it).
void force_ratio_and_slope(const LayeredContact::Table& t, double chi, double& g, double& slope) {
  if (chi >= t.end_chi) {
    g = t.end_g * std::pow(chi / t.end_chi, t.end_exponent);
    slope = t.end_exponent * g / chi;
  } else {
    const double position = chi / t.step;
    const int i = static_cast<int>(position);
    g = hermite(t.g, t.dg, i, position - i, t.step);
    slope = hermite_slope(t.g, t.dg, i, position - i, t.step);
  }
}

/// W(χ) = U/U_Hertz = 5Ψ(χ)/χ⁵ (χ > 0).
double energy_ratio(const LayeredContact::Table& t, double chi) {
  if (chi >= t.end_chi) {
    const double p = t.end_exponent;
    const double psi = t.end_psi + t.end_g * std::pow(t.end_chi, -p) *
                                       (std::pow(chi, p + 5.0) - std::pow(t.end_chi, p + 5.0)) / (p + 5.0);
    return 5.0 * psi / std::pow(chi, 5);
  }
  const double position = chi / t.step;
  const int i = static_cast<int>(position);
  return hermite(t.w, t.dw, i, position - i, t.step);
}

}  // namespace

double LayeredContact::stiffness(double overlap) const {
  if (!(overlap > 0.0)) return 0.0;
  const double root = std::sqrt(overlap);
  const double chi = std::sqrt(radius_) * root / thickness_;
  double g, slope;
  force_ratio_and_slope(*table_, chi, g, slope);
  // F = Kδ^{3/2}G(χ), dχ/dδ = χ/(2δ).
  return hertz_stiffness_ * root * (1.5 * g + 0.5 * chi * slope);
}

LayeredContact::HertzRatios LayeredContact::hertz_ratios(double chi) const {
  HertzRatios out;
  if (!(chi > 0.0)) return out;
  double slope;
  force_ratio_and_slope(*table_, chi, out.force, slope);
  // S/S_Hertz with S_Hertz = (3/2)Kδ^{1/2}: (1.5G + 0.5χG')/1.5.
  out.damping = std::sqrt(out.force + chi * slope / 3.0);
  out.energy = energy_ratio(*table_, chi);
  return out;
}

double LayeredContact::energy(double overlap) const {
  if (!(overlap > 0.0)) return 0.0;
  const double root = std::sqrt(overlap);
  const double chi = std::sqrt(radius_) * root / thickness_;
  const double hertz = 0.4 * hertz_stiffness_ * overlap * overlap * root;  // (8/15)E*√R δ^{5/2}
  return hertz * energy_ratio(*table_, chi);
}

double LayeredContact::contact_radius(double overlap) const {
  if (!(overlap > 0.0)) return 0.0;
  const Table& t = *table_;
  const double chi = std::sqrt(radius_ * overlap) / thickness_;
  if (chi >= t.end_chi) {
    // Beyond the table: a/t continues at the end's ratio λ/χ (thin-layer a² ∝ Rδ).
    return thickness_ * chi * t.lam.back() / t.end_chi;
  }
  const double position = chi / t.step;
  const int i = static_cast<int>(position);
  return thickness_ * hermite(t.lam, t.dlam, i, position - i, t.step);
}

// ---------------------------------------------------------------------------------------------

LayeredImpact layered_impact(const LayeredContact& contact, double mass, double speed) {
  constexpr const char* kFunction = "layered_impact";
  require_positive("effective_mass_kg", mass, kFunction);
  require_positive("impact_speed_m_s", speed, kFunction);
  const double kinetic = 0.5 * mass * speed * speed;
  // δ_max: U is increasing; bracket from the Hertz value (the layer is stiffer, so δ_max
  // is smaller), then bisection on ln δ to double precision.
  const double hertz_max = std::pow(kinetic / (0.4 * 4.0 / 3.0 * contact.effective_modulus_pa() *
                                               std::sqrt(contact.effective_radius_m())),
                                    0.4);
  double hi = 2.0 * hertz_max, lo = hi;
  while (contact.energy(lo) > kinetic) lo *= 0.5;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (contact.energy(mid) > kinetic ? hi : lo) = mid;
  }
  LayeredImpact out;
  out.max_overlap_m = 0.5 * (lo + hi);
  out.max_force_n = contact.force(out.max_overlap_m);
  // t_c = 2∫₀^{δm} dδ/√(v² − 2U/m). With δ = δm(1 − w²): dδ = −2δm w dw and
  // v² − 2U/m ≈ (2F(δm)/m)δm w² near w = 0, so the integrand is smooth; 64-point
  // Gauss–Legendre: the integrand's only non-smoothness is the δ^{1/4}-type start at
  // w = 1 (Hertz), which costs < 1e-7 relative (checked against the Hertz closed form).
  std::vector<double> x, w;
  gauss_legendre_unit(64, x, w);
  const double dm = out.max_overlap_m;
  double integral = 0.0;
  for (int i = 0; i < 64; ++i) {
    const double u = x[i];
    const double delta = dm * (1.0 - u * u);
    const double remaining = speed * speed - 2.0 * contact.energy(delta) / mass;
    // Near u = 0 the difference loses digits: use the local expansion there.
    const double local = 2.0 * out.max_force_n * dm * u * u / mass;
    const double denominator = std::sqrt(std::max(remaining, u < 1e-3 ? local : 0.0));
    integral += w[i] * 2.0 * dm * u / denominator;
  }
  out.contact_time_s = 2.0 * integral;
  return out;
}

namespace {

struct OneCollision {
  const LayeredContact& contact;
  double mass, damping;
  double total_force(double x, double v) const {
    if (x <= 0.0) return 0.0;
    return contact.force(x) + damping * std::sqrt(2.0 / 3.0 * mass * contact.stiffness(x)) * v;
  }
};

/// The one-collision solve of layered_realised_restitution with `steps` RK4 steps per
/// elastic contact time (arguments valid).
double realised_restitution(const LayeredContact& contact, double mass, double speed, double damping,
                            int steps) {
  const OneCollision model{contact, mass, damping};
  const double h = layered_impact(contact, mass, speed).contact_time_s / steps;
  double x = 0.0, v = speed;
  auto accel = [&](double xx, double vv) { return -model.total_force(xx, vv) / mass; };
  for (long step = 0; step < 200L * steps; ++step) {
    const double k1x = v, k1v = accel(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = accel(x + h * k3x, v + h * k3v);
    const double nx = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double nv = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    // End: the total force returns to zero (no tension) or the overlap to zero, on the
    // way out (v < 0). Linear interpolation of v at the force's zero crossing.
    if (nv < 0.0) {
      const double f_now = model.total_force(x, v), f_next = model.total_force(nx, nv);
      if (nx <= 0.0 || f_next <= 0.0) {
        const double s = (f_now - f_next) != 0.0 ? std::clamp(f_now / (f_now - f_next), 0.0, 1.0) : 1.0;
        return -(v + s * (nv - v)) / speed;
      }
    }
    x = nx;
    v = nv;
  }
  throw base::NumericalError("layered_realised_restitution: contact did not end");
}

}  // namespace

double layered_realised_restitution(const LayeredContact& contact, double mass, double speed, double damping) {
  constexpr const char* kFunction = "layered_realised_restitution";
  require_positive("effective_mass_kg", mass, kFunction);
  require_positive("impact_speed_m_s", speed, kFunction);
  require(damping >= 0.0 && damping <= 100.0, "damping_coefficient", damping, "in [0, 100]", kFunction);
  // Step: the elastic contact time over 20000 (RK4, the force's δ^{1/4}-type start costs
  // an O(h^{5/4}) local error in the first steps only: ε converged to ~1e-6, docs).
  return realised_restitution(contact, mass, speed, damping, 20000);
}

double layered_damping_for_restitution(const LayeredContact& contact, double mass, double speed,
                                       double restitution) {
  require(restitution >= 1e-3 && restitution <= 1.0, "restitution", restitution, "in [0.001, 1]",
          "layered_damping_for_restitution");
  if (restitution == 1.0) return 0.0;
  // ln ε(γ) is nearly linear in u = ln(1 + γ) (as for Hertz, cor_models.cpp): bisection
  // on u with the Illinois update.
  const double target = std::log(restitution);
  auto residual = [&](double u) {
    return std::log(layered_realised_restitution(contact, mass, speed, std::min(std::expm1(u), 100.0))) - target;
  };
  double lo = 0.0, f_lo = -target, hi = std::log1p(100.0), f_hi = residual(hi);
  if (f_hi > 0.0) throw base::NumericalError("layered_damping_for_restitution: not reached at damping 100");
  const double u = base::illinois_root(residual, lo, f_lo, hi, f_hi, 1e-7, 1e-12, 100);
  return std::min(std::expm1(u), 100.0);
}

// ---------------------------------------------------------------------------------------------
// Damping table of the layered law (LayeredDampingTable).

struct LayeredDampingTable::Table {
  std::vector<double> log_xi;          // ln ξ nodes, uniform
  std::vector<double> u;               // ln(1 + γ) nodes, uniform from 0
  std::vector<double> log_eps;         // ln ε, row per ξ node (decreasing along u)
};

namespace {

// Grid: 61 ξ nodes (12 per decade over [1e-3, 100]) by 41 γ nodes (u = ln(1 + γ) over
// [0, ln 101]). RK4 at 4000 steps per contact time: ε to ~1e-5 (the δ^{1/4}-type start,
// docs), far below the interpolation error. Accuracy of the inversion: test.
constexpr int kDampingXiNodes = 61;
constexpr int kDampingGammaNodes = 41;
constexpr int kDampingSteps = 4000;

std::shared_ptr<const LayeredDampingTable::Table> build_damping_table(const LayeredContact& prototype) {
  auto table = std::make_shared<LayeredDampingTable::Table>();
  const double lo = std::log(LayeredDampingTable::kMinOverlapParameter);
  const double hi = std::log(LayeredDampingTable::kMaxOverlapParameter);
  const double u_max = std::log1p(100.0);
  for (int i = 0; i < kDampingXiNodes; ++i) table->log_xi.push_back(lo + (hi - lo) * i / (kDampingXiNodes - 1));
  for (int j = 0; j < kDampingGammaNodes; ++j) table->u.push_back(u_max * j / (kDampingGammaNodes - 1));
  table->log_eps.resize(static_cast<std::size_t>(kDampingXiNodes * kDampingGammaNodes));
  // A unit impact (m* = 1 kg, v = 1 m/s) on the prototype's moduli and radius; the
  // thickness gives each node its ξ (ε depends on nothing else, class comment).
  const double mass = 1.0, speed = 1.0;
  const double k = 4.0 / 3.0 * prototype.effective_modulus_pa() * std::sqrt(prototype.effective_radius_m());
  const double hertz_overlap = std::pow(1.25 * mass * speed * speed / k, 0.4);
  for (int i = 0; i < kDampingXiNodes; ++i) {
    const double thickness = std::sqrt(prototype.effective_radius_m() * hertz_overlap) / std::exp(table->log_xi[i]);
    const LayeredContact node(prototype, thickness);
    for (int j = 0; j < kDampingGammaNodes; ++j) {
      const double gamma = std::min(std::expm1(table->u[static_cast<std::size_t>(j)]), 100.0);
      table->log_eps[static_cast<std::size_t>(i * kDampingGammaNodes + j)] =
          j == 0 ? 0.0 : std::log(realised_restitution(node, mass, speed, gamma, kDampingSteps));
    }
  }
  return table;
}

/// u = ln(1 + γ) with ln ε(u) = target on row i (linear between the nodes; ln ε falls along u).
double row_inverse(const LayeredDampingTable::Table& t, int i, double target) {
  const double* row = &t.log_eps[static_cast<std::size_t>(i * kDampingGammaNodes)];
  if (target >= row[0]) return 0.0;
  for (int j = 1; j < kDampingGammaNodes; ++j) {
    if (row[j] <= target) {
      const double s = (row[j - 1] - target) / (row[j - 1] - row[j]);
      return t.u[static_cast<std::size_t>(j - 1)] + s * (t.u[static_cast<std::size_t>(j)] - t.u[static_cast<std::size_t>(j - 1)]);
    }
  }
  return t.u.back();
}

}  // namespace

LayeredDampingTable::LayeredDampingTable(const LayeredContact& contact) {
  struct Entry {
    double nu, share;
    std::shared_ptr<const Table> table;
  };
  static std::mutex mutex;
  static std::vector<Entry> cache;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (const auto& e : cache) {
      if (e.nu == contact.layer_poisson_ && e.share == contact.layer_share_) {
        table_ = e.table;
        return;
      }
    }
  }
  auto table = build_damping_table(contact);  // outside the lock: ~1 s
  const std::lock_guard<std::mutex> lock(mutex);
  if (cache.size() >= 32) cache.erase(cache.begin());
  cache.push_back({contact.layer_poisson_, contact.layer_share_, table});
  table_ = std::move(table);
}

double LayeredDampingTable::impact_overlap_parameter(const LayeredContact& contact, double mass, double speed) {
  const double k = 4.0 / 3.0 * contact.effective_modulus_pa() * std::sqrt(contact.effective_radius_m());
  const double hertz_overlap = std::pow(1.25 * mass * speed * speed / k, 0.4);
  return std::sqrt(contact.effective_radius_m() * hertz_overlap) / contact.thickness_m();
}

double LayeredDampingTable::damping_for_restitution(double xi, double restitution) const {
  const Table& t = *table_;
  if (restitution >= 1.0) return 0.0;
  const double target = std::log(restitution);
  const double position = std::clamp((std::log(std::max(xi, kMinOverlapParameter)) - t.log_xi.front()) /
                                         (t.log_xi[1] - t.log_xi[0]),
                                     0.0, static_cast<double>(kDampingXiNodes - 1));
  const int i = std::min(static_cast<int>(position), kDampingXiNodes - 2);
  const double s = position - i;
  const double u = (1.0 - s) * row_inverse(t, i, target) + s * row_inverse(t, i + 1, target);
  return std::min(std::expm1(u), 100.0);
}

}  // namespace pdamp::formulas
