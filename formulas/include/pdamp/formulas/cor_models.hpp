// Coefficient-of-restitution models, the contact level of pdamp (PHYSICS.md §6).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace pdamp::formulas {

/// ε(v): normal restitution as a function of the normal impact speed v >= 0 (m/s).
class RestitutionModel {
 public:
  virtual ~RestitutionModel() = default;
  virtual double restitution(double impact_speed_m_s) const = 0;
  /// Short description for reports, e.g. "constant 0.8".
  virtual std::string describe() const = 0;
};

/// ε = const in (0, 1].
std::unique_ptr<RestitutionModel> make_constant_restitution(double restitution);
/// Tabulated ε(v) with monotone piecewise-cubic (Fritsch-Carlson) interpolation,
/// clamped to the end values outside the table. speeds strictly increasing (>= 0),
/// values in (0, 1], >= 2 points; std::invalid_argument otherwise.
std::unique_ptr<RestitutionModel> make_tabulated_restitution(std::span<const double> speeds_m_s,
                                                             std::span<const double> values);
/// Thornton (1997) elastic-perfectly-plastic impact: ε = 1 for v <= v_y and
/// ε = √(6√3/5)·√(1 − (v_y/v)²/6)·[(v_y/v)/((v_y/v) + 2√(6/5 − (v_y/v)²/5))]^{1/4}
/// above, with v_y from the limiting contact pressure p_y (NOT the yield stress Y;
/// p_y ≈ 1.6 Y at first yield) and the contact's E*, R*, m*.
std::unique_ptr<RestitutionModel> make_thornton_restitution(double limiting_pressure_pa,
                                                            double effective_modulus_pa,
                                                            double effective_radius_m,
                                                            double effective_mass_kg);
/// Yield speed of an elastic sphere contact: the impact speed at which the Hertz
/// peak pressure reaches p_y, v_y² = (π⁵/30)·R*³ p_y⁵ /(E*⁴ m*) (for a sphere on a
/// flat, = 1.56² p_y⁵/(E*⁴ρ) as in Thornton 1997), m/s.
double yield_speed(double limiting_pressure_pa, double effective_modulus_pa,
                   double effective_radius_m, double effective_mass_kg);

/// Measured impacts: normal impact speed (m/s) and restitution.
struct ImpactData {
  std::vector<double> speed_m_s;
  std::vector<double> restitution;
};
/// Reads a CSV with a header naming the columns `impact_speed_m_s` and `restitution`
/// (any order, extra columns ignored); std::invalid_argument naming file and line.
ImpactData read_impact_csv(const std::string& path);

enum class RestitutionLaw {
  kConstant,  ///< ε = ε₀
  kLinear,    ///< ε = ε₀ − k·v (steel-polymer: nearly flat, slight decrease)
  kThornton,  ///< fit p_y with the given E*, R*, m*
};
struct RestitutionFit {
  RestitutionLaw law = RestitutionLaw::kConstant;
  std::vector<double> coefficients;  ///< kConstant: {ε₀}; kLinear: {ε₀, k s/m}; kThornton: {p_y Pa}
  double rms_residual = 0.0;         ///< √(mean (ε_fit − ε_data)²)
  int points = 0;
  std::unique_ptr<RestitutionModel> model;
};
/// Least-squares fit (NLopt) of a law to measured data; the contact's E*, R*, m*
/// are needed for kThornton only.
RestitutionFit fit_restitution(const ImpactData& data, RestitutionLaw law,
                               double effective_modulus_pa = 0.0, double effective_radius_m = 0.0,
                               double effective_mass_kg = 0.0);

/// Damped Hertz contact F = K δ^{3/2} + γ_n·√(m* K)·δ^{1/4}·δ̇ (K = (4/3)E*√R*): in
/// units δ/δ₀ and t/t₀ it is x'' = −x^{3/2} − γ_n x^{1/4} x', so ε depends on the
/// dimensionless γ_n alone, for any speed, mass and stiffness. The textbook law
/// (PHYSICS.md §6, S_n = 2E*√(R*δ) = (3/2)Kδ^{1/2}) is γ_n = −√5·β with
/// β = ln ε/√(ln²ε + π²), but it reaches ε only if the contact is taken to end at
/// zero overlap with a tensile force allowed.
/// pdamp's contact ends when the total force returns to zero (no tension), so γ_n
/// is calibrated by a one-collision solve: realised_restitution(γ_n) integrates the
/// dimensionless ODE to that end, and damping_for_restitution inverts it.
double realised_restitution(double damping_coefficient);
/// γ_n >= 0 with realised_restitution(γ_n) = ε, ε in (0, 1]; relative accuracy 1e-9.
double damping_for_restitution(double restitution);
/// Precomputed inverse for the DEM's hot loop (velocity-dependent ε needs a γ_n
/// per impact): damping coefficient interpolated from a fine table, |error in
/// realised ε| < 1e-4 over ε in [0.01, 1].
class DampingTable {
 public:
  DampingTable();
  double damping_for_restitution(double restitution) const;
 private:
  std::vector<double> damping_;  // at ε on a uniform grid
};

}  // namespace pdamp::formulas
