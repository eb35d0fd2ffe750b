// Buffered walls (a polymer layer on the container walls, docs/theory.md §5) against Hertz's
// elastic impact, the energy balance of the bottomed-out layer, and the layer sizing of
// formulas::size_buffer_layer checked in the DEM.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "pdamp/formulas/layered_contact.hpp"

namespace {

namespace dr = pdamp::dem_reference;
namespace fm = pdamp::formulas;
using dem_test::kPi;

constexpr double kRadius = 0.005;
constexpr double kBoxLength = 0.1;  // along x, the layered axis
constexpr double kThickness = 1.5e-4;
// Steel spheres (material 0, also the hard wall) on a polyurethane-like layer
// (material 1; its modulus stands for the value at the design frequency and temperature).
constexpr double kSteelE = 210e9, kSteelNu = 0.3, kSteelRho = 7850.0;
constexpr double kLayerE = 100e6, kLayerNu = 0.45, kLayerRho = 1200.0;

/// 1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂, written out (the reference shares no code with the DEM).
double effective_modulus(double e1, double nu1, double e2, double nu2) {
  return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
}

/// Hertz stiffness K = (4/3)E*√r of a sphere on a flat surface, N/m^{3/2}.
double hertz_stiffness(double e_star) { return 4.0 / 3.0 * e_star * std::sqrt(kRadius); }

/// Elastic maximum penetration from ½mv² = (2/5)Kδ^{5/2} (docs/theory.md §5), m.
double elastic_penetration(double mass, double stiffness, double v) {
  return std::pow(1.25 * mass * v * v / stiffness, 0.4);
}

/// One steel sphere in a box layered on its x walls; restitution of sphere–layer and
/// sphere–steel, no friction (normal impacts), no gravity.
dr::WorldOptions layered_world(double layer_eps, double steel_eps, double max_speed) {
  dr::WorldOptions o = dem_test::box_world(1, kRadius, steel_eps, 0.0);
  auto& c = o.compartments.front();
  c.container.box_inner_size_m = {kBoxLength, 0.05, 0.05};
  o.materials.push_back(dr::MaterialOptions{"polyurethane", {kLayerRho, kLayerE, kLayerNu}});
  c.layer.thickness_m = kThickness;
  c.layer.material = 1;
  c.layer.axis = 0;
  dr::ContactPairOptions pair;
  pair.material_a = 0;
  pair.material_b = 1;
  pair.restitution.constant = layer_eps;
  pair.friction = 0.0;
  o.pairs.push_back(pair);
  o.integration.max_impact_speed_m_s = max_speed;
  return o;
}

struct LayerImpact {
  double penetration_m = 0.0;  ///< deepest penetration below the layer surface, m
  double rebound = 0.0;        ///< rebound speed / impact speed
};

/// One sphere hits the layered −x wall at speed v; the penetration is measured from the
/// sphere's centre and the layer surface at x = −L/2 + t.
LayerImpact layer_impact(const dr::WorldOptions& options, double v, double thickness) {
  dr::World world(options);
  const double surface = -0.5 * options.compartments.front().container.box_inner_size_m[0] + thickness;
  const double r = world.radius(0);
  const double gap = 20.0 * v * world.time_step_s();
  world.set_particle_state(0, {surface + r + gap, 0.0, 0.0}, {-v, 0.0, 0.0}, {0.0, 0.0, 0.0});
  const dr::ContainerState rest;
  LayerImpact out;
  bool touched = false;
  for (long k = 0; k < 2'000'000; ++k) {
    world.step(rest);
    out.penetration_m = std::max(out.penetration_m, surface + r - world.position(0)[0]);
    const bool touching = world.contact_census({0.0, 0.0, 0.0}).touching_walls > 0;
    if (touching) touched = true;
    if (touched && !touching) break;
  }
  REQUIRE(world.status().outcome == dr::Outcome::kCompleted);
  out.rebound = world.velocity(0)[0] / v;
  return out;
}

/// The DEM's layered law for the test's materials (formulas::LayeredContact, whose own
/// tests check it against Hertz, the thin-layer limits and Dimitriadis et al. 2002).
fm::LayeredContact layer_law(double thickness) {
  return fm::LayeredContact(kRadius, kLayerE, kLayerNu, kSteelE, kSteelNu, thickness);
}

}  // namespace

