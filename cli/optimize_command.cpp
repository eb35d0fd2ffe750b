// pdamp optimize (and pdamp run on task kinds filling_ratios, placement and clearance): the
// case's design task (tasks/filling_ratios, tasks/placement, tasks/clearance), its files and
// its printout.
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli_hooks.hpp"
#include "errors.hpp"
#include "flags.hpp"
#include "output.hpp"
#include "pdamp/report/external_program.hpp"
#include "pdamp/report/task_files.hpp"
#include "pdamp/tasks/clearance.hpp"
#include "pdamp/tasks/filling_ratios.hpp"
#include "pdamp/tasks/placement.hpp"
#include "structure_commands.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace opt = optimizer;
using case_file::Case;

const FlagSpec kBackendFlag{"--backend", "NAME",
                            "local stage of the relaxed solve: nlopt (ISRES global stage, then SLSQP)\n"
                            "                          or ipopt (the same global stage, then Ipopt: the hybrid);\n"
                            "                          default: the task's backend (nlopt)"};
const FlagSpec kVerifyFlag{"--verify", "",
                           "run the DEM verification (the task's verify settings, or their defaults when the\n"
                           "                          task has none): DEM-in-the-loop free decay of the chosen and the\n"
                           "                          baseline design against the prediction (docs/optimizer.md)"};

std::optional<opt::Backend> backend_flag(const ParsedArgs& args) {
  const auto name = args.optional_text("--backend");
  if (!name) return std::nullopt;
  if (const auto b = opt::backend_from_string(*name)) return *b;
  throw InputError("--backend", "", "'" + *name + "': must be nlopt or ipopt");
}

std::string seconds_or_not_settled(double t) {
  return std::isfinite(t) ? format_number(t, 4) + " s" : std::string("not settled");
}

std::string design_row(const opt::FillingDesign& d, bool whole) {
  std::string slabs;
  for (const auto& l : d.layers) slabs += (slabs.empty() ? "" : ", ") + (whole ? std::to_string(std::lround(l.slabs)) : format_number(l.slabs, 4));
  return "n = (" + slabs + "), " + format_number(d.total_mass_kg * 1e3, 4) + " g, settling " +
         (std::isfinite(d.settling_time_s) ? format_number(d.settling_time_s, 5) + " s" : "not settled") +
         ", objective " + format_number(d.objective, 6);
}

std::string difference_text(const tasks::Agreement& a) {
  return a.compared == tasks::Compared::kSettledOnlyOne ? std::string("only one settled")
                                          : "difference " + format_number(100.0 * a.relative_difference, 3) + " %";
}

Rows verification_rows(const tasks::Verification& v) {
  Rows rows;
  const bool settling = v.settling_objective;
  for (const auto& d : v.designs) {
    const double pred = d.predicted_objective;
    std::string line = settling ? "predicted " + seconds_or_not_settled(pred) + ", DEM " + seconds_or_not_settled(d.dem.objective)
                                : "predicted " + format_number(pred, 4) + " m2 s, DEM " + format_number(d.dem.objective, 4) + " m2 s";
    line += "; end envelope predicted " + format_number(d.predicted_end_envelope_m * 1e3, 4) + " mm, DEM " +
            format_number(d.dem.end_envelope_m * 1e3, 4) + " mm; energy error " + format_number(d.dem.energy_error, 2) +
            "; " +
            difference_text(d.agreement) + ": " + (d.agreement.within ? "pass" : "FAIL");
    rows.push_back({"verify " + d.name, line});
    if (const auto& s = d.softening_check)
      rows.push_back({"verify " + d.name + " stiffer",
                      "softening " + format_number(s->stiffness_softening, 3) + ": DEM " +
                          (settling ? seconds_or_not_settled(s->dem.objective) : format_number(s->dem.objective, 4) + " m2 s") +
                          "; judged run " + difference_text(s->agreement) + ": " +
                          (s->agreement.within ? "converged" : "NOT CONVERGED")});
  }
  rows.push_back({"verify ranking", std::string("chosen ahead of baseline: predicted ") +
                                        (v.predicted_chosen_ahead ? "yes" : "no") + ", DEM " +
                                        (v.dem_chosen_ahead ? "yes" : "no") + (v.ranking_passed ? ": pass" : ": FAIL")});
  rows.push_back({"verify softening", v.softening_check == tasks::SofteningCheckKind::kTwoSoftenings
                                          ? std::string(v.softening_converged ? "converged" : "NOT CONVERGED") +
                                                " (each design also ten times stiffer)"
                                          : v.softening_check == tasks::SofteningCheckKind::kFullStiffness ? "full stiffness" : "not checked"});
  rows.push_back({"verification", std::string(v.passed ? "PASS" : "FAIL") + " (tolerance " +
                                      format_number(100.0 * v.spec.tolerance_relative, 3) + " %, " +
                                      format_number(v.spec.duration_s, 4) + " s simulated each, " +
                                      format_number(v.wall_time_s, 4) + " s wall)"});
  return rows;
}

