// Coefficient-of-restitution models: the contact level of pdamp (docs/theory.md §6).
#pragma once

#include <memory>
#include <span>
#include <string>
#include <vector>

namespace pdamp::formulas {

/// ε(v): normal restitution as a function of the normal impact speed v >= 0 (m/s).
/// restitution() throws std::invalid_argument for a negative or non-finite speed.
class RestitutionModel {
 public:
  virtual ~RestitutionModel() = default;
  /// ε in (0, 1] at the normal impact speed v >= 0, m/s.
  virtual double restitution(double impact_speed_m_s) const = 0;
  /// Short description for reports, e.g. "constant 0.8".
  virtual std::string describe() const = 0;
};

/// ε = const in (0, 1].
std::unique_ptr<RestitutionModel> make_constant_restitution(double restitution);

/// ε = ε₀ − k·v (v in m/s), clamped to [kMinLinearRestitution, 1]: the steel-polymer
/// trend of docs/theory.md §6 (nearly flat, slight linear decrease). ε₀ in (0, 1], k finite
/// (s/m; k > 0 is a decrease).
std::unique_ptr<RestitutionModel> make_linear_restitution(double intercept, double slope_s_per_m);
/// Floor of the linear law, so that a steep line never gives ε <= 0.
inline constexpr double kMinLinearRestitution = 1e-3;

/// Tabulated ε(v) with monotone piecewise-cubic (Fritsch–Carlson 1980) interpolation:
/// exact at the nodes, no overshoot between them (monotone data give a monotone
/// curve), linear data reproduced exactly; clamped to the end values outside the
/// table. speeds strictly increasing (>= 0, finite), values in (0, 1], >= 2 points,
/// equal lengths; std::invalid_argument otherwise.
std::unique_ptr<RestitutionModel> make_tabulated_restitution(std::span<const double> speeds_m_s,
                                                             std::span<const double> values);

/// Thornton (1997, J. Appl. Mech. 64:383) elastic–perfectly-plastic impact of a
/// sphere: Hertz loading up to the limiting contact pressure p_y, then a linear
/// plastic force–overlap law, Hertz unloading with an enlarged radius. With r = v_y/v:
/// ε = 1 for v <= v_y and, above,
/// ε = √(6√3/5)·√(1 − r²/6)·[r/(r + 2√(6/5 − r²/5))]^{1/4},
/// continuous at v_y, decreasing, ε ~ 1.19·r^{1/4} (∝ v^{−1/4}) for v ≫ v_y.
/// p_y is the limiting contact PRESSURE, not the yield stress Y (p_y ≈ 1.6 Y at first
/// yield: use make_thornton_restitution_from_yield_stress for Y). E* (Pa), R* (m),
/// m* (kg) are the contact's effective quantities (docs/theory.md §5); all > 0.
std::unique_ptr<RestitutionModel> make_thornton_restitution(double limiting_pressure_pa,
                                                            double effective_modulus_pa,
                                                            double effective_radius_m,
                                                            double effective_mass_kg);
/// Peak (centre) contact pressure over yield stress at first yield of a Hertz contact
/// (Johnson, Contact Mechanics 1985, ch. 6: p₀ = 1.60 Y for ν = 0.3, von Mises; the
/// mean pressure is then 2/3 p₀ = 1.07 Y). Thornton's p_y limits the peak pressure.
inline constexpr double kLimitingPressurePerYieldStress = 1.6;
/// Thornton's law from the yield stress Y (Pa) of the softer body: p_y = 1.6·Y.
std::unique_ptr<RestitutionModel> make_thornton_restitution_from_yield_stress(
    double yield_stress_pa, double effective_modulus_pa, double effective_radius_m,
    double effective_mass_kg);
/// Yield speed of an elastic sphere contact: the impact speed at which the Hertz
/// peak pressure p₀ = 2E*a/(πR*) (a² = R*δ) reaches p_y, from ½m*v² = (8/15)E*√R*δ^{5/2}:
/// v_y² = (π⁵/30)·R*³ p_y⁵ /(E*⁴ m*), m/s. For a sphere on a flat (m* = (4/3)πR³ρ,
/// R* = R) v_y = √(π⁴/40)·√(p_y⁵/(E*⁴ρ)) = 1.56·√(p_y⁵/(E*⁴ρ)) as in Thornton (1997).
/// All inputs > 0 and finite; std::invalid_argument otherwise.
double yield_speed(double limiting_pressure_pa, double effective_modulus_pa,
                   double effective_radius_m, double effective_mass_kg);

/// Measured impacts: normal impact speed (m/s) and restitution.
struct ImpactData {
  std::vector<double> speed_m_s;
  std::vector<double> restitution;
};
/// Reads a CSV with a header naming the columns `impact_speed_m_s` and `restitution`
/// (any order, extra columns ignored, blank lines and lines starting with '#'
/// skipped); std::invalid_argument naming file and line for a missing column, a
/// short row, a non-numeric or non-finite value, a negative speed, ε outside (0, 1]
/// or a file without data rows, and if the file cannot be read (missing, a directory,
/// a FIFO: base::read_input_file).
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
/// Least-squares fit (NLopt SLSQP, bounded) of a law to measured data, minimising
/// Σ(ε_law(v_i) − ε_i)². kConstant needs >= 1 point, kLinear >= 2 distinct speeds
/// and keeps the line in [kMinLinearRestitution, 1] over [0, max speed]; kThornton
/// fits ln p_y (conditioning) for the given E* (Pa), R* (m), m* (kg), all > 0, and
/// needs >= 1 point. std::invalid_argument for bad data or parameters.
RestitutionFit fit_restitution(const ImpactData& data, RestitutionLaw law,
                               double effective_modulus_pa = 0.0, double effective_radius_m = 0.0,
                               double effective_mass_kg = 0.0);

/// Damped Hertz contact F = K δ^{3/2} + γ_n·√(m* K)·δ^{1/4}·δ̇ (K = (4/3)E*√R*): in
/// units δ₀ = (m*v²/K)^{2/5} and t₀ = δ₀/v it is x'' = −x^{3/2} − γ_n x^{1/4} x',
/// x(0) = 0, x'(0) = 1, so ε depends on the dimensionless γ_n alone, for any speed,
/// mass and stiffness. The textbook law (docs/theory.md §6, S_n = 2E*√(R*δ) = (3/2)Kδ^{1/2})
/// is γ_n = −√5·β with β = ln ε/√(ln²ε + π²); it reaches ε (to ~1e-6) only if the
/// contact is taken to end at zero overlap with a tensile force allowed.
/// pdamp's contact ends when the total force returns to zero (no tension), which
/// happens at a positive overlap, so the realised ε is higher (0.397 for a target 0.3).
/// realised_restitution(γ_n) integrates the dimensionless ODE to that end (adaptive
/// Dormand–Prince from a series start, |error| < 1e-10, ~30 µs) for γ_n in
/// [0, kMaxDampingCoefficient]; std::invalid_argument otherwise. ε falls from 1 with
/// slope −π/√5 at γ_n = 0 and tends to ≈ 1.25/γ_n² for large γ_n.
double realised_restitution(double damping_coefficient);
/// Largest γ_n accepted (ε = 1.25e-4): beyond it the zero of the total force lies in
/// a slow creeping return whose force (~x^{5/2}/γ_n²) drowns in the integration error.
inline constexpr double kMaxDampingCoefficient = 100.0;
/// γ_n >= 0 with realised_restitution(γ_n) = ε for ε in [kMinCalibratedRestitution, 1]
/// (ε = 1 gives 0); the realised ε matches to 1e-9 (absolute). Costs ~6 one-collision
/// solves (~0.2 ms): use DampingTable in a time loop.
double damping_for_restitution(double restitution);
/// Smallest ε damping_for_restitution accepts (γ_n ≈ 35).
inline constexpr double kMinCalibratedRestitution = 1e-3;

/// Precomputed inverse for the DEM's hot loop (velocity-dependent ε needs a γ_n
/// per impact): γ_n linearly interpolated on a uniform grid of ε over
/// [kMinRestitution, 1]; |realised ε − ε| < 1e-5 everywhere on that range.
/// Built once (~a few ms); the lookup is a few ns and never allocates.
class DampingTable {
 public:
  static constexpr double kMinRestitution = 0.01;  ///< lower end of the table's ε range
  static constexpr int kPoints = 2001;             ///< uniform ε grid points
  DampingTable();
  /// γ_n for ε in [kMinRestitution, 1]; std::invalid_argument outside.
  double damping_for_restitution(double restitution) const {
    if (!(restitution >= kMinRestitution && restitution <= 1.0)) throw_out_of_range(restitution);
    const double position = (restitution - kMinRestitution) * kInverseStep;
    const int index = position >= kPoints - 1 ? kPoints - 2 : static_cast<int>(position);
    const double fraction = position - index;
    return damping_[index] + fraction * (damping_[index + 1] - damping_[index]);
  }

 private:
  static constexpr double kInverseStep = (kPoints - 1) / (1.0 - kMinRestitution);
  [[noreturn]] static void throw_out_of_range(double restitution);
  std::vector<double> damping_;  // γ_n at ε_i = kMinRestitution + i/kInverseStep
};

}  // namespace pdamp::formulas