// Reference: the one-body elastic impact on the bonded-layer law, formulas::layered_impact
// (½mv² = U(δ_max) by bisection), and the input ε of the sphere–layer pair for the
// rebound. The 0.15 mm layer under a 5 mm sphere (a/t ≈ 2 at the peak) is much stiffer
// than the Hertz half-space of the same modulus: the penetration must be well below
// Hertz's. 1% on δ_max: the impact is resolved by ~900 steps (the step is set by the
// stiffer steel contact), the peak read to a step's travel. 2% on ε (the DEM's
// tolerance for single impacts; the layered damping table itself realises ε within 1e-3, tests/formulas).
TEST_CASE("a slow sphere presses into the bonded layer as the layered law predicts and rebounds with its restitution",
          "[dem_reference]") {
  const double v = 0.5;
  const double m = kSteelRho * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
  const double hertz = elastic_penetration(m, hertz_stiffness(effective_modulus(kSteelE, kSteelNu, kLayerE, kLayerNu)), v);
  const double expected = fm::layered_impact(layer_law(kThickness), m, v).max_overlap_m;
  const auto elastic = layer_impact(layered_world(1.0, 0.9, 1.0), v, kThickness);
  INFO("penetration " << elastic.penetration_m << " m, layered law " << expected << " m, Hertz half-space "
                      << hertz << " m, thickness " << kThickness << " m, rebound " << elastic.rebound);
  CHECK(elastic.penetration_m == Approx(expected).epsilon(0.01));
  CHECK(elastic.penetration_m < 0.8 * hertz);
  CHECK(elastic.rebound == Approx(1.0).epsilon(0.005));
  for (const double eps : {0.3, 0.7}) {
    const auto damped = layer_impact(layered_world(eps, 0.9, 1.0), v, kThickness);
    INFO("layer epsilon " << eps << ": rebound " << damped.rebound << ", penetration " << damped.penetration_m);
    CHECK(damped.rebound == Approx(eps).epsilon(0.02));
    CHECK(damped.penetration_m < expected);
  }
}

// Reference: a thick layer (χ = √(rδ)/t ≈ 0.016) is a Hertz half-space, δ_max =
// (15mv²/(16E*√r))^{2/5} with E* of steel on the layer, written out here. 1.5%:
// Dimitriadis' first-order term makes the 45 mm layer ~1.7% stiffer in force at this χ,
// i.e. ~0.7% less penetration, plus the 1% resolution of the peak. At 5 m/s the sphere
// sinks 0.63 mm, 0.13 of its radius: beyond the DEM's overlap limit for hard contacts
// (0.1 r), which a soft layer's surface must not trip (the run would stop as unstable).
TEST_CASE("a sphere on a thick layer presses in by the Hertz half-space penetration", "[dem_reference]") {
  const double thick = 0.045;
  for (const double v : {0.5, 5.0}) {
    CAPTURE(v);
    const double m = kSteelRho * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
    const double e_star = effective_modulus(kSteelE, kSteelNu, kLayerE, kLayerNu);
    const double expected = elastic_penetration(m, hertz_stiffness(e_star), v);
    const fm::Material steel{kSteelRho, kSteelE, kSteelNu}, layer{kLayerRho, kLayerE, kLayerNu};
    REQUIRE(fm::max_penetration(fm::sphere_wall_contact(kRadius, m, steel, layer), v) ==
            Approx(expected).epsilon(1e-12));
    dr::WorldOptions o = layered_world(1.0, 0.9, v);
    o.compartments.front().container.box_inner_size_m = {0.2, 0.2, 0.2};
    o.compartments.front().layer.thickness_m = thick;
    const auto impact = layer_impact(o, v, thick);  // requires a completed run
    INFO("penetration " << impact.penetration_m << " m, Hertz " << expected << " m");
    CHECK(impact.penetration_m == Approx(expected).epsilon(0.015));
    CHECK(impact.penetration_m < expected);
    if (v > 1.0) CHECK(impact.penetration_m > o.integration.max_overlap_fraction * kRadius);
  }
}

