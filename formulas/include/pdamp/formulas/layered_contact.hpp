// Contact of a sphere with an elastic layer bonded to a rigid wall (docs/theory.md §5).
//
// Derivations, limits and the numerical reference: docs/hertz_and_buffer.md, section
// "A thin layer is not a half-space".
#pragma once

#include <memory>

namespace pdamp::formulas {

/// Surface-compliance kernel of an elastic layer of thickness t bonded to a rigid
/// substrate, shear-free on top: the Hankel transform of the surface deflection under
/// a normal pressure p̄(ξ) is w̄ = (2/E') (p̄/ξ) L(ξt), E' = E/(1 − ν²), with
///   L(u) = (2κ sinh 2u − 4u) / (2κ cosh 2u + 1 + κ² + 4u²),  κ = 3 − 4ν.
/// L → 1 for u → ∞ (half-space); L = c₁u + c₃u³ + … for u → 0 (thin layer).
/// u >= 0, ν in [0, 0.5]; evaluated without overflow for any u.
double bonded_layer_kernel(double u, double poisson_ratio);
/// 1 − L(u), evaluated without cancellation for large u (it decays like 4u²e^{−2u}/κ).
double bonded_layer_kernel_complement(double u, double poisson_ratio);

/// Thin-layer expansion L(u) = c₁u + c₃u³ + O(u⁵) of the bonded-layer kernel:
///   c₁ = 4(κ − 1)/(κ + 1)² = (1 − 2ν)/(2(1 − ν)²),  c₃ = (8κ/3)/(κ + 1)² − 16(κ − 1)/(κ + 1)³.
/// The surface deflection is then w = (t/M) p − (t³/E₃) ∇²p with the constrained
/// (oedometric) modulus M = E'/(2c₁) = E(1 − ν)/((1 + ν)(1 − 2ν)) and E₃ = E'/(2c₃)
/// (E₃ = E at ν = 0.5); ℓ = t √(c₃/c₁) is the length over which the squeeze flow
/// spreads a load (ℓ → ∞ at ν = 0.5).
struct ThinLayerModuli {
  double linear_coefficient = 0.0;   ///< c₁, dimensionless (0 at ν = 0.5)
  double cubic_coefficient = 0.0;    ///< c₃, dimensionless (2/3 at ν = 0.5)
  double constrained_modulus_pa = 0.0;  ///< M, Pa (+inf at ν = 0.5)
  double squeeze_modulus_pa = 0.0;      ///< E₃, Pa
  double spreading_length_m = 0.0;      ///< ℓ, m (+inf at ν = 0.5)
};
/// E > 0, ν in [0, 0.5], t > 0; std::invalid_argument otherwise.
ThinLayerModuli thin_layer_moduli(double youngs_modulus_pa, double poisson_ratio, double thickness_m);

/// Leading-order thin-layer solution (a ≫ t) for a rigid frictionless sphere of radius R
/// on the bonded layer, as a function of the contact radius a: the pressure solves
/// p − ℓ²∇²p = (M/t)(δ − r²/2R) in r < a with p(a) = p'(a) = 0, so (x = a/ℓ)
///   δ = (a²/2R) D(x),  F = (π M ℓ⁴ /(R t)) x² B(x),
///   D = 1 + 4/x² − 2 I₀(x)/(x I₁(x)),  B = 2 + x²/4 − x I₀(x)/I₁(x).
/// Limits: x → ∞ (compressible) a² = 2Rδ and F = π M R δ²/t (elastic foundation);
/// x → 0 (incompressible) a² = 4Rδ and F = (2π/3) E₃ R² δ³/t³.
struct ThinLayerPoint {
  double overlap_m = 0.0;  ///< δ, m
  double force_n = 0.0;    ///< F, N
};
/// a, R, E, t > 0, ν in [0, 0.5]; std::invalid_argument otherwise.
ThinLayerPoint thin_layer_indentation(double contact_radius_m, double sphere_radius_m,
                                      double youngs_modulus_pa, double poisson_ratio, double thickness_m);
/// Elastic-foundation (compressible thin-layer) force π M R δ²/t, N (δ <= 0 gives 0).
double foundation_force(double overlap_m, double sphere_radius_m, double youngs_modulus_pa,
                        double poisson_ratio, double thickness_m);
/// Incompressible bonded thin-layer force (2π/3) E R² δ³/t³, N (ν = 0.5, E₃ = E).
double incompressible_thin_layer_force(double overlap_m, double sphere_radius_m,
                                       double youngs_modulus_pa, double thickness_m);

/// Dimitriadis et al. (2002, Biophys. J. 82:2798, bonded sample) small-χ correction,
/// χ = √(Rδ)/t: F/F_Hertz = 1 − (2α₀/π)χ + (4α₀²/π²)χ² − (8/π³)(α₀³ + 4π²β₀/15)χ³
/// + (16α₀/π⁴)(α₀³ + 3π²β₀/5)χ⁴, α₀ = −(1.2876 − 1.4678ν + 1.3442ν²)/(1 − ν),
/// β₀ = (0.6387 − 1.0277ν + 1.5164ν²)/(1 − ν) (their fits over 0.3 <= ν <= 0.5).
/// Stated valid for χ <~ 1 (their 10% band); rigid indenter.
double dimitriadis_force_ratio(double chi, double poisson_ratio);

/// Exact (linear elastic, paraboloidal sphere, frictionless) solution of a sphere
/// pressed into the bonded layer, at one contact radius. Abel representation
/// p̄(ξ) = ∫₀^a φ(s) cos ξs ds turns the mixed boundary-value problem into the Fredholm
/// equation of the second kind
///   φ(s) − (2k/π) ∫₀^a φ(u) ∫₀^∞ [1 − L(ξt)] cos ξs cos ξu dξ du = (E*/π)(δ − s²/R),
/// (k = E*/E'_layer, 1 for a rigid sphere), solved by Gauss–Legendre Nyström; δ from
/// φ(a) = 0 (no edge singularity), F = 2π ∫₀^a φ ds.
struct LayerIndentation {
  double contact_radius_over_thickness = 0.0;  ///< λ = a/t (input)
  double overlap_parameter = 0.0;              ///< χ = √(Rδ)/t
  double overlap_over_hertz = 0.0;             ///< g = Rδ/a² (1 for the half-space)
  double force_over_hertz = 0.0;               ///< F / [(4/3) E* √R δ^{3/2}] at the same δ
};
/// λ >= 0, ν in [0, 0.5], layer_share k = E*/E'_layer in (0, 1]; nodes = 0 picks the
/// quadrature from λ (converged to ~1e-7, docs); std::invalid_argument otherwise.
LayerIndentation solve_layer_indentation(double contact_radius_over_thickness, double poisson_ratio,
                                         double layer_share = 1.0, int nodes = 0);

/// Thickness-aware normal contact of a sphere (or sphere-sphere pair of effective
/// radius R*) on a layer of thickness t bonded to a rigid wall, frictionless at the
/// sphere; valid for a/t from 0 (Hertz) to the thin-layer limits. The elastic sphere
/// enters as a half-space compliance added to the layer's (exact for a ≪ R): E* from
/// both materials and the layer's kernel weighted by k = E*/E'_layer.
/// F(δ) = F_Hertz(δ)·G(χ), χ = √(R*δ)/t, G tabulated from solve_layer_indentation on a
/// uniform χ grid (cubic Hermite); beyond the table (χ > kMaxTabulatedOverlapParameter)
/// G continues as the power law of its end slope. Build: ~0.3 s (one table per (ν, k),
/// cached; copies share it). Evaluation: allocation-free, force ~20 ns, stiffness ~30 ns.
class LayeredContact {
 public:
  /// Upper end of the table in χ = √(Rδ)/t: the table covers δ = t (bottoming out)
  /// for R/t <= kMaxTabulatedOverlapParameter².
  static constexpr double kMaxTabulatedOverlapParameter = 16.0;
  /// R* > 0, t > 0 (m); E > 0 (Pa); layer ν in [0, 0.5]; sphere ν in [0, 0.5);
  /// E_sphere = +inf for a rigid sphere. std::invalid_argument otherwise.
  LayeredContact(double effective_radius_m, double layer_modulus_pa, double layer_poisson_ratio,
                 double sphere_modulus_pa, double sphere_poisson_ratio, double thickness_m);
  /// Elastic force F(δ), N; 0 for δ <= 0.
  double force(double overlap_m) const;
  /// dF/dδ, N/m; 0 for δ <= 0.
  double stiffness(double overlap_m) const;
  /// Stored energy ∫₀^δ F dδ', J; 0 for δ <= 0.
  double energy(double overlap_m) const;
  /// F/F_Hertz at χ = √(R*δ)/t (1 at χ = 0).
  double force_over_hertz(double overlap_parameter) const;
  double effective_modulus_pa() const { return effective_modulus_; }  ///< E*, Pa
  double effective_radius_m() const { return radius_; }               ///< R*, m
  double thickness_m() const { return thickness_; }                   ///< t, m
  /// Contact radius a at overlap δ (from the table of a/t), m.
  double contact_radius(double overlap_m) const;

