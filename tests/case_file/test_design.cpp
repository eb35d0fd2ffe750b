// Designs of a filling_ratios case as cases of their own (case_file::with_design): read
// again by the reader, with their own beds, resolved JSON and physics hash.
#include <catch2/catch.hpp>

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