int run_filling_ratios_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  if (args.has("--verify") && args.has("--no-verify")) throw InputError("--verify", "", "and --no-verify exclude each other");
  tasks::FillingRatiosOptions options;
  if (const auto method = args.optional_text("--method")) {
    if (*method != "formulas" && *method != "calibrated")
      throw InputError("--method", "", "'" + *method + "': task kind filling_ratios takes formulas or calibrated");
    options.calibrated = *method == "calibrated";
  }
  const bool calibrated = options.calibrated.value_or(c.task.filling_ratios->calibration.has_value());
  if (const auto cache = args.optional_text("--calibration-cache")) {
    if (!calibrated) throw InputError("--calibration-cache", "", "applies to calibrated beds (--method calibrated)");
    if (const std::string problem = tasks::prepare_calibration_cache(*cache); !problem.empty())
      throw InputError("--calibration-cache", "", problem);
    options.calibration_cache = *cache;
  }
  options.backend = backend_flag(args);
  options.force_verify = args.has("--verify");
  options.skip_verify = args.has("--no-verify");
  const bool verify = !options.skip_verify && (options.force_verify || c.task.filling_ratios->verify);
  if (!verify) refuse_checkpoint_flags(args, "applies to the DEM verification (--verify)");
  auto files = output_dir(args, context);
  if (verify) {
    const tasks::CheckpointFile folder = checkpoint_file(args, "verify");
    if (!folder.path.empty()) options.checkpoint_dir = folder.path.parent_path();
    options.resume = folder.resume;
  }
  CliHooks hooks(checkpoint_interval(args), args.has("--accept-long-run"));
  // Signals wait for a checkpoint during the runs, then for the commit (dem_results_ready).
  const std::optional<report::DeferredSignals> deferred =
      options.checkpoint_dir.empty() ? std::nullopt : std::make_optional<report::DeferredSignals>();
  tasks::FillingRatiosResult result = tasks::run_filling_ratios(c, options, hooks, context.executor);
  if (deferred) dem_results_ready(files.get());
  std::vector<std::string> warnings = result.warnings;
  if (files)
    for (auto& w : report::write_files(*files, result)) warnings.push_back(w);
  json out = tasks::to_json(result);
  out["file"] = output_folder(files.get()).file("optimize.json");
  const auto& r = result.optimum;
  const auto& p = result.problem;
  const std::string unit = p.options.objective == opt::FillingObjective::kSettlingTime ? "s" : "m2_s";
  Rows rows = {{"case", c.name},
               {"objective", std::string(opt::to_string(p.options.objective)) + " (" + unit + ")"},
               {"mass budget", format_number(result.mass_budget_kg * 1e3, 5) + " g"},
               {"relaxed optimum", design_row(r.relaxed, false)},
               {r.enumerated ? "whole-slab designs" : "rounded neighbours",
                std::to_string(r.neighbours_feasible) + " feasible of " + std::to_string(r.neighbours_total) +
                    ", the feasible evaluated"},
               {"chosen", design_row(r.chosen, true)},
               {"baseline (" + r.baseline_layer + ")", design_row(r.baseline, true)},
               {"same mass, one compartment", format_number(r.same_mass.total_mass_kg * 1e3, 4) + " g at h = " +
                                                  format_number(r.same_mass.layers.front().clearance_m * 1e3, 4) +
                                                  " mm, settling " + seconds_or_not_settled(r.same_mass.settling_time_s)},
               {"without particles", "settling " + seconds_or_not_settled(r.bare.settling_time_s)},
               {"case start", design_row(r.initial, true)},
               {"solver", r.summary.brief_report()},
               {"time", format_number(r.solve_time_s, 4) + " s, " + std::to_string(r.decay_evaluations) + " free decays"}};
  for (const auto& l : r.chosen.layers)
    rows.push_back({"chosen " + l.name, std::to_string(std::lround(l.slabs)) + " slabs, phi = " +
                                            format_number(l.filling_ratio, 4) + ", h = " + format_number(l.clearance_m * 1e3, 4) +
                                            " mm, m = " + format_number(l.bed_mass_kg * 1e3, 4) + " g"});
  if (const auto& cal = result.calibration)
    rows.push_back({"calibration", std::to_string(cal->beds.size()) + " beds, " + std::to_string(cal->runs) +
                                       " DEM decays run (the others cached in " + cal->cache_dir.string() + "), " +
                                       format_number(cal->wall_time_s, 4) + " s wall"});
  if (result.verification)
    for (auto& row : verification_rows(*result.verification)) rows.push_back(std::move(row));
  for (const auto& round : result.rounds) {
    if (result.rounds.size() < 2) break;
    std::string line = round.passed ? "pass" : "fail";
    for (const auto& d : round.designs) {
      line += "; " + d.name + " (";
      for (std::size_t k = 0; k < d.slabs.size(); ++k) line += (k ? ", " : "") + format_number(d.slabs[k], 3);
      line += ") " + (d.compared == tasks::Compared::kSettledOnlyOne ? std::string("only one settled")
                                                        : format_number(100.0 * d.relative_difference, 3) + " %");
    }
    if (!round.recalibrated.empty()) line += "; recalibrated " + std::to_string(round.recalibrated.size()) + " bed(s)";
    rows.push_back({"design loop round " + std::to_string(round.round), line});
  }
  if (result.rounds.size() > 1) rows.push_back({"design loop", std::string(tasks::to_string(*result.loop_outcome))});
  const int code = finish(args, files.get(), out, warnings, rows, {"optimize.json", &c, context.report}, &result);
  remove_checkpoints(files.get(), result.checkpoints);
  return code;
}

