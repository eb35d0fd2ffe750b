// Task kind filling_ratios (filling_ratios.hpp).
#include "pdamp/tasks/filling_ratios.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <sstream>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

namespace opt = optimizer;
namespace st = structure;
using case_file::Case;
using nlohmann::json;
using base::format_number;
using base::InputError;

std::string_view to_string(Compared compared) {
  switch (compared) {
    case Compared::kObjective: return "objective";
    case Compared::kEndEnvelope: return "end_envelope";
    case Compared::kSettledOnlyOne: return "settled_only_one";
  }
  return "";
}

std::string_view to_string(SofteningCheckKind kind) {
  switch (kind) {
    case SofteningCheckKind::kOff: return "off";
    case SofteningCheckKind::kFullStiffness: return "full_stiffness";
    case SofteningCheckKind::kTwoSoftenings: return "two_softenings";
  }
  return "";
}

std::string_view to_string(LoopOutcome outcome) {
  switch (outcome) {
    case LoopOutcome::kAgreed: return "agreed";
    case LoopOutcome::kRoundsExhausted: return "rounds_exhausted";
    case LoopOutcome::kNothingToRecalibrate: return "nothing_to_recalibrate";
  }
  return "";
}

namespace {

bool settled(const VerifiedDecay& v) { return std::isfinite(v.settling.settling_time_s); }

}  // namespace

const base::Fields<VerifiedDecay>& VerifiedDecay::fields() {
  using V = VerifiedDecay;
  static const auto f =
      base::Fields<V>()
          .derived("settled", settled, "", "the DEM decay reached the threshold within the record")
          .derived("outcome", [](const V& v) { return std::string(settled(v) ? "settled" : "not_settled"); }, "",
                   "settled or not_settled")
          .derived("settling_time_s", [](const V& v) { return v.settling.settling_time_s; }, "s",
                   "when the envelope reached the threshold (null: not settled)", base::kNullable)
          .field("objective", &V::objective, "s or m2_s", "the DEM's settling time or 1/2 integral of e^2 dt",
                 base::kNullable)
          .field("end_envelope_m", &V::end_envelope_m, "m", "the envelope at the end of the record", base::kNullable)
          .derived("damping_ratio", [](const V& v) { return v.settling.damping_ratio; }, "1",
                   "equivalent damping ratio from the decrement down to the threshold", base::kNullable)
          .field("threshold_m", &V::threshold_m, "m", "the settling threshold at the first damper's site")
          .field("initial_envelope_m", &V::initial_envelope_m, "m", "the envelope the decay starts from")
          .field("energy_error", &V::energy_error, "1", "relative error of the co-simulation's energy ledger")
          .field("dem_dissipated_energy_j", &V::dem_dissipated_j, "J", "energy the beds dissipated")
          .field("structural_dissipated_energy_j", &V::structural_dissipated_j, "J",
                 "energy the structure's own damping dissipated")
          .field("steps", &V::steps, "", "integration steps")
          .field("time_step_s", &V::time_step_s, "s", "the integration step")
          .field("solve_time_s", &V::wall_time_s, "s", "wall time")
          .field("time_s", &V::time_s, "s", "the co-simulation's samples", base::kHidden)
          .field("site_displacement_m", &V::site_displacement_m, "m",
                 "displacement about the static offset at the first damper's site, per sample", base::kHidden)
          .field("settling", &V::settling, "", "the envelope and its settling", base::kHidden)
          .field("warnings", &V::warnings, "", "the co-simulation's warnings", base::kHidden);
  return f;
}

const base::Fields<VerifiedDecay>& VerifiedDecay::summary_fields() {
  static const auto f = fields().view(
      {"settled", "settling_time_s", "objective", "end_envelope_m", "energy_error", "steps", "time_step_s", "solve_time_s"});
  return f;
}

const base::Fields<SofteningCheck>& SofteningCheck::fields() {
  using S = SofteningCheck;
  static const auto f =
      base::Fields<S>()
          .field("stiffness_softening", &S::stiffness_softening, "1", "the stiffer run's verify softening")
          .field("dem", &S::dem, VerifiedDecay::summary_fields(), "the DEM decay with contacts ten times stiffer")
          .derived("compared", [](const S& s) { return s.agreement.compared; }, "",
                   "objective, end_envelope or settled_only_one")
          .derived("relative_difference", [](const S& s) { return s.agreement.relative_difference; }, "1",
                   "(judged - stiffer)/stiffer", base::kNullable)
          .derived("converged", [](const S& s) { return s.agreement.within; }, "",
                   "the two agree within the tolerance");
  return f;
}