// Reference: energy conservation of the bottomed-out layer (50 µm: a layer that the
// 4 m/s impact compresses fully under the bonded-layer law). Elastic on both contacts
// (ε = 1), the layer and, below δ = t, the hard wall act in parallel, so the deepest
// penetration δ solves ½mv² = U_layer(δ) + (2/5)K_s (δ − t)^{5/2} (bisection here; U_layer
// from the layered law). It lies below t + the steel Hertz overlap at the full impact
// energy, and far short of the layer's own δ_max without the hard wall. 1%: the steel
// contact is resolved by ~50 steps and its peak read to a step's travel.
TEST_CASE("a fast sphere bottoms out the layer and the hard wall stops it", "[dem_reference]") {
  const double v = 4.0, thin = 5e-5;
  const double m = kSteelRho * 4.0 / 3.0 * kPi * kRadius * kRadius * kRadius;
  const fm::LayeredContact law = layer_law(thin);
  const double k_steel = hertz_stiffness(effective_modulus(kSteelE, kSteelNu, kSteelE, kSteelNu));
  const double energy = 0.5 * m * v * v;
  const auto stored = [&](double delta) {
    const double hard = std::max(delta - thin, 0.0);
    return law.energy(delta) + 0.4 * k_steel * std::pow(hard, 2.5);
  };
  double lo = 0.0, hi = 1e-3;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (stored(mid) < energy ? lo : hi) = mid;
  }
  const double expected = 0.5 * (lo + hi);
  const double soft_only = fm::layered_impact(law, m, v).max_overlap_m;
  const double steel_only = elastic_penetration(m, k_steel, v);

  dr::WorldOptions o = layered_world(1.0, 1.0, v);
  o.compartments.front().layer.thickness_m = thin;
  const auto impact = layer_impact(o, v, thin);
  INFO("penetration " << impact.penetration_m << " m; energy balance " << expected << " m; thickness + steel "
                      << thin + steel_only << " m; soft layer alone " << soft_only << " m");
  CHECK(impact.penetration_m == Approx(expected).epsilon(0.01));
  CHECK(impact.penetration_m > thin);
  CHECK(impact.penetration_m < thin + steel_only);
  CHECK(impact.penetration_m < soft_only);
  CHECK(impact.rebound == Approx(1.0).epsilon(0.005));
}

