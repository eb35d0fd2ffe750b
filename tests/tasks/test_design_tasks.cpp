// The design studies as library calls, without the binary: the filling ratios of the shipped
// optimisation (the closed forms only) and the placement of the shipped beam case.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "cli/cli_support.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/tasks/bed_calibration.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/placement.hpp"
#include "support/temp_dir.hpp"

using namespace pdamp;
using test::case_path;

// Reference: the optimiser's own scoring (evaluate_filling_design) of the chosen slabs, and
// the budget. The comparison decay of the chosen design is the same free decay sampled more
// densely: its settling time is the design's (the settling instant is found by bisection,
// not on the samples), to the bisection's tolerance.
TEST_CASE("filling ratios: the chosen design is within the budget and its decay is the optimiser's", "[tasks]") {
  const auto c = case_file::load_case(case_path("manipulator_link_optimize.json"));
  tasks::FillingRatiosOptions options;
  options.skip_verify = true;
  options.calibrated = false;  // the closed forms
  const auto r = tasks::run_filling_ratios(c, options, base::silent_hooks(), base::local_executor());
  CHECK_FALSE(r.verification.has_value());
  const auto& chosen = r.optimum.chosen;
  CHECK(chosen.total_mass_kg <= r.mass_budget_kg * (1.0 + 1e-9));
  for (const auto& l : chosen.layers) CHECK(l.slabs == std::round(l.slabs));
  const auto again = optimizer::evaluate_filling_design(r.problem.modal, r.problem.options, chosen.slabs());
  CHECK(again.objective == chosen.objective);
  REQUIRE(r.comparison.decays.size() == 4);  // chosen, baseline, initial, without particles
  CHECK(r.comparison.decays[0].settling_time_s == Approx(chosen.settling_time_s).epsilon(1e-6));
  CHECK(r.comparison.decays[1].settling_time_s == Approx(r.optimum.baseline.settling_time_s).epsilon(1e-6));
  // Without particles the comparison's envelope ends above every design's.
  for (std::size_t k = 0; k < 3; ++k)
    CHECK(r.comparison.decays[3].samples.back().threshold_measure_m > r.comparison.decays[k].samples.back().threshold_measure_m);
  // The references: without particles only the structure damps (its decay is slower than
  // any design's); the same mass in one compartment is scored at its own best clearance.
  CHECK(r.optimum.bare.total_mass_kg == 0.0);
  CHECK(r.optimum.bare.objective > chosen.objective);
  CHECK(r.optimum.bare.objective > r.optimum.baseline.objective);
  CHECK(r.optimum.same_mass.total_mass_kg == chosen.total_mass_kg);
  // Its clearance is searched from one sphere diameter of travel (the candidates' smallest)
  // up: nearby clearances inside that range are no better.
  const double h = r.optimum.same_mass.layers.front().clearance_m;
  double smallest = INFINITY;
  for (const auto& l : r.problem.options.layers) smallest = std::min(smallest, l.slab_length_m);
  CHECK(h >= smallest * (1.0 - 1e-12));
  for (const double factor : {0.95, 1.05}) {
    if (h * factor < smallest) continue;
    double particles = 0.0;
    for (const auto& l : chosen.layers) particles += l.particles;
    const auto nearby = optimizer::evaluate_single_compartment(r.problem.modal, r.problem.options, chosen.total_mass_kg,
                                                               particles, h * factor);
    CHECK(nearby.objective >= r.optimum.same_mass.objective);
  }
  const auto j = tasks::to_json(r);
  CHECK(j["verification"].is_null());
  CHECK(j["designs"]["same_mass"]["layers"][0]["slabs"].is_null());
  CHECK(j["design"]["total_mass_kg"] == chosen.total_mass_kg);
}

