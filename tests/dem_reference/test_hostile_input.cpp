// Hostile input (docs/bad_inputs.md), the DEM part: restitution below the damping table, exceptions
// inside the OpenMP step, inner structures outside their container, the ranges of the
// options, the run estimate and the first progress report.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem_test_support.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/formulas/cor_models.hpp"

namespace {

namespace dr = pdamp::dem_reference;
namespace fm = pdamp::formulas;

bool has(const std::vector<std::string>& lines, const std::string& text) {
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
}

std::string all(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  return text;
}

/// A user restitution law (RestitutionOptions::model is open to any) that has no data
/// above `limit`: it throws there, as a law fitted to a measured range may.
class LawWithoutDataAbove final : public fm::RestitutionModel {
 public:
  explicit LawWithoutDataAbove(double limit) : limit_(limit) {}
  double restitution(double v) const override {
    if (v > limit_) throw std::runtime_error("test law: no data above " + std::to_string(limit_) + " m/s");
    return 0.8;
  }
  std::string describe() const override { return "test law"; }

 private:
  double limit_;
};

/// The low-intensity damper (cases/low_intensity_36_spheres.json), softened 100x.
dr::DamperSimulationOptions low_intensity() {
  dr::DamperSimulationOptions o;
  auto& c = o.world.compartments.front();
  c.particles = {dr::ParticleGroupOptions{36, 0.005, 0.0, 0}};
  c.lattice_counts = {6, 6, 1};
  o.world.materials.front().material.youngs_modulus_pa = 210e9 / 100.0;
  o.amplitude_m = 0.04;
  o.frequency_hz = 2.0;
  o.transient_periods = 0;
  o.analysed_periods = 1;
  o.samples_per_period = 64;
  return o;
}

}  // namespace

TEST_CASE("restitution below the damping table's 0.01 is refused at validation", "[dem_reference]") {
  dr::WorldOptions o;
  o.default_pair.restitution.constant = 0.001;
  CHECK(all(o.validate()) == "dem.default_pair.restitution.constant = 0.001: must be in [0.01, 1]\n");

  dr::WorldOptions table;
  table.default_pair.restitution.table_speeds_m_s = {0.0, 1.0, 2.0};
  table.default_pair.restitution.table_values = {0.8, 0.5, 0.005};
  CHECK(all(table.validate()) == "dem.default_pair.restitution.table_values[2] = 0.005: must be in [0.01, 1]\n");

  dr::WorldOptions at_limit;
  at_limit.default_pair.restitution.constant = 0.01;
  CHECK(at_limit.validate().empty());
}

TEST_CASE("a velocity-dependent restitution law is checked up to the largest impact speed", "[dem_reference]") {
  // ε = 0.8 − 0.5 v: 0.3 at 1 m/s, the floor 1e-3 from 1.6 m/s on.
  const std::shared_ptr<const fm::RestitutionModel> steep = fm::make_linear_restitution(0.8, 0.5);
  dr::WorldOptions o;
  o.default_pair.restitution.model = steep;
  o.integration.max_impact_speed_m_s = 1.0;
  CHECK(o.validate().empty());
  o.integration.max_impact_speed_m_s = 2.0;
  const auto errors = o.validate();
  REQUIRE(errors.size() == 1);
  CHECK_THAT(errors[0], Catch::StartsWith("dem.default_pair.restitution.model = "));
  CHECK_THAT(errors[0], Catch::Contains("must give a restitution in [0.01, 1] at impact speeds 0 to 2"));
  CHECK_THAT(errors[0], Catch::Contains("gives 0.001 at"));

  // run_harmonic raises the speed to the drive's 2XΩ + √(2|g|L) = 1.89 m/s here: the
  // law fine at the world's 1 m/s is refused for the run.
  auto run = low_intensity();
  run.world.default_pair.restitution.model = steep;
  CHECK(run.world.validate().empty());
  const auto run_errors = run.validate();
  REQUIRE(run_errors.size() == 1);
  CHECK_THAT(run_errors[0], Catch::StartsWith("dem.default_pair.restitution.model = "));
  CHECK_THROWS_WITH(dr::run_harmonic(run), Catch::Contains("restitution.model"));

  // A law that throws inside the checked range is reported, not propagated.
  dr::WorldOptions throwing;
  throwing.default_pair.restitution.model = std::make_shared<LawWithoutDataAbove>(0.5);
  const auto thrown = throwing.validate();
  REQUIRE(thrown.size() == 1);
  CHECK_THAT(thrown[0], Catch::Contains("throws at"));
  CHECK_THAT(thrown[0], Catch::Contains("test law: no data above"));
}

