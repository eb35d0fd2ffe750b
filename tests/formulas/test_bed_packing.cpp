// Tests of the collected lattice bed: placement, clearance and the rejected inputs.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "pdamp/formulas/bed_packing.hpp"

namespace {

namespace fm = pdamp::formulas;

// Geometric checks use 1e-12 m: the coordinates are sums of a few multiples of r
// (~1e-2 m), whose round-off is ~1e-17 m; 1e-12 m is far below any real misplacement.
constexpr double kGeometry = 1e-12;

fm::Container level2_box() {
  fm::Container box;
  box.box_inner_size_m = {0.160, 0.061, 0.040};
  return box;
}

fm::Container cylinder(double radius_m, double length_m, int axis) {
  fm::Container c;
  c.shape = fm::ContainerShape::kCylinder;
  c.cylinder_inner_radius_m = radius_m;
  c.cylinder_inner_length_m = length_m;
  c.cylinder_axis = axis;
  return c;
}

fm::LatticePacking along_x_gravity_down() {
  fm::LatticePacking packing;
  packing.drive_axis = 0;
  packing.gravity_axis_sign = std::pair{2, -1};
  return packing;
}

double distance(const fm::Vec3& p, const fm::Vec3& q) {
  return std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
}

// Brute force over all pairs: the smallest centre distance (reference for "no overlap").
double min_pair_distance(const std::vector<fm::Vec3>& centres) {
  double smallest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < centres.size(); ++i) {
    for (std::size_t j = i + 1; j < centres.size(); ++j)
      smallest = std::min(smallest, distance(centres[i], centres[j]));
  }
  return smallest;
}

void check_inside_box(const fm::Container& box, const std::vector<fm::Vec3>& centres, double r) {
  for (const auto& c : centres) {
    for (int axis = 0; axis < 3; ++axis)
      CHECK(std::abs(c[axis]) + r <= 0.5 * box.box_inner_size_m[axis] + kGeometry);
  }
}

void check_inside_cylinder(const fm::Container& cyl, const std::vector<fm::Vec3>& centres, double r) {
  const int axis = cyl.cylinder_axis;
  for (const auto& c : centres) {
    const double radial = std::hypot(c[(axis + 1) % 3], c[(axis + 2) % 3]);
    CHECK(radial + r <= cyl.cylinder_inner_radius_m + kGeometry);
    CHECK(std::abs(c[axis]) + r <= 0.5 * cyl.cylinder_inner_length_m + kGeometry);
  }
}

std::map<double, int> count_by(const std::vector<fm::Vec3>& centres, int axis) {
  std::map<double, int> counts;
  for (const auto& c : centres) ++counts[c[axis]];
  return counts;
}

}  // namespace

TEST_CASE("36 spheres of 5 mm on a 6x6x1 lattice in the Level II box leave a clearance of 100 mm",
          "[formulas]") {
  const fm::Container box = level2_box();
  fm::LatticePacking packing = along_x_gravity_down();
  packing.lattice_counts = std::array{6, 6, 1};
  const double r = 0.005;
  const fm::LatticeBed bed = fm::collected_lattice(box, 36, r, packing);

  // Hand result: 6 slabs of 2r = 10 mm along the 160 mm drive: h = 160 − 60 = 100 mm.
  REQUIRE(bed.centres_m.size() == 36);
  CHECK(bed.slabs == 6);
  CHECK(bed.bed_extent_m == Approx(0.060).margin(kGeometry));
  CHECK(bed.clearance_m == Approx(0.100).margin(kGeometry));
  check_inside_box(box, bed.centres_m, r);
  CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));

  // First slab against the collect wall at x = −80 mm: centres at −75 mm, then every 10 mm.
  const auto by_x = count_by(bed.centres_m, 0);
  REQUIRE(by_x.size() == 6);
  CHECK(by_x.begin()->first == Approx(-0.075).margin(kGeometry));
  CHECK(by_x.rbegin()->first == Approx(-0.025).margin(kGeometry));
  for (const auto& [x, n] : by_x) CHECK(n == 6);
  // One layer resting on the floor (gravity −z): z = −20 + 5 mm.
  for (const auto& c : bed.centres_m) CHECK(c[2] == Approx(-0.015).margin(kGeometry));
  // Centred across y: from −25 to +25 mm in the 61 mm width.
  const auto by_y = count_by(bed.centres_m, 1);
  CHECK(by_y.begin()->first == Approx(-0.025).margin(kGeometry));
  CHECK(by_y.rbegin()->first == Approx(0.025).margin(kGeometry));
}

