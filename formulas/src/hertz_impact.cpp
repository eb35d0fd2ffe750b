// Hertz contact of elastic spheres, impact penetration and duration, and buffered-wall sizing.
#include "pdamp/formulas/hertz_impact.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "pdamp/base/checks.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"  // kPi, kStandardGravity
#include "pdamp/formulas/layered_contact.hpp"

namespace pdamp::formulas {

const base::Fields<BufferDesign>& BufferDesign::fields() {
  using B = BufferDesign;
  static const auto f =
      base::Fields<B>()
          .derived("model", [](const B& b) { return std::string(b.model == BufferModel::kLayered ? "layered" : "half_space"); },
                   "", "the contact law the layer was sized with: layered or half_space")
          .field("layer_thickness_m", &B::layer_thickness_m, "m", "the layer thickness t")
          .field("allowable_strain", &B::allowable_strain, "1", "the tip strain t was sized to")
          .field("impact_velocity_m_s", &B::impact_velocity_m_s, "m/s", "the design impact speed")
          .field("max_penetration_m", &B::max_penetration_m, "m", "delta_max at that speed")
          .field("contact_time_s", &B::contact_time_s, "s", "the elastic contact time")
          .field("contact_time_over_period", &B::contact_time_over_period, "1", "contact time times the frequency")
          .field("effective_mass_kg", &B::effective_mass_kg, "kg", "the mass behind one contact")
          .field("max_force_n", &B::max_force_n, "N", "the peak contact force")
          .field("contact_radius_m", &B::contact_radius_m, "m", "the contact radius at delta_max")
          .field("contact_radius_over_thickness", &B::contact_radius_over_thickness, "1", "a/t at delta_max")
          .field("half_space_thickness_m", &B::half_space_thickness_m, "m", "the half-space rule's thickness")
          .field("layered_compression_of_half_space_design", &B::layered_compression_of_half_space_design, "1",
                 "delta_max/t of a layer of that thickness under the layered law")
          .field("assumptions", &B::assumptions, "", "sentences with the numbers used")
          .field("warnings", &B::warnings, "", "validity-range violations");
  return f;
}
namespace {

/// Thresholds of the buffer's validity warnings (docs/hertz_and_buffer.md).
constexpr double kMaxContactTimeOverPeriod = 0.1;    // impact short against the period
constexpr double kMaxContactRadiusOverRadius = 0.2;  // Hertz small-strain: a ≪ r
constexpr double kIntensityMismatch = 1e-6;          // relative X-Γ disagreement warned about
// Half-space sizing warned about above this a/t: at a/t = 0.3 the exact bonded-layer
// solution is already 1.3-1.45x stiffer than Hertz for nu = 0.3-0.5 (docs).
constexpr double kMaxHalfSpaceContactOverThickness = 0.3;

using base::format_number;
using base::positive_finite;
using base::violation;

std::string field(const std::string& prefix, const char* name) {
  return prefix.empty() ? std::string(name) : prefix + "." + name;
}

bool valid(const Material& m) {
  return positive_finite(m.density_kg_m3) && positive_finite(m.youngs_modulus_pa) && m.poisson_ratio >= 0.0 &&
         m.poisson_ratio <= 0.5;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) text += (text.empty() ? "" : "\n") + line;
  return text;
}

void require_valid(const Material& m, const char* function, const char* name) {
  if (!valid(m)) throw std::invalid_argument(std::string(function) + ": " + joined(m.validate(name)));
}

/// (1 − ν²)/E: the compliance of one body in 1/E*.
double compliance(const Material& m) {
  return (1.0 - m.poisson_ratio * m.poisson_ratio) / m.youngs_modulus_pa;
}

void require_valid(const HertzContact& c, double speed, const char* function) {
  base::require_positive("impact_speed_m_s", speed, function);
  base::require_positive("effective_modulus_pa", c.effective_modulus_pa, function);
  base::require_positive("effective_radius_m", c.effective_radius_m, function);
  base::require_positive("effective_mass_kg", c.effective_mass_kg, function);
}

/// I = ∫₀¹ (1 − x^{5/2})^{-1/2} dx = (2/5)·B(2/5, 1/2) (substitute u = x^{5/2}).
double half_contact_integral() {
  static const double value = 0.4 * std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
  return value;
}

}  // namespace