// Reference: the scan evaluates sites and the refinement only improves on the best of them;
// the case's own site is one of the candidates the search may choose.
TEST_CASE("placement: the chosen site damps at least as much as every scanned site and the case's own", "[tasks]") {
  const auto c = case_file::load_case(case_path("free_free_beam_placement.json"));
  const auto s = tasks::run_placement(c, {});
  const auto& r = s.result;
  for (const auto& p : r.scan) CHECK(r.best.objective >= p.objective);
  REQUIRE(r.current.has_value());
  CHECK(r.best.objective >= r.current->objective);
  CHECK(tasks::to_json(s)["design"]["objective"] == r.best.objective);
}

namespace {

/// The shipped optimisation cut short (fewer evaluations, a 1 s verification of contacts
/// softened 1e-4) with its softening check on or off.
case_file::Case short_verification(bool softening_check, double axial_gravity_m_s2 = 0.0,
                                   double stiffness_softening = 1e-4) {
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  nlohmann::json c = nlohmann::json::parse(in);
  c["task"]["global_evaluations"] = 30;
  c["task"]["max_evaluations"] = 120;
  c["task"]["verify"] = {{"duration_s", 1.0}, {"stiffness_softening", stiffness_softening},
                         {"softening_check", softening_check}};
  c["task"].erase("calibration");
  if (axial_gravity_m_s2 != 0.0) {
    c["structure"]["axial_gravity_m_s2"] = axial_gravity_m_s2;
    c["structure"]["geometric_stiffness"] = true;
  }
  return case_file::load_case_document(c, "short_verification.json");
}

}  // namespace

// Reference: the check's definition: each design's DEM decay runs again with contacts ten
// times stiffer, and the judged run is compared with it as the prediction is with the DEM
// (objectives, or the envelopes at the end when neither settled); a design passes only
// when both comparisons agree within the tolerance. Without the check the judged runs are
// the same runs (same seed and settings): equal to the bit.
TEST_CASE("the DEM verification checks its softening against contacts ten times stiffer", "[tasks]") {
  tasks::FillingRatiosOptions options;
  const auto checked = tasks::run_filling_ratios(short_verification(true), options, base::silent_hooks(),
                                                 base::local_executor());
  REQUIRE(checked.verification);
  const auto& v = *checked.verification;
  CHECK(v.softening_check == tasks::SofteningCheckKind::kTwoSoftenings);
  bool converged = true;
  for (const auto& d : v.designs) {
    INFO(d.name);
    REQUIRE(d.softening_check);
    const auto& s = *d.softening_check;
    CHECK(s.stiffness_softening == Approx(1e-3).epsilon(1e-12));
    // A stiffer contact takes a smaller step (t_c ∝ E^(−2/5)): 10^(2/5) = 2.5 times.
    CHECK(s.dem.time_step_s / d.dem.time_step_s == Approx(std::pow(10.0, -0.4)).epsilon(1e-6));
    CHECK(s.dem.steps > 2 * d.dem.steps);
    // 1 s does not settle: the envelopes at the end are compared.
    REQUIRE(s.agreement.compared == tasks::Compared::kEndEnvelope);
    CHECK(s.agreement.relative_difference ==
          Approx((d.dem.end_envelope_m - s.dem.end_envelope_m) / s.dem.end_envelope_m).epsilon(1e-12));
    CHECK(s.agreement.within == (std::abs(s.agreement.relative_difference) <= v.spec.tolerance_relative));
    CHECK(d.passed == (d.agreement.within && s.agreement.within));
    converged = converged && s.agreement.within;
  }
  CHECK(v.softening_converged == converged);
  const auto j = tasks::to_json(checked);
  CHECK(j["verification"]["softening_check"]["kind"] == "two_softenings");
  CHECK(j["verification"]["designs"]["chosen"]["softening_check"]["stiffness_softening"] == Approx(1e-3));

  const auto unchecked = tasks::run_filling_ratios(short_verification(false), options, base::silent_hooks(),
                                                   base::local_executor());
  REQUIRE(unchecked.verification);
  CHECK(unchecked.verification->softening_check == tasks::SofteningCheckKind::kOff);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& d = unchecked.verification->designs[k];
    CHECK_FALSE(d.softening_check);
    CHECK(d.dem.site_displacement_m == v.designs[k].dem.site_displacement_m);
    CHECK(d.passed == d.agreement.within);
  }
}