  /// The law relative to Hertz's at χ = √(R*δ)/t, the three numbers a DEM step needs
  /// (they depend on R* and t only through χ, so one object serves every sphere size):
  struct HertzRatios {
    double force = 1.0;    ///< G = F/F_Hertz
    double damping = 1.0;  ///< √(S/S_Hertz) = √(G + χG'/3), S = dF/dδ: the damping scale ratio
    double energy = 1.0;   ///< W = U/U_Hertz
  };
  /// χ >= 0 (0 gives Hertz: all ones).
  HertzRatios hertz_ratios(double overlap_parameter) const;

  /// The same materials (and table) at another thickness t > 0.
  LayeredContact(const LayeredContact& materials, double thickness_m);

  struct Table;  ///< dimensionless G(χ), W(χ), λ(χ) on a uniform χ grid (internal)

 private:
  friend class LayeredDampingTable;  // keys its cache on the layer's (ν, k)
  double radius_ = 0.0, thickness_ = 0.0, effective_modulus_ = 0.0;
  double layer_poisson_ = 0.0, layer_share_ = 1.0;  // ν and k = E*/E'_layer of the table
  double hertz_stiffness_ = 0.0;  // K = (4/3) E* √R*
  std::shared_ptr<const Table> table_;
};

/// Elastic impact on the layered law at normal speed v > 0 with effective mass m* > 0:
/// maximum overlap (energy balance ½m*v² = U(δ_max)), its force, and the contact time
/// 2∫₀^{δ_max} dδ/√(v² − 2U(δ)/m*) (Gauss–Legendre after δ = δ_max(1 − w²)).
struct LayeredImpact {
  double max_overlap_m = 0.0;
  double max_force_n = 0.0;
  double contact_time_s = 0.0;
};
LayeredImpact layered_impact(const LayeredContact& contact, double effective_mass_kg, double impact_speed_m_s);

/// Restitution realised by the layered law with the DEM's damping generalised through
/// the local stiffness S = dF/dδ:
///   F = F_el(δ) + γ_n √((2/3) m* S(δ)) δ̇,
/// which is exactly the Hertz damping γ_n √(m*K) δ^{1/4} δ̇ of cor_models.hpp when t → ∞
/// (S = (3/2)K δ^{1/2}). Contact ends when the total force returns to zero (no tension),
/// as in the DEM. Unlike Hertz, ε depends on v and m* (the layer has a length scale t).
/// Fixed-step RK4 (docs for the accuracy). γ_n in [0, 100], m*, v > 0.
double layered_realised_restitution(const LayeredContact& contact, double effective_mass_kg,
                                    double impact_speed_m_s, double damping_coefficient);
/// γ_n with layered_realised_restitution(...) = ε (|Δε| < 1e-6), ε in [1e-3, 1].
double layered_damping_for_restitution(const LayeredContact& contact, double effective_mass_kg,
                                       double impact_speed_m_s, double restitution);

/// γ_n realising ε on the layered law, tabulated for a DEM (one solve per first touch
/// would cost milliseconds). Dimensional analysis of the one-collision ODE with δ scaled
/// by the Hertz maximum overlap δ_H = (15m*v²/(16E*√R*))^{2/5} and time by δ_H/v: the
/// inertia coefficient is m*v²/(Kδ_H^{5/2}) = 5/2 and the damping coefficient γ_n√(5/2),
/// so ε depends on (γ_n, ν, k) and, through G(χ), only on ξ = √(R*δ_H)/t: the Hertz
/// overlap parameter of the impact. The table holds ln ε on a grid of (ln ξ, ln(1 + γ_n))
/// (ln ε is nearly linear in ln(1 + γ_n), cor_models.cpp) and inverts it by linear
/// interpolation at the two neighbouring ξ nodes, blended linearly in ln ξ: realised ε
/// within 1e-3 relative of the target (test). Below ξ = kMinOverlapParameter the law is
/// Hertz's within 0.2% and the first node answers; above kMaxOverlapParameter (δ_H of
/// 10⁴t²/R*: 100 layer thicknesses at R*/t = 100, far beyond bottoming out, where the
/// hard wall takes over; the law there is the table's power-law continuation) the last
/// node answers. Build: ~0.5 s per (ν, k), cached; copies share it.
class LayeredDampingTable {
 public:
  static constexpr double kMinOverlapParameter = 1e-3;
  static constexpr double kMaxOverlapParameter = 100.0;
  /// The table of `contact`'s (ν, k); its R* and t do not matter.
  explicit LayeredDampingTable(const LayeredContact& contact);
  /// ξ = √(R*δ_H)/t of an impact at speed v >= 0 with effective mass m* > 0 on `contact`'s
  /// modulus, radius and thickness.
  static double impact_overlap_parameter(const LayeredContact& contact, double effective_mass_kg,
                                         double impact_speed_m_s);
  /// γ_n in [0, 100] for ξ >= 0 and ε in (0, 1] (ε below the table's reach gives 100).
  double damping_for_restitution(double impact_overlap_parameter, double restitution) const;

  struct Table;  ///< ln ε on the (ln ξ, ln(1 + γ)) grid (internal)

 private:
  std::shared_ptr<const Table> table_;
};

}  // namespace pdamp::formulas