const base::Fields<DesignCheck>& DesignCheck::fields() {
  using D = DesignCheck;
  static const auto f =
      base::Fields<D>()
          .derived("slabs", [](const D& d) { return d.design.slabs(); }, "", "the slabs of each layer")
          .field("particles", &D::particles, "", "spheres in all layers")
          .derived("bed_mass_kg", [](const D& d) { return d.design.total_mass_kg; }, "kg", "particle mass")
          .group("predicted", "the prediction over the verification's duration",
                 base::Fields<D>()
                     .derived("settled", [](const D& d) { return d.predicted.settled; }, "",
                              "the predicted decay settles within the duration")
                     .derived("settling_time_s", [](const D& d) { return d.predicted.settling_time_s; }, "s",
                              "predicted settling time (null: not settled)", base::kNullable)
                     .field("objective", &D::predicted_objective, "s or m2_s", "the predicted objective",
                            base::kNullable)
                     .field("end_envelope_m", &D::predicted_end_envelope_m, "m",
                            "the predicted envelope at the end", base::kNullable))
          .field("dem", &D::dem, "", "the DEM-in-the-loop decay")
          .derived("compared", [](const D& d) { return d.agreement.compared; }, "",
                   "objective, end_envelope or settled_only_one")
          .derived("relative_difference", [](const D& d) { return d.agreement.relative_difference; }, "1",
                   "(DEM - predicted)/predicted", base::kNullable)
          .field("passed", &D::passed, "", "within the tolerance, and the softening check's if run")
          .field("softening_check", &D::softening_check, "", "the same decay ten times stiffer", base::kOmitEmpty);
  return f;
}

const base::Fields<Verification>& Verification::fields() {
  using V = Verification;
  static const auto f =
      base::Fields<V>()
          .derived("method", [](const V&) { return std::string("dem"); }, "", "the judge: the DEM in the loop")
          .derived("what", [](const V&) { return std::string(V::kWhat); }, "", "what was run")
          .derived("objective",
                   [](const V& v) { return std::string(v.settling_objective ? "settling_time" : "integral_square"); },
                   "", "settling_time or integral_square")
          .derived("duration_s", [](const V& v) { return v.spec.duration_s; }, "s", "each DEM decay's duration")
          .derived("tolerance_relative", [](const V& v) { return v.spec.tolerance_relative; }, "1",
                   "the largest relative difference that passes")
          .derived("stiffness_softening", [](const V& v) { return v.spec.stiffness_softening; }, "1",
                   "the verification's softening, on top of the case's")
          .field("dem_stiffness_softening", &V::dem_stiffness_softening, "1", "the case's /dem softening")
          .derived("effective_stiffness_softening",
                   [](const V& v) { return v.dem_stiffness_softening * v.spec.stiffness_softening; }, "1",
                   "the softening the judged runs ran at")
          .derived("require_ranking", [](const V& v) { return v.spec.require_ranking; }, "",
                   "the DEM must rank the chosen design ahead")
          .group("softening_check", "the check that the softening has converged",
                 base::Fields<V>()
                     .field("kind", &V::softening_check, "", "two_softenings, full_stiffness or off")
                     .derived("rule",
                              [](const V&) {
                                return std::string(
                                    "each design again with contacts ten times stiffer (at most full stiffness); "
                                    "converged when the two DEM objectives agree within tolerance_relative");
                              },
                              "", "the rule")
                     .field("converged", &V::softening_converged, "", "every design's check agreed"))
          .derived("designs",
                   [](const V& v) {
                     json designs = json::object();
                     for (const auto& d : v.designs) designs[d.name] = base::to_json(d);
                     return designs;
                   },
                   "", "each design's check, by name (chosen, baseline)")
          .group("ranking", "the designs' order",
                 base::Fields<V>()
                     .field("predicted_chosen_ahead", &V::predicted_chosen_ahead, "",
                            "the prediction ranks the chosen design ahead")
                     .field("dem_chosen_ahead", &V::dem_chosen_ahead, "", "the DEM ranks the chosen design ahead")
                     .field("passed", &V::ranking_passed, "", "= dem_chosen_ahead"))
          .field("passed", &V::passed, "", "every design passed, and the ranking when required")
          .field("wall_time_s", &V::wall_time_s, "s", "wall time of the verification")
          .field("mpi", &V::mpi, "", "how the decays spread over processes", base::kOmitEmpty);
  return f;
}

const base::Fields<VerificationRound::Design>& VerificationRound::Design::fields() {
  using D = VerificationRound::Design;
  static const auto f =
      base::Fields<D>()
          .field("slabs", &D::slabs, "", "the slabs of each layer")
          .field("predicted_objective", &D::predicted_objective, "s or m2_s", "the predicted objective",
                 base::kNullable)
          .field("dem_objective", &D::dem_objective, "s or m2_s", "the DEM's objective", base::kNullable)
          .field("predicted_end_envelope_m", &D::predicted_end_envelope_m, "m", "the predicted envelope at the end",
                 base::kNullable)
          .field("dem_end_envelope_m", &D::dem_end_envelope_m, "m", "the DEM's envelope at the end", base::kNullable)
          .field("compared", &D::compared, "", "objective, end_envelope or settled_only_one")
          .field("relative_difference", &D::relative_difference, "1", "(DEM - predicted)/predicted", base::kNullable)
          .field("passed", &D::passed, "", "within the tolerance");
  return f;
}