std::vector<std::string> Material::validate(const std::string& prefix) const {
  std::vector<std::string> problems;
  if (!positive_finite(density_kg_m3)) {
    problems.push_back(violation(field(prefix, "density_kg_m3"), density_kg_m3, "> 0 and finite"));
  }
  if (!positive_finite(youngs_modulus_pa)) {
    problems.push_back(violation(field(prefix, "youngs_modulus_pa"), youngs_modulus_pa, "> 0 and finite"));
  }
  // ν = 0.5 (incompressible: rubbers, polyurethane) is allowed. Hertz (E* = E/(1−ν²)),
  // Mindlin's G* and the Rayleigh time stay finite there; only the constrained modulus
  // of a thin bonded layer diverges, and the layered law (layered_contact.hpp) takes
  // that limit.
  if (!(poisson_ratio >= 0.0 && poisson_ratio <= 0.5)) {
    problems.push_back(violation(field(prefix, "poisson_ratio"), poisson_ratio, "in [0, 0.5]"));
  }
  return problems;
}

double effective_modulus(const Material& a, const Material& b) {
  require_valid(a, "effective_modulus", "a");
  require_valid(b, "effective_modulus", "b");
  return 1.0 / (compliance(a) + compliance(b));
}

double effective_modulus_rigid(const Material& a) {
  require_valid(a, "effective_modulus_rigid", "a");
  return 1.0 / compliance(a);
}

double HertzContact::force(double overlap_m) const {
  if (!(overlap_m > 0.0)) return 0.0;
  return 4.0 / 3.0 * effective_modulus_pa * std::sqrt(effective_radius_m) * overlap_m * std::sqrt(overlap_m);
}

HertzContact sphere_sphere_contact(double radius1_m, double mass1_kg, const Material& m1, double radius2_m,
                                   double mass2_kg, const Material& m2) {
  constexpr const char* kFunction = "sphere_sphere_contact";
  base::require_positive("radius1_m", radius1_m, kFunction);
  base::require_positive("mass1_kg", mass1_kg, kFunction);
  base::require_positive("radius2_m", radius2_m, kFunction);
  base::require_positive("mass2_kg", mass2_kg, kFunction);
  require_valid(m1, kFunction, "m1");
  require_valid(m2, kFunction, "m2");
  HertzContact contact;
  contact.effective_modulus_pa = 1.0 / (compliance(m1) + compliance(m2));
  contact.effective_radius_m = radius1_m * radius2_m / (radius1_m + radius2_m);
  contact.effective_mass_kg = mass1_kg * mass2_kg / (mass1_kg + mass2_kg);
  return contact;
}

HertzContact sphere_wall_contact(double radius_m, double mass_kg, const Material& sphere,
                                 const Material& wall) {
  constexpr const char* kFunction = "sphere_wall_contact";
  base::require_positive("radius_m", radius_m, kFunction);
  base::require_positive("mass_kg", mass_kg, kFunction);
  require_valid(sphere, kFunction, "sphere");
  require_valid(wall, kFunction, "wall");
  return {1.0 / (compliance(sphere) + compliance(wall)), radius_m, mass_kg};
}

HertzContact sphere_rigid_wall_contact(double radius_m, double mass_kg, const Material& sphere) {
  constexpr const char* kFunction = "sphere_rigid_wall_contact";
  base::require_positive("radius_m", radius_m, kFunction);
  base::require_positive("mass_kg", mass_kg, kFunction);
  require_valid(sphere, kFunction, "sphere");
  return {1.0 / compliance(sphere), radius_m, mass_kg};
}

