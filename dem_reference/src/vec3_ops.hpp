// Dot product and norm of Vec3 for the run machinery (private; one written order of
// operations, so every part that projects on the drive gets the same bits).
#pragma once

#include <cmath>

#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference::detail {

inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

}  // namespace pdamp::dem_reference::detail