const base::Fields<VerificationRound>& VerificationRound::fields() {
  using R = VerificationRound;
  static const auto f =
      base::Fields<R>()
          .field("round", &R::round, "", "1, 2, ...")
          .derived("designs",
                   [](const R& r) {
                     json designs = json::object();
                     for (const auto& d : r.designs) designs[d.name] = base::to_json(d);
                     return designs;
                   },
                   "", "each design verified, by name")
          .field("ranking_passed", &R::ranking_passed, "", "the DEM ranks the chosen design ahead")
          .field("passed", &R::passed, "", "the round's verification passed")
          .field("recalibrated", &R::recalibrated, "", "the beds recalibrated after it (empty: the loop ended)");
  return f;
}

namespace {

/// Instants of the comparison decays (decay_compare.csv).
constexpr int kComparisonSamples = 2001;

bool settling_objective(const case_file::FillingRatioProblem& p) {
  return p.options.objective == opt::FillingObjective::kSettlingTime;
}

/// a ahead of b (settles sooner, or the smaller objective): settled beats not settled; two
/// unsettled decays rank by their envelopes at the end.
bool ahead(double objective_a, double end_a, double objective_b, double end_b) {
  if (std::isfinite(objective_a) && std::isfinite(objective_b)) return objective_a < objective_b;
  if (std::isfinite(objective_a) != std::isfinite(objective_b)) return std::isfinite(objective_a);
  return end_a < end_b;
}

VerifiedDecay verified_decay(const DemDecay& d) {
  const auto& r = d.cosimulation;
  VerifiedDecay v;
  v.time_s = r.history.time_s;
  for (std::size_t i = 0; i < v.time_s.size(); ++i)
    v.site_displacement_m.push_back(r.history.site_displacement_m(static_cast<Eigen::Index>(i), 0) - d.static_offset_m);
  v.settling = d.settling;
  v.threshold_m = d.threshold_m;
  v.initial_envelope_m = d.initial_envelope_m;
  v.energy_error = r.energy.relative_error;
  v.dem_dissipated_j = r.energy.dem_dissipated_j();
  v.structural_dissipated_j = r.energy.structural_damping_j;
  v.steps = r.steps;
  v.time_step_s = r.time_step_s;
  v.wall_time_s = r.wall_time_s;
  v.warnings = d.warnings;
  return v;
}

/// The design's slabs as whole numbers (the optimiser's are whole already).
std::vector<long> whole_slabs(const opt::FillingDesign& design) {
  std::vector<long> slabs;
  for (const auto& l : design.layers) slabs.push_back(std::lround(l.slabs));
  return slabs;
}

/// The checkpoint of design `name`'s verification decay at verify softening `softening`
/// (`suffix` "" for the judged run, "_stiffer" for the softening check's).
DemDecayCheckpoint verification_checkpoint(const FillingRatiosOptions& o, const std::string& name,
                                           const std::string& suffix, const opt::FillingDesign& design,
                                           double softening, base::RunHooks& hooks) {
  DemDecayCheckpoint checkpoint;
  if (o.checkpoint_dir.empty()) return checkpoint;
  checkpoint.file = {o.checkpoint_dir / ("verify_" + name + suffix + ".checkpoint"), o.resume};
  checkpoint.kind = "verify_" + name + suffix;
  std::ostringstream design_text;
  for (double n : design.slabs()) design_text << ' ' << n;
  design_text << "; softening " << softening;
  checkpoint.settings = "design" + design_text.str();
  // A design that completed before the interruption left no checkpoint: it runs again.
  if (checkpoint.file.resume && !std::filesystem::exists(checkpoint.file.path)) {
    checkpoint.file.resume = false;
    hooks.note("pdamp: warning: no checkpoint of the " + name + suffix + " design's verification: it runs from the start");
  }
  return checkpoint;
}

/// The DEM-in-the-loop decay of `design` over the verification's duration (the task's
/// decay from its initial state, on the design's modes) at verify softening `softening`.
VerifiedDecay verification_decay(const Case& c, const case_file::FillingRatioProblem& p, const case_file::VerifySpec& verify,
                                 const std::string& label, const opt::FillingDesign& design, const detail::DesignModes& modes,
                                 double softening, const DemDecayCheckpoint& checkpoint, base::RunHooks& hooks) {
  const Case dc = case_file::with_design(c, whole_slabs(design), softening);
  std::vector<st::Damper> containers = {p.options.damper};
  containers.insert(containers.end(), p.options.fixed_dampers.begin(), p.options.fixed_dampers.end());
  case_file::DecayTask decay = c.task.filling_ratios->decay;
  decay.duration_s = verify.duration_s;
  return verified_decay(dem_decay(dc, modes.modal, containers, detail::dem_dampers(dc), modes.initial_modal_displacements,
                                  decay, "pdamp optimize --verify (" + label + ")", "/task/verify/duration_s", checkpoint,
                                  hooks));
}

/// The verification's softening check runs ten times stiffer, at most full stiffness
/// (E·dem·verify <= E); none is possible when the judged runs are at full stiffness already.
double stiffer_softening(const Case& c, const case_file::VerifySpec& verify) {
  return std::min(10.0 * verify.stiffness_softening, 1.0 / c.dem.stiffness_softening);
}
bool at_full_stiffness(const Case& c, const case_file::VerifySpec& verify) {
  return c.dem.stiffness_softening * verify.stiffness_softening >= 1.0;
}

/// The cost of `decays` DEM decays over `duration_s` at each of `softenings`, each like one
/// of the case's own design (its layers' initial slabs; the mass budget keeps the designs
/// tried of about this size), `parallel` at a time: noted and checked (memory,
/// kMaxDemWallTime_s for the whole) before any work. Each decay is checked again as it starts.
void check_design_decays_cost(const Case& c, const case_file::FillingRatioProblem& p, double duration_s,
                              const std::vector<double>& softenings, std::size_t decays, int parallel,
                              const std::string& label, const std::string& duration_pointer, base::RunHooks& hooks) {
  std::vector<long> slabs;
  for (const auto& layer : p.options.layers) slabs.push_back(layer.initial_slabs);
  const detail::DesignModes modes = detail::design_modes(c, p, slabs);
  double wall_s = 0.0;
  std::string each;
  for (const double softening : softenings) {
    const Case dc = case_file::with_design(c, slabs, softening);
    const auto options = dem_decay_options(dc, modes.modal, modes.initial_modal_displacements, duration_s);
    const CoupledRunEstimate e = check_coupled_decay(dc, modes.modal, detail::dem_dampers(dc), options, label,
                                                       duration_pointer, hooks);
    wall_s += static_cast<double>(decays) * e.wall_time_s / std::max(parallel, 1);
    each += (each.empty() ? "" : "; at softening " + format_number(softening, 3) + ": ") + estimate_text(e);
  }
  check_wall_time(c, wall_s, label, duration_pointer,
                  "a shorter " + duration_pointer + ", softer contacts or fewer layers and slabs", hooks);
  hooks.note(label + ": " + std::to_string(decays * softenings.size()) + " DEM decays, each about one of the case's "
             "own design (" + each + "); about " + format_number(wall_s, 2) + " s in all");
}

/// How `objective` (with `end_envelope_m`) agrees with a reference: the objectives when both
/// are finite (settled), the envelopes at the end when neither is, else not comparable.
Agreement agreement(double objective, double end_envelope_m, double reference_objective,
                    double reference_end_envelope_m, double tolerance) {
  Agreement out;
  if (std::isfinite(reference_objective) && std::isfinite(objective)) {
    out.compared = Compared::kObjective;
    out.relative_difference = (objective - reference_objective) / reference_objective;
  } else if (!std::isfinite(reference_objective) && !std::isfinite(objective)) {
    out.compared = Compared::kEndEnvelope;  // neither settled: how far each got
    out.relative_difference = (end_envelope_m - reference_end_envelope_m) / reference_end_envelope_m;
  } else {
    out.compared = Compared::kSettledOnlyOne;
  }
  out.within = std::isfinite(out.relative_difference) && std::abs(out.relative_difference) <= tolerance;
  return out;
}

/// The DEM objective of a verification decay: its settling time, or ½∫e² dt of its envelope.
double dem_objective(const case_file::FillingRatioProblem& p, const VerifiedDecay& dem) {
  return settling_objective(p) ? dem.settling.settling_time_s
                               : st::half_integral_square(dem.time_s, dem.settling.sample_envelope_m);
}

double end_envelope(const VerifiedDecay& dem) {
  return dem.settling.envelope_m.empty() ? NAN : dem.settling.envelope_m.back();
}

/// The design against its DEM decay `dem` (and, if run, the same decay ten times stiffer).
DesignCheck check_design(const case_file::FillingRatioProblem& p, const case_file::VerifySpec& verify,
                         const std::string& name, const opt::FillingDesign& design, const detail::DesignModes& modes,
                         VerifiedDecay dem, std::optional<SofteningCheck> stiffer) {
  DesignCheck out;
  out.name = name;
  out.design = design;
  for (const auto& l : design.layers) out.particles += static_cast<int>(std::lround(l.particles));
  const std::vector<double> slabs = design.slabs();
  opt::FillingRatioOptions options = p.options;
  options.decay.duration_s = verify.duration_s;
  options.decay.initial_modal_amplitudes = modes.initial_modal_displacements.cwiseAbs();  // released from rest
  out.predicted = opt::evaluate_filling_design(modes.modal, options, slabs);
  out.predicted_objective = settling_objective(p) ? out.predicted.settling_time_s : out.predicted.integral_square_m2_s;
  out.dem = std::move(dem);
  out.dem.end_envelope_m = end_envelope(out.dem);
  out.dem.objective = dem_objective(p, out.dem);

  // The prediction at the DEM's instants (its envelope for the plot and the end value).
  st::FreeDecayOptions at_samples = options.decay;
  at_samples.sample_times_s = out.dem.time_s;
  at_samples.sample_times_s.front() = 0.0;
  for (auto& t : at_samples.sample_times_s) t = std::clamp(t, 0.0, verify.duration_s);
  at_samples.sample_times_s.back() = verify.duration_s;
  std::vector<st::Damper> dampers = {opt::filling_damper(options, slabs)};
  dampers.insert(dampers.end(), options.fixed_dampers.begin(), options.fixed_dampers.end());
  const st::FreeDecay curve = st::free_decay(modes.modal, dampers, at_samples);
  for (const auto& s : curve.samples) out.predicted_envelope_m.push_back(s.threshold_measure_m);
  out.predicted_end_envelope_m = out.predicted_envelope_m.empty() ? NAN : out.predicted_envelope_m.back();

  out.agreement = agreement(out.dem.objective, out.dem.end_envelope_m, out.predicted_objective,
                            out.predicted_end_envelope_m, verify.tolerance_relative);
  out.passed = out.agreement.within;
  if (stiffer) {
    stiffer->dem.objective = dem_objective(p, stiffer->dem);
    stiffer->dem.end_envelope_m = end_envelope(stiffer->dem);
    stiffer->agreement = agreement(out.dem.objective, out.dem.end_envelope_m, stiffer->dem.objective,
                                   stiffer->dem.end_envelope_m, verify.tolerance_relative);
    out.passed = out.passed && stiffer->agreement.within;
    out.softening_check = std::move(stiffer);
  }
  return out;
}

/// The DEM verification of the chosen and baseline designs: independent DEM runs (one World
/// each, single-threaded by default), a batch of jobs of `executor` on two threads or over
/// processes: each design at the verification's softening, then (softening check) each ten
/// times stiffer. Every process optimised the same way (NLopt's seed is fixed); a job carries
/// the fingerprint of the run it is (design and softening), so a process that chose another
/// design refuses it.
/// The DEM decays run so far, by design and softening: a later round of the design loop
/// reuses them (the same inputs give the same run) instead of running them again.
using DecayRuns = std::map<std::string, VerifiedDecay>;

Verification verify_designs(const Case& c, const case_file::FillingRatioProblem& p, const opt::FillingRatioResult& r,
                            const case_file::VerifySpec& verify, const FillingRatiosOptions& o, base::RunHooks& hooks,
                            base::Executor& executor, std::vector<std::filesystem::path>& checkpoints, DecayRuns& runs) {
  const auto start = std::chrono::steady_clock::now();
  Verification v;
  v.spec = verify;
  v.dem_stiffness_softening = c.dem.stiffness_softening;
  v.settling_objective = settling_objective(p);
  const double stiffer = stiffer_softening(c, verify);
  const bool full_stiffness = at_full_stiffness(c, verify);
  v.softening_check = !verify.softening_check ? SofteningCheckKind::kOff
                      : full_stiffness         ? SofteningCheckKind::kFullStiffness
                                               : SofteningCheckKind::kTwoSoftenings;
  const std::size_t softenings = v.softening_check == SofteningCheckKind::kTwoSoftenings ? 2 : 1;

  // Job k: design k % 2 at softening k / 2 (the judged runs first).
  const std::pair<std::string, const opt::FillingDesign*> designs[] = {{"chosen", &r.chosen}, {"baseline", &r.baseline}};
  const std::size_t jobs = 2 * softenings;
  std::vector<DemDecayCheckpoint> files(jobs);
  const detail::DesignModes modes[] = {detail::design_modes(c, p, whole_slabs(r.chosen)),
                                       detail::design_modes(c, p, whole_slabs(r.baseline))};
  const auto softening_of = [&](std::size_t k) { return k < 2 ? verify.stiffness_softening : stiffer; };
  const auto suffix_of = [](std::size_t k) { return std::string(k < 2 ? "" : "_stiffer"); };
  for (std::size_t k = 0; k < jobs; ++k) {
    files[k] = verification_checkpoint(o, designs[k % 2].first, suffix_of(k), *designs[k % 2].second, softening_of(k), hooks);
    if (!files[k].file.path.empty()) checkpoints.push_back(files[k].file.path);
  }
  const auto run_key = [&](std::size_t k) {
    std::ostringstream key;
    for (const double n : designs[k % 2].second->slabs()) key << n << ' ';
    key << "softening " << softening_of(k);
    return key.str();
  };
  std::vector<std::size_t> to_run;
  for (std::size_t k = 0; k < jobs; ++k)
    if (!runs.contains(run_key(k))) to_run.push_back(k);
  // A job's inputs are its run key: a process asked for a run checks that its own
  // optimisation chose the same design.
  const auto ran = base::run_jobs<VerifiedDecay>(
      executor, to_run.size(), true,
      [&](std::size_t j) {
        const std::size_t k = to_run.at(j);
        const std::string label = designs[k % 2].first + (k < 2 ? "" : ", softening " + format_number(softening_of(k), 3));
        return verification_decay(c, p, verify, label, *designs[k % 2].second, modes[k % 2], softening_of(k), files[k],
                                  hooks);
      },
      &v.mpi, [&](std::size_t j) { return run_key(to_run.at(j)); },
      static_cast<std::size_t>(std::max(executor.concurrency(2), 1)));
  for (std::size_t j = 0; j < to_run.size(); ++j) runs[run_key(to_run[j])] = ran[j];
  std::vector<VerifiedDecay> decays;
  for (std::size_t k = 0; k < jobs; ++k) decays.push_back(runs.at(run_key(k)));
  v.softening_converged = true;
  for (std::size_t k = 0; k < 2; ++k) {
    std::optional<SofteningCheck> check;
    if (softenings == 2) {
      check.emplace();
      check->stiffness_softening = stiffer;
      check->dem = decays[k + 2];
    }
    v.designs.push_back(
        check_design(p, verify, designs[k].first, *designs[k].second, modes[k], decays[k], std::move(check)));
    if (v.designs.back().softening_check) v.softening_converged &= v.designs.back().softening_check->agreement.within;
  }
  const DesignCheck& a = v.designs[0];
  const DesignCheck& b = v.designs[1];
  v.predicted_chosen_ahead = ahead(a.predicted_objective, a.predicted_end_envelope_m, b.predicted_objective,
                                   b.predicted_end_envelope_m);
  v.dem_chosen_ahead = ahead(a.dem.objective, a.dem.end_envelope_m, b.dem.objective, b.dem.end_envelope_m);
  v.ranking_passed = v.dem_chosen_ahead;
  v.passed = a.passed && b.passed && (!verify.require_ranking || v.ranking_passed);
  v.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return v;
}

/// The closed-form envelopes of the chosen, baseline and starting designs and of the
/// structure without particles (the containers empty: linear, so exact) on one grid.
DesignComparison compare_designs(const case_file::FillingRatioProblem& p, const opt::FillingRatioResult& r) {
  st::FreeDecayOptions decay = p.options.decay;
  decay.sample_times_s = st::uniform_sample_times(decay.duration_s, kComparisonSamples);
  DesignComparison out;
  for (const auto* d : {&r.chosen, &r.baseline, &r.initial, &r.bare}) {
    std::vector<st::Damper> dampers = {opt::filling_damper(p.options, d->slabs())};
    dampers.insert(dampers.end(), p.options.fixed_dampers.begin(), p.options.fixed_dampers.end());
    out.decays.push_back(st::free_decay(p.modal, dampers, decay));
  }
  return out;
}

}  // namespace