TEST_CASE("a bed collected on the positive side mirrors the negative one", "[formulas]") {
  fm::LatticePacking packing = along_x_gravity_down();
  packing.lattice_counts = std::array{6, 6, 1};
  packing.collect_side = +1;
  const fm::LatticeBed bed = fm::collected_lattice(level2_box(), 36, 0.005, packing);
  CHECK(bed.clearance_m == Approx(0.100).margin(kGeometry));
  const auto by_x = count_by(bed.centres_m, 0);
  CHECK(by_x.rbegin()->first == Approx(0.075).margin(kGeometry));
  CHECK(by_x.begin()->first == Approx(0.025).margin(kGeometry));
}

TEST_CASE("a partly used explicit lattice counts only the slabs it fills", "[formulas]") {
  fm::LatticePacking packing = along_x_gravity_down();
  packing.lattice_counts = std::array{6, 6, 1};
  const fm::LatticeBed bed = fm::collected_lattice(level2_box(), 33, 0.005, packing);
  // 33 = 5 full slabs of 6 + 3: six slabs, the last partial; h = 160 − 60 mm.
  CHECK(bed.slabs == 6);
  CHECK(bed.clearance_m == Approx(0.100).margin(kGeometry));
  CHECK(count_by(bed.centres_m, 0).rbegin()->second == 3);
  CHECK(fm::collected_lattice(level2_box(), 30, 0.005, packing).clearance_m ==
        Approx(0.110).margin(kGeometry));
}

TEST_CASE("the automatic fill takes every site of a slab, lowest first", "[formulas]") {
  const fm::Container box = level2_box();
  const double r = 0.005;
  const fm::LatticeBed bed = fm::collected_lattice(box, 36, r, along_x_gravity_down());
  // Hand count: floor(61/10) = 6 sites across y, floor(40/10) = 4 up z: 24 per slab, so
  // 36 spheres take 2 slabs (24 + 12) and h = 160 − 20 = 140 mm.
  CHECK(bed.slabs == 2);
  CHECK(bed.clearance_m == Approx(0.140).margin(kGeometry));
  check_inside_box(box, bed.centres_m, r);
  CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));

  // The second slab (x = −65 mm) holds its 12 spheres in the two lowest rows.
  std::map<double, int> second_slab_rows;
  for (const auto& c : bed.centres_m) {
    if (std::abs(c[0] + 0.065) < kGeometry) ++second_slab_rows[c[2]];
  }
  REQUIRE(second_slab_rows.size() == 2);
  CHECK(second_slab_rows.begin()->first == Approx(-0.015).margin(kGeometry));
  CHECK(second_slab_rows.rbegin()->first == Approx(-0.005).margin(kGeometry));
  CHECK(second_slab_rows.begin()->second == 6);

  SECTION("the order is deterministic and the bed rests on the wall gravity points to") {
    fm::LatticePacking packing;
    packing.drive_axis = 0;
    packing.gravity_axis_sign = std::pair{1, +1};  // gravity towards +y
    const fm::LatticeBed first = fm::collected_lattice(box, 30, r, packing);
    const fm::LatticeBed again = fm::collected_lattice(box, 30, r, packing);
    CHECK(first.centres_m == again.centres_m);
    // The lowest row touches the +y wall (centre r below +30.5 mm); the 6 spheres of
    // the partial second slab (30 = 24 + 6) fill the 4 sites of that row and 2 of the next.
    double max_y = -1.0;
    for (const auto& c : first.centres_m) max_y = std::max(max_y, c[1]);
    CHECK(max_y == Approx(0.0305 - r).margin(kGeometry));
    int lowest_row_in_last_slab = 0;
    for (const auto& c : first.centres_m) {
      if (std::abs(c[0] + 0.065) < kGeometry && std::abs(c[1] - max_y) < kGeometry) ++lowest_row_in_last_slab;
    }
    CHECK(lowest_row_in_last_slab == 4);
  }
  SECTION("without gravity the cross-section is centred") {
    fm::LatticePacking packing;
    packing.drive_axis = 0;
    const fm::LatticeBed free = fm::collected_lattice(box, 48, r, packing);
    double sum_y = 0.0, sum_z = 0.0;
    for (const auto& c : free.centres_m) {
      sum_y += c[1];
      sum_z += c[2];
    }
    CHECK(std::abs(sum_y) < kGeometry);
    CHECK(std::abs(sum_z) < kGeometry);
  }
}

