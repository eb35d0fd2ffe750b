// The motion-mode labels of docs/theory.md §8.1 (docs/dem.md "Motion modes") on
// runs that show each mode. The thresholds come from the mode definitions and the ideal
// orbits of docs/theory.md §2-3 (dem_reference/src/damper_simulation.cpp, ModeThresholds),
// not from these runs. Softened runs (E/100) are repeated at full stiffness under [long].
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"

namespace {

namespace dr = pdamp::dem_reference;

/// The shipped low-intensity layer (cases/low_intensity_36_spheres.json, docs/theory.md §8):
/// 36 steel spheres r = 5 mm, 6 × 6 × 1 collected against −x in 160 × 61 × 40 mm
/// (h_roll = 0.1 m), 2 Hz along x, gravity −z; ε, μ, μ_r as given, E = 210 GPa / softening.
dr::DamperSimulationOptions layer(double x_over_h, double restitution, double friction, double rolling,
                                  double softening) {
  auto o = dem_test::shipped_layer(x_over_h, restitution, friction, rolling, softening);
  o.samples_per_period = 200;
  return o;
}

/// A small bed without gravity: n × n × n steel spheres r = 2.5 mm collected against −x
/// in a box n·5 mm + h long (x) and n·5 mm + 0.2 mm wide, driven along x at f.
dr::DamperSimulationOptions floating_bed(int n, double clearance_m, double x_over_h, double frequency_hz,
                                         double restitution, double friction, double softening) {
  dr::DamperSimulationOptions o;
  o.world.gravity_m_s2 = {0.0, 0.0, 0.0};
  auto& c = o.world.compartments.front();
  const double side = n * 0.005;
  c.container.box_inner_size_m = {side + clearance_m, side + 2e-4, side + 2e-4};
  c.particles = {dr::ParticleGroupOptions{n * n * n, 0.0025, 0.0, 0}};
  c.lattice_counts = {n, n, n};
  o.world.materials.front().material.youngs_modulus_pa = 210e9 / softening;
  o.world.default_pair.restitution.constant = restitution;
  o.world.default_pair.friction = friction;
  o.frequency_hz = frequency_hz;
  o.amplitude_m = x_over_h * clearance_m;
  o.samples_per_period = 200;
  return o;
}


/// One run of `o` with `transient` and `analysed` periods, completed.
dr::DamperResult run(dr::DamperSimulationOptions o, int transient, int analysed) {
  o.transient_periods = transient;
  o.analysed_periods = analysed;
  auto r = dr::run_harmonic(o);
  REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
  return r;
}

std::string label(const dr::DamperResult& r) { return std::string(dr::to_string(r.motion_mode)); }

/// The indicators in one line, for the failure message.
std::string describe(const dr::DamperResult& r) {
  const auto& m = r.indicators;
  char line[400];
  std::snprintf(line, sizeof line,
                "%s: eta* %.3f +- %.3f, m_f %.2f, stroke %.2f, locked %.2f, coherence %.2f, lag %.0f deg, "
                "crossings %.2f, eta variation %.2f, base %.2f of %.2f, airborne %.2f, spread %.2f, mobile %.2f, "
                "Gamma %.2f",
                label(r).c_str(), r.eta_star, r.eta_star_stderr, m.apparent_mass_fraction,
                m.relative_stroke_over_clearance, m.phase_locked_stroke, m.phase_coherence, m.phase_lag_deg,
                m.crossing_fraction, m.eta_star_variation, m.base_contact_fraction, m.settled_base_contact_fraction,
                m.airborne_fraction, m.spread_over_packed, m.mobile_fraction, r.intensity);
  return line;
}

// The runs, softened by `softening` (100 in the unit tests, 1 in the [long] repeat).
// solid_like: the layer with μ = 0.5 and rolling resistance μ_r = 0.1 at X = 0.05 h
// (Γ = 0.08): a sphere moving with the base needs the rolling-resistance torque
// μ_r·m g·r to balance m·a_c·r, so it stays put for Γ < μ_r, and the friction for Γ < μ.
dr::DamperSimulationOptions solid_run(double softening) { return layer(0.05, 0.7, 0.5, 0.1, softening); }
// decoupled: 8 spheres without gravity, clearance 20 mm, X = 0.6 mm at 50 Hz (X = 0.03 h):
// the bed drifts through the clearance and the container moves around it.
dr::DamperSimulationOptions decoupled_run(double softening) {
  return floating_bed(2, 0.020, 0.03, 50.0, 0.5, 0.3, softening);
}
// bouncing: 27 spheres without gravity, h = 15 mm, ε = 0.5, above the onset (0.27 h).
dr::DamperSimulationOptions bouncing_run(double x_over_h, double softening) {
  return floating_bed(3, 0.015, x_over_h, 50.0, 0.5, 0.3, softening);
}
// scattering without gravity: the same bed below the onset, X = 0.15 h.
dr::DamperSimulationOptions scattering_run(double softening) { return bouncing_run(0.15, softening); }
// global fluidisation: 27 nearly elastic spheres (ε = 0.95, μ = 0.05), h = 30 mm = twice the
// packed bed, X = 0.15 h (below the onset): a granular gas.
dr::DamperSimulationOptions global_run(double softening) {
  return floating_bed(3, 0.030, 0.15, 50.0, 0.95, 0.05, softening);
}
// local fluidisation: 64 spheres (ε = 0.5), h = 4 mm (a fifth of the packed bed), X = 0.2 h:
// the outer spheres are agitated around a core that stays packed.
dr::DamperSimulationOptions local_run(double softening) {
  return floating_bed(4, 0.004, 0.2, 50.0, 0.5, 0.3, softening);
}

}  // namespace

