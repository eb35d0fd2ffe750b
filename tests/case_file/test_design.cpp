// Designs of a filling_ratios case as cases of their own (case_file::with_design): read
// again by the reader, with their own beds, resolved JSON and physics hash.
#include <catch2/catch.hpp>

#include <cmath>

#include "pdamp/case_file/case.hpp"

using namespace pdamp;

namespace {

case_file::Case shipped() {
  return case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/manipulator_link_optimize.json");
}

}  // namespace

// Reference: the reader itself on the edited document (counts = slabs x spheres per slab,
// the bed mass the count's), and the case's own softening times the design's.
TEST_CASE("a design is the case read again with its slabs, its layers of no slab left out", "[case_file]") {
  const auto c = shipped();
  const auto& task = *c.task.filling_ratios;
  REQUIRE(c.dampers.front().layers.size() == 3);
  const auto d = case_file::with_design(c, {6, 0, 2}, 1e-3);
  const auto& layers = d.dampers.front().layers;
  REQUIRE(layers.size() == 2);
  CHECK(layers[0].name == c.dampers.front().layers[0].name);
  CHECK(layers[1].name == c.dampers.front().layers[2].name);  // not renamed by the gap
  CHECK(layers[0].particle_count == 6 * task.spheres_per_slab[0]);
  CHECK(layers[1].particle_count == 2 * task.spheres_per_slab[2]);
  const auto& original = c.dampers.front().layers[0];
  CHECK(layers[0].bed_mass_kg == Approx(original.bed_mass_kg / original.particle_count * layers[0].particle_count));
  CHECK(layers[0].clearance_m < original.container.inner_length(c.dampers.front().drive_axis));
  CHECK(d.dem.stiffness_softening == Approx(c.dem.stiffness_softening * 1e-3));
  // The design's own identity: another design hashes differently, the same one the same.
  CHECK(case_file::physics_hash(d, "dem") != case_file::physics_hash(c, "dem"));
  CHECK(case_file::physics_hash(case_file::with_design(c, {6, 0, 2}, 1e-3), "dem") == case_file::physics_hash(d, "dem"));
  CHECK(case_file::physics_hash(case_file::with_design(c, {6, 1, 2}, 1e-3), "dem") != case_file::physics_hash(d, "dem"));
}

TEST_CASE("a design the reader refuses is the case's error naming the layer", "[case_file]") {
  const auto c = shipped();
  try {
    (void)case_file::with_design(c, {1000, 1, 1});
    FAIL("no error");
  } catch (const case_file::CaseError& e) {
    CHECK_THAT(e.pointer(), Catch::StartsWith("/dampers/0/layers/0"));
  }
  CHECK_THROWS_AS(case_file::with_design(c, {1, 1}), case_file::CaseError);
}

// Reference: the container is the bed plus h along the drive, so lengthening it by Δh
// gives the reader's derived clearance h + Δh with the bed unchanged; the task becomes the
// frf of the clearance task's band and base motion.
TEST_CASE("a clearance variant is the case read again with its container changed along the drive", "[case_file]") {
  const auto c = case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/beam_clearance.json");
  const auto& layer = c.dampers.front().layers.front();
  REQUIRE(layer.clearance_m == Approx(0.030).epsilon(1e-9));
  const auto v = case_file::with_clearance(c, 0.0112);
  const auto& changed = v.dampers.front().layers.front();
  CHECK(changed.clearance_m == Approx(0.0112).epsilon(1e-9));
  CHECK(changed.container.inner_length(0) == Approx(layer.container.inner_length(0) - 0.0188).epsilon(1e-9));
  CHECK(changed.bed_mass_kg == Approx(layer.bed_mass_kg));
  REQUIRE(v.task.kind == case_file::TaskKind::kFrf);
  CHECK(v.task.frf->min_frequency_hz == c.task.clearance->band.min_frequency_hz);
  CHECK(v.task.frf->base_amplitude_m == c.task.clearance->band.base_amplitude_m);
  // A clearance the bed does not fit into is the reader's error naming the container.
  try {
    (void)case_file::with_clearance(c, -0.01);
    FAIL("no error");
  } catch (const case_file::CaseError& e) {
    CHECK_THAT(e.pointer(), Catch::StartsWith("/dampers/0/layers/0"));
  }
}

// Reference: geometry by hand. The shipped buffered case lines both end caps (t = 2 mm) of a
// 99.5 mm cylinder around a staggered lattice of 21 slabs, 20√2 r + 2r = 75.71 mm: the clearance
// between the linings is 99.5 − 4 − 75.71 mm. A thicker lining in the same container takes twice
// its change off h; the clearance patch on that case restores h with the container 2Δt longer.
TEST_CASE("a buffered wall's lining takes its thickness off the clearance, and its variant keeps h", "[case_file]") {
  const auto c = case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/free_free_beam_buffered_clearance.json");
  const auto& layer = c.dampers.front().layers.front();
  const double extent = 20.0 * std::sqrt(2.0) * 0.0025 + 0.005;
  REQUIRE(layer.compartment.layer.thickness_m == 0.002);
  CHECK(layer.clearance_m == Approx(0.0995 - 0.004 - extent).epsilon(1e-12));
  const auto thicker = case_file::with_merge_patch(c, case_file::wall_layer_patch(c, 0.003));
  CHECK(thicker.dampers.front().layers.front().clearance_m == Approx(layer.clearance_m - 0.002).epsilon(1e-12));
  const auto same_h = case_file::with_merge_patch(thicker, case_file::clearance_patch(thicker, layer.clearance_m));
  const auto& kept = same_h.dampers.front().layers.front();
  CHECK(kept.clearance_m == Approx(layer.clearance_m).epsilon(1e-12));
  CHECK(kept.compartment.layer.thickness_m == 0.003);
  CHECK(kept.container.inner_length(0) == Approx(0.0995 + 0.002).epsilon(1e-12));
  // A lining that leaves no room is refused naming it; a layer without one has no variant.
  try {
    (void)case_file::with_merge_patch(c, case_file::wall_layer_patch(c, 0.05));
    FAIL("no error");
  } catch (const case_file::CaseError& e) {
    CHECK(e.pointer() == "/dampers/0/layers/0/wall_layer/thickness_m");
  }
  const auto bare = case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/cases/free_free_beam_mode_clearance.json");
  CHECK_THROWS_AS(case_file::wall_layer_patch(bare, 0.001), case_file::CaseError);
}