std::string site_text(const opt::PlacementPoint& p) {
  return std::isfinite(p.position_m) ? "x = " + format_number(p.position_m, 6) + " m" : "'" + p.site + "'";
}

std::string modes_text(const opt::PlacementPoint& p) {
  std::string out;
  for (const auto& m : p.modes) {
    if (!out.empty()) out += "; ";
    out += "mode " + std::to_string(m.mode + 1) + ": X = " + format_number(m.damper_amplitude_m * 1e3, 4) +
           " mm, eta* = " + format_number(m.eta_star, 3) + ", zeta_add = " + format_number(100.0 * m.added_damping_ratio, 4) +
           " %";
    if (m.rotation_flagged)
      out += ", rotation " + (std::isfinite(m.rotation_ratio) ? format_number(100.0 * m.rotation_ratio, 3) + " %" : "> 100 %");
  }
  return out;
}

int run_placement_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  if (args.optional_text("--method").value_or("") == "dem")
    throw InputError("--method", "", "'dem': task kind placement takes formulas or field");
  refuse_checkpoint_flags(args, "applies to task kind filling_ratios (a placement's DEM decays are not checkpointed)");
  tasks::PlacementOptions options;
  options.method = loss_method(args);
  options.force_verify = args.has("--verify");
  options.skip_verify = args.has("--no-verify");
  auto files = output_dir(args, context);
  options.backend = backend_flag(args);
  CliHooks hooks(checkpoint_interval(args), args.has("--accept-long-run"));
  const auto study = tasks::run_placement(c, options, hooks, context.executor);
  std::vector<std::string> warnings = study.warnings;
  if (files)
    for (auto& w : report::write_files(*files, study)) warnings.push_back(w);
  json out = tasks::to_json(study);
  out["file"] = output_folder(files.get()).file("placement.json");
  const auto& r = study.result;
  Rows rows = {{"case", c.name},
               {"objective", std::string(opt::to_string(study.objective)) + " of zeta_add over the target modes"},
               {"chosen site", site_text(r.best) + ", objective " + format_number(100.0 * r.best.objective, 5) + " %"},
               {"chosen, per mode", modes_text(r.best)}};
  if (r.current) {
    rows.push_back({"case site", site_text(*r.current) + ", objective " + format_number(100.0 * r.current->objective, 5) + " %"});
    rows.push_back({"case site, per mode", modes_text(*r.current)});
  }
  rows.push_back({"solver", r.refined ? r.summary.brief_report() : std::string("every candidate point evaluated")});
  if (const auto& v = study.verification) {
    for (const auto& site : v->sites) {
      std::string line = site_text(site.predicted) + ": objective predicted " +
                         format_number(100.0 * site.predicted_objective, 4) + " %, DEM " +
                         format_number(100.0 * site.dem_objective, 4) + " % (" +
                         format_number(100.0 * site.relative_difference, 3) + " %)";
      for (const auto& m : site.modes)
        line += "; mode " + std::to_string(m.mode + 1) + ": " + format_number(100.0 * m.predicted_damping_ratio, 4) +
                " % vs " + format_number(100.0 * m.dem_damping_ratio, 4) + " %, " + format_number(m.wall_time_s, 3) + " s";
      rows.push_back({"DEM check, " + site.role, line});
    }
    rows.push_back({"verification", std::string(v->passed ? "PASS" : "FAIL") + " (chosen within " +
                                        format_number(100.0 * v->settings.tolerance_relative, 3) + " %: " +
                                        (v->chosen_agrees ? "yes" : "no") + "; DEM ranks the chosen site first: " +
                                        (v->ranking_agrees ? "yes" : "no") + ")"});
  }
  rows.push_back({"time", format_number(r.solve_time_s, 4) + " s, " + std::to_string(r.evaluations) + " sites"});
  return finish(args, files.get(), out, warnings, rows, {"placement.json", &c, context.report}, &study);
}