TEST_CASE("a cylinder driven along its axis holds the square-lattice sites of its disk", "[formulas]") {
  const double r = 0.005;
  SECTION("R = 4r: 9 sites on the axis-registered lattice") {
    // Hand count, |offset| + r <= R i.e. |offset| <= 3r: on the axis-registered lattice
    // (0, ±2r)² gives 9 sites (the corners at 2√2 r = 2.83r fit); offset by r along one
    // axis gives 8, along both 4. So 9 per slab: 20 spheres take 3 slabs.
    const fm::Container cyl = cylinder(4.0 * r, 0.100, 0);
    fm::LatticePacking packing = along_x_gravity_down();
    const fm::LatticeBed one = fm::collected_lattice(cyl, 9, r, packing);
    CHECK(one.slabs == 1);
    const fm::LatticeBed bed = fm::collected_lattice(cyl, 20, r, packing);
    CHECK(bed.slabs == 3);
    CHECK(bed.clearance_m == Approx(0.070).margin(kGeometry));
    check_inside_cylinder(cyl, bed.centres_m, r);
    CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));
    // The last slab's 2 spheres sit in the lowest row, z = −2r.
    for (const auto& c : bed.centres_m) {
      if (std::abs(c[0] - (-0.05 + 5.0 * r)) < kGeometry) CHECK(c[2] == Approx(-2.0 * r).margin(kGeometry));
    }
  }
  SECTION("R = 4.5r: 12 sites on the lattice offset by r along both axes") {
    // |offset| <= 3.5r: axis-registered 9 (±4r does not fit), offset along one axis 8,
    // offset along both: (±r, ±r) 4 + (±3r, ±r) 4 + (±r, ±3r) 4 = 12 ((3r, 3r) = 4.24r does not).
    const fm::Container cyl = cylinder(4.5 * r, 0.100, 2);
    fm::LatticePacking packing;
    packing.drive_axis = 2;
    const fm::LatticeBed bed = fm::collected_lattice(cyl, 24, r, packing);
    CHECK(bed.slabs == 2);
    check_inside_cylinder(cyl, bed.centres_m, r);
    CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));
    CHECK_THROWS_WITH(fm::collected_lattice(cyl, 24 * 5, r, packing),
                      Catch::Contains("fill 10 slabs of 12 sites"));
  }
  SECTION("an explicit block rests as low as the curved wall allows") {
    const fm::Container cyl = cylinder(4.0 * r, 0.100, 0);
    fm::LatticePacking packing = along_x_gravity_down();
    packing.lattice_counts = std::array{2, 3, 2};
    const fm::LatticeBed bed = fm::collected_lattice(cyl, 12, r, packing);
    CHECK(bed.slabs == 2);
    check_inside_cylinder(cyl, bed.centres_m, r);
    CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));
    // A row of 3 (half-width 2r) touches the wall at depth √((3r)² − (2r)²) = √5 r.
    double lowest = 0.0;
    for (const auto& c : bed.centres_m) lowest = std::min(lowest, c[2]);
    CHECK(lowest == Approx(-std::sqrt(5.0) * r).margin(kGeometry));
    packing.lattice_counts = std::array{2, 4, 2};
    CHECK_THROWS_WITH(fm::collected_lattice(cyl, 12, r, packing),
                      Catch::Contains("do not fit in inner_radius_m = 0.02"));
  }
  SECTION("a cylinder driven across its axis is not supported yet") {
    const fm::Container cyl = cylinder(4.0 * r, 0.100, 2);
    CHECK_THROWS_WITH(fm::collected_lattice(cyl, 9, r, along_x_gravity_down()),
                      Catch::Contains("drive_axis = 0, cylinder_axis = 2) is not supported yet"));
  }
}