namespace {

VerificationRound round_summary(int round, const Verification& v) {
  VerificationRound out;
  out.round = round;
  for (const auto& d : v.designs)
    out.designs.push_back({d.name, d.design.slabs(), d.predicted_objective, d.dem.objective,
                           d.predicted_end_envelope_m, d.dem.end_envelope_m, d.agreement.compared,
                           d.agreement.relative_difference, d.passed});
  out.ranking_passed = v.ranking_passed;
  out.passed = v.passed;
  return out;
}

}  // namespace

FillingRatiosResult run_filling_ratios(const Case& c, const FillingRatiosOptions& o, base::RunHooks& hooks, base::Executor& executor) {
  const case_file::FillingRatiosTask& task = *c.task.filling_ratios;
  FillingRatiosResult out;
  out.case_name = c.name;
  out.mass_budget_kg = task.mass_budget_kg;
  // The DEM verification: the task's verify block, or --verify with its defaults.
  std::optional<case_file::VerifySpec> verify = task.verify;
  if (!verify && o.force_verify) {
    verify = case_file::VerifySpec{};
    verify->duration_s = task.decay.duration_s;
  }
  if (o.skip_verify) verify.reset();
  const bool calibrated = o.calibrated.value_or(task.calibration.has_value());
  // The DEM runs (the beds' calibration, each round's verification, the recalibrations) are
  // the executor's batches, spread over its processes; every process optimises alike between
  // them (NLopt's seed is fixed), on the same beds. Without DEM runs the task is the
  // optimisation alone, on the primary process.
  if (!verify && !calibrated) executor.primary_only();
  out.problem = case_file::filling_ratio_problem(c);
  if (verify) {  // the first round: the chosen and the baseline design, at one or two softenings
    std::vector<double> softenings = {verify->stiffness_softening};
    if (verify->softening_check && !at_full_stiffness(c, *verify)) softenings.push_back(stiffer_softening(c, *verify));
    check_design_decays_cost(c, out.problem, verify->duration_s, softenings, 2, executor.concurrency(2),
                             "pdamp optimize --verify", "/task/verify/duration_s", hooks);
  }
  // A verification of a design chosen on the closed forms often fails (they can miss how a
  // bed comes down from collect-and-collide): say so once, when the runs' cost is accepted
  // and before they start.
  if (verify && !calibrated)
    hooks.note("pdamp optimize: note: the DEM will check a design chosen on the closed forms, which it often does not "
               "confirm; to choose on beds calibrated by the DEM add \"calibration\": {} to the task or run: pdamp "
               "optimize " + c.path + " --method calibrated");
  if (calibrated) {
    case_file::CalibrationSpec spec;
    if (task.calibration) {
      spec = *task.calibration;
    } else {
      spec.duration_s = task.verify ? task.verify->duration_s : task.decay.duration_s;
      spec.stiffness_softening = task.verify ? task.verify->stiffness_softening : 1.0;
    }
    std::size_t beds = 0;  // every candidate bed, before the cache is read
    for (const auto& layer : out.problem.options.layers) beds += static_cast<std::size_t>(std::max(layer.max_slabs(), 0));
    check_design_decays_cost(c, out.problem, spec.duration_s, {spec.stiffness_softening}, beds, executor.concurrency(2),
                             "the bed calibration", task.calibration ? "/task/calibration/duration_s" : "/task/verify/duration_s",
                             hooks);
    out.calibration = calibrate_beds(c, out.problem, spec,
                                     o.calibration_cache.empty() ? default_calibration_cache() : o.calibration_cache,
                                     hooks, executor);
    out.problem.options.bed_models = out.calibration->models();
  }

  opt::Options solver;
  solver.backend = o.backend.value_or(*opt::backend_from_string(task.backend));
  solver.global_evaluations = task.global_evaluations;
  solver.max_evaluations = task.max_evaluations;
  const auto optimise = [&] {
    try {
      out.optimum = opt::optimize_filling_ratios(out.problem.modal, out.problem.options, solver);
    } catch (const std::invalid_argument& e) {
      throw InputError(c.path, "/task", e.what());
    }
    for (const auto* d : {&out.optimum.chosen, &out.optimum.relaxed, &out.optimum.baseline})
      if (!std::isfinite(d->objective))
        throw base::NumericalError("pdamp optimize: a design's objective is not finite");
  };
  optimise();

  if (verify) {
    // The design loop: on calibrated beds a failed round recalibrates the chosen design's
    // beds where it operates, optimises and verifies again (docs/optimizer.md).
    const int rounds = out.calibration ? verify->rounds : 1;
    DecayRuns runs;
    for (int round = 1;; ++round) {
      out.verification = verify_designs(c, out.problem, out.optimum, *verify, o, hooks, executor, out.checkpoints, runs);
      out.rounds.push_back(round_summary(round, *out.verification));
      if (out.verification->passed) {
        out.loop_outcome = LoopOutcome::kAgreed;
        break;
      }
      if (round >= rounds) {
        out.loop_outcome = LoopOutcome::kRoundsExhausted;
        break;
      }
      // The chosen design's rate of decay down to its threshold: its ζ_eq when it settled,
      // else over the whole record.
      const DesignCheck& chosen = out.verification->designs.front();
      const auto& settling = chosen.dem.settling;
      const double design_damping = std::isfinite(settling.damping_ratio)
                                        ? settling.damping_ratio
                                        : decay_damping_ratio(settling.envelope_time_s, settling.envelope_m,
                                                              settling.frequency_hz);
      out.rounds.back().recalibrated =
          recalibrate_in_design(c, out.problem, *out.calibration, whole_slabs(chosen.design), design_damping,
                                chosen.dem.threshold_m, hooks, executor);
      if (out.rounds.back().recalibrated.empty()) {
        out.loop_outcome = LoopOutcome::kNothingToRecalibrate;
        break;
      }
      hooks.note("pdamp optimize: round " + std::to_string(round) + " of the design loop failed; recalibrated " +
                 std::to_string(out.rounds.back().recalibrated.size()) + " bed(s) where the chosen design operates");
      out.problem.options.bed_models = out.calibration->models();
      optimise();
    }
  }
  const auto& p = out.problem;
  const auto& r = out.optimum;
  out.warnings = p.warnings;
  out.warnings.insert(out.warnings.end(), r.warnings.begin(), r.warnings.end());
  if (out.calibration)
    out.warnings.push_back("same_mass is by the closed forms: one compartment holding the chosen mass is no candidate "
                           "bed and has no calibration");
  if (out.verification) {
    for (const auto& d : out.verification->designs) {
      for (const auto& w : d.dem.warnings) out.warnings.push_back("verify (" + d.name + "): " + w);
      if (d.softening_check && !d.softening_check->agreement.within)
        out.warnings.push_back("verify (" + d.name + "): the softening has not converged: ten times stiffer contacts " +
                               "change the DEM objective by " +
                               (d.softening_check->agreement.compared == Compared::kSettledOnlyOne
                                    ? std::string("settling in one run only")
                                    : format_number(100.0 * d.softening_check->agreement.relative_difference, 3) + " %") +
                               ": raise /task/verify/stiffness_softening towards 1");
    }
    if (!out.verification->passed)
      out.warnings.push_back("the DEM verification failed (tolerance " + format_number(verify->tolerance_relative, 3) +
                             (out.verification->ranking_passed ? "" : "; the DEM does not rank the chosen design ahead of the baseline") +
                             (out.rounds.size() > 1 ? " after " + std::to_string(out.rounds.size()) + " rounds of the design loop" : "") +
                             "): see verification in the result");
  }
  try {
    out.comparison = compare_designs(p, r);
  } catch (const std::invalid_argument& e) {
    throw base::NumericalError(std::string("pdamp optimize: the comparison decays failed: ") + e.what());
  }
  return out;
}