double max_penetration(const HertzContact& contact, double impact_speed_m_s) {
  require_valid(contact, impact_speed_m_s, "max_penetration");
  const double v = impact_speed_m_s;
  return std::pow(15.0 * contact.effective_mass_kg * v * v /
                      (16.0 * contact.effective_modulus_pa * std::sqrt(contact.effective_radius_m)),
                  0.4);
}

double contact_time(const HertzContact& contact, double impact_speed_m_s) {
  // Energy conservation gives δ' = v√(1 − (δ/δ_max)^{5/2}); the approach takes
  // (δ_max/v)·I and the restitution the same.
  return 2.0 * half_contact_integral() * max_penetration(contact, impact_speed_m_s) / impact_speed_m_s;
}

double contact_time_coefficient() { return 2.0 * std::pow(15.0 / 16.0, 0.4) * half_contact_integral(); }

std::vector<std::string> BufferDesignInput::validate() const {
  std::vector<std::string> problems;
  const auto positive = [&](double value, const char* name) {
    if (!positive_finite(value)) problems.push_back(violation(name, value, "> 0 and finite"));
  };
  const auto non_negative = [&](double value, const char* name) {
    if (!base::non_negative_finite(value)) problems.push_back(violation(name, value, ">= 0 and finite"));
  };
  positive(frequency_hz, "frequency_hz");
  non_negative(amplitude_m, "amplitude_m");
  non_negative(intensity, "intensity");
  non_negative(impact_velocity_m_s, "impact_velocity_m_s");
  if (amplitude_m == 0.0 && intensity == 0.0 && impact_velocity_m_s == 0.0) {
    problems.push_back(
        "amplitude_m = 0 and intensity = 0: give the design stroke or intensity (or impact_velocity_m_s)");
  }
  positive(particle_radius_m, "particle_radius_m");
  if (!(particles_per_contact >= 1.0 && std::isfinite(particles_per_contact))) {
    problems.push_back(violation("particles_per_contact", particles_per_contact, ">= 1 and finite"));
  }
  for (auto& line : particle.validate("particle")) problems.push_back(std::move(line));
  for (auto& line : layer.validate("layer")) problems.push_back(std::move(line));
  // ε_a = 1 is full compression; a strain above it would put the sphere through the layer.
  if (!(allowable_strain > 0.0 && allowable_strain <= 1.0)) {
    problems.push_back(violation("allowable_strain", allowable_strain, "in (0, 1]"));
  }
  if (model != BufferModel::kLayered && model != BufferModel::kHalfSpace) {
    problems.push_back("model = " + std::to_string(static_cast<int>(model)) + ": must be layered or half_space");
  }
  return problems;
}

namespace {

/// The design impact of a buffer: the stroke (given, or from Γ), the impact speed (given,
/// or the bouncing optimum's 2XΩ) and the mass m* that drives one contact.
struct DesignImpact {
  double stroke_m = 0.0, speed_m_s = 0.0, effective_mass_kg = 0.0;
};

DesignImpact design_impact(const BufferDesignInput& input, const char* caller) {
  if (const auto problems = input.validate(); !problems.empty())
    throw std::invalid_argument(std::string(caller) + ": " + joined(problems));
  const double omega = 2.0 * kPi * input.frequency_hz;
  const double r = input.particle_radius_m;
  DesignImpact impact;
  impact.stroke_m = input.amplitude_m > 0.0 ? input.amplitude_m : input.intensity * kStandardGravity / (omega * omega);
  impact.speed_m_s = input.impact_velocity_m_s > 0.0 ? input.impact_velocity_m_s : 2.0 * impact.stroke_m * omega;
  impact.effective_mass_kg = input.particles_per_contact * input.particle.density_kg_m3 * 4.0 / 3.0 * kPi * r * r * r;
  return impact;
}

LayeredContact layer_contact(const BufferDesignInput& input, double thickness_m) {
  return LayeredContact(input.particle_radius_m, input.layer.youngs_modulus_pa, input.layer.poisson_ratio,
                        input.particle.youngs_modulus_pa, input.particle.poisson_ratio, thickness_m);
}

}  // namespace

