// Modal reduced models of structures (PHYSICS.md §7). Level III arrives with the
// structure issue; this header holds the modal data type the couplings will share.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace pdamp::structure {

/// Mass-normalised modal data: q̈_j + 2ζ_j ω_j q̇_j + ω_j² q_j = Φ_jᵀ f.
struct ModalModel {
  Eigen::VectorXd natural_frequencies_hz;  ///< f_j, Hz, > 0
  Eigen::VectorXd damping_ratios;          ///< ζ_j, dimensionless, >= 0
  Eigen::MatrixXd mode_shapes;             ///< Φ (dofs x modes), mass-normalised, 1/√kg
  std::vector<std::string> validate() const;
};

}  // namespace pdamp::structure
