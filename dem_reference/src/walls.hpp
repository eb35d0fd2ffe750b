// Wall features of the damper body: container faces, cylinder mantles, inner plates
// and pins, and buffered layers, with the sphere–wall gap in the body frame.
#pragma once

#include <cmath>
#include <vector>

#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference::detail {

enum class WallKind {
  kPlane,           ///< infinite plane; particles on the side of `normal`
  kCylinderInside,  ///< particles inside an infinite cylinder (container mantle)
  kBox,             ///< particles outside an axis-aligned solid box (plate)
  kPin,             ///< particles outside an axis-aligned finite solid cylinder (pin)
};

struct WallFeature {
  WallKind kind = WallKind::kPlane;
  int compartment = 0;
  int material = 0;
  /// Curvature radius across the contact for Hertz: 0 flat, > 0 convex, < 0 concave, m.
  double curvature_radius_m = 0.0;
  /// > 0: the surface of a layer of this thickness bonded to the hard wall behind it
  /// (the layered contact law, formulas::LayeredContact), m; 0: a solid wall (Hertz).
  double layer_thickness_m = 0.0;
  double centre[3] = {0.0, 0.0, 0.0};  ///< body frame: plane point / axis point / box or pin centre, m
  double normal[3] = {0.0, 0.0, 0.0};  ///< plane: unit normal into the particle region
  int axis = 0;                        ///< cylinder and pin axis
  double radius = 0.0;                 ///< cylinder inner radius or pin radius, m
  double half[3] = {0.0, 0.0, 0.0};    ///< box half sizes; pin: half[0] = half length, m
};

/// Gap between the sphere (centre p in the body frame, radius r) and the wall:
/// negative = overlap. Writes the unit normal from the sphere towards the wall.
[[gnu::always_inline]] inline double wall_gap(const WallFeature& w, const double* p, double r, double* n) {
  switch (w.kind) {
    case WallKind::kPlane: {
      const double d = (p[0] - w.centre[0]) * w.normal[0] + (p[1] - w.centre[1]) * w.normal[1] +
                       (p[2] - w.centre[2]) * w.normal[2];
      n[0] = -w.normal[0];
      n[1] = -w.normal[1];
      n[2] = -w.normal[2];
      return d - r;
    }
    case WallKind::kCylinderInside: {
      double q[3] = {p[0] - w.centre[0], p[1] - w.centre[1], p[2] - w.centre[2]};
      q[w.axis] = 0.0;
      const double rho = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
      if (rho > 0.0) {
        n[0] = q[0] / rho;
        n[1] = q[1] / rho;
        n[2] = q[2] / rho;
      } else {
        n[0] = n[1] = n[2] = 0.0;
        n[(w.axis + 1) % 3] = 1.0;
      }
      return w.radius - rho - r;
    }
    case WallKind::kBox: {
      double q[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        const double lo = w.centre[a] - w.half[a];
        const double hi = w.centre[a] + w.half[a];
        q[a] = p[a] < lo ? lo : (p[a] > hi ? hi : p[a]);
        if (q[a] != p[a]) inside = false;
      }
      if (inside) {
        // Centre inside the box (deep overlap): leave through the nearest face.
        int best = 0;
        double depth = 1e300;
        double sign = 1.0;
        for (int a = 0; a < 3; ++a) {
          const double rel = p[a] - w.centre[a];
          const double d = w.half[a] - std::abs(rel);
          if (d < depth) {
            depth = d;
            best = a;
            sign = rel >= 0.0 ? 1.0 : -1.0;
          }
        }
        n[0] = n[1] = n[2] = 0.0;
        n[best] = -sign;
        return -depth - r;
      }
      const double d[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
      const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      n[0] = d[0] / dist;
      n[1] = d[1] / dist;
      n[2] = d[2] / dist;
      return dist - r;
    }
    case WallKind::kPin: {
      double rel[3] = {p[0] - w.centre[0], p[1] - w.centre[1], p[2] - w.centre[2]};
      const double s = rel[w.axis];
      rel[w.axis] = 0.0;
      const double rho = std::sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2]);
      const double len = w.half[0];
      if (rho < w.radius && std::abs(s) < len) {
        // Centre inside the pin: leave radially or through the nearer end.
        const double radial = w.radius - rho;
        const double axial = len - std::abs(s);
        n[0] = n[1] = n[2] = 0.0;
        if (radial < axial && rho > 0.0) {
          n[0] = -rel[0] / rho;
          n[1] = -rel[1] / rho;
          n[2] = -rel[2] / rho;
          return -radial - r;
        }
        n[w.axis] = s >= 0.0 ? -1.0 : 1.0;
        return -axial - r;
      }
      const double sc = s < -len ? -len : (s > len ? len : s);
      const double scale = rho > w.radius ? w.radius / rho : 1.0;
      double d[3] = {rel[0] * scale - rel[0], rel[1] * scale - rel[1], rel[2] * scale - rel[2]};
      d[w.axis] = sc - s;
      const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      n[0] = d[0] / dist;
      n[1] = d[1] / dist;
      n[2] = d[2] / dist;
      return dist - r;
    }
  }
  n[0] = n[1] = n[2] = 0.0;
  return 1e300;
}

/// Hertz curvature radius (WallFeature::curvature_radius_m convention: 0 flat, > 0
/// convex, < 0 concave) of the wall part nearest to a sphere centred at p (body frame).
/// A pin's end faces are flat: only its mantle (and, for want of a Hertz radius of a
/// sharp edge, its rims) has the pin's curvature. Taken when a contact is listed, so a
/// sphere that slides over a rim keeps the curvature of where it was listed.
[[gnu::always_inline]] inline double contact_curvature_radius(const WallFeature& w, const double* p) {
  if (w.kind != WallKind::kPin) return w.curvature_radius_m;
  double rho2 = 0.0;
  for (int a = 0; a < 3; ++a) {
    if (a != w.axis) rho2 += (p[a] - w.centre[a]) * (p[a] - w.centre[a]);
  }
  const bool beyond_end = std::abs(p[w.axis] - w.centre[w.axis]) > w.half[0];
  return beyond_end && rho2 <= w.radius * w.radius ? 0.0 : w.curvature_radius_m;
}

/// Effective inner container of a compartment: the hard container less its layers.
formulas::Container layered_container(const CompartmentOptions& c);
/// All wall features of all compartments (body frame).
std::vector<WallFeature> build_walls(const WorldOptions& options);

}  // namespace pdamp::dem_reference::detail
