// Hertz impact of elastic spheres and buffered-wall sizing (docs/theory.md §5).
//
// Derivations, constants and the buffer's assumptions: docs/hertz_and_buffer.md.
#pragma once

#include <string>
#include <vector>

#include "pdamp/base/record.hpp"

namespace pdamp::formulas {

/// Isotropic elastic material. Defaults: structural steel.
struct Material {
  double density_kg_m3 = 7850.0;     ///< ρ, kg/m^3, > 0
  double youngs_modulus_pa = 210e9;  ///< E, Pa, > 0
  double poisson_ratio = 0.3;        ///< ν, in [0, 0.5] (0.5: incompressible)
  /// One line per violation, "<prefix>.youngs_modulus_pa = -1: must be > 0 and finite"
  /// (no prefix and dot when prefix is empty); empty when valid.
  std::vector<std::string> validate(const std::string& prefix) const;
};
/// 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂, Pa. Throws std::invalid_argument for an invalid material.
double effective_modulus(const Material& a, const Material& b);
/// E* of a sphere on a rigid wall: E/(1−ν²), Pa. Throws std::invalid_argument for an invalid material.
double effective_modulus_rigid(const Material& a);

/// Effective quantities of one contact: sphere-sphere (1/R* = 1/R₁ + 1/R₂,
/// 1/m* = 1/m₁ + 1/m₂) or sphere-wall (R* = R, m* = m, wall rigid unless given).
struct HertzContact {
  double effective_modulus_pa = 0.0;  ///< E*
  double effective_radius_m = 0.0;    ///< R*
  double effective_mass_kg = 0.0;     ///< m*
  /// Elastic force F = (4/3) E* √R* δ^{3/2}, N, for the overlap δ in m (0 for δ <= 0).
  double force(double overlap_m) const;
};
/// The factories throw std::invalid_argument naming the value unless radii and masses
/// are > 0 and finite and the materials valid.
HertzContact sphere_sphere_contact(double radius1_m, double mass1_kg, const Material& m1, double radius2_m,
                                   double mass2_kg, const Material& m2);
HertzContact sphere_wall_contact(double radius_m, double mass_kg, const Material& sphere,
                                 const Material& wall);
HertzContact sphere_rigid_wall_contact(double radius_m, double mass_kg, const Material& sphere);

/// Elastic impact at normal approach speed v > 0 (docs/theory.md §5). Energy balance
/// ½m*v² = ∫₀^δ F dδ' = (8/15) E* √R* δ^{5/2} at the turning point gives
///   δ_max = (15 m* v² / (16 E* √R*))^{2/5}, m.
/// Both throw std::invalid_argument unless v > 0 and finite and the contact's E*, R*,
/// m* are > 0 and finite.
double max_penetration(const HertzContact& contact, double impact_speed_m_s);
/// Duration of the elastic impact (approach and restitution are symmetric), s:
///   t_c = 2 (δ_max/v) I,  I = ∫₀¹ (1 − x^{5/2})^{-1/2} dx = (2/5)·B(2/5, 1/2) ≈ 1.4717,
/// i.e. t_c = contact_time_coefficient()·(m*²/(R* E*² v))^{1/5} ≈ 2.868 (m*²/(R* E*² v))^{1/5}.
double contact_time(const HertzContact& contact, double impact_speed_m_s);
/// C = 2·(15/16)^{2/5}·(2/5)·B(2/5, 1/2) ≈ 2.8683 in t_c = C (m*²/(R* E*² v))^{1/5},
/// dimensionless, exact to double precision (from std::tgamma).
double contact_time_coefficient();

/// Contact law used to size the buffer layer.
enum class BufferModel {
  /// Sphere on a layer of thickness t bonded to the rigid wall, frictionless at the
  /// sphere (LayeredContact, layered_contact.hpp): exact linear elasticity for any a/t.
  kLayered,
  /// The source study's rule: Hertz half-space of the layer material, t = δ_max(v).
  /// Ignores the wall under the layer (a/t = √(r/t) > 1 always): kept for comparison.
  kHalfSpace,
};

/// Design of a polymer layer on a container wall (docs/theory.md §5): the thickness t
/// whose tip strain under the design impact, δ_max/t (the compression of the layer under
/// the sphere's tip over its thickness), equals the allowable strain ε_a of the polymer:
/// δ_max(t) = ε_a·t. ε_a = 1 is the layer the design impact just compresses fully
/// ("bottoms out"; beyond it the hard wall's contact acts in parallel, the DEM's business).
/// The impact is one sphere of the bed's front row (radius r, particle material) on the
/// layer, carrying the momentum of particles_per_contact spheres; the wall behind the
/// layer is rigid and driven.
/// Layer Poisson ratio for polyurethane-like buffers (0.48–0.5 measured; 0.5 = incompressible).
inline constexpr double kDefaultLayerPoissonRatio = 0.48;
/// Allowable tip strain δ_max/t of a polyurethane-like buffer: about 0.3 (an elastomer
/// stays near its linear, elastic range up to a nominal compression of some tens of per
/// cent; a layer compressed fully cannot be incompressible and elastic at once).
inline constexpr double kDefaultAllowableStrain = 0.3;
struct BufferDesignInput {
  double frequency_hz = 60.0;  ///< design frequency f, Hz, > 0
  double amplitude_m = 0.0;    ///< design stroke X, m, >= 0; 0 = derive from intensity
  /// Design Γ = XΩ²/g (g = 9.80665 m/s²), >= 0, used when amplitude_m = 0 (then X = Γg/Ω²);
  /// ignored (with a warning if it disagrees) when amplitude_m > 0.
  double intensity = 0.0;
  double particle_radius_m = 0.0;  ///< sphere radius r, m, > 0
  Material particle;               ///< sphere material (density gives the particle mass)
  /// Modulus at the design frequency and temperature (density unused); ν in [0, 0.5]
  /// (0.5 = incompressible). Callers should default polyurethane-like layers to
  /// kDefaultLayerPoissonRatio.
  Material layer{1200.0, 60e6, kDefaultLayerPoissonRatio};
  /// Particles whose momentum drives one contact with the layer (the collected bed
  /// hits the layer with its front row: bed_particles / front_row_particles), >= 1.
  double particles_per_contact = 1.0;
  /// Impact speed, m/s, >= 0; 0 = bouncing optimum 2XΩ (impact against the wall moving at −V).
  double impact_velocity_m_s = 0.0;
  BufferModel model = BufferModel::kLayered;  ///< contact law of the sizing
  /// Allowable tip strain ε_a = δ_max/t at the design impact, in (0, 1] (1: the design
  /// impact compresses the layer fully). kLayered only: the half-space rule is the
  /// source study's t = δ_max and ignores it.
  double allowable_strain = kDefaultAllowableStrain;
  /// One line per violation ("particle_radius_m = -0.005: must be > 0 and finite");
  /// X or Γ (or an impact speed) must be given: amplitude_m = intensity = 0 is a
  /// violation unless impact_velocity_m_s > 0.
  std::vector<std::string> validate() const;
};
struct BufferDesign {
  BufferModel model = BufferModel::kLayered;  ///< contact law used
  /// Layered: the t whose tip strain at the design impact is the allowable one,
  /// δ_max(t) = ε_a·t, i.e. ½m*v² = ∫₀^{ε_a t} F(δ; t) dδ. Half-space: t = Hertz δ_max. m
  double layer_thickness_m = 0.0;
  /// ε_a the thickness was sized to: the input's (layered), 1 (half-space: t = δ_max).
  double allowable_strain = 1.0;
  double impact_velocity_m_s = 0.0;       ///< design impact speed v, m/s
  /// δ_max at v under the model's law (= allowable_strain·layer_thickness_m), m
  double max_penetration_m = 0.0;
  double contact_time_s = 0.0;            ///< elastic contact time at v under the model's law, s
  double contact_time_over_period = 0.0;  ///< t_c·f; the impact picture needs it small (warning above 0.1)
  double effective_mass_kg = 0.0;         ///< m* = particles_per_contact·(4/3)πr³ρ, kg
  double max_force_n = 0.0;               ///< F(δ_max) under the model's law, N
  /// Contact radius at δ_max, m: layered from the exact solution; half-space √(r δ_max).
  double contact_radius_m = 0.0;
  double contact_radius_over_thickness = 0.0;  ///< a/t at δ_max
  /// Both models' comparison numbers, whichever sizes: the half-space thickness
  /// t_H = Hertz δ_max(v), m, and δ_max/t_H under the layered law for a layer of
  /// thickness t_H (how far the design impact really compresses the half-space design).
  double half_space_thickness_m = 0.0;
  double layered_compression_of_half_space_design = 0.0;
  std::vector<std::string> assumptions;   ///< readable sentences with the numbers used
  std::vector<std::string> warnings;      ///< validity-range violations (docs/command_line.md)
  static const base::Fields<BufferDesign>& fields();
};
/// Sizes the layer: X from Γ if needed, v = 2XΩ unless given, m* from the bed's sharing,
/// E* from particle and layer; kLayered: t from ½m*v² = U(ε_a t; t) with the layered law
/// (bisection in ln t), t_c from the one-degree-of-freedom impact; kHalfSpace: t = δ_max(v).
/// Throws std::invalid_argument with all of input.validate()'s lines (newline-separated)
/// for invalid input.
BufferDesign size_buffer_layer(const BufferDesignInput& input);
/// The tip strain δ_max/t that the input's design impact (speed and m* as size_buffer_layer
/// takes them) gives a bonded layer of thickness t > 0 under the layered law: a layer
/// survives its design impact when this is at most input.allowable_strain. Throws
/// std::invalid_argument for invalid input or t.
double layer_tip_strain(const BufferDesignInput& input, double thickness_m);

}  // namespace pdamp::formulas
