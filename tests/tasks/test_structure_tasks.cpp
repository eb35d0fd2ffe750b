// The structure studies as library calls, without the binary: modes, the harmonic-balance
// frequency response and the averaged free decay of shipped cases.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>

#include "cli/cli_support.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/mode_decay.hpp"
#include "pdamp/tasks/frf.hpp"
#include "pdamp/tasks/modes.hpp"

using namespace pdamp;
using test::case_path;

// Reference: the containers add mass and no stiffness, so every natural frequency with them
// is below the bare one; μ = b² Σ m_bed / m_j is recomputed here from the result's drive
// shapes, the case's bed masses and the modal masses (rounding only).
TEST_CASE("modes: the containers lower every frequency, and the mass ratio is b^2 m_bed / m_j", "[tasks]") {
  const auto c = case_file::load_case(case_path("beam_base_excited.json"));
  const auto m = tasks::run_modes(c, {});
  REQUIRE(m.mode_count >= 2);
  double bed = 0.0;
  for (const auto& l : c.dampers.front().layers) bed += l.bed_mass_kg;
  for (Eigen::Index j = 0; j < m.mode_count; ++j) {
    CHECK(m.frequencies_with_containers_hz[j] < m.modal.natural_frequencies_hz[j]);
    const double b = m.drive_shapes(j, 0);
    CHECK(m.mass_ratio(j, 0) == Approx(b * b * bed / m.modal.modal_masses_kg[j]).epsilon(1e-12));
  }
  CHECK(m.backbone_of_mode.count(0) == 1);
  CHECK(tasks::to_json(m, {})["modes"].size() == static_cast<std::size_t>(m.mode_count));
}

// Reference: the linear response without beds peaks at the first natural frequency with the
// containers (a lightly damped mode, ζ = 0.3%); 0.5% is two steps of the task's frequency grid.
TEST_CASE("frf: the response without beds peaks at the first natural frequency with the containers", "[tasks]") {
  const auto c = case_file::load_case(case_path("beam_base_excited.json"));
  const auto r = tasks::run_frf(c, {}, base::silent_hooks(), base::local_executor());
  REQUIRE(r.harmonic.has_value());
  const auto& response = r.harmonic->response;
  REQUIRE_FALSE(response.linear_peaks.empty());
  const auto modes = tasks::run_modes(c, {});
  CHECK(response.linear_peaks.front().frequency_hz == Approx(modes.frequencies_with_containers_hz[0]).epsilon(5e-3));
  // The beds damp the resonance: a lower peak than without them.
  REQUIRE(tasks::first_output_peak(response) != nullptr);
  CHECK(tasks::first_output_peak(response)->magnitude < response.linear_peaks.front().magnitude);
  CHECK(tasks::to_json(r, {})["peaks"].size() == response.peaks.size());
}

TEST_CASE("frf and decay refuse a case whose task is of another kind, naming /task", "[tasks]") {
  const auto decay_case = case_file::load_case(case_path("manipulator_link_decay.json"));
  CHECK_THROWS_AS(tasks::run_frf(decay_case, {}, base::silent_hooks(), base::local_executor()), base::InputError);
  const auto frf_case = case_file::load_case(case_path("beam_base_excited.json"));
  try {
    (void)tasks::run_decay(frf_case, {}, base::silent_hooks());
    FAIL("no error");
  } catch (const base::InputError& e) {
    CHECK(e.pointer() == "/task");
  }
}

// Reference: energy conservation. The averaged decay integrates the dissipated energies with
// the amplitudes, so the initial mechanical energy is the final one plus what the structure
// and each layer dissipated, to the integrator's accuracy (the shipped link closes to 5e-12).
TEST_CASE("decay: the initial energy is the final energy plus what the structure and the layers dissipated", "[tasks]") {
  const auto c = case_file::load_case(case_path("manipulator_link_decay.json"));
  const auto r = tasks::run_decay(c, {}, base::silent_hooks());
  const auto& first = r.decay.samples.front();
  const auto& last = r.decay.samples.back();
  double dissipated = last.structural_dissipated_energy_j;
  for (double e : last.layer_dissipated_energy_j) dissipated += e;
  CHECK(first.mechanical_energy_j == Approx(last.mechanical_energy_j + dissipated).epsilon(1e-9));
  CHECK(std::isfinite(r.decay.settling_time_s));
  const auto j = tasks::to_json(r, {});
  CHECK(j["settling_time_s"] == r.decay.settling_time_s);
  CHECK(j["decay"]["file"].is_null());
}