std::string check_text(const tasks::ClearanceCheck& k) {
  std::string line = "h = " + format_number(k.clearance_m * 1e3, 4) + " mm: predicted " +
                     format_number(k.predicted_peak, 4) + " at " + format_number(k.predicted_frequency_hz, 4) + " Hz" +
                     (k.predicted_peak > k.predicted_sweep_peak * 1.001
                          ? " (an upper branch; sweeps reach " + format_number(k.predicted_sweep_peak, 4) + ")"
                          : std::string()) +
                     ", DEM " +
                     format_number(k.dem_peak, 4) + " +- " + format_number(k.dem_peak_standard_error, 2) + " at " +
                     format_number(k.dem_frequency_hz, 4) + " Hz (" + std::string(structure::to_string(k.dem_sweep)) + ")";
  line += ", peak " + format_number(100.0 * k.peak_relative_difference, 3) + " %";
  if (std::isfinite(k.band_centre_relative_difference))
    line += ", band centre " + format_number(100.0 * k.band_centre_relative_difference, 3) + " %";
  if (k.ranking != tasks::DemRanking::kChosen) line += ", " + std::string(tasks::to_string(k.ranking)) + " than chosen";
  if (k.unconverged_points > 0) line += ", " + std::to_string(k.unconverged_points) + " point(s) not converged";
  return line + ", " + format_number(k.wall_time_s, 3) + " s";
}

int run_clearance_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  if (const auto method = args.optional_text("--method"); method && *method != "formulas")
    throw InputError("--method", "", "'" + *method + "': task kind clearance takes formulas (the layer's closed form)");
  if (args.has("--calibration-cache"))
    throw InputError("--calibration-cache", "", "applies to task kind filling_ratios; this case's task is clearance");
  refuse_checkpoint_flags(args, "applies to task kind filling_ratios (the clearance's stepped sines are not checkpointed)");
  tasks::ClearanceOptions options;
  options.backend = backend_flag(args);
  options.force_verify = args.has("--verify");
  options.skip_verify = args.has("--no-verify");
  auto files = output_dir(args, context);
  CliHooks hooks(checkpoint_interval(args), args.has("--accept-long-run"));
  const tasks::ClearanceStudy study = tasks::run_clearance(c, options, hooks, context.executor);
  std::vector<std::string> warnings = study.warnings;
  if (files)
    for (auto& w : report::write_files(*files, study)) warnings.push_back(w);
  json out = tasks::to_json(study);
  out["file"] = output_folder(files.get()).file("clearance.json");
  const auto& r = study.sizing.response;
  Rows rows = {{"case", c.name},
               {"objective", std::string(opt::to_string(study.objective)) + " of |X/U| (mode " +
                                 std::to_string(study.mode + 1) + ", U = " + format_number(study.base_amplitude_m * 1e3, 4) +
                                 " mm)"},
               {"chosen clearance", format_number(r.clearance_m * 1e3, 5) + " mm: peak |X/U| " +
                                        format_number(r.peak_transmissibility, 4) + " at " +
                                        format_number(r.peak_frequency_hz, 4) + " Hz, X = " +
                                        format_number(r.damper_amplitude_m * 1e3, 4) + " mm" +
                                        (r.held_at_onset ? " (held at the onset)" : "")},
               {"closed form", format_number(study.sizing.estimate.clearance_m * 1e3, 5) + " mm"},
               {"case clearance", format_number(study.current.clearance_m * 1e3, 5) + " mm: peak |X/U| " +
                                      format_number(study.current.peak_transmissibility, 4)},
               {"solver", study.sizing.summary.brief_report()}};
  if (const auto& v = study.verification) {
    for (const auto& k : v->checks) rows.push_back({k.factor == 1.0 ? "DEM check, chosen" : "DEM check, " +
                                                        format_number(k.factor, 3) + " h", check_text(k)});
    rows.push_back({"verification", std::string(v->passed ? "PASS" : "FAIL") + " (chosen within " +
                                        format_number(100.0 * v->settings.tolerance_relative, 3) + " %: " +
                                        (v->chosen_agrees ? "yes" : "no") + "; DEM contradicts no predicted ranking: " +
                                        (v->ranking_agrees ? "yes" : "no") + "; every neighbour above it: " +
                                        (v->ranking_resolved ? "yes" : "no") + "; neighbours within " +
                                        format_number(100.0 * v->settings.tolerance_relative, 3) + " %: " +
                                        (v->neighbours_agree ? "yes" : "no") + ")"});
  }
  rows.push_back({"time", format_number(study.sizing.solve_time_s, 4) + " s (sizing)"});
  return finish(args, files.get(), out, warnings, rows, {"clearance.json", &c, context.report}, &study);
}

}  // namespace

