// Particle dampers attached to a modal model: the first-harmonic equivalent dynamic
// stiffness of each bed layer and the point mass of each container (docs/theory.md §7.2,
// docs/structure_coupling.md §1-2).
#pragma once

#include <complex>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/structure/modal_model.hpp"
#include "pdamp/surrogate/loss_model.hpp"

namespace pdamp::structure {

/// One bed in a container: its own clearance and characteristic live in its loss model.
struct DamperLayer {
  std::string name;                                          ///< label for reports
  double bed_mass_kg = 0.0;                                  ///< m_bed, kg, > 0
  std::shared_ptr<const surrogate::LossModel> loss_model;    ///< η*(f, X), m_app/m_bed(f, X); required
  /// The bed has come down from above its loss model's onset (free_decay sets it for a
  /// release above the onset): the coupling then asks loss_model->evaluate_from_above.
  bool from_above = false;
};

/// A particle damper at a named point of a ModalModel.
///
/// The container is rigid and follows the point's translation: its empty mass acts along
/// x and y as a point mass, added exactly to the modal dynamic stiffness as
/// −Ω² m_c Φ_dᵀΦ_d (Φ_d the 2 x modes translation rows at the point; this couples the modes,
/// the modal basis is not recomputed), and its rotary inertia J_c about the out-of-plane axis
/// through the site as −Ω² J_c θ_dᵀθ_d (θ_d the point's rotation row). The beds
/// act along the drive direction n only (across the drive they are taken as carried by the
/// base without dissipation: neither mass nor damping is added there).
struct Damper {
  std::string name;                            ///< label for reports
  std::string point;                           ///< named point of the ModalModel
  Eigen::Vector2d drive_direction{1.0, 0.0};   ///< unit vector n in the x-y plane (the container's drive axis)
  double container_mass_kg = 0.0;              ///< empty container m_c, kg, >= 0
  /// Empty container's moment of inertia about the out-of-plane axis through the site,
  /// kg·m², >= 0 (0: neglected; a box of mass m and sides a (drive), b (in-plane, across)
  /// centred on the site has m(a² + b²)/12).
  double container_rotary_inertia_kg_m2 = 0.0;
  /// Length of the container along its drive, m, >= 0 (0: unknown; rotation_warnings
  /// then says nothing). Only for the rotation check: the beds act at the site.
  double length_along_drive_m = 0.0;
  std::vector<DamperLayer> layers;             ///< beds, each at its own clearance; may be empty
  /// One line per violated rule, prefixed "dampers[i]." by the caller's index.
  std::vector<std::string> validate(const ModalModel& model) const;
};

/// Where the site rotates, the container's ends move beyond its translation: by θ_j·L/2 in
/// mode j (θ_j the site's rotation per unit q_j, L the container's length along the drive)
/// against its translation along the drive b_dj. The closed forms and the fields are for a
/// container in pure translation, so one sentence per damper and mode where θ_j·L/2 exceeds
/// `fraction` of |b_dj| (0.1 by default: the beds' ends then see 10% more or less stroke).
std::vector<std::string> rotation_warnings(const ModalModel& model, const std::vector<Damper>& dampers,
                                           double fraction = 0.1);
/// The ratio rotation_warnings tests, θ_j·(L/2) / |b_dj| with b_dj = Φ_j(site)·n: the
/// container ends' extra motion from the site's rotation against its translation along
/// the drive, dimensionless; 0 when L <= 0 (unknown) or θ_j = 0, +infinity at a node of
/// the translation where the site still rotates.
double rotation_ratio(const PointModeShape& site, Eigen::Index mode, const Eigen::Vector2d& drive_direction,
                      double length_along_drive_m);

/// How the coupling treats answers a loss model cannot give.
struct CouplingOptions {
  /// m_app/m_bed used where a loss model returns NaN (a field without apparent mass),
  /// dimensionless: 1 = bed carried rigidly (the classical added mass, default), 0 = bed
  /// that transmits no inertial force (the ideal bouncing orbit at its peak). Flagged
  /// kLossApparentMassMissing in the result. Any finite value.
  double apparent_mass_fraction_if_missing = 1.0;
  std::vector<std::string> validate() const;
};

/// The first-harmonic equivalent of one layer at drive amplitude X (absolute, along n).
///
/// Force the container applies to the bed, F̂ = Z(Ω, X)·X̂, with
///   Z = −Ω² m_bed (m_app/m_bed) + iΩ c_eq,   c_eq = η*(f, X)·m_bed·Ω,
/// so the bed pushes the structure with −F̂. Check: the energy per cycle π c_eq Ω X² equals
/// 2π·η*·½ m_bed (XΩ)², the definition of η* (docs/theory.md §1), and Im(F̂ conj V̂)/(Ω|V̂|²)
/// = m_app (V̂ = iΩX̂).
struct LayerImpedance {
  std::complex<double> dynamic_stiffness_n_m;    ///< Z, N/m
  std::complex<double> d_dynamic_stiffness_d_stroke;  ///< ∂Z/∂X at fixed Ω, N/m²
  double eta_star = 0.0;                          ///< η* used
  double apparent_mass_fraction = 0.0;            ///< m_app/m_bed used (after the NaN rule)
  std::uint32_t loss_warnings = 0;                ///< surrogate::LossWarning bits
};
/// Z of one layer at f (> 0, Hz) and stroke X (> 0, m).
LayerImpedance layer_impedance(const DamperLayer& layer, double frequency_hz, double stroke_m,
                               const CouplingOptions& options = {});

/// A damper's sum over its layers (the container mass is not in it: it is linear and
/// belongs to the structure's dynamic stiffness).
struct DamperImpedance {
  std::complex<double> dynamic_stiffness_n_m;         ///< Σ Z_l, N/m
  std::complex<double> d_dynamic_stiffness_d_stroke;  ///< Σ ∂Z_l/∂X, N/m²
  std::uint32_t loss_warnings = 0;                    ///< OR of the layers' bits
};
DamperImpedance damper_impedance(const Damper& damper, double frequency_hz, double stroke_m,
                                 const CouplingOptions& options = {});

/// The strokes at which any layer of the damper jumps at f, ascending and unique, m.
std::vector<double> damper_discontinuities_m(const Damper& damper, double frequency_hz);
/// The union of the layers' stroke ranges at f, m (the scan range of a root search).
surrogate::StrokeRange damper_stroke_range_m(const Damper& damper, double frequency_hz);

/// A modal model with dampers attached, in the arrays every coupling solver uses.
struct CoupledModel {
  Eigen::VectorXd angular_frequencies_rad_s;  ///< ω_j, rad/s
  Eigen::VectorXd damping_ratios;             ///< ζ_j
  Eigen::VectorXd modal_masses_kg;            ///< m_j, kg
  /// Modal mass matrix with the containers: diag(m_j) + Σ_d m_c,d Φ_dᵀΦ_d, kg.
  Eigen::MatrixXd mass_with_containers_kg;
  /// Column d: b_d = Φ_dᵀ n_d, the damper's drive displacement per unit modal coordinate.
  Eigen::MatrixXd drive_shapes;
  /// Γ (modes x 2) of the model (empty if it cannot take base motion).
  Eigen::MatrixXd base_participation;
  /// Σ_d m_c,d Φ_dᵀ (modes x 2): the containers' share of the base-motion load, kg.
  Eigen::MatrixXd container_participation;
  std::vector<Damper> dampers;
  CouplingOptions options;
};
/// Checks what the coupling uses of the model (sizes, signs; ModalModel::validate stays the
/// owner of the full rules), the dampers and the options, and builds the
/// arrays; throws std::invalid_argument with every violation, one per line.
CoupledModel couple(const ModalModel& model, const std::vector<Damper>& dampers,
                    const CouplingOptions& options = {});

/// Natural frequencies of the modal model with the empty containers attached (beds
/// removed), Hz, ascending: the modal stiffness diag(m_j ω_j²) against
/// mass_with_containers_kg, the linear system of the FRF's "without beds" curve.
/// std::runtime_error if the eigensolver fails.
Eigen::VectorXd natural_frequencies_with_containers_hz(const CoupledModel& coupled);

/// The linear modal dynamic stiffness with the containers (layers removed), modes x modes:
/// diag(m_j(ω_j² − Ω² + 2iζ_jω_jΩ)) − Ω²·Σ m_c Φ_dᵀΦ_d. Writes into `out` (resized once).
void linear_dynamic_stiffness(const CoupledModel& coupled, double angular_frequency_rad_s,
                              Eigen::MatrixXcd& out);

}  // namespace pdamp::structure