// The DEM stepped sine as a library call on the CLI tests' one-mode case (a 0.5 kg mode at
// 2 Hz, 0.3 kg container, a small bed). Reference: the rules themselves: every point runs
// at least the case's /dem/transient_periods, and reports its convergence; points that would
// fall on one frequency are refused before any run, naming the flags.
TEST_CASE("frf --method dem: the case's transient periods are honoured and each point says whether it converged",
          "[tasks][dem]") {
  auto c = case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/one_mode_dem_frf.json");
  c.dem.simulation.transient_periods = 12;
  tasks::FrfOptions o;
  o.method = tasks::FrfMethod::kDem;
  o.dem = tasks::default_dem_frf_options(c);
  o.dem.points = 2;
  o.dem.min_frequency_hz = 1.5;
  o.dem.max_frequency_hz = 1.7;
  o.dem.directions = {structure::SweepDirection::kUp};
  const auto r = tasks::run_frf(c, o, base::silent_hooks(), base::local_executor());
  REQUIRE(r.stepped);
  CHECK(r.stepped->settling.min_transient_periods == 12);
  const auto& points = r.stepped->branches.at(0).points;
  REQUIRE(points.size() == 2);
  for (const auto& p : points) {
    INFO(p.frequency_hz << " Hz: " << p.transient_periods << " transient periods, change " << p.window_max_relative_change);
    CHECK(p.transient_periods >= 12);
    CHECK(p.analysed_periods == c.dem.simulation.analysed_periods);
    CHECK(p.period_magnitudes.size() == static_cast<std::size_t>(p.periods()));
    CHECK(p.window_periods == static_cast<int>(structure::kConvergenceWindowPeriods));
    CHECK(p.converged == (p.window_max_relative_change <= o.dem.settling.stable_tolerance &&
                          p.window_relative_drift <= o.dem.settling.stable_tolerance));
    // Unconverged: one warning naming the frequency and the scatter.
    std::size_t named = 0;
    for (const auto& w : r.warnings)
      if (w.find("not converged") != std::string::npos &&
          w.find(base::format_number(p.frequency_hz, 5) + " Hz") != std::string::npos)
        ++named;
    CHECK(named == (p.converged ? 0u : 1u));
  }
  const auto json = tasks::to_json(r, tasks::OutputFolder{});
  CHECK(json["frf"]["stepped_sine"]["min_transient_periods"] == 12);
  for (const auto& p : json["frf"]["points"]) {
    CHECK(p.contains("converged"));
    CHECK(p["periods"].get<int>() >= 12 + c.dem.simulation.analysed_periods);
    CHECK(p["convergence"].contains("max_relative_change"));
  }
}

TEST_CASE("frf --method dem: points that would fall on one frequency are refused before the run, naming the flags",
          "[tasks][dem]") {
  const auto c = case_file::load_case(std::string(PDAMP_SOURCE_DIR) + "/tests/cli/data/one_mode_dem_frf.json");
  tasks::FrfOptions o;
  o.method = tasks::FrfMethod::kDem;
  o.dem = tasks::default_dem_frf_options(c);
  o.dem.points = 1000;  // 1e-9 Hz apart: far closer than a step per period (N ~ 1e5)
  o.dem.min_frequency_hz = 1.5;
  o.dem.max_frequency_hz = 1.5 + 1e-6;
  bool refused = false;
  try {
    tasks::run_frf(c, o, base::silent_hooks(), base::local_executor());
  } catch (const base::InputError& e) {
    refused = true;
    CHECK(e.file() == "--dem-points, --dem-min-frequency, --dem-max-frequency");
    CHECK(std::string(e.rule()).find("fall on one frequency") != std::string::npos);
  }
  CHECK(refused);
}

// Reference: the same DEM decay run whole. The check's decay ends after the first period
// below 0.9 of its measured fraction (tasks::DecayStop); the measure stops at the first
// period below the fraction, so it sees the same periods and gives the same bits. Mode 3
// of the shipped free-free beam from 0.5 mm comes down to half in about 15 of 30 periods
// (contacts softened 1000 times: a test of the bookkeeping, not of the bed).
TEST_CASE("a mode's DEM decay check ends after its measure and measures what the whole decay does", "[tasks]") {
  std::ifstream in(case_path("free_free_beam_damping.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["task"].erase("dem_check");
  document["task"].erase("calibration");
  document["dem"] = {{"stiffness_softening", 0.001}};
  const auto c = case_file::load_case_document(document, case_path("free_free_beam_damping.json"));
  const auto modes = tasks::run_modes(c, {});
  const auto setup = case_file::structure_setup(c, case_file::LossMethod::kFormulas);
  const Eigen::Index mode = 2;
  const double f = modes.frequencies_with_containers_hz[mode];
  const double q0 = 0.0005 / std::abs(modes.drive_shapes(mode, 0));
  const tasks::ModeDecayWindow window{30, 0.5};
  const auto check = tasks::mode_decay_check(c, 0, setup.modal, setup.dampers.front(), "free_end", static_cast<int>(mode),
                                             q0, f, window, "check", "/task", base::silent_hooks());

  Eigen::VectorXd q = Eigen::VectorXd::Zero(setup.modal.mode_count());
  q[mode] = q0;
  case_file::DecayTask decay;
  decay.initial_state = case_file::DecayTask::InitialState::kModalAmplitudes;
  decay.modal_amplitudes.assign(q.data(), q.data() + q.size());
  decay.duration_s = window.periods / f;
  decay.settling_threshold = window.amplitude_fraction;
  const auto whole = tasks::dem_decay(c, setup.modal, {setup.dampers.front()}, {case_file::cosimulation_damper(c, 0)}, q,
                                      decay, "whole", "/task", {}, base::silent_hooks());
  const auto& h = whole.cosimulation.history;
  const double whole_ratio =
      tasks::modal_decay_damping_ratio(h.time_s, h.modal_displacements.col(mode), f, window.amplitude_fraction) -
      check.bare_damping_ratio;
  CHECK(check.dem_damping_ratio == whole_ratio);
  CHECK(check.dem_final_fraction < window.amplitude_fraction);
  CHECK(check.dem_final_fraction > 0.25);  // ended soon after half, not at 30 periods (about 0.1)
}
