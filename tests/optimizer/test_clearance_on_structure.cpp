// Tests of the clearance on a structure (docs/optimizer.md): the single-mode closed form for h
// against optimizer::solve on the harmonic balance, on a hand-built 1-mode model and on the
// base-excited beam of cases/beam_base_excited.json, for both objectives; error paths.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include <stdexcept>

#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/structure/beam.hpp"
#include "optimizer/beam_problem.hpp"

namespace {

namespace opt = pdamp::optimizer;
namespace fm = pdamp::formulas;
namespace st = pdamp::structure;
using pdamp::test::beam_model;
using pdamp::test::beam_options;

/// A 2 kg oscillator on a base at 3 Hz, ζ = 0.5 %, as a mass-normalised mode:
/// φ = 1/√m, Γ = √m (x direction).
st::ModalModel one_mode_model() {
  const double mass_kg = 2.0;
  st::ModalModel model;
  model.natural_frequencies_hz = Eigen::VectorXd::Constant(1, 3.0);
  model.damping_ratios = Eigen::VectorXd::Constant(1, 0.005);
  model.modal_masses_kg = Eigen::VectorXd::Ones(1);
  st::PointModeShape site;
  site.name = "site";
  site.translation = Eigen::MatrixXd::Zero(2, 1);
  site.translation(0, 0) = 1.0 / std::sqrt(mass_kg);
  site.rotation = Eigen::RowVectorXd::Zero(1);
  model.points.push_back(site);
  model.base_participation = Eigen::MatrixXd::Zero(1, 2);
  model.base_participation(0, 0) = std::sqrt(mass_kg);
  return model;
}

opt::ClearanceOnStructureOptions one_mode_options(fm::DamperModel damper_model) {
  opt::ClearanceOnStructureOptions o;
  o.site = "site";
  o.container_mass_kg = 0.1;
  o.bed_mass_kg = 0.1;
  o.model = damper_model;
  o.base_amplitude_m = 1e-3;
  o.frequency_min_hz = 2.4;
  o.frequency_max_hz = 3.6;
  o.frequency_points = 200;
  return o;
}

/// Peak |X/U| at n clearances geometrically spaced over [lo, hi]: the smallest of them.
double scanned_lowest_peak(const st::ModalModel& model, const opt::ClearanceOnStructureOptions& o, double lo,
                           double hi, int n) {
  double best = 1e300;
  for (int k = 0; k < n; ++k) {
    const double h = lo * std::pow(hi / lo, static_cast<double>(k) / (n - 1));
    best = std::min(best, opt::clearance_response(model, o, h).peak_transmissibility);
  }
  return best;
}

void report(const char* label, const opt::ClearanceOnStructureResult& r) {
  std::printf("%s: h formula %.3f mm, solver %.3f mm (%+.2f %%); peak X/U %.3f at %.3f Hz (formula %.3f at %.3f Hz),"
              " X %.3f mm, x_opt %.3f mm, onset %.3f mm%s; %d evaluations, %.3f s\n",
              label, 1e3 * r.estimate.clearance_m, 1e3 * r.clearance_m,
              100.0 * (r.clearance_m / r.estimate.clearance_m - 1.0), r.response.peak_transmissibility,
              r.response.peak_frequency_hz, r.estimate.transmissibility, r.estimate.resonance_hz,
              1e3 * r.response.damper_amplitude_m, 1e3 * r.response.design_stroke_m, 1e3 * r.response.onset_m,
              r.response.held_at_onset ? " (held)" : "", r.summary.evaluations, r.solve_time_s);
}

}  // namespace