// Reference: counting. A lane (one position across the drive and gravity) of N spheres
// settles into a bottom row of min(N, floor(L/2r)) spheres; h = L − longest row·2r. The DEM
// shows the settled state (tests/dem_reference "a bed stacked two high settles ...", and
// docs/collect_and_collide.md §8): 4 slabs of 8 × 2 in 28 mm settle into 5 bottom rows and
// 3 mm of travel; 7 slabs in 40 mm into 8 rows, wall to wall. Exact integers and sums of
// r-multiples: 1e-12 m.
TEST_CASE("a bed stacked two high settles into longer bottom rows and a smaller clearance", "[formulas]") {
  const double r = 0.0025;
  const auto box = [](double length) {
    fm::Container b;
    b.box_inner_size_m = {length, 0.041, 0.012};
    return b;
  };
  const fm::LatticePacking packing = along_x_gravity_down();
  const fm::LatticeBed narrow = fm::collected_lattice(box(0.028), 64, r, packing);
  CHECK(narrow.slabs == 4);
  CHECK(narrow.spheres_per_lane == 2);
  CHECK(narrow.clearance_m == Approx(0.008).margin(kGeometry));
  CHECK(narrow.settled_clearance_m == Approx(0.003).margin(kGeometry));
  CHECK(narrow.settled_upper_spheres == 24);
  const fm::LatticeBed jammed = fm::collected_lattice(box(0.040), 112, r, packing);
  CHECK(jammed.clearance_m == Approx(0.005).margin(kGeometry));
  CHECK(jammed.settled_clearance_m == Approx(0.0).margin(kGeometry));
  CHECK(jammed.settled_upper_spheres == 48);
  // Two slabs (4 a lane) fit on the base: one layer, h = L − 4·2r.
  const fm::LatticeBed spread = fm::collected_lattice(box(0.040), 32, r, packing);
  CHECK(spread.settled_clearance_m == Approx(0.020).margin(kGeometry));
  CHECK(spread.settled_upper_spheres == 0);

  SECTION("one sphere high, no gravity across the drive, or a cylinder: the lattice's clearance") {
    fm::Container low = box(0.040);
    low.box_inner_size_m[2] = 0.006;
    const fm::LatticeBed single = fm::collected_lattice(low, 56, r, packing);
    CHECK(single.spheres_per_lane == 1);
    CHECK(single.settled_clearance_m == single.clearance_m);
    fm::LatticePacking weightless = packing;
    weightless.gravity_axis_sign.reset();
    CHECK(fm::collected_lattice(box(0.028), 64, r, weightless).settled_clearance_m == Approx(0.008).margin(kGeometry));
    fm::LatticePacking along_drive = packing;
    along_drive.gravity_axis_sign = std::pair{0, -1};
    CHECK(fm::collected_lattice(box(0.028), 64, r, along_drive).settled_clearance_m == Approx(0.008).margin(kGeometry));
    const fm::LatticeBed tube = fm::collected_lattice(cylinder(0.0125, 0.104335, 0), 260, 0.0025, packing);
    CHECK(tube.settled_clearance_m == tube.clearance_m);
  }
}