// Reference: docs/theory.md §8.1 definition of solid-like motion, the bed moving with the
// container: relative stroke ≪ h and m_app = m_bed. The bed does not move at all (see
// solid_run), so m_f = 1 within the elastic jitter (5%).
TEST_CASE("a layer held by rolling resistance at Gamma = 0.08 is solid_like", "[dem_reference]") {
  const auto r = run(solid_run(100.0), 1, 3);
  INFO(describe(r));
  CHECK(label(r) == "solid_like");
  CHECK(r.indicators.relative_stroke_over_clearance < 0.01);
  CHECK(r.indicators.apparent_mass_fraction == Approx(1.0).margin(0.05));
}

// Reference: decoupled, the bed at rest in the inertial frame (m_f = 0, η* = 0): its
// relative motion is the container's own, mirrored (lag near 180°, within 20°).
TEST_CASE("a floating bed at X = 0.03 h without gravity is decoupled", "[dem_reference]") {
  const auto r = run(decoupled_run(100.0), 10, 10);
  INFO(describe(r));
  CHECK(label(r) == "decoupled");
  CHECK(std::abs(r.indicators.apparent_mass_fraction) < 0.1);
  CHECK(r.eta_star < 0.1);
  CHECK(std::abs(r.indicators.phase_lag_deg) > 160.0);
}

// Reference: the ideal bouncing orbit (docs/theory.md §2): one crossing per half period,
// η* = 1.08 at X = 0.4 h and 0.59 at X = h for a plastic block; with ε = 0.5 the bed
// rebounds and loses less at X = h (measured 1.05 and 0.46: within 0.2 of the plastic
// value at 0.4 h, above half of it at h). No gravity: no base contact.
TEST_CASE("a collected bed without gravity at X/h = 0.4 and 1.0 is bouncing collect-and-collide",
          "[dem_reference]") {
  for (const double x : {0.4, 1.0}) {
    const auto r = run(bouncing_run(x, 100.0), 8, 6);
    INFO("X/h = " << x << ": " << describe(r));
    CHECK(label(r) == "bouncing_collect_and_collide");
    CHECK(r.indicators.crossing_fraction > 0.9);
    CHECK(r.indicators.base_contact_fraction == 0.0);
    CHECK(r.eta_star > (x < 0.5 ? 0.85 : 0.3));
  }
}

// Reference: the rolling orbit of docs/theory.md §3 above X_opt ≈ 0.4 h_roll: the layer
// crosses in step once per half period while rolling on its base (at X = 0.6 h, Γ = 0.97:
// the drive acceleration stays below gravity). η* near the ideal 0.88 (rolling curve at
// 0.6 h): above 0.7.
TEST_CASE("the shipped layer at X/h = 0.6 is rolling collect-and-collide", "[dem_reference]") {
  const auto r = run(layer(0.6, 0.7, 0.15, 0.005, 100.0), 2, 4);
  INFO(describe(r));
  CHECK(label(r) == "rolling_collect_and_collide");
  CHECK(r.indicators.crossing_fraction > 0.9);
  CHECK(r.eta_star > 0.7);
}

// Reference: the shipped layer with ε = 0.7, μ = 0.15, μ_r = 0.005 and identical spheres (no
// lot variation): the 36 clones scatter η* from period to period (coefficient of
// variation 0.15-0.41, standard error 0.05-0.07; the premise asks for more than 0.1) while
// the bed crosses the clearance in step with the drive. The label reads the phase-locked
// crossing, not that scatter: rolling at X = 0.4 h (η* 0.89-0.92, high) and X = h (η*
// 0.46-0.58 in physics versions 4 and 3; the old rule, variation < 0.25 and period
// correlation > 0.8, called it scattering). The runs that show the scatter are those at
// 50 steps per contact (given): at the automatic 20 the X = h run locks without it
// (variation 0.04), which would leave the label nothing to read past.
TEST_CASE("rolling runs with period-to-period scatter are rolling collect-and-collide", "[dem_reference]") {
  for (const double x : {0.4, 1.0}) {
    auto o = layer(x, 0.7, 0.15, 0.005, 100.0);
    o.world.compartments.front().particles.front().lot_diameter_variation_m = 0.0;
    o.world.integration.steps_per_contact = 50;
    const auto r = run(o, 3, 8);
    INFO("X/h = " << x << ": " << describe(r));
    CHECK(label(r) == "rolling_collect_and_collide");
    CHECK(r.indicators.eta_star_variation > 0.1);
    CHECK(r.indicators.phase_coherence > 0.9);
    CHECK(r.eta_star > (x < 0.5 ? 0.8 : 0.45));
  }
}