// Reference: the sizing itself (docs/theory.md §5: the sizing "must be checked in the DEM").
// formulas::size_buffer_layer (layered model) chooses the thickness t whose tip strain
// δ_max/t under the design impact (one front-row sphere carrying particles_per_contact
// spheres at v = 2XΩ) is the allowable strain ε_a. The DEM gets the designed t and one
// sphere of that effective mass (density scaled, same radius and moduli) at the design
// speed, elastic like the sizing: penetration/t within 5% of ε_a (the impact is resolved
// to < 1%), at the default ε_a = 0.3 and at ε_a = 1 (full compression). At 80% of the
// design speed the fully compressible design must not bottom out and must match the
// layered law's δ_max there (formulas::layered_impact, 1%). The half-space sizing of the
// source study, labelled as such, gives a thicker layer than full compression that the
// same impact does not nearly compress.
TEST_CASE("the buffered-wall sizing reaches its allowable strain under the design impact in the DEM", "[dem_reference]") {
  fm::BufferDesignInput input;
  input.frequency_hz = 60.0;
  input.amplitude_m = 0.001;
  input.particle_radius_m = kRadius;
  input.particle = fm::Material{kSteelRho, kSteelE, kSteelNu};
  input.layer = fm::Material{kLayerRho, kLayerE, kLayerNu};
  input.particles_per_contact = 4.0;
  input.model = fm::BufferModel::kLayered;
  const fm::BufferDesign at_default_strain = fm::size_buffer_layer(input);
  REQUIRE(at_default_strain.allowable_strain == fm::kDefaultAllowableStrain);
  input.allowable_strain = 1.0;
  const fm::BufferDesign design = fm::size_buffer_layer(input);
  input.model = fm::BufferModel::kHalfSpace;
  const fm::BufferDesign half_space = fm::size_buffer_layer(input);
  const double v = design.impact_velocity_m_s;
  REQUIRE(v == Approx(2.0 * 0.001 * 2.0 * kPi * 60.0).epsilon(1e-12));

  const auto world_for = [&](double thickness) {
    dr::WorldOptions o = layered_world(1.0, 1.0, v);
    // Material 2: the bed's share on one front-row sphere, steel with 4× the density.
    fm::Material carrier = input.particle;
    carrier.density_kg_m3 *= input.particles_per_contact;
    o.materials.push_back(dr::MaterialOptions{"steel_carrying_4", carrier});
    o.compartments.front().particles.front().material = 2;
    o.compartments.front().layer.thickness_m = thickness;
    o.default_pair.restitution.constant = 1.0;
    // Overlaps of ~5% of the radius are the design's point, not an instability.
    o.integration.max_overlap_fraction = 0.2;
    return o;
  };
  const dr::WorldOptions o = world_for(design.layer_thickness_m);
  REQUIRE(dr::World(o).mass(0) == Approx(design.effective_mass_kg).epsilon(1e-12));

  const auto at_design = layer_impact(o, v, design.layer_thickness_m);
  const auto at_strain = layer_impact(world_for(at_default_strain.layer_thickness_m), v, at_default_strain.layer_thickness_m);
  const auto slower = layer_impact(o, 0.8 * v, design.layer_thickness_m);
  const double slower_expected =
      fm::layered_impact(layer_law(design.layer_thickness_m), design.effective_mass_kg, 0.8 * v).max_overlap_m;
  const auto on_half_space_design = layer_impact(world_for(half_space.layer_thickness_m), v, half_space.layer_thickness_m);
  INFO("designed thickness " << design.layer_thickness_m << " m at strain 1, " << at_default_strain.layer_thickness_m
                             << " m at strain 0.3 (half-space sizing " << half_space.layer_thickness_m
                             << " m) at v = " << v << " m/s, m* = " << design.effective_mass_kg
                             << " kg: penetration/t = " << at_design.penetration_m / design.layer_thickness_m
                             << " at v, " << slower.penetration_m / design.layer_thickness_m << " at 0.8 v, "
                             << at_strain.penetration_m / at_default_strain.layer_thickness_m
                             << " on the 0.3 design; on the half-space design "
                             << on_half_space_design.penetration_m / half_space.layer_thickness_m);
  CHECK(at_design.penetration_m / design.layer_thickness_m == Approx(1.0).epsilon(0.05));
  CHECK(at_strain.penetration_m / at_default_strain.layer_thickness_m == Approx(0.3).epsilon(0.05));
  CHECK(slower.penetration_m < design.layer_thickness_m);
  CHECK(slower.penetration_m == Approx(slower_expected).epsilon(0.01));
  CHECK(design.layer_thickness_m < half_space.layer_thickness_m);
  CHECK(on_half_space_design.penetration_m < 0.8 * half_space.layer_thickness_m);
}

// Reference: geometry. The collected bed's clearance in a layered box is the inner
// length less both layers and the bed's extent (docs/theory.md §9, "Clearance of a real bed").
TEST_CASE("a layered compartment's clearance excludes both layers", "[dem_reference]") {
  dr::WorldOptions o = layered_world(0.8, 0.8, 1.0);
  auto& c = o.compartments.front();
  c.particles.front().count = 8;
  c.lattice_counts = {2, 2, 2};
  dr::World world(o);
  CHECK(world.clearance_m(0) == Approx(kBoxLength - 2.0 * kThickness - 4.0 * kRadius).epsilon(1e-12));
  // The bed starts against the layer, not the hard wall.
  double lowest = 1.0;
  for (int i = 0; i < world.particle_count(); ++i) lowest = std::min(lowest, world.position(i)[0]);
  CHECK(lowest == Approx(-0.5 * kBoxLength + kThickness + kRadius).epsilon(1e-12));
}

TEST_CASE("invalid wall layers are refused naming the field", "[dem_reference]") {
  dr::WorldOptions o = layered_world(0.8, 0.8, 1.0);
  o.compartments.front().layer.thickness_m = 0.02;  // above a quarter of the 0.05 m inner size
  o.compartments.front().layer.material = 5;
  o.compartments.front().layer.axis = 3;
  const auto errors = o.validate();
  REQUIRE(errors.size() == 3);
  CHECK_THAT(errors[0], Catch::StartsWith("dem.compartments[0].layer.material = 5: must index materials"));
  CHECK(errors[1] == "dem.compartments[0].layer.axis = 3: must be -1 (all walls), 0, 1 or 2");
  CHECK_THAT(errors[2], Catch::StartsWith("dem.compartments[0].layer.thickness_m = 0.02: must be <"));
  CHECK_THROWS_AS(dr::World(o), std::invalid_argument);
}