TEST_CASE("an exception in a contact law on two threads stops the world with kFailed, not std::terminate",
          "[dem_reference]") {
  // 2000 spheres with 2 threads run the step on an OpenMP team (above 1500 particles).
  // The law passes validation (it is checked to 1 m/s) and throws above 3 m/s: the bed
  // is thrown at 5 m/s into the −x and −y walls, which particles of both threads'
  // partitions touch, so both threads throw in the same sweep.
  for (const int threads : {2, 1}) {
    auto o = dem_test::box_world(2000, 0.004, 0.8, 0.3);
    o.threads = threads;
    o.integration.max_impact_speed_m_s = 1.0;
    o.default_pair.restitution.model = std::make_shared<LawWithoutDataAbove>(3.0);
    REQUIRE(o.validate().empty());
    dr::World world(o);
    world.add_velocity({-5.0, -5.0, 0.0});
    const dr::ContainerState rest;
    for (int k = 0; k < 20 && world.status().outcome == dr::Outcome::kCompleted; ++k) world.step(rest);
    INFO("threads " << threads);
    REQUIRE(world.status().outcome == dr::Outcome::kFailed);
    CHECK_THAT(world.status().message, Catch::Contains("failed: test law: no data above 3"));
    CHECK_THAT(world.status().message, Catch::StartsWith("step "));
    // A failed world stays stopped: further steps do nothing.
    const auto steps = world.step_count();
    world.step(rest);
    CHECK(world.step_count() == steps);
  }
}

TEST_CASE("inner structures outside their container are refused with both extents", "[dem_reference]") {
  // Default container: box 160 × 61 × 40 mm centred on the compartment origin.
  dr::WorldOptions o;
  auto& c = o.compartments.front();
  c.plates = {dr::PlateOptions{{0.0, 0.0, 0.0}, {0.002, 0.061, 0.040}, -1},   // divider: touches y and z walls
              dr::PlateOptions{{0.3, 0.0, 0.0}, {0.002, 0.02, 0.02}, -1},     // wholly outside (+x)
              dr::PlateOptions{{0.0, 0.03, 0.0}, {0.01, 0.02, 0.01}, -1},     // partly through the +y wall
              dr::PlateOptions{{0.0, 0.0, 0.0}, {0.2, 0.1, 0.1}, -1}};        // fills the container
  c.pins = {dr::PinOptions{{0.05, 0.0, 0.0}, 2, 0.003, 0.06, -1},   // through both z walls
            dr::PinOptions{{0.05, 0.0, 0.03}, 2, 0.003, 0.019, -1},  // above the lid: 0.0205..0.0395 > 0.02
            dr::PinOptions{{0.0, 0.0335, 0.0}, 0, 0.003, 0.02, -1}}; // touches the +y wall from outside only
  const auto errors = o.validate();
  INFO(all(errors));
  REQUIRE(errors.size() == 4);
  CHECK(errors[0] ==
        "dem.compartments[0].plates[1].centre_m = [0.3, 0, 0]: plate 1 spans x [0.299, 0.301], y [-0.01, 0.01], "
        "z [-0.01, 0.01] m, the container's inside x [-0.08, 0.08], y [-0.0305, 0.0305], z [-0.02, 0.02] m "
        "(compartment frame): the plate must reach into the container");
  CHECK_THAT(errors[1], Catch::StartsWith("dem.compartments[0].plates[3].size_m = [0.2, 0.1, 0.1]: plate 3 spans"));
  CHECK_THAT(errors[1], Catch::EndsWith("the plate must leave room for the bed"));
  CHECK_THAT(errors[2], Catch::StartsWith("dem.compartments[0].pins[1].centre_m = [0.05, 0, 0.03]: pin 1 spans"));
  CHECK_THAT(errors[2], Catch::Contains("z [0.0205, 0.0395] m, the container's inside"));
  CHECK_THAT(errors[3], Catch::StartsWith("dem.compartments[0].pins[2].centre_m = [0, 0.0335, 0]: pin 2 spans"));

  // A cylinder: a plate beside the mantle but inside the bounding box is outside.
  dr::WorldOptions cyl;
  auto& cc = cyl.compartments.front();
  cc.container = {fm::ContainerShape::kCylinder, {0.0, 0.0, 0.0}, 0.0125, 0.110, 0};
  cc.particles = {dr::ParticleGroupOptions{20, 0.0025, 0.0, 0}};
  cc.lattice_counts.clear();
  cc.plates = {dr::PlateOptions{{0.0, 0.011, 0.011}, {0.01, 0.002, 0.002}, -1}};  // corner: 0.01² + 0.01² > R²
  const auto cyl_errors = cyl.validate();
  REQUIRE(cyl_errors.size() == 1);
  CHECK_THAT(cyl_errors[0], Catch::StartsWith("dem.compartments[0].plates[0].centre_m = [0, 0.011, 0.011]"));
  cc.plates.front().centre_m = {0.0, 0.011, 0.0};  // reaches through the mantle
  CHECK(cyl.validate().empty());
}

