// The base-excited beam of the clearance-on-structure problem, shared by its test and the
// benchmark (bench/bench_optimizer.cpp), so both solve the same problem.
#pragma once

#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/structure/beam.hpp"

namespace pdamp::test {

/// cases/beam_base_excited.json: a standing 0.6 m spring-steel cantilever, 30 x 2 mm,
/// clamped at its foot, gravity compressing it, the damper (0.3 kg container, 36 spheres
/// of 5 mm = 0.148 kg) at the tip, whose weight loads the geometric stiffness.
inline structure::ModalModel beam_model() {
  structure::BeamModel beam;
  structure::BeamSegment segment;
  segment.length_m = 0.6;
  segment.section.shape = structure::SectionShape::kSolidRectangle;
  segment.section.width_m = 0.03;
  segment.section.depth_m = 0.002;
  segment.material = {206e9, 7850.0};
  segment.elements = 24;
  beam.segments.push_back(segment);
  beam.supports.push_back({structure::Support::Kind::kClamped, 0.0, 0.0, 0.0, 0.0});
  beam.points.push_back({"tip", 0.6});
  beam.points.push_back({"middle", 0.3});
  beam.carried_weights.push_back({0.6, 0.3 + 0.148});
  beam.axial_gravity_m_s2 = -9.80665;
  beam.geometric_stiffness = true;
  structure::ModalDamping damping;
  damping.ratios = {0.002};
  return structure::beam_modal_model(beam, 3, damping).modal;
}

inline optimizer::ClearanceOnStructureOptions beam_options() {
  optimizer::ClearanceOnStructureOptions o;
  o.site = "tip";
  o.drive_direction = {0.0, 1.0};
  o.base_direction = {0.0, 1.0};
  o.container_mass_kg = 0.3;
  o.bed_mass_kg = 0.148;
  o.model = formulas::DamperModel::kRolling;
  o.base_amplitude_m = 1.33e-3;
  o.frequency_min_hz = 1.2;
  o.frequency_max_hz = 2.4;
  o.frequency_points = 200;
  return o;
}

}  // namespace pdamp::test