// Reference: the beam analysed anew with the design's own bed weights (case_file::with_design,
// then structure_setup and the static release on it): a link standing under axial gravity,
// whose geometric stiffness the beds' weights load. The verification scores each design on
// those modes; the search's modes (the case's starting design's) differ where the mass does.
// Contacts softened 1e-3, not 1e-4: the beds' impacts on the link's lighter, standing modes
// reach the DEM's overlap limit (0.1 r) at 1e-4 on some realisations of the beds.
TEST_CASE("under axial gravity the verification scores each design on its own modes", "[tasks]") {
  const case_file::Case c = short_verification(false, -9.80665, 1e-3);
  tasks::FillingRatiosOptions options;
  const auto r = tasks::run_filling_ratios(c, options, base::silent_hooks(), base::local_executor());
  REQUIRE(r.verification);
  bool warned = false;
  for (const auto& w : r.warnings) warned = warned || w.find("its own") != std::string::npos;
  CHECK(warned);
  for (const auto& d : r.verification->designs) {
    INFO(d.name);
    std::vector<long> slabs;
    for (const auto& l : d.design.layers) slabs.push_back(std::lround(l.slabs));
    const case_file::Case dc = case_file::with_design(c, slabs);
    const auto setup = case_file::structure_setup(dc, case_file::LossMethod::kFormulas);
    // Another bed mass than the starting design's, other modes (the baseline may weigh the same).
    const bool other_mass = std::abs(d.design.total_mass_kg - r.optimum.initial.total_mass_kg) > 1e-9;
    CHECK((setup.modal.natural_frequencies_hz(0) != r.problem.modal.natural_frequencies_hz(0)) == other_mass);
    auto own = r.problem.options;
    own.decay.duration_s = r.verification->spec.duration_s;
    own.decay.initial_modal_amplitudes =
        case_file::initial_modal_amplitudes(dc, setup, c.task.filling_ratios->decay).cwiseAbs();
    const auto expected = optimizer::evaluate_filling_design(setup.modal, own, d.design.slabs());
    CHECK(d.predicted.objective == expected.objective);
  }
}

namespace {

/// Records the notes a task gives.
struct NoteHooks : base::RunHooks {
  std::vector<std::string> notes;
  void note(const std::string& text) override { notes.push_back(text); }
};

/// The shipped optimisation on calibrated beds, each bed's decay cut to 1.5 s (5 periods) of
/// contacts softened 1e-3 (softer, a single slab's fast impacts in its 50 mm of travel
/// overlap more than the DEM allows).
case_file::Case short_calibration() {
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  nlohmann::json c = nlohmann::json::parse(in);
  c["task"].erase("verify");
  c["task"]["calibration"] = {{"duration_s", 1.5}, {"stiffness_softening", 1e-3}};
  return case_file::load_case_document(c, "short_calibration.json");
}

}  // namespace