TEST_CASE("every DEM option has a physical range", "[dem_reference]") {
  const auto errors_of = [](const auto& edit) {
    dr::DamperSimulationOptions o = low_intensity();
    edit(o);
    return o.validate();
  };
  const auto refused = [&](const auto& edit, const std::string& line) {
    const auto errors = errors_of(edit);
    INFO(all(errors));
    CHECK(has(errors, line));
  };
  refused([](auto& o) { o.world.integration.max_impact_speed_m_s = 1e200; },
          "dem.integration.max_impact_speed_m_s = 1e+200: must be in (0, 1000] m/s");
  refused([](auto& o) { o.world.integration.max_impact_speed_m_s = 1e60; },
          "dem.integration.max_impact_speed_m_s = 1e+60: must be in (0, 1000] m/s");
  refused([](auto& o) { o.world.integration.time_step_s = 1e-15; },
          "dem.integration.time_step_s = 1e-15: must be 0 (automatic) or in [1e-10, 0.001] s");
  refused([](auto& o) { o.world.integration.steps_per_contact = 1000000; },
          "dem.integration.steps_per_contact = 1000000: must be 0 (automatic) or in [20, 10000]");
  refused([](auto& o) { o.world.integration.skin_fraction = 1e-6; },
          "dem.integration.skin_fraction = 1e-06: must be in [0.01, 2]");
  refused([](auto& o) { o.world.threads = 100000; }, "dem.threads = 100000: must be in [0, 1024] (0 = all available)");
  refused([](auto& o) { o.world.gravity_m_s2[2] = -1e300; }, "dem.gravity_m_s2[2] = -1e+300: must be in [-10000, 10000] m/s^2");
  refused([](auto& o) { o.world.compartments[0].offset_m[1] = NAN; }, "dem.compartments[0].offset_m[1] = nan: must be finite");
  refused([](auto& o) { o.world.compartments[0].particles[0].radius_m = 1e-9; },
          "dem.compartments[0].particles[0].radius_m = 1e-09: must be in [1e-05, 1] m");
  refused([](auto& o) { o.world.default_pair.rolling_friction = 2.0; }, "dem.default_pair.rolling_friction = 2: must be in [0, 1]");
  refused([](auto& o) { o.frequency_hz = 1e-6; }, "dem.frequency_hz = 1e-06: must be in [0.01, 10000] Hz");
  refused([](auto& o) { o.amplitude_m = 100.0; }, "dem.amplitude_m = 100: must be in (0, 10] m");
  refused([](auto& o) { o.settling_time_s = 1e9; }, "dem.settling_time_s = 1e+09: must be -1 (automatic) or in [0, 100] s");
  refused([](auto& o) { o.transient_periods = 1000000; }, "dem.transient_periods = 1000000: must be in [0, 100000]");
  refused([](auto& o) { o.analysed_periods = -3; }, "dem.analysed_periods = -3: must be in [1, 100000]");
  refused([](auto& o) { o.samples_per_period = 8; }, "dem.samples_per_period = 8: must be in [16, 100000]");
  refused([](auto& o) { o.snapshots = 65; }, "dem.snapshots = 65: must be in [0, 64]");
  // Each within range, together beyond memory: refused before anything is allocated.
  refused(
      [](auto& o) {
        o.samples_per_period = 100000;
        o.analysed_periods = 100000;
      },
      "dem.samples_per_period = 100000: samples_per_period x analysed_periods = 10000000000 recorded samples must be "
      "<= 10000000");
  // 2XΩ at 10 m and 10 kHz: far beyond any impact the contact law describes.
  refused(
      [](auto& o) {
        o.amplitude_m = 1.0;
        o.frequency_hz = 1000.0;
      },
      "dem.amplitude_m = 1: the drive's impact speed");
  CHECK(errors_of([](auto&) {}).empty());
}