// Reference: the scattered state below the onset (docs/theory.md §4): no synchronous orbit,
// little dissipation. The layer at X = 0.2 h_roll (onset 0.376 h) and the floating bed at
// X = 0.15 h (onset 0.27 h); neither crosses in step (crossings < 0.5).
TEST_CASE("below the onset the layer and a floating bed are scattering", "[dem_reference]") {
  const auto layer_run = run(layer(0.2, 0.7, 0.15, 0.005, 100.0), 2, 6);
  const auto floating = run(scattering_run(100.0), 10, 10);
  for (const auto* r : {&layer_run, &floating}) {
    INFO(describe(*r));
    CHECK(label(*r) == "scattering");
    CHECK(r->indicators.crossing_fraction < 0.5);
    CHECK(r->eta_star < 0.25);
  }
}

// Reference: global fluidisation, all of the bed mobile: nearly elastic spheres keep
// fluctuation speeds of order V (measured 0.9-1.7 V, every sphere above V/2), far more
// than a collected bed; they bounce off the walls (m_f ≈ 3, beyond any collected bed).
TEST_CASE("a bed of nearly elastic spheres driven at Gamma = 45 is global_fluidisation", "[dem_reference]") {
  const auto r = run(global_run(100.0), 10, 10);
  INFO(describe(r));
  CHECK(label(r) == "global_fluidisation");
  CHECK(r.indicators.mobile_fraction > 0.95);
}

// Reference: local fluidisation, part of the bed mobile: the spheres next to the walls
// and edges move faster than V/2 relative to the bed, the core less (measured 38%).
TEST_CASE("a tight bed of 64 spheres at Gamma = 8 is local_fluidisation", "[dem_reference]") {
  const auto r = run(local_run(100.0), 10, 10);
  INFO(describe(r));
  CHECK(label(r) == "local_fluidisation");
  CHECK(r.indicators.mobile_fraction > 0.15);
  CHECK(r.indicators.mobile_fraction < 0.75);
}

// Reference: the same runs at full stiffness (E = 210 GPa): softening by 100 lengthens the
// contacts (t_c ∝ E^(−2/5), 6×) but leaves them far shorter than a period, so the labels
// must not change.
TEST_CASE("full stiffness gives the same labels as the softened unit runs", "[dem_reference][long]") {
  struct Case {
    const char* name;
    dr::DamperSimulationOptions options;
    int transient, analysed;
    const char* label;
  };
  const std::vector<Case> cases = {
      {"solid", solid_run(1.0), 1, 3, "solid_like"},
      {"decoupled", decoupled_run(1.0), 10, 10, "decoupled"},
      {"bouncing 0.4", bouncing_run(0.4, 1.0), 8, 6, "bouncing_collect_and_collide"},
      {"bouncing 1.0", bouncing_run(1.0, 1.0), 8, 6, "bouncing_collect_and_collide"},
      {"scattering", scattering_run(1.0), 10, 10, "scattering"},
      {"global", global_run(1.0), 10, 10, "global_fluidisation"},
      {"local", local_run(1.0), 10, 10, "local_fluidisation"},
      {"rolling 0.6", layer(0.6, 0.7, 0.15, 0.005, 1.0), 2, 4, "rolling_collect_and_collide"},
  };
  for (const auto& c : cases) {
    const auto r = run(c.options, c.transient, c.analysed);
    INFO(c.name << ": " << describe(r));
    CHECK(label(r) == c.label);
  }
}

// Reference: the same layer at full stiffness with identical spheres (η* = 0.87 ± 0.07
// at X = 0.4 h, 0.41 ± 0.03 at X = h, both labelled scattering by the earlier rule):
// the bed crosses the clearance in step with the drive, so both are collect-and-collide.
// At X = 0.4 h the bed rolls on its base (Γ = 0.64); at X = h (Γ = 1.6) about half of
// the spheres hop after the wall impacts and the base-contact fraction sits near its
// threshold (0.44-0.56 across stiffness and lot), so there either family is accepted.
TEST_CASE("the layer of identical spheres at full stiffness is collect-and-collide", "[dem_reference][long]") {
  for (const double x : {0.4, 1.0}) {
    auto o = layer(x, 0.7, 0.15, 0.005, 1.0);
    o.world.compartments.front().particles.front().lot_diameter_variation_m = 0.0;
    const auto r = run(o, 3, 8);
    INFO("X/h = " << x << ": " << describe(r));
    if (x < 0.5) {
      CHECK(label(r) == "rolling_collect_and_collide");
      CHECK(r.eta_star > 0.75);
    } else {
      CHECK(label(r).find("collect_and_collide") != std::string::npos);
    }
    CHECK(r.indicators.crossing_fraction > 0.9);
  }
}