TEST_CASE("beds that do not fit are rejected with the numbers", "[formulas]") {
  const fm::Container box = level2_box();
  fm::LatticePacking packing = along_x_gravity_down();
  SECTION("more spheres than the explicit lattice") {
    packing.lattice_counts = std::array{6, 6, 1};
    CHECK_THROWS_WITH(fm::collected_lattice(box, 40, 0.005, packing),
                      "collected_lattice: count = 40 spheres > 36 sites of lattice_counts 6 x 6 x 1");
  }
  SECTION("an explicit lattice wider than the box") {
    packing.lattice_counts = std::array{6, 7, 1};
    CHECK_THROWS_WITH(fm::collected_lattice(box, 36, 0.005, packing),
                      Catch::Contains("7 sites need 0.07 m along axis 1, the inner length is 0.061 m"));
  }
  SECTION("too many spheres for the length: no clearance left") {
    // 24 per slab: 384 spheres take 16 slabs = 160 mm, the whole length (h = 0).
    CHECK_THROWS_WITH(fm::collected_lattice(box, 384, 0.005, packing),
                      Catch::Contains("fill 16 slabs of 24 sites") && Catch::Contains("must be > 0"));
    CHECK_THROWS_AS(fm::collected_lattice(box, 1000, 0.005, packing), std::invalid_argument);
    CHECK(fm::collected_lattice(box, 360, 0.005, packing).clearance_m == Approx(0.010).margin(kGeometry));
  }
  SECTION("spheres larger than the cross-section") {
    CHECK_THROWS_WITH(fm::collected_lattice(box, 1, 0.025, packing),
                      Catch::Contains("no sphere of radius_m = 0.025 fits in the cross-section"));
  }
  SECTION("invalid radius, count and axes") {
    CHECK_THROWS_WITH(fm::collected_lattice(box, 36, -0.005, packing),
                      "collected_lattice: radius_m = -0.005: must be > 0 and finite");
    CHECK_THROWS_WITH(fm::collected_lattice(box, 0, 0.005, packing),
                      Catch::Contains("count = 0: must be >= 1"));
    packing.drive_axis = 3;
    packing.collect_side = 0;
    CHECK_THROWS_WITH(fm::collected_lattice(box, 36, 0.005, packing),
                      Catch::Contains("packing.drive_axis = 3: must be 0, 1 or 2\npacking.collect_side = 0"));
  }
}

TEST_CASE("containers report their inner lengths and their invalid sizes", "[formulas]") {
  const fm::Container box = level2_box();
  CHECK(box.inner_length(1) == 0.061);
  CHECK(box.validate("damper.container").empty());
  const fm::Container cyl = cylinder(0.02, 0.1, 1);
  CHECK(cyl.inner_length(1) == 0.1);
  CHECK(cyl.inner_length(0) == 0.04);
  CHECK_THROWS_WITH(cyl.inner_length(3), Catch::Contains("axis = 3: must be 0, 1 or 2"));

  fm::Container bad_box;
  bad_box.box_inner_size_m = {0.1, -0.06, std::nan("")};
  CHECK(bad_box.validate("c") ==
        std::vector<std::string>{"c.box_inner_size_m[1] = -0.06: must be > 0 and finite",
                                 "c.box_inner_size_m[2] = nan: must be > 0 and finite"});
  fm::Container bad_cyl = cylinder(0.0, 0.1, 5);
  CHECK(bad_cyl.validate("") ==
        std::vector<std::string>{"cylinder_inner_radius_m = 0: must be > 0 and finite",
                                 "cylinder_axis = 5: must be 0, 1 or 2"});
  CHECK_THROWS_WITH(fm::collected_lattice(bad_box, 1, 0.005, fm::LatticePacking{}),
                    Catch::Contains("container.box_inner_size_m[1] = -0.06"));
}