double layer_tip_strain(const BufferDesignInput& input, double thickness_m) {
  const DesignImpact impact = design_impact(input, "layer_tip_strain");
  if (!(thickness_m > 0.0) || !std::isfinite(thickness_m))
    throw std::invalid_argument("layer_tip_strain: thickness_m = " + format_number(thickness_m, 6) +
                                ": must be > 0 and finite");
  return layered_impact(layer_contact(input, thickness_m), impact.effective_mass_kg, impact.speed_m_s).max_overlap_m /
         thickness_m;
}

BufferDesign size_buffer_layer(const BufferDesignInput& input) {
  const DesignImpact impact = design_impact(input, "size_buffer_layer");
  const double f = input.frequency_hz;
  const double omega = 2.0 * kPi * f;
  const double r = input.particle_radius_m;
  const double stroke = impact.stroke_m;
  const double intensity = stroke * omega * omega / kStandardGravity;

  BufferDesign design;
  design.impact_velocity_m_s = impact.speed_m_s;
  design.effective_mass_kg = impact.effective_mass_kg;
  // E* from both materials (the layer may be incompressible: E*, not Material::validate).
  const double layer_compliance =
      (1.0 - input.layer.poisson_ratio * input.layer.poisson_ratio) / input.layer.youngs_modulus_pa;
  const HertzContact contact{1.0 / (compliance(input.particle) + layer_compliance), r, design.effective_mass_kg};
  const double v = design.impact_velocity_m_s;
  const double half_space_thickness = max_penetration(contact, v);
  design.half_space_thickness_m = half_space_thickness;
  const auto layered = [&](double thickness_m) { return layer_contact(input, thickness_m); };
  const LayeredContact half_space_design = layered(half_space_thickness);
  design.layered_compression_of_half_space_design =
      layered_impact(half_space_design, design.effective_mass_kg, v).max_overlap_m / half_space_thickness;
  design.model = input.model;
  if (input.model == BufferModel::kHalfSpace) {
    design.allowable_strain = 1.0;  // the source study's rule, t = δ_max, as it was
    design.max_penetration_m = half_space_thickness;
    design.layer_thickness_m = half_space_thickness;
    design.contact_time_s = contact_time(contact, v);
    design.max_force_n = contact.force(design.max_penetration_m);
    design.contact_radius_m = std::sqrt(r * design.max_penetration_m);
  } else {
    // δ_max(t) = ε_a t  <=>  ½m*v² = U(ε_a t; t) (energy balance at the turning point,
    // docs/hertz_and_buffer.md "Buffered-wall sizing"). U(ε_a t; t) grows with t: with
    // χ = √(rε_a/t) it is U_Hertz(ε_a t)·W(χ), ∝ t^{5/2} for a/t → 0, ∝ t² for the
    // compressible and ∝ t for the incompressible thin layer. Bisection on ln t between
    // t_H/ε_a (an upper bound: the bonded layer is stiffer than Hertz, G >= 1, so
    // U(ε_a t; t) >= U_Hertz(t_H) = ½m*v² there) and 1e-6 of it. ε_a = 1 is the former
    // full-compression sizing, to the bit.
    const double strain = input.allowable_strain;
    design.allowable_strain = strain;
    const double kinetic = 0.5 * design.effective_mass_kg * v * v;
    double hi = half_space_thickness / strain, lo = 1e-6 * hi;
    for (int i = 0; i < 200 && hi / lo - 1.0 > 1e-13; ++i) {
      const double mid = std::sqrt(lo * hi);
      (layered(mid).energy(strain * mid) > kinetic ? hi : lo) = mid;
    }
    const double thickness = std::sqrt(lo * hi);
    const LayeredContact law = layered(thickness);
    const LayeredImpact impact = layered_impact(law, design.effective_mass_kg, v);
    design.layer_thickness_m = thickness;
    design.max_penetration_m = impact.max_overlap_m;  // = ε_a t to the bisection's 1e-13
    design.contact_time_s = impact.contact_time_s;
    design.max_force_n = impact.max_force_n;
    design.contact_radius_m = law.contact_radius(impact.max_overlap_m);
  }
  design.contact_time_over_period = design.contact_time_s * f;
  design.contact_radius_over_thickness = design.contact_radius_m / design.layer_thickness_m;
  const double thickness = design.layer_thickness_m;
  const double a = design.contact_radius_m;

  auto& said = design.assumptions;
  if (input.impact_velocity_m_s > 0.0) {
    said.push_back("Impact speed v = " + format_number(v, 4) + " m/s as given (not derived from the design stroke).");
  } else {
    const std::string origin = input.amplitude_m > 0.0
                                   ? "the design stroke X = " + format_number(stroke, 4) + " m"
                                   : "the design stroke X = Gamma*g/Omega^2 = " + format_number(stroke, 4) +
                                         " m (Gamma = " + format_number(input.intensity, 4) + ")";
    said.push_back("Impact speed v = 2*X*Omega = " + format_number(v, 4) + " m/s from " + origin +
                   " at f = " + format_number(f, 4) +
                   " Hz: at the bouncing optimum the bed leaves one wall at the peak container velocity V = X*Omega "
                   "and meets the other wall moving at -V (docs/theory.md, section 2).");
  }
  if (input.particles_per_contact == 1.0) {
    said.push_back("One sphere (r = " + format_number(r, 4) + " m, m = " + format_number(design.effective_mass_kg, 4) +
                   " kg) hits the layer alone: particles_per_contact = 1.");
  } else {
    said.push_back("The bed's mass is shared over its front row: each front-row sphere (r = " + format_number(r, 4) +
                   " m) hits the layer carrying " + format_number(input.particles_per_contact, 4) +
                   " spheres, m* = " + format_number(design.effective_mass_kg, 4) +
                   " kg, as a rigid column (no wave travel or rebound inside the bed).");
  }
  const bool half_space = input.model == BufferModel::kHalfSpace;
  said.push_back(
      "The wall behind the layer is rigid and driven (no wall mass in m*); the layer is bonded to the wall "
      "and the sphere's contact with the layer is frictionless; E* = " +
      format_number(contact.effective_modulus_pa, 4) + " Pa from both materials.");
  said.push_back("Layer modulus E = " + format_number(input.layer.youngs_modulus_pa, 4) +
                 " Pa (nu = " + format_number(input.layer.poisson_ratio, 3) +
                 ") is taken at the design frequency and temperature: polymers are rate- and temperature-dependent "
                 "(viscoelastic), and the contact law is elastic, so the layer's own loss is not in this sizing.");
  if (half_space) {
    said.push_back(
        "Model half_space (the source study's sizing): Hertz treats the layer as a half-space, valid while "
        "the contact radius a = sqrt(r*delta) is small against the thickness; here a = " +
        format_number(a, 4) + " m is " + format_number(a / thickness, 3) + " times the thickness " +
        format_number(thickness, 4) +
        " m. Under the layered law (bonded layer) the design impact compresses this layer to only " +
        format_number(design.layered_compression_of_half_space_design, 3) + " of its thickness.");
    said.push_back(
        "The thickness equals the Hertz delta_max so the design impact just compresses the layer fully "
        "(strain 1 under the sphere's tip): a first sizing beyond linear elasticity, to be checked in the "
        "DEM. The allowable strain (" +
        format_number(input.allowable_strain, 4) + ") is not used by this rule (model layered sizes to it).");
  } else {
    const double strain = design.allowable_strain;
    said.push_back(
        "Model layered: sphere on an elastic layer of thickness t bonded to the rigid wall (exact linear "
        "elasticity for any a/t, Hertz for a/t -> 0, thin-layer limits for a/t >> 1; "
        "docs/hertz_and_buffer.md). The thickness t = " +
        format_number(thickness, 4) + " m is the one whose tip strain at the design impact is the allowable strain " +
        format_number(strain, 4) + " (delta_max = " + format_number(design.max_penetration_m, 4) +
        " m, the compression under the sphere's tip over the thickness): 1/2 m* v^2 = integral_0^(eps_a t) "
        "F(delta; t) ddelta. The half-space sizing would give " +
        format_number(half_space_thickness, 4) + " m, which this impact compresses to only " +
        format_number(design.layered_compression_of_half_space_design, 3) + " of its thickness.");
    said.push_back(
        "At the design impact the contact radius is a = " + format_number(a, 4) +
        " m, a/t = " + format_number(a / thickness, 3) + "; a tip strain of " + format_number(strain, 3) +
        (strain >= 1.0 ? " (full compression: the layer bottoms out) is far beyond linear elasticity"
                       : " is beyond the small strains of linear elasticity") +
        " (and the paraboloid needs a << r): a sizing estimate, to be checked in the DEM with the layered law.");
  }
  auto& warn = design.warnings;
  if (design.contact_time_over_period > kMaxContactTimeOverPeriod) {
    warn.push_back("contact time " + format_number(design.contact_time_s, 4) + " s is " +
                   format_number(design.contact_time_over_period, 3) +
                   " of the period (> 0.1): the impact is not short against the period, so it is not an impact "
                   "and the collect-and-collide timing does not hold");
  }
  if (half_space && a > kMaxHalfSpaceContactOverThickness * thickness) {
    warn.push_back("half-space sizing: contact radius a = " + format_number(a, 4) + " m is " +
                   format_number(a / thickness, 3) + " times the layer thickness " + format_number(thickness, 4) +
                   " m (> 0.3): the layer is thin, not the half-space Hertz assumes; bonded to the rigid wall it is "
                   "stiffer, and the design impact compresses it to only " +
                   format_number(design.layered_compression_of_half_space_design, 3) +
                   " of its thickness (model layered)");
  }
  // χ = √(r δ_max)/t at the design impact (√(r/t) at full compression).
  const double chi = std::sqrt(r * design.max_penetration_m) / thickness;
  if (!half_space && chi > LayeredContact::kMaxTabulatedOverlapParameter) {
    warn.push_back("layered law: sqrt(r*delta_max)/t = " + format_number(chi, 3) + " exceeds the tabulated " +
                   "exact solution (" + format_number(LayeredContact::kMaxTabulatedOverlapParameter, 3) +
                   "): the force continues as the table's end power law (thin-layer regime)");
  }
  if (a > kMaxContactRadiusOverRadius * r) {
    warn.push_back("contact radius a = " + format_number(a, 4) + " m is " + format_number(a / r, 3) +
                   " of the particle radius " + format_number(r, 4) +
                   " m (> 0.2): the contact law needs a << r (small strain, paraboloidal sphere)");
  }
  if (input.impact_velocity_m_s == 0.0 && intensity < 1.0) {
    warn.push_back("design intensity Gamma = " + format_number(intensity, 3) +
                   " < 1: the bed rolls rather than flies (docs/theory.md, section 3), so the bouncing impact "
                   "speed 2*X*Omega "
                   "overestimates the impact");
  }
  if (input.amplitude_m > 0.0 && input.intensity > 0.0 &&
      std::abs(input.intensity - intensity) > kIntensityMismatch * intensity) {
    warn.push_back("intensity = " + format_number(input.intensity, 6) +
                   " disagrees with amplitude_m = " + format_number(input.amplitude_m, 6) +
                   " m (Gamma = " + format_number(intensity, 6) + "): the amplitude is used");
  }
  return design;
}

}  // namespace pdamp::formulas