// Reference: the cache's contract (a bed's file holds its decay's field and periods; a
// repeated calibration runs nothing and reads the same numbers; a damaged file runs that bed
// again), the problem's candidates (6 + 3 + 2 beds), and the optimiser's own scoring of the
// chosen design on the calibrated beds.
TEST_CASE("calibrated beds: one DEM decay per candidate bed, cached and resumed bed by bed", "[tasks]") {
  const test::TempDir cache("bed_calibration");
  const auto c = short_calibration();
  tasks::FillingRatiosOptions options;
  options.calibration_cache = cache.path;
  const auto first = tasks::run_filling_ratios(c, options, base::silent_hooks(), base::local_executor());
  REQUIRE(first.calibration);
  const auto& calibration = *first.calibration;
  CHECK(calibration.beds.size() == 11);
  CHECK(calibration.runs == 11);
  for (const auto& bed : calibration.beds) {
    INFO(bed.layer << " " << bed.slabs);
    CHECK_FALSE(bed.cached);
    CHECK(std::filesystem::exists(bed.file));
    CHECK(bed.periods.size() >= 4);  // 1.5 s at about 3.5 Hz: 4 whole periods after the first crossing
    CHECK(bed.field.bed_mass_kg == Approx(bed.slabs * 16 * first.problem.options.layers[0].sphere_mass_kg));
  }
  CHECK(tasks::to_json(first)["method"] == "calibrated");
  const auto again = optimizer::evaluate_filling_design(first.problem.modal, first.problem.options,
                                                        first.optimum.chosen.slabs());
  CHECK(again.objective == first.optimum.chosen.objective);

  // A verification decay too short to give the design's rate (NaN): the loop has nothing to
  // recalibrate with, runs nothing and keeps every bed (it once ran the beds with NaN damping).
  tasks::BedCalibration unchanged = calibration;
  CHECK(tasks::recalibrate_in_design(c, first.problem, unchanged, {1, 3, 2}, NAN, 1e-3, base::silent_hooks(),
                                     base::local_executor())
            .empty());
  CHECK(unchanged.runs == calibration.runs);
  for (std::size_t b = 0; b < calibration.beds.size(); ++b)
    CHECK(unchanged.beds[b].extra_damping_ratio == calibration.beds[b].extra_damping_ratio);

  // Again: every bed from the cache, the same fields, the same choice.
  const auto second = tasks::run_filling_ratios(c, options, base::silent_hooks(), base::local_executor());
  CHECK(second.calibration->runs == 0);
  for (std::size_t b = 0; b < calibration.beds.size(); ++b) {
    CHECK(second.calibration->beds[b].cached);
    CHECK(second.calibration->beds[b].field == calibration.beds[b].field);
  }
  CHECK(second.optimum.chosen.slabs() == first.optimum.chosen.slabs());

  // A damaged file: that bed runs again (the same numbers: the same DEM), with a note.
  { std::ofstream(calibration.beds[4].file) << "{ not json"; }
  NoteHooks hooks;
  const auto third = tasks::run_filling_ratios(c, options, hooks, base::local_executor());
  CHECK(third.calibration->runs == 1);
  CHECK_FALSE(third.calibration->beds[4].cached);
  // The same DEM run again: the same field (its provenance's time aside).
  CHECK(third.calibration->beds[4].field.points == calibration.beds[4].field.points);
  CHECK(third.calibration->beds[4].field.grid == calibration.beds[4].field.grid);
  // The notes: the calibration's cost, the bed's own estimate, and the damaged file named.
  CHECK(std::count_if(hooks.notes.begin(), hooks.notes.end(), [&](const std::string& note) {
          return note.find(calibration.beds[4].file.string()) != std::string::npos;
        }) == 1);
  CHECK(std::count_if(hooks.notes.begin(), hooks.notes.end(), [](const std::string& note) {
          return note.find("particle-steps") != std::string::npos;
        }) == 2);

  // An edited file (a period's η* times 50, under the same name and key) and another bed's
  // file saved under this one's name with its key edited to this bed's: not trusted (once the
  // edit changed the chosen design with no word), each run again with a note saying why.
  const auto edit = [](const std::filesystem::path& file, const auto& change) {
    std::ifstream in(file);
    nlohmann::json d = nlohmann::json::parse(in);
    in.close();
    change(d);
    std::ofstream(file) << d.dump(1);
  };
  edit(calibration.beds[5].file, [](nlohmann::json& d) { d["periods"][0][3] = 50.0 * d["periods"][0][3].get<double>(); });
  std::filesystem::copy_file(calibration.beds[7].file, calibration.beds[6].file,
                             std::filesystem::copy_options::overwrite_existing);
  const std::string own_key = calibration.beds[6].key;
  edit(calibration.beds[6].file, [&](nlohmann::json& d) { d["key"] = own_key; });
  NoteHooks edited;
  const auto fourth = tasks::run_filling_ratios(c, options, edited, base::local_executor());
  CHECK(fourth.calibration->runs == 2);
  for (const std::size_t b : {std::size_t{5}, std::size_t{6}}) {
    CAPTURE(b);
    CHECK_FALSE(fourth.calibration->beds[b].cached);
    CHECK(fourth.calibration->beds[b].field.points == calibration.beds[b].field.points);
  }
  CHECK(std::count_if(edited.notes.begin(), edited.notes.end(), [](const std::string& note) {
          return note.find("its content does not match its digest") != std::string::npos;
        }) == 2);

  // --method formulas: the closed forms, no calibration.
  options.calibrated = false;
  const auto closed_forms = tasks::run_filling_ratios(c, options, base::silent_hooks(), base::local_executor());
  CHECK_FALSE(closed_forms.calibration);
  CHECK(tasks::to_json(closed_forms)["method"] == "formulas");
}

