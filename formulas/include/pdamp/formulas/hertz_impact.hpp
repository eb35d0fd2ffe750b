// Hertz impact of elastic spheres and buffered-wall sizing (PHYSICS.md §5).
#pragma once

#include <string>
#include <vector>

namespace pdamp::formulas {

/// Isotropic elastic material. Defaults: structural steel.
struct Material {
  double density_kg_m3 = 7850.0;     ///< ρ, kg/m^3, > 0
  double youngs_modulus_pa = 210e9;  ///< E, Pa, > 0
  double poisson_ratio = 0.3;        ///< ν, in [0, 0.5)
  std::vector<std::string> validate(const std::string& prefix) const;
};
/// 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂, Pa.
double effective_modulus(const Material& a, const Material& b);
/// E* of a sphere on a rigid wall: E/(1−ν²), Pa.
double effective_modulus_rigid(const Material& a);

/// Effective quantities of one contact: sphere-sphere (1/R* = 1/R₁ + 1/R₂,
/// 1/m* = 1/m₁ + 1/m₂) or sphere-wall (R* = R, m* = m, wall rigid unless given).
struct HertzContact {
  double effective_modulus_pa = 0.0;  ///< E*
  double effective_radius_m = 0.0;    ///< R*
  double effective_mass_kg = 0.0;     ///< m*
  /// Elastic force F = (4/3) E* √R* δ^{3/2}, N (δ >= 0 in m).
  double force(double overlap_m) const;
};
HertzContact sphere_sphere_contact(double radius1_m, double mass1_kg, const Material& m1,
                                   double radius2_m, double mass2_kg, const Material& m2);
HertzContact sphere_wall_contact(double radius_m, double mass_kg, const Material& sphere,
                                 const Material& wall);
HertzContact sphere_rigid_wall_contact(double radius_m, double mass_kg, const Material& sphere);

/// Elastic impact at normal approach speed v > 0 (PHYSICS.md §5):
/// δ_max = (15 m* v² / (16 E* √R*))^{2/5};
/// t_c = 2 (δ_max/v) ∫₀¹ (1 − x^{5/2})^{-1/2} dx ≈ 2.868 (m*²/(R* E*² v))^{1/5}.
double max_penetration(const HertzContact& contact, double impact_speed_m_s);
double contact_time(const HertzContact& contact, double impact_speed_m_s);

/// Design of a polymer layer on a container wall that the design impact just
/// compresses fully ("compression collect-and-collide", PHYSICS.md §5).
struct BufferDesignInput {
  double frequency_hz = 60.0;   ///< design frequency f, Hz, > 0
  double amplitude_m = 0.0;     ///< design stroke X, m; 0 = derive from intensity
  double intensity = 0.0;       ///< design Γ = XΩ²/g (used when amplitude_m = 0)
  double particle_radius_m = 0.0;
  Material particle;
  Material layer;               ///< modulus at the design frequency and temperature
  /// Particles whose momentum drives one contact with the layer (the collected bed
  /// hits the layer with its front row: bed_particles / front_row_particles), >= 1.
  double particles_per_contact = 1.0;
  /// Impact speed, m/s; 0 = bouncing optimum 2XΩ (impact against the wall moving at −V).
  double impact_velocity_m_s = 0.0;
  std::vector<std::string> validate() const;
};
struct BufferDesign {
  double layer_thickness_m = 0.0;      ///< = max_penetration_m: the design impact just bottoms out
  double impact_velocity_m_s = 0.0;
  double max_penetration_m = 0.0;
  double contact_time_s = 0.0;
  double contact_time_over_period = 0.0;
  double effective_mass_kg = 0.0;
  double max_force_n = 0.0;
  double contact_radius_m = 0.0;       ///< a = √(R δ_max); half-space valid while a ≲ thickness
  std::vector<std::string> assumptions;
  std::vector<std::string> warnings;
};
BufferDesign size_buffer_layer(const BufferDesignInput& input);

}  // namespace pdamp::formulas
