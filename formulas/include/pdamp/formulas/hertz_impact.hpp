// Hertz impact of elastic spheres and buffered-wall sizing (PHYSICS.md §5).
//
// Derivations, constants and the buffer's assumptions: docs/hertz_and_buffer.md.
#pragma once

#include <string>
#include <vector>

namespace pdamp::formulas {

/// Isotropic elastic material. Defaults: structural steel.
struct Material {
  double density_kg_m3 = 7850.0;     ///< ρ, kg/m^3, > 0
  double youngs_modulus_pa = 210e9;  ///< E, Pa, > 0
  double poisson_ratio = 0.3;        ///< ν, in [0, 0.5)
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

/// Elastic impact at normal approach speed v > 0 (PHYSICS.md §5). Energy balance
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

/// Design of a polymer layer on a container wall that the design impact just
/// compresses fully ("compression collect-and-collide", PHYSICS.md §5).
/// The impact is one sphere of the bed's front row (radius r, particle material) on an
/// elastic half-space of the layer material, carrying the momentum of
/// particles_per_contact spheres; the wall behind the layer is rigid and driven.
struct BufferDesignInput {
  double frequency_hz = 60.0;  ///< design frequency f, Hz, > 0
  double amplitude_m = 0.0;    ///< design stroke X, m, >= 0; 0 = derive from intensity
  /// Design Γ = XΩ²/g (g = 9.80665 m/s²), >= 0, used when amplitude_m = 0 (then X = Γg/Ω²);
  /// ignored (with a warning if it disagrees) when amplitude_m > 0.
  double intensity = 0.0;
  double particle_radius_m = 0.0;  ///< sphere radius r, m, > 0
  Material particle;               ///< sphere material (density gives the particle mass)
  Material layer;                  ///< modulus at the design frequency and temperature (density unused)
  /// Particles whose momentum drives one contact with the layer (the collected bed
  /// hits the layer with its front row: bed_particles / front_row_particles), >= 1.
  double particles_per_contact = 1.0;
  /// Impact speed, m/s, >= 0; 0 = bouncing optimum 2XΩ (impact against the wall moving at −V).
  double impact_velocity_m_s = 0.0;
  /// One line per violation ("particle_radius_m = -0.005: must be > 0 and finite");
  /// X or Γ (or an impact speed) must be given: amplitude_m = intensity = 0 is a
  /// violation unless impact_velocity_m_s > 0.
  std::vector<std::string> validate() const;
};
struct BufferDesign {
  double layer_thickness_m = 0.0;         ///< = max_penetration_m: the design impact just bottoms out, m
  double impact_velocity_m_s = 0.0;       ///< design impact speed v, m/s
  double max_penetration_m = 0.0;         ///< Hertz δ_max at v, m
  double contact_time_s = 0.0;            ///< Hertz t_c at v, s
  double contact_time_over_period = 0.0;  ///< t_c·f; the impact picture needs it small (warning above 0.1)
  double effective_mass_kg = 0.0;         ///< m* = particles_per_contact·(4/3)πr³ρ, kg
  double max_force_n = 0.0;               ///< (4/3) E* √r δ_max^{3/2}, N
  double contact_radius_m = 0.0;          ///< a = √(r δ_max), m; half-space valid while a ≲ thickness
  std::vector<std::string> assumptions;   ///< readable sentences with the numbers used
  std::vector<std::string> warnings;      ///< validity-range violations (INTERFACE.md)
};
/// Sizes the layer: X from Γ if needed, v = 2XΩ unless given, m* from the bed's sharing,
/// E* from particle and layer, thickness = δ_max(v). Throws std::invalid_argument with
/// all of input.validate()'s lines (newline-separated) for invalid input.
BufferDesign size_buffer_layer(const BufferDesignInput& input);

}  // namespace pdamp::formulas