// Reference: for the 2 kg oscillator M = 1 + (m_c + m_app)/2, P = √2 + (m_c + m_app)/√2,
// so Γ_eff = bP/M = 1 exactly, ζ_s' = ζ/√M, and h = U/(2 (x_opt/h)(ζ_s' + ½η*_opt μ)).
TEST_CASE("closed form for h on a 1-mode oscillator", "[optimizer]") {
  const auto damper_model = GENERATE(fm::DamperModel::kRolling, fm::DamperModel::kBouncing);
  CAPTURE(fm::to_string(damper_model));
  const opt::ClearanceOnStructureOptions o = one_mode_options(damper_model);
  const opt::ClearanceEstimate e = opt::estimate_clearance_on_structure(one_mode_model(), o);
  const double m_app = e.apparent_mass_fraction * o.bed_mass_kg;
  const double mass = 1.0 + (o.container_mass_kg + m_app) / 2.0;
  CHECK(e.participation == Approx(1.0).epsilon(1e-12));
  CHECK(e.structural_damping == Approx(0.005 / std::sqrt(mass)).epsilon(1e-12));
  CHECK(e.mass_ratio == Approx(o.bed_mass_kg / 2.0 / mass).epsilon(1e-12));
  CHECK(e.resonance_hz == Approx(3.0 / std::sqrt(mass)).epsilon(1e-12));
  const double x_over_h = damper_model == fm::DamperModel::kRolling ? 0.4 : 1.0 / M_PI;
  CHECK(e.stroke_over_clearance == Approx(x_over_h).epsilon(2e-4));  // rolling: 0.8976·1.4/π = 0.40001
  CHECK(e.clearance_m ==
        Approx(o.base_amplitude_m / (2.0 * e.stroke_over_clearance *
                                     (e.structural_damping + 0.5 * e.eta_star_design * e.mass_ratio)))
            .epsilon(1e-12));
  if (damper_model == fm::DamperModel::kBouncing) CHECK(e.eta_star_design == Approx(4.0 / M_PI).epsilon(1e-9));
}

// The optimiser on the harmonic balance (every root, the largest non-unstable one per
// frequency) against the closed form. 1 mode: the formula's approximations (resonance at
// ω_r, the bed's base load iΩc_eq·U and the absolute-vs-relative motion neglected, η*
// and m_app frozen at the design point along the peak) are O(ζ_tot) ≈ 2.5-3.5 % in X/U
// at most and in fact partly cancel: 0.13 % (rolling) and 0.20 % (bouncing) observed; 1 %
// asked. The beam: ζ_tot = 0.17 (μ = 0.39) is a heavily damped peak, 6 % below ω_r,
// and the other 2 modes add their quasi-static share: 3.8 % observed, 6 % asked.
TEST_CASE("design stroke at resonance: optimiser vs closed form", "[optimizer]") {
  SECTION("1-mode oscillator") {
    const auto damper_model = GENERATE(fm::DamperModel::kRolling, fm::DamperModel::kBouncing);
    CAPTURE(fm::to_string(damper_model));
    opt::ClearanceOnStructureOptions o = one_mode_options(damper_model);
    o.objective = opt::ClearanceObjective::kDesignStrokeAtResonance;
    const opt::ClearanceOnStructureResult r = opt::size_clearance_on_structure(one_mode_model(), o);
    report(fm::to_string(damper_model).data(), r);
    INFO(r.summary.full_report());
    CHECK(r.summary.outcome == opt::Outcome::kConverged);
    CHECK(r.response.damper_amplitude_m / r.response.design_stroke_m == Approx(1.0).epsilon(1e-3));
    CHECK(r.clearance_m == Approx(r.estimate.clearance_m).epsilon(0.01));
    CHECK(r.response.peak_transmissibility == Approx(r.estimate.transmissibility).epsilon(0.01));
    CHECK_FALSE(r.response.held_at_onset);
    CHECK(r.solve_time_s < 1.0);  // ~0.15 s; the bound leaves room for a loaded machine
  }
  SECTION("base-excited beam, rolling") {
    opt::ClearanceOnStructureOptions o = beam_options();
    o.objective = opt::ClearanceObjective::kDesignStrokeAtResonance;
    const opt::ClearanceOnStructureResult r = opt::size_clearance_on_structure(beam_model(), o);
    report("beam", r);
    INFO(r.summary.full_report());
    CHECK(r.summary.outcome == opt::Outcome::kConverged);
    CHECK(r.response.damper_amplitude_m / r.response.design_stroke_m == Approx(1.0).epsilon(1e-3));
    CHECK(r.clearance_m == Approx(r.estimate.clearance_m).epsilon(0.06));
    CHECK(r.estimate.mass_ratio > 0.3);
    CHECK(r.solve_time_s < 1.0);
  }
}

