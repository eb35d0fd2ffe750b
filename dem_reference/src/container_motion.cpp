// Harmonic container motion x_c = X sin(Ωt) along an axis (docs/theory.md §1).
#include "pdamp/dem_reference/container_motion.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pdamp::dem_reference {

namespace {
constexpr double kTwoPi = 6.28318530717958647692;
}  // namespace

HarmonicMotion::HarmonicMotion(const Vec3& axis, double amplitude_m, double frequency_hz)
    : axis_(axis), amplitude_m_(amplitude_m), frequency_hz_(frequency_hz) {
  const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    std::ostringstream msg;
    msg << "drive_axis = [" << axis[0] << ", " << axis[1] << ", " << axis[2] << "]: must be a finite non-zero vector";
    throw std::invalid_argument(msg.str());
  }
  if (!std::isfinite(amplitude_m) || amplitude_m < 0.0) {
    throw std::invalid_argument("amplitude_m = " + std::to_string(amplitude_m) + ": must be >= 0");
  }
  if (!std::isfinite(frequency_hz) || frequency_hz <= 0.0) {
    throw std::invalid_argument("frequency_hz = " + std::to_string(frequency_hz) + ": must be > 0");
  }
  for (auto& a : axis_) a /= norm;
}

ContainerState HarmonicMotion::state(double time_s) const {
  const double omega = angular_frequency_rad_s();
  const double s = amplitude_m_ * std::sin(omega * time_s);
  const double v = amplitude_m_ * omega * std::cos(omega * time_s);
  ContainerState state;
  for (std::size_t a = 0; a < 3; ++a) {
    state.position_m[a] = s * axis_[a];
    state.velocity_m_s[a] = v * axis_[a];
  }
  return state;
}

double HarmonicMotion::angular_frequency_rad_s() const { return kTwoPi * frequency_hz_; }
double HarmonicMotion::velocity_amplitude_m_s() const { return amplitude_m_ * angular_frequency_rad_s(); }
double HarmonicMotion::intensity() const {
  const double omega = angular_frequency_rad_s();
  return amplitude_m_ * omega * omega / formulas::kStandardGravity;
}

}  // namespace pdamp::dem_reference