TEST_CASE("estimate_run predicts the time step, the steps and the recorded samples of a run", "[dem_reference]") {
  auto o = low_intensity();
  o.snapshots = 2;
  const dr::RunEstimate e = dr::estimate_run(o);
  const dr::DamperResult r = dr::run_harmonic(o);
  REQUIRE(r.summary.outcome == dr::Outcome::kCompleted);
  CHECK(e.particles == 36);
  CHECK(e.time_step_s == r.time_step_s);
  CHECK(e.steps_per_period == r.steps_per_period);
  CHECK(e.total_steps == r.summary.steps);
  CHECK(e.total_steps == e.settling_steps + e.transient_steps + e.analysed_steps);
  CHECK(e.particle_steps == static_cast<double>(r.summary.particle_steps));
  CHECK(e.recorded_samples == static_cast<std::int64_t>(r.series.time_s.size()));
  CHECK(e.recorded_samples == static_cast<std::int64_t>(r.series.force_n.size()));
  CHECK(e.snapshots == static_cast<int>(r.snapshots.size()));
  CHECK(e.snapshot_bytes == 2 * 36 * (3 * sizeof(dr::Vec3) + sizeof(double) + sizeof(int)));
  CHECK(e.signal_bytes >= static_cast<std::size_t>(e.recorded_samples) * 7 * sizeof(double));
  CHECK(e.memory_bytes == e.particle_bytes + e.neighbour_bytes + e.contact_bytes + e.signal_bytes + e.snapshot_bytes);
  CHECK(e.wall_time_s == Approx(e.particle_steps / e.particle_steps_per_s));

  // The world part against a built world of 2000 spheres (the reserves dominate there).
  dr::DamperSimulationOptions big = low_intensity();
  big.world = dem_test::box_world(2000, 0.004, 0.8, 0.3);
  const dr::RunEstimate eb = dr::estimate_run(big);
  const dr::World world(big.world);
  const double world_bytes = static_cast<double>(eb.particle_bytes + eb.neighbour_bytes + eb.contact_bytes);
  INFO("estimate " << world_bytes << " B, world " << world.memory_bytes() << " B");
  CHECK(world_bytes > 0.7 * static_cast<double>(world.memory_bytes()));
  CHECK(world_bytes < 1.5 * static_cast<double>(world.memory_bytes()));

  // Memory that would not fit shows in the estimate, which allocates nothing of it.
  auto huge = low_intensity();
  huge.samples_per_period = 100000;
  huge.analysed_periods = 100;
  const auto eh = dr::estimate_run(huge);
  CHECK(eh.recorded_samples == 10000000);
  CHECK(eh.signal_bytes > 700'000'000);
}

TEST_CASE("the first progress report comes before the world is built, as stage setup", "[dem_reference]") {
  auto o = low_intensity();
  struct Hooks : pdamp::base::RunHooks {
    std::vector<pdamp::base::Progress> reports;
    void progress(const pdamp::base::Progress& p) override { reports.push_back(p); }
  } hooks;
  const auto r = dr::run_harmonic(o, hooks);
  const auto& reports = hooks.reports;
  REQUIRE(reports.size() >= 2);
  CHECK(reports[0].stage == "setup");
  CHECK(reports[1].stage == "setup");
  CHECK(reports[0].eta_s > 0.0);
  CHECK(std::isnan(reports[0].steps_per_s));  // no rate before the first step
  // Simulated time since the drive started, from the settling's start (negative) to the
  // run's end; no label (the caller names the run).
  const double end_s = (o.transient_periods + o.analysed_periods) / o.frequency_hz;
  const std::int64_t settling_steps = r.summary.steps - (o.transient_periods + o.analysed_periods) * r.steps_per_period;
  CHECK(reports[0].done == Approx(-static_cast<double>(settling_steps) * r.time_step_s).epsilon(1e-12));
  for (const auto& p : reports) {
    CHECK(p.label.empty());
    CHECK_FALSE(p.counts_points);
    CHECK(p.total == Approx(end_s).epsilon(1e-12));
    CHECK(p.done <= p.total);
  }
}