// Reference: the loop's definition (docs/optimizer.md, "Calibrated beds"): a round that fails
// recalibrates the chosen design's beds with the damping the design's other beds add, then
// optimises and verifies again, up to verify.rounds; a design verified before is not run
// again (the same inputs, the same DEM decay). A tolerance no decay meets makes every
// round fail.
TEST_CASE("the design loop recalibrates the chosen design's beds and stops after its rounds", "[tasks]") {
  const test::TempDir cache("design_loop");
  std::ifstream in(case_path("manipulator_link_optimize.json"));
  nlohmann::json document = nlohmann::json::parse(in);
  document["task"]["calibration"] = {{"duration_s", 1.5}, {"stiffness_softening", 1e-3}};
  document["task"]["verify"] = {{"duration_s", 1.5}, {"stiffness_softening", 1e-3}, {"softening_check", false},
                                {"tolerance_relative", 1e-6}, {"rounds", 2}};
  const auto c = case_file::load_case_document(document, "design_loop.json");
  tasks::FillingRatiosOptions options;
  options.calibration_cache = cache.path;
  NoteHooks hooks;
  const auto r = tasks::run_filling_ratios(c, options, hooks, base::local_executor());
  REQUIRE(r.verification);
  CHECK_FALSE(r.verification->passed);
  REQUIRE_FALSE(r.rounds.empty());
  const auto& first = r.rounds.front();
  CHECK_FALSE(first.passed);
  int layers = 0;
  for (const double n : first.designs.front().slabs) layers += n > 0.0 ? 1 : 0;
  if (layers < 2) {
    // A single bed is its own calibration: nothing to recalibrate, the loop ends.
    CHECK(r.rounds.size() == 1);
    CHECK(r.loop_outcome == tasks::LoopOutcome::kNothingToRecalibrate);
    return;
  }
  REQUIRE(r.rounds.size() == 2);
  CHECK(r.loop_outcome == tasks::LoopOutcome::kRoundsExhausted);
  // A bed of the chosen design whose decay alone is slower than the design's now carries the
  // difference, the damping its other beds add; one that decays faster alone (the other beds
  // add nothing it lacks) keeps its calibration, as does every bed outside the design.
  CHECK_FALSE(first.recalibrated.empty());
  CHECK(first.recalibrated.size() <= static_cast<std::size_t>(layers));
  CHECK(r.rounds.back().recalibrated.empty());
  int raised = 0;
  for (const auto& bed : r.calibration->beds) {
    const bool in_design = first.designs.front().slabs.at(static_cast<std::size_t>(bed.layer_index)) == bed.slabs;
    if (bed.extra_damping_ratio > 0.0) CHECK(in_design);
    raised += bed.extra_damping_ratio > 0.0 ? 1 : 0;
  }
  CHECK(raised == static_cast<int>(first.recalibrated.size()));
  CHECK(r.calibration->runs == 11 + raised);
  // A design verified in both rounds: the same DEM decay, not a new one.
  for (const auto& d : r.rounds.back().designs)
    for (const auto& before : first.designs)
      if (before.slabs == d.slabs) CHECK(before.dem_end_envelope_m == d.dem_end_envelope_m);
  const auto j = tasks::to_json(r);
  CHECK(j["design_loop"]["rounds"].size() == 2);
  CHECK(j["design_loop"]["outcome"] == "rounds_exhausted");
}