int run_optimize_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  if (c.task.kind == case_file::TaskKind::kPlacement && c.task.placement) return run_placement_case(args, context, c);
  if (c.task.kind == case_file::TaskKind::kClearance && c.task.clearance) return run_clearance_case(args, context, c);
  if (c.task.kind != case_file::TaskKind::kFillingRatios || !c.task.filling_ratios)
    throw InputError(c.path, "/task",
                     "pdamp optimize needs a task of kind filling_ratios, placement or clearance (this case's task is '" +
                         std::string(case_file::to_string(c.task.kind)) +
                         "'): give \"task\": {\"kind\": \"filling_ratios\", \"mass_budget_kg\", \"initial_state\", "
                         "\"duration_s\"}, {\"kind\": \"placement\", \"targets\"} or {\"kind\": \"clearance\", \"mode\", ...} "
                         "(docs/cases.md, Format 2)");
  return run_filling_ratios_case(args, context, c);
}

Command optimize_command() {
  return {{"optimize", "pdamp optimize CASE.json [--backend nlopt|ipopt] [--method formulas|field|calibrated] [--calibration-cache DIR] [--verify|--no-verify] [--resume] [-o DIR] [--json]",
           "optimise the case's task (kind filling_ratios: whole slabs per layer of the first damper\n"
           "for the fastest free decay under a particle-mass budget; relaxed solve, every\n"
           "whole-slab design, single-layer baseline; with the task's verify block or --verify, the\n"
           "DEM-in-the-loop check of the chosen and baseline designs. Kind placement: the site\n"
           "along a beam, or among named points, where the damper adds the most damping to the\n"
           "target modes. Kind clearance: the clearance of a single-layer damper for the lowest\n"
           "resonant peak under a base motion; with verify, the DEM stepped sine at the chosen\n"
           "clearance and its neighbours; docs/optimizer.md)",
           concat_flags({kBackendFlag,
            {"--method", "M", "each layer's eta*(f, X): placement formulas (the closed forms; default) or\n"
                              "                          field (its field_file); filling_ratios formulas or calibrated (each\n"
                              "                          candidate bed's DEM decay; default: calibrated with a calibration block)"},
            kCalibrationCacheFlag,
            kVerifyFlag, kNoVerifyFlag,
            {"-o", "DIR", "write optimize.json, designs.csv, decay_compare.csv, decay_compare.gp/png/svg,\n"
                          "                          case_resolved.json and with the verification verify_decay.csv,\n"
                          "                          verify_decay.gp/png/svg into DIR, atomically (placement:\n"
                          "                          placement.json, placement.csv, placement.gp/png/svg; clearance:\n"
                          "                          clearance.json, clearance.csv, clearance.gp/png/svg and with the\n"
                          "                          verification clearance_checks.csv, clearance_verify.csv/gp/png/svg;\n"
                          "                          the verification's verify_chosen.checkpoint, verify_baseline.checkpoint\n"
                          "                          while running)"},
            kJsonFlag}, kCheckpointFlags),
           1},
          [](const ParsedArgs& args, CommandContext& context) {
            return run_optimize_case(args, context, case_file::load_case(args.positional().at(0)));
          },
          true};
}

}  // namespace pdamp::cli
