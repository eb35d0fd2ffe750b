// Modal reduced models of structures (docs/theory.md §7): the data every coupling shares.
// A ModalModel comes from the beam finite elements (beam.hpp) or from imported modal
// data (a user's own FE package; a 1-DOF oscillator is one mode).
//
// Planar convention: a structure lies in the x-y plane, rotations are about z. For a
// beam, x runs along its axis from its first end, y is transverse in the plane.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace pdamp::structure {

/// The shape of every mode at one named point: displacement (x, y) and rotation (about z)
/// per unit modal coordinate q_j.
struct PointModeShape {
  std::string name;
  Eigen::MatrixXd translation;  ///< 2 x modes: rows x, y; m per unit q
  Eigen::RowVectorXd rotation;  ///< 1 x modes; rad per unit q
};

/// Modal equations  m_j (q̈_j + 2ζ_j ω_j q̇_j + ω_j² q_j) = Σ_points φ_j(p)ᵀ F_p − Γ_jᵀ ü_base.
/// Mass-normalised modes have m_j = 1 kg (units of φ then 1/√kg); imported data may
/// carry other modal masses. Base motion is a rigid translation of every support.
struct ModalModel {
  Eigen::VectorXd natural_frequencies_hz;  ///< f_j, Hz, > 0, ascending
  Eigen::VectorXd damping_ratios;          ///< ζ_j, dimensionless, >= 0
  Eigen::VectorXd modal_masses_kg;         ///< m_j, kg, > 0 (1 for mass-normalised shapes)
  std::vector<PointModeShape> points;      ///< shapes at the named points
  /// Γ (modes x 2): column k is Φᵀ M r_k for a unit base translation along x (k = 0) or
  /// y (k = 1), in kg per unit q. Empty (0 columns) when the model cannot take base motion.
  Eigen::MatrixXd base_participation;
  /// Full FE mode shapes (dofs x modes), empty for imported data.
  Eigen::MatrixXd mode_shapes;

  Eigen::Index mode_count() const { return natural_frequencies_hz.size(); }
  /// The named point; throws std::invalid_argument naming it (and the known names) if absent.
  const PointModeShape& point(const std::string& name) const;
  /// Problems, one line each, naming the field and the allowed range; empty when valid.
  std::vector<std::string> validate() const;
};

/// The static response of the retained modes to a force F (x, y) at a named point:
/// q0_j = φ_j(p)·F/(m_j ω_j²), the initial state of a release from imported modal data
/// (truncated to the kept modes; a beam's static_deflection_modal_amplitudes projects the
/// exact static deflection instead). Throws std::invalid_argument for an unknown point.
Eigen::VectorXd modal_static_deflection_amplitudes(const ModalModel& model, const std::string& point,
                                                   const Eigen::Vector2d& force_n);

}  // namespace pdamp::structure