// Reference: q = e^(−ζω_n t) cos(ω_d t), sampled 100 times a period of f_d = f_n √(1 − ζ²),
// each sample a millionth of a step after its instant so that the crests fall inside their
// own periods: the period maxima are the crests e^(−ζω_n (kT_d + δ)) (cos ω_d δ ≈ 1 − 1e-15),
// so the fit gives ζ ω_n / ω_d = ζ/√(1 − ζ²); the window stops at half the first crest.
TEST_CASE("the damping ratio of a modal decay is the slope of its period maxima", "[tasks]") {
  const double zeta = 0.02, fn = 10.0, fd = fn * std::sqrt(1.0 - zeta * zeta);
  std::vector<double> t;
  Eigen::VectorXd q(4001);
  for (int i = 0; i <= 4000; ++i) {
    t.push_back((i + 1e-6) / (100.0 * fd));
    q[i] = std::exp(-zeta * 2.0 * M_PI * fn * t.back()) * std::cos(2.0 * M_PI * fd * t.back());
  }
  CHECK(tasks::modal_decay_damping_ratio(t, q, fd, 0.5) == Approx(zeta / std::sqrt(1.0 - zeta * zeta)).epsilon(1e-9));
  CHECK(tasks::modal_decay_damping_ratio(t, q, fd, 0.0) == Approx(zeta / std::sqrt(1.0 - zeta * zeta)).epsilon(1e-9));
  // Fewer than two whole periods: no ratio.
  CHECK(std::isnan(tasks::modal_decay_damping_ratio({0.0, 0.05}, Eigen::Vector2d(1.0, 0.5), fd, 0.5)));
}

// A layer's name is a label: it neither leads the bed's cache file out of the cache folder
// (once "../../x" wrote outside it, "/abs" into an absolute folder, a NUL cut the name so that
// beds overwrote one file, 300 bytes failed with "File name too long") nor changes the key.
TEST_CASE("a layer's name cannot lead its calibration file out of the cache folder nor change its key", "[tasks]") {
  const std::filesystem::path dir = std::filesystem::path("cache") / "beds";
  const std::string key = "0123456789abcdef";
  for (const std::string& name : {std::string("../../x"), std::string("/abs/olute"), std::string("lo\0w", 4),
                                  std::string("lo\0v", 4), std::string(300, 'a'), std::string("sub/dir"),
                                  std::string(".hidden"), std::string("-rf"), std::string("..")}) {
    CAPTURE(base::printable(name));
    const auto file = tasks::calibration_cache_file(dir, name, 3, key);
    CHECK(file.parent_path() == dir);
    const std::string leaf = file.filename().string();
    CHECK(leaf.size() <= 130);  // 100 for the name, then "_3_" + 16 + ".json"
    CHECK(leaf.front() != '.');
    CHECK(leaf.find('\0') == std::string::npos);
    CHECK(leaf.substr(leaf.size() - 24) == "_3_" + key + ".json");
  }
  // Two names cut at the same NUL are two files (their keys differ in the bed's physics, and
  // the names stay apart after the NUL).
  CHECK(tasks::calibration_cache_file(dir, std::string("lo\0w", 4), 1, key) !=
        tasks::calibration_cache_file(dir, std::string("lo\0v", 4), 1, key));

  std::ifstream in(case_path("manipulator_link_optimize.json"));
  const nlohmann::json document = nlohmann::json::parse(in);
  nlohmann::json renamed = document;
  renamed["dampers"][0]["name"] = "another damper";
  for (auto& layer : renamed["dampers"][0]["layers"]) layer["name"] = "../" + layer["name"].get<std::string>();
  nlohmann::json heavier = document;
  heavier["dampers"][0]["container_mass_kg"] = 0.3;
  const auto key_of = [](const nlohmann::json& j) {
    const auto c = case_file::load_case_document(j, "key.json");
    const auto spec = c.task.filling_ratios->calibration.value();
    return tasks::calibration_key(case_file::with_design(c, {1, 0, 0}, spec.stiffness_softening, true), spec, 0.0);
  };
  CHECK(key_of(renamed) == key_of(document));
  CHECK(key_of(heavier) != key_of(document));
}
