// Wall features from the compartment options (container faces, layers, plates, pins).
#include "walls.hpp"

namespace pdamp::dem_reference::detail {

namespace {

bool layered(const WallLayerOptions& layer, int face_axis) {
  return layer.thickness_m > 0.0 && (layer.axis < 0 || layer.axis == face_axis);
}

WallFeature plane(int compartment, int material, const Vec3& offset, int axis, double side,
                  double half_length) {
  WallFeature w;
  w.kind = WallKind::kPlane;
  w.compartment = compartment;
  w.material = material;
  for (int a = 0; a < 3; ++a) w.centre[a] = offset[static_cast<std::size_t>(a)];
  w.centre[axis] += side * half_length;
  w.normal[axis] = -side;
  return w;
}

}  // namespace

formulas::Container layered_container(const CompartmentOptions& c) {
  return c.container.lined(c.layer.thickness_m, c.layer.axis);
}

std::vector<WallFeature> build_walls(const WorldOptions& options) {
  std::vector<WallFeature> walls;
  for (std::size_t ci = 0; ci < options.compartments.size(); ++ci) {
    const auto& c = options.compartments[ci];
    const int id = static_cast<int>(ci);
    const double t = c.layer.thickness_m;
    const auto add_face = [&](int axis, double half_length) {
      for (const double side : {-1.0, 1.0}) {
        walls.push_back(plane(id, c.wall_material, c.offset_m, axis, side, half_length));
        // The layer surface is a second contact plane t inside the hard face: both act
        // once the layer is fully compressed.
        if (layered(c.layer, axis)) {
          walls.push_back(plane(id, c.layer.material, c.offset_m, axis, side, half_length - t));
          walls.back().layer_thickness_m = t;
        }
      }
    };
    if (c.container.shape == formulas::ContainerShape::kBox) {
      for (int a = 0; a < 3; ++a) add_face(a, 0.5 * c.container.box_inner_size_m[static_cast<std::size_t>(a)]);
    } else {
      const int axis = c.container.cylinder_axis;
      add_face(axis, 0.5 * c.container.cylinder_inner_length_m);
      WallFeature mantle;
      mantle.kind = WallKind::kCylinderInside;
      mantle.compartment = id;
      mantle.material = c.wall_material;
      for (int a = 0; a < 3; ++a) mantle.centre[a] = c.offset_m[static_cast<std::size_t>(a)];
      mantle.axis = axis;
      mantle.radius = c.container.cylinder_inner_radius_m;
      mantle.curvature_radius_m = -mantle.radius;
      walls.push_back(mantle);
      if (t > 0.0 && (c.layer.axis < 0 || c.layer.axis != axis)) {
        mantle.material = c.layer.material;
        mantle.radius -= t;
        mantle.curvature_radius_m = -mantle.radius;
        mantle.layer_thickness_m = t;
        walls.push_back(mantle);
      }
    }
    for (const auto& plate : c.plates) {
      WallFeature w;
      w.kind = WallKind::kBox;
      w.compartment = id;
      w.material = plate.material >= 0 ? plate.material : c.wall_material;
      for (std::size_t a = 0; a < 3; ++a) {
        w.centre[a] = c.offset_m[a] + plate.centre_m[a];
        w.half[a] = 0.5 * plate.size_m[a];
      }
      walls.push_back(w);
    }
    for (const auto& pin : c.pins) {
      WallFeature w;
      w.kind = WallKind::kPin;
      w.compartment = id;
      w.material = pin.material >= 0 ? pin.material : c.wall_material;
      for (std::size_t a = 0; a < 3; ++a) w.centre[a] = c.offset_m[a] + pin.centre_m[a];
      w.axis = pin.axis;
      w.radius = pin.radius_m;
      w.half[0] = 0.5 * pin.length_m;
      w.curvature_radius_m = pin.radius_m;
      walls.push_back(w);
    }
  }
  return walls;
}

}  // namespace pdamp::dem_reference::detail