json to_json(const FillingRatiosResult& res) {
  const auto& r = res.optimum;
  const auto& p = res.problem;
  json neighbours = json::array();
  for (const auto& d : r.neighbours) neighbours.push_back(opt::FillingDesign::neighbour_fields().to_json(d));
  const auto& s = r.summary;
  const std::string unit = p.options.objective == opt::FillingObjective::kSettlingTime ? "s" : "m2_s";
  json result = {
      {"task", "filling_ratios"},
      {"case", res.case_name},
      {"method", res.calibration ? "calibrated" : "formulas"},
      {"damper", p.options.damper.name},
      {"mass_budget_kg", res.mass_budget_kg},
      {"objective", {{"kind", std::string(opt::to_string(p.options.objective))}, {"unit", unit},
                     {"value", r.chosen.objective}}},
      {"design", base::to_json(r.chosen)},
      {"designs", {{"chosen", base::to_json(r.chosen)},
                   {"relaxed", base::to_json(r.relaxed)},
                   {"baseline", base::to_json(r.baseline)},
                   {"initial", base::to_json(r.initial)},
                   {"bare", base::to_json(r.bare)},
                   {"same_mass", base::to_json(r.same_mass)}}},
      {"references", {{"baseline", "the best single layer of the case's containers within the budget"},
                      {"bare", "the structure with the damper's containers empty"},
                      {"same_mass", "the chosen design's particle mass in one compartment at its own best clearance"}}},
      {"baseline_layer", r.baseline_layer},
      {"baseline_evaluations", r.baseline_evaluations},
      {"rounding", {{"rule", r.enumerated ? "every whole-slab design, the feasible ones evaluated, the best chosen"
                                          : "each relaxed n_k floored and ceiled (one value when within 1e-6 of a whole "
                                            "number); every feasible point evaluated, the best chosen"},
                    {"enumerated", r.enumerated},
                    {"neighbours_total", r.neighbours_total},
                    {"neighbours_feasible", r.neighbours_feasible},
                    {"neighbours", neighbours}}},
      {"solver", {{"backend", std::string(opt::to_string(s.backend))},
                  {"outcome", std::string(opt::to_string(s.outcome))},
                  {"iterations", s.iterations},
                  {"evaluations", s.evaluations},
                  {"global_evaluations", s.global_evaluations},
                  {"gradient_evaluations", s.gradient_evaluations},
                  {"global_stage_s", s.stage_times.global_stage_s},
                  {"local_stage_s", s.stage_times.local_stage_s},
                  {"message", s.message},
                  {"report", s.brief_report()}}},
      {"decay_evaluations", r.decay_evaluations},
      {"solve_time_s", r.solve_time_s}};
  result["calibration"] = res.calibration ? base::to_json(*res.calibration) : json(nullptr);
  result["verification"] = res.verification ? base::to_json(*res.verification) : json(nullptr);
  result["design_loop"] = res.rounds.empty() ? json(nullptr)
                                             : json{{"rounds", base::to_json(res.rounds)}, {"outcome", to_string(*res.loop_outcome)}};
  return result;
}

}  // namespace pdamp::tasks