TEST_CASE("a staggered cylinder bed stacks shifted slabs in the hollows at pitch r√2", "[formulas]") {
  const double r = 0.0025;
  // The shipped free-free beam's cylinder: R = 5r. Hand count of |offset| <= 4r: the
  // axis-registered lattice (0, ±2r, ±4r)² holds 1 + 4 + 4 + 4 = 13 sites ((±2r, ±2r) at
  // 2.83r; (±4r, 0) and (0, ±4r) on the wall), the shifted one (±r, ±3r)² 4 + 8 = 12
  // ((±3r, ±3r) at 4.24r do not fit). 260 spheres: 10 pairs of 25 and 10 in slab 21.
  const fm::Container cyl = cylinder(5.0 * r, 0.090, 0);
  fm::LatticePacking packing = along_x_gravity_down();
  packing.staggered = true;
  const fm::LatticeBed bed = fm::collected_lattice(cyl, 260, r, packing);
  CHECK(bed.slabs == 21);
  CHECK(bed.bed_extent_m == Approx(20.0 * std::sqrt(2.0) * r + 2.0 * r).margin(kGeometry));
  CHECK(bed.clearance_m == Approx(0.090 - bed.bed_extent_m).margin(kGeometry));
  CHECK(bed.settled_clearance_m == bed.clearance_m);
  check_inside_cylinder(cyl, bed.centres_m, r);
  // Touching (every shifted sphere rests on four of each neighbouring slab), nowhere closer.
  CHECK(min_pair_distance(bed.centres_m) == Approx(2.0 * r).margin(kGeometry));
  const auto slabs = count_by(bed.centres_m, 0);
  REQUIRE(slabs.size() == 21);
  int slab = 0;
  for (auto it = slabs.begin(); it != slabs.end(); ++it, ++slab) {  // from the collect wall at −L/2
    CHECK(it->second == (slab == 20 ? 10 : slab % 2 == 0 ? 13 : 12));
  }
  // The simple cubic lattice of the same bed needs 20 slabs of 13, 100 mm: not in 90 mm.
  CHECK_THROWS_WITH(fm::collected_lattice(cyl, 260, r, along_x_gravity_down()), Catch::Contains("fill 20 slabs of 13 sites"));

  SECTION("refusals") {
    CHECK_THROWS_WITH(fm::collected_lattice(level2_box(), 36, 0.005, [] {
      fm::LatticePacking p;
      p.staggered = true;
      return p;
    }()),
                      Catch::Contains("staggered: supported in a cylinder only"));
    packing.lattice_counts = std::array{2, 2, 2};
    CHECK_THROWS_WITH(fm::collected_lattice(cyl, 8, r, packing), Catch::Contains("no lattice_counts"));
    packing.lattice_counts.reset();
    CHECK_THROWS_WITH(fm::collected_lattice(cylinder(1.5 * r, 0.1, 0), 8, r, packing),
                      Catch::Contains("no shifted site fits"));
  }
}

// Reference: geometry by hand. A lining of thickness t on the faces normal to an axis takes
// 2t off the inner length along it; on a cylinder's mantle it takes t off the radius.
TEST_CASE("a lined container loses the lining's thickness on the lined faces only", "[formulas]") {
  const double t = 0.001;
  fm::Container box;
  box.box_inner_size_m = {0.1, 0.06, 0.04};
  const fm::Container x_lined = box.lined(t, 0);
  CHECK(x_lined.box_inner_size_m[0] == Approx(0.098).margin(kGeometry));
  CHECK(x_lined.box_inner_size_m[1] == 0.06);
  const fm::Container all_lined = box.lined(t, -1);
  CHECK(all_lined.box_inner_size_m[1] == Approx(0.058).margin(kGeometry));
  CHECK(all_lined.box_inner_size_m[2] == Approx(0.038).margin(kGeometry));
  const fm::Container cyl = cylinder(0.0125, 0.1, 0);
  const fm::Container caps = cyl.lined(t, 0);
  CHECK(caps.cylinder_inner_length_m == Approx(0.098).margin(kGeometry));
  CHECK(caps.cylinder_inner_radius_m == 0.0125);
  const fm::Container mantle = cyl.lined(t, 2);
  CHECK(mantle.cylinder_inner_length_m == 0.1);
  CHECK(mantle.cylinder_inner_radius_m == Approx(0.0115).margin(kGeometry));
  const fm::Container both = cyl.lined(t, -1);
  CHECK(both.inner_length(0) == Approx(0.098).margin(kGeometry));
  CHECK(both.inner_length(1) == Approx(0.023).margin(kGeometry));
  CHECK(cyl.lined(0.0, -1).inner_length(0) == 0.1);
}
