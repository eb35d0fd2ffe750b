// The container's rigid-body motion: the state a driver gives the world each step,
// the load the world returns, and the prescribed harmonic drive.
#pragma once

#include <array>

#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference {

/// Row-major 3×3 rotation matrix (body frame → world frame).
using Matrix3 = std::array<double, 9>;
inline constexpr Matrix3 kIdentity{1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};

/// Rigid-body state of the damper body (all compartments move with it), world frame.
struct ContainerState {
  Vec3 position_m{0.0, 0.0, 0.0};          ///< origin of the body frame, m
  Vec3 velocity_m_s{0.0, 0.0, 0.0};        ///< velocity of the body-frame origin, m/s
  Matrix3 orientation = kIdentity;         ///< body → world rotation, orthonormal
  Vec3 angular_velocity_rad_s{0.0, 0.0, 0.0};  ///< world frame, rad/s
};

/// What the container applies to the particles during one step (the structure
/// receives the opposite): the sum of all wall, inner-structure and layer contact
/// forces, and their moment about the body-frame origin.
struct ContainerLoad {
  Vec3 force_n{0.0, 0.0, 0.0};    ///< N, world frame
  Vec3 moment_nm{0.0, 0.0, 0.0};  ///< N·m, world frame, about ContainerState::position_m
};

/// A prescribed container motion: the state at any time.
class ContainerMotion {
 public:
  virtual ~ContainerMotion() = default;
  /// Rigid-body state at time t (s).
  virtual ContainerState state(double time_s) const = 0;
};

/// Harmonic translation x_c(t) = X sin(Ωt)·a along a unit axis a, Ω = 2πf
/// (docs/theory.md §1): velocity XΩ cos(Ωt)·a, no rotation.
class HarmonicMotion final : public ContainerMotion {
 public:
  /// axis: any non-zero vector (normalised here); amplitude X >= 0 m; frequency f > 0 Hz.
  /// Throws std::invalid_argument naming the value otherwise.
  HarmonicMotion(const Vec3& axis, double amplitude_m, double frequency_hz);
  ContainerState state(double time_s) const override;

  const Vec3& axis() const { return axis_; }
  double amplitude_m() const { return amplitude_m_; }
  double frequency_hz() const { return frequency_hz_; }
  double angular_frequency_rad_s() const;
  double period_s() const { return 1.0 / frequency_hz_; }
  /// V = XΩ, m/s.
  double velocity_amplitude_m_s() const;
  /// Γ = XΩ²/g with g = 9.80665 m/s².
  double intensity() const;

 private:
  Vec3 axis_;
  double amplitude_m_;
  double frequency_hz_;
};

}  // namespace pdamp::dem_reference