// The lowest peak: the solver's h beats (to 1e-3) a 13-point scan of the search box, and
// sits near the top of the η* curve (the ideal peak (1+κ)h/π: 0.446 h rolling, h/π
// bouncing), not at the onset. On the beam it sits next to the cliff below which the
// damper is overwhelmed (a high branch, X/h ≈ 6-10), which the global stage keeps to.
TEST_CASE("lowest FRF peak: optimiser vs scan and closed form", "[optimizer]") {
  SECTION("1-mode oscillator") {
    const auto damper_model = GENERATE(fm::DamperModel::kRolling, fm::DamperModel::kBouncing);
    CAPTURE(fm::to_string(damper_model));
    opt::ClearanceOnStructureOptions o = one_mode_options(damper_model);
    o.objective = opt::ClearanceObjective::kLowestPeak;
    const st::ModalModel model = one_mode_model();
    const opt::ClearanceOnStructureResult r = opt::size_clearance_on_structure(model, o);
    report(fm::to_string(damper_model).data(), r);
    INFO(r.summary.full_report());
    CHECK(r.summary.outcome == opt::Outcome::kConverged);
    const double h0 = r.estimate.clearance_m;
    CHECK(r.response.peak_transmissibility <= 1.001 * scanned_lowest_peak(model, o, h0 / 3.0, 3.0 * h0, 13));
    const double ideal_peak = fm::optimum_stroke(damper_model, 1.0, o.model_options).x_opt_ideal_m;
    CHECK(r.response.damper_amplitude_m / r.clearance_m == Approx(ideal_peak).epsilon(0.03));
    // the peak is flat: the design-stroke h gives a peak within 4 % of the lowest
    CHECK(opt::clearance_response(model, o, h0).peak_transmissibility <= 1.04 * r.response.peak_transmissibility);
    CHECK(r.clearance_m == Approx(h0).epsilon(damper_model == fm::DamperModel::kRolling ? 0.15 : 0.03));
  }
  SECTION("base-excited beam, rolling") {
    opt::ClearanceOnStructureOptions o = beam_options();
    o.objective = opt::ClearanceObjective::kLowestPeak;
    const st::ModalModel model = beam_model();
    const opt::ClearanceOnStructureResult r = opt::size_clearance_on_structure(model, o);
    report("beam", r);
    INFO(r.summary.full_report());
    const double h0 = r.estimate.clearance_m;
    CHECK(r.response.peak_transmissibility <= 1.001 * scanned_lowest_peak(model, o, h0 / 3.0, 3.0 * h0, 13));
    CHECK(r.clearance_m == Approx(h0).epsilon(0.06));
    CHECK(r.response.peak_transmissibility < 3.6);
    // below the cliff: the high branch (damper overwhelmed) is the largest stable response
    CHECK(opt::clearance_response(model, o, 0.85 * h0).peak_transmissibility > 5.0 * r.response.peak_transmissibility);
  }
}

// Above the lowest-peak h the resonant response is held at the onset (harmonic_balance's
// held_at_jump): X = X_onset(h) = 0.376 h, so the peak grows linearly with h. The case's
// h = 30 mm is there: X = 11.3 mm, as its description says.
TEST_CASE("the onset cliff holds the peak at the onset for large clearances", "[optimizer]") {
  const opt::ClearanceOnStructureOptions o = beam_options();
  const opt::ClearanceResponse r = opt::clearance_response(beam_model(), o, 0.030);
  CHECK(r.held_at_onset);
  CHECK(r.damper_amplitude_m == Approx(r.onset_m).epsilon(1e-9));
  CHECK(r.damper_amplitude_m == Approx(0.01128).epsilon(2e-3));
  CHECK(r.peak_transmissibility == Approx(r.damper_amplitude_m / o.base_amplitude_m).epsilon(1e-3));
}

TEST_CASE("clearance on a structure rejects invalid input", "[optimizer]") {
  const st::ModalModel model = one_mode_model();
  opt::ClearanceOnStructureOptions o = one_mode_options(fm::DamperModel::kRolling);
  SECTION("auto model") {
    o.model = fm::DamperModel::kAuto;
    CHECK_THROWS_WITH(opt::estimate_clearance_on_structure(model, o), Catch::Contains("model = auto"));
  }
  SECTION("unknown site") {
    o.site = "nowhere";
    CHECK_THROWS_AS(opt::estimate_clearance_on_structure(model, o), std::invalid_argument);
  }
  SECTION("mode out of range") {
    o.mode = 1;
    CHECK_THROWS_WITH(opt::estimate_clearance_on_structure(model, o), Catch::Contains("mode = 1"));
  }
  SECTION("bad numbers") {
    o.bed_mass_kg = 0.0;
    o.frequency_max_hz = 1.0;
    o.drive_direction = {1.0, 1.0};
    const std::vector<std::string> problems = o.validate();
    CHECK(problems.size() == 3);
  }
  SECTION("no base participation") {
    st::ModalModel bare = model;
    bare.base_participation.resize(1, 0);
    CHECK_THROWS_WITH(opt::estimate_clearance_on_structure(bare, o), Catch::Contains("base participation"));
  }
}
