// pdamp modes, frf and decay: a format-2 case's structure tasks (tasks/modes, frf, decay),
// their files (report/task_files) and their printout (docs/structure_cli.md).
#include "structure_commands.hpp"

#include <optional>

#include <nlohmann/json.hpp>

#include "cli_hooks.hpp"
#include "errors.hpp"
#include "flags.hpp"
#include "output.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/report/external_program.hpp"
#include "pdamp/report/task_files.hpp"
#include "pdamp/tasks/bed_calibration.hpp"
#include "pdamp/tasks/case_checks.hpp"
#include "pdamp/tasks/decay.hpp"
#include "pdamp/tasks/frf.hpp"
#include "pdamp/tasks/modes.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace st = structure;
using case_file::Case;

/// --dem-points: at most.
constexpr long long kMaxDemPoints = 1000;

std::string optional_number(double value, int digits, const std::string& otherwise) {
  return std::isfinite(value) ? format_number(value, digits) : otherwise;
}

// ---------------------------------------------------------------- modes

int run_modes_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  tasks::ModesOptions options;
  if (args.optional_text("--method") == "calibrated") {
    options.calibrated = true;
  } else {
    options.method = loss_method(args);
    if (args.has("--method")) options.calibrated = false;
  }
  if (const auto cache = args.optional_text("--calibration-cache")) {
    const bool task_calibrates = c.task.kind == case_file::TaskKind::kModes && c.task.modes && c.task.modes->calibration;
    const bool task_searches = c.task.kind == case_file::TaskKind::kModes && c.task.modes && c.task.modes->clearance_search;
    if (!options.calibrated.value_or(task_calibrates) && !task_searches)
      throw InputError("--calibration-cache", "",
                       "applies to calibrated modes (--method calibrated, the task's calibration or clearance_search)");
    if (const std::string problem = tasks::prepare_calibration_cache(*cache); !problem.empty())
      throw InputError("--calibration-cache", "", problem);
    options.calibration_cache = *cache;
  }
  auto files = output_dir(args, context);
  CliHooks hooks;
  const auto modes = tasks::run_modes(c, options, hooks, context.executor);
  std::vector<std::string> warnings = modes.warnings;
  if (files)
    for (auto& w : report::write_files(*files, modes)) warnings.push_back(w);
  json result = tasks::to_json(modes, output_folder(files.get()));
  Rows rows = {{"case", c.name}, {"method", std::string(case_file::to_string(options.method))}};
  for (const auto& m : modes.calibrations)
    rows.push_back({"calibration, mode " + std::to_string(m.mode + 1),
                    std::to_string(2 * m.amplitude_points) + " DEM points, " +
                        (m.cached ? "cached" : "run in " + format_number(m.wall_time_s, 3) + " s") + ": " +
                        base::printable(m.file.string())});
  for (Eigen::Index j = 0; j < modes.mode_count; ++j) {
    std::string row = format_number(modes.frequencies_with_containers_hz[j], 6) + " Hz (bare " +
                      format_number(modes.modal.natural_frequencies_hz[j], 6) + " Hz), mu = " +
                      format_number(modes.modal_mass_ratio(j), 4);
    if (const auto backbone = tasks::backbone_summary(modes, j))
      row += ", zeta_add max " + format_number(backbone->max_added_damping_ratio, 4) + " at X = " +
             format_number(backbone->max_added_damping_amplitude_m, 4) + " m";
    rows.push_back({"mode " + std::to_string(j + 1), row});
  }
  for (const auto& check : modes.dem_checks)
    rows.push_back({"DEM check, mode " + std::to_string(check.mode + 1),
                    "X = " + format_number(check.damper_amplitude_m * 1e3, 4) + " mm: zeta_add predicted " +
                        format_number(100.0 * check.predicted_damping_ratio, 4) + " %, DEM " +
                        format_number(100.0 * check.dem_damping_ratio, 4) + " %; whole zeta differs by " +
                        format_number(100.0 * check.whole_relative_difference(), 3) + " % (" +
                        format_number(check.wall_time_s, 3) + " s)"});
  if (!modes.dem_checks.empty())
    rows.push_back({"DEM check", std::string(modes.dem_checks_passed() ? "passed" : "failed") + " (whole damping ratios within " +
                                     format_number(100.0 * modes.dem_check_tolerance, 3) + " %)"});
  if (const auto& search = modes.clearance_search) {
    for (std::size_t k = 0; k < search->candidates.size(); ++k) {
      const auto& candidate = search->candidates[k];
      const bool lined = !search->settings.wall_layer_thicknesses_m.empty();
      std::string row =
          !candidate.buildable
              ? "not run: the lining's tip strain " + format_number(candidate.layer_tip_strain, 3) +
                    " under the buffer's design impact exceeds the allowable strain"
              : "zeta_add " + (std::isfinite(candidate.objective) ? format_number(100.0 * candidate.objective, 4) + " %" : "-") +
                    " (inner length " + format_number(candidate.inner_length_m * 1e3, 5) + " mm" +
                    (std::isfinite(candidate.layer_tip_strain)
                         ? "; lining tip strain " + format_number(candidate.layer_tip_strain, 3)
                         : std::string()) +
                    "; calibration " +
                    (candidate.calibration.cached ? "cached" : format_number(candidate.calibration.wall_time_s, 3) + " s") + ")";
      if (!candidate.checks.empty())
        row += "; checked decays: calibrated " + format_number(100.0 * candidate.predicted_check_mean, 4) + " %, DEM " +
               format_number(100.0 * candidate.dem_check_mean, 4) + " %" + (candidate.checks_passed ? "" : " (a decay missed)");
      rows.push_back({"h = " + format_number(candidate.clearance_m * 1e3, 4) + " mm" +
                          (lined ? ", t = " + format_number(candidate.wall_layer_thickness_m * 1e3, 4) + " mm" : "") +
                          (k == search->chosen ? " (chosen)" : ""),
                      row});
    }
    if (search->verified)
      rows.push_back({"clearance search", std::string(search->passed ? "passed" : "failed") + ": chosen " +
                                              (search->chosen_agrees ? "agrees" : "misses") + ", ranking " +
                                              (search->ranking_agrees ? "not contradicted" : "contradicted") + " by the DEM"});
  }
  return finish(args, files.get(), result, warnings, rows, {"modes.json", &c, context.report}, &modes);
}

// ---------------------------------------------------------------- frf

/// --method dem: the band and points (flags, else the task's), the directions, the signal.
tasks::DemFrfOptions dem_frf_options(const ParsedArgs& args, const Case& c) {
  tasks::DemFrfOptions o = tasks::default_dem_frf_options(c);
  o.points = static_cast<int>(args.optional_integer("--dem-points", 2, kMaxDemPoints).value_or(o.points));
  o.min_frequency_hz = args.optional_number("--dem-min-frequency", {0.0, 1e6, true}).value_or(o.min_frequency_hz);
  o.max_frequency_hz = args.optional_number("--dem-max-frequency", {0.0, 1e6, true}).value_or(o.max_frequency_hz);
  if (o.max_frequency_hz == o.min_frequency_hz)
    throw InputError("--dem-points, --dem-min-frequency, --dem-max-frequency", "",
                     "the band [" + format_number(o.min_frequency_hz) + ", " + format_number(o.max_frequency_hz) +
                         "] Hz is one frequency: the " + std::to_string(o.points) +
                         " points would all fall on it (give --dem-max-frequency above --dem-min-frequency)");
  if (!(o.max_frequency_hz > o.min_frequency_hz))
    throw InputError("--dem-max-frequency", "", format_number(o.max_frequency_hz) + " Hz: must exceed the lowest frequency " +
                                                    format_number(o.min_frequency_hz) + " Hz (--dem-min-frequency or the task's)");
  const std::string direction = args.optional_text("--dem-sweep").value_or("both");
  if (direction != "up" && direction != "down" && direction != "both")
    throw InputError("--dem-sweep", "", "'" + direction + "': must be up, down or both");
  o.directions.clear();
  if (direction != "down") o.directions.push_back(st::SweepDirection::kUp);
  if (direction != "up") o.directions.push_back(st::SweepDirection::kDown);
  const std::string signal = args.optional_text("--dem-signal").value_or("stepped");
  if (signal != "stepped" && signal != "linear") throw InputError("--dem-signal", "", "'" + signal + "': must be stepped or linear");
  o.linear_sweep = signal == "linear";
  o.sweep_rate_hz_s = args.optional_number("--dem-sweep-rate", {0.0, 1e6, true});
  o.settling.stable_tolerance = args.optional_number("--dem-tolerance", {0.0, 0.99, true}).value_or(o.settling.stable_tolerance);
  o.settling.max_transient_periods = static_cast<int>(
      args.optional_integer("--dem-max-periods", 0, 100000).value_or(o.settling.max_transient_periods));
  return o;
}

std::string dem_peak_row(const st::SteppedSinePeak& bp, std::size_t points) {
  const st::SteppedSinePoint& top = *bp.ascending[bp.peak.index];
  return format_number(bp.peak.frequency_hz, 5) + " Hz (largest of " + std::to_string(points) + " points at " +
         format_number(top.frequency_hz, 5) + " Hz), |out| = " + format_number(bp.peak.magnitude, 4) +
         (bp.output == 0 && std::isfinite(top.standard_error) ? " +- " + format_number(top.standard_error, 2) : "") +
         ", 0.9 band centre " + format_number(bp.peak.band_centre_hz, 5) + " Hz, largest points within [" +
         format_number(bp.peak.indistinguishable_low_hz, 4) + ", " + format_number(bp.peak.indistinguishable_high_hz, 4) +
         "] Hz, maximum within [" + format_number(bp.peak.maximum_low_hz, 4) + ", " +
         format_number(bp.peak.maximum_high_hz, 4) + "] Hz, half-power zeta " + format_number(bp.peak.damping_ratio, 3);
}

Rows harmonic_rows(const tasks::HarmonicFrf& h) {
  const auto& response = h.response;
  Rows rows = {{"method", std::string(case_file::to_string(h.method))},
               {"outcome", h.converged ? "converged" : "some_roots_not_converged"}};
  for (const auto& p : response.peaks)
    rows.push_back({"peak " + response.output_names[p.output],
                    format_number(p.frequency_hz, 6) + " Hz, |out| = " + format_number(p.magnitude, 4) +
                        (std::isfinite(p.damping_ratio) ? ", zeta = " + format_number(p.damping_ratio, 4) : "")});
  for (const auto& p : response.linear_peaks)
    rows.push_back({"without beds " + response.output_names[p.output],
                    format_number(p.frequency_hz, 6) + " Hz, |out| = " + format_number(p.magnitude, 4)});
  for (const auto& e : response.branch_ends)
    if (e.kind != st::BranchEnd::Kind::kStrokeRange)
      rows.push_back({std::string(tasks::branch_end_kind(e.kind)), format_number(e.frequency_hz, 6) + " Hz, X = " +
                                                                        format_number(e.damper_amplitude_m, 4) + " m"});
  return rows;
}

Rows stepped_rows(const tasks::SteppedSineFrf& s) {
  Rows rows = {{"method", "dem"}};
  const auto& names = s.damper_names;
  for (const auto& branch : s.branches) {
    for (std::size_t d = 0; d < names.size(); ++d)
      rows.push_back({"peak " + std::string(st::to_string(branch.sweep)) + " " + names[d], dem_peak_row(st::stepped_sine_peak(branch, d), branch.points.size())});
    for (const auto& p : branch.points)
      rows.push_back({std::string(st::to_string(branch.sweep)) + " " + format_number(p.frequency_hz, 6) + " Hz",
                      "|out| = " + format_number(p.magnitude.front(), 4) +
                          (std::isfinite(p.standard_error) ? " +- " + format_number(p.standard_error, 2) : "") +
                          ", bed eta* " + format_number(p.bed_eta_star.front(), 3) + ", m_app/m_bed " +
                          format_number(p.bed_apparent_mass_fraction.front(), 3) + ", energy error " +
                          format_number(p.energy_error, 2)});
  }
  rows.push_back({"DEM wall time", format_number(s.solve_time_s, 4) + " s (" +
                                       (s.parallel ? "directions in parallel" : "one after the other") + ")"});
  return rows;
}

Rows linear_rows(const tasks::LinearSweepFrf& l) {
  Rows rows = {{"method", "dem, linear sine sweep"},
               {"sweep rate", format_number(l.rate_hz_s, 4) + " Hz/s over [" + format_number(l.min_frequency_hz, 5) + ", " +
                                  format_number(l.max_frequency_hz, 5) + "] Hz (" + format_number(l.duration_s, 4) + " s; " +
                                  l.rate_basis + ")"}};
  for (const auto& s : l.sweeps) {
    for (std::size_t d = 0; d < l.damper_names.size(); ++d) {
      const st::SweepPeak& sp = s.peaks[d];
      rows.push_back(
          {"peak " + std::string(st::to_string(s.sweep)) + " " + l.damper_names[d],
           sp.found() ? format_number(sp.peak.frequency_hz, 5) + " Hz, |out| = " + format_number(sp.peak.magnitude, 4) +
                            " +- " + format_number(sp.standard_error(), 2) + ", 0.9 band centre " +
                            optional_number(sp.peak.band_centre_hz, 5, "outside the band") +
                            (std::isfinite(sp.peak.band_centre_hz) ? " Hz" : "") + ", half-power zeta " +
                            format_number(sp.peak.damping_ratio, 3)
                      : "fewer than " + std::to_string(st::kSweepWindowCycles) + " cycles"});
    }
    rows.push_back({std::string(st::to_string(s.sweep)) + " sweep", std::to_string(s.cycles.size()) + " cycles, energy error " +
                                            format_number(s.energy_error, 2) + ", " + std::to_string(s.steps) +
                                            " steps of " + format_number(s.time_step_s, 3) + " s"});
  }
  rows.push_back({"DEM wall time", format_number(l.solve_time_s, 4) + " s (" +
                                       (l.parallel ? "directions in parallel" : "one after the other") + ")"});
  return rows;
}

Rows compare_rows(const tasks::FrfResult& r) {
  Rows rows = {{"method", "compare (formulas, field, dem)"}};
  const auto row = [&](const std::string& name, const std::optional<tasks::PeakAgreement>& a) {
    if (!a) {
      rows.push_back({name, "-"});
      return;
    }
    const auto percent = [](double v) { return std::isfinite(v) ? format_number(100.0 * v, 3) : std::string("-"); };
    const auto zeta = [](double v) { return std::isfinite(v) ? format_number(v, 3) : std::string("-"); };
    rows.push_back({name, format_number(a->frequency_hz, 5) + " Hz, |out| = " + format_number(a->magnitude, 4) +
                              " (vs dem: f " + percent(a->frequency_relative_difference) + "%, 0.9 band centre " +
                              percent(a->band_centre_relative_difference) + "%, |out| " +
                              percent(a->magnitude_relative_difference) + "%; zeta " + zeta(a->damping_ratio) + " vs " +
                              zeta(a->dem_damping_ratio) + ")"});
  };
  for (std::size_t k = 0; k < r.stepped->branches.size(); ++k) {
    const auto& branch = r.stepped->branches[k];
    const std::string sweep(st::to_string(branch.sweep));
    rows.push_back({"peak dem " + sweep, dem_peak_row(st::stepped_sine_peak(branch), branch.points.size())});
    row("peak formulas vs " + sweep, r.agreement[k].formulas);
    row("peak field vs " + sweep, r.agreement[k].field);
  }
  return rows;
}

int run_frf_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  tasks::require_task(c, case_file::TaskKind::kFrf);
  tasks::FrfOptions options;
  if (args.has("--compare")) {
    if (args.optional_text("--method"))
      throw InputError("--compare", "", "runs every method (formulas, field, dem): give no --method with it");
    options.method = tasks::FrfMethod::kCompare;
  } else if (dem_method(args)) {
    options.method = tasks::FrfMethod::kDem;
  } else {
    options.method = loss_method(args) == case_file::LossMethod::kField ? tasks::FrfMethod::kField : tasks::FrfMethod::kFormulas;
  }
  if (options.method == tasks::FrfMethod::kDem || options.method == tasks::FrfMethod::kCompare)
    options.dem = dem_frf_options(args, c);
  else
    refuse_flags(args, kDemSweepFlags, "applies to --method dem or --compare (the DEM in the loop)");
  auto files = output_dir(args, context);
  CliHooks hooks;
  const auto result = tasks::run_frf(c, options, hooks, context.executor);
  std::vector<std::string> warnings = result.warnings;
  if (files)
    for (auto& w : report::write_files(*files, result)) warnings.push_back(w);
  json out = tasks::to_json(result, output_folder(files.get()));
  Rows rows;
  switch (options.method) {
    case tasks::FrfMethod::kFormulas:
    case tasks::FrfMethod::kField: rows = harmonic_rows(*result.harmonic); break;
    case tasks::FrfMethod::kDem: rows = result.linear ? linear_rows(*result.linear) : stepped_rows(*result.stepped); break;
    case tasks::FrfMethod::kCompare: rows = compare_rows(result); break;
  }
  rows.insert(rows.begin(), {"case", c.name});
  if (out.contains("frf")) out["frf"]["warnings"] = warnings;
  return finish(args, files.get(), out, warnings, rows, {"frf.json", &c, context.report}, &result);
}

// ---------------------------------------------------------------- decay

int run_decay_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  tasks::require_task(c, case_file::TaskKind::kDecay);
  tasks::DecayOptions options;
  if (dem_method(args)) {
    options.method = tasks::DecayMethod::kDem;
  } else {
    refuse_checkpoint_flags(args, "applies to --method dem (the DEM runs checkpoint)");
    refuse_flags(args, {{"--snapshots", "N", ""}}, "applies to --method dem (the beds' particles)");
    options.method = loss_method(args) == case_file::LossMethod::kField ? tasks::DecayMethod::kField : tasks::DecayMethod::kFormulas;
  }
  options.snapshots = static_cast<int>(args.optional_integer("--snapshots", 0, dem_reference::limits::kMaxSnapshots).value_or(0));
  auto files = output_dir(args, context);
  if (options.method == tasks::DecayMethod::kDem) options.checkpoint.file = checkpoint_file(args, "decay_dem");
  CliHooks hooks(checkpoint_interval(args), args.has("--accept-long-run"));
  // Signals wait for a checkpoint during the run, then for the commit (dem_results_ready).
  const std::optional<report::DeferredSignals> deferred =
      options.checkpoint.file.path.empty() ? std::nullopt : std::make_optional<report::DeferredSignals>();
  tasks::DecayResult result = tasks::run_decay(c, options, hooks, context.executor);
  if (deferred) dem_results_ready(files.get());
  std::vector<std::string> warnings = result.warnings;
  if (files)
    for (auto& w : report::write_files(*files, result)) warnings.push_back(w);
  json out = tasks::to_json(result, output_folder(files.get()));
  out["decay"]["warnings"] = warnings;
  const tasks::DecaySummary d = tasks::decay_summary(result);
  Rows rows = {{"case", c.name},
               {"method", d.method},
               {"outcome", d.settled ? "settled" : "not_settled"},
               {"settling_time_s", d.settled ? format_number(d.settling_time_s, 6) : "not settled"},
               {"damping_ratio", std::isfinite(d.damping_ratio) ? format_number(d.damping_ratio, 4) : "-"},
               {"dominant mode", std::to_string(d.dominant_mode)},
               {"threshold_m", format_number(d.threshold_m, 4)}};
  if (options.method == tasks::DecayMethod::kDem) {
    const auto& r = result.dem.cosimulation;
    rows.push_back({"energy_error", format_number(r.energy.relative_error, 3)});
    rows.push_back({"DEM steps", std::to_string(r.steps) + " of " + format_number(r.time_step_s, 3) + " s in " +
                                     format_number(r.wall_time_s, 3) + " s"});
  } else {
    for (const auto& l : out["decay"]["layers"])
      rows.push_back({"dissipated by " + l["name"].get<std::string>(),
                      format_number(l["dissipated_energy_j"].get<double>(), 4) + " J (" +
                          format_number(100.0 * l["share"].get<double>(), 3) + "%)"});
  }
  const int code = finish(args, files.get(), out, warnings, rows, {"decay.json", &c, context.report}, &result);
  remove_checkpoints(files.get(), {options.checkpoint.file.path});
  return code;
}

int run_modes(const ParsedArgs& args, CommandContext& context) {
  return run_modes_case(args, context, case_file::load_case(args.positional().at(0)));
}
int run_frf(const ParsedArgs& args, CommandContext& context) {
  return run_frf_case(args, context, case_file::load_case(args.positional().at(0)));
}
int run_decay(const ParsedArgs& args, CommandContext& context) {
  return run_decay_case(args, context, case_file::load_case(args.positional().at(0)));
}

}  // namespace

int run_structure_case(const ParsedArgs& args, CommandContext& context, const Case& c) {
  switch (c.task.kind) {
    case case_file::TaskKind::kModes: return run_modes_case(args, context, c);
    case case_file::TaskKind::kFrf: return run_frf_case(args, context, c);
    case case_file::TaskKind::kDecay: return run_decay_case(args, context, c);
    case case_file::TaskKind::kDamperDesign:
    case case_file::TaskKind::kFillingRatios:
    case case_file::TaskKind::kPlacement:
    case case_file::TaskKind::kClearance: break;
  }
  throw std::logic_error("run_structure_case: not a structure task");
}

std::vector<Command> structure_commands() {
  return {
      {{"modes", "pdamp modes CASE.json [--method formulas|field|calibrated] [--calibration-cache DIR] [-o DIR] [--json]",
        "natural frequencies (with the empty containers attached, and bare), mode shapes at the\n"
        "named points, modal mass ratio per damper and backbones f(X), zeta_add(X) per mode",
        {{"--method", "M",
          "source of each layer's eta*(f, X) and apparent mass: formulas (the closed\n"
          "                          forms of its model and clearance), field (the layer's field_file, made\n"
          "                          by pdamp field) or calibrated (the task's calibrated modes, its\n"
          "                          calibration's or else its dem_check's, from a DEM field of the bed;\n"
          "                          the others by formulas); default calibrated when the task has a\n"
          "                          calibration, else formulas"},
         kCalibrationCacheFlag, {"-o", "DIR", "write modes.csv, backbone_mode<j>.csv, backbone.gp/png/svg, modes.json\n"
                                    "                          and case_resolved.json into DIR, atomically"},
         kJsonFlag}, 1},
       run_modes, true},
      {{"frf", "pdamp frf CASE.json [--method formulas|field|dem | --compare] [--dem-points N] [--dem-sweep D] [-o DIR] [--json]",
        "frequency response of the structure with its dampers (task kind frf): every harmonic-\n"
        "balance root, its stability, branches, jumps and peaks, and the response without beds",
        concat_flags({kMethodFlag,
         {"--compare", "", "run formulas, field (when every layer has a field_file, else skipped\n"
                           "                          with a warning) and dem on the case: one figure frf_compare.png/svg,\n"
                           "                          frf_compare.csv, and the peaks' relative differences from dem"},
         {"-o", "DIR", "write frf.csv, frf_branches.csv, frf.gp/png/svg (dem: frf_dem.csv,\n"
                       "                          frf_dem.gp/png/svg; --compare: frf_compare.csv/gp/png/svg), frf.json\n"
                       "                          and case_resolved.json into DIR, atomically"},
         kJsonFlag}, kDemSweepFlags), 1},
       run_frf, true},
      {{"decay", "pdamp decay CASE.json [--method formulas|field|dem] [--snapshots N] [--resume] [--checkpoint-interval S] [-o DIR] [--json]",
        "free decay of the structure with its dampers (task kind decay): envelope, settling time,\n"
        "equivalent damping ratio and the energy each layer dissipates",
        concat_flags({kMethodFlag,
                      {"--snapshots", "N", "--method dem: every bed's particles N times over the decay, for\n"
                                           "                          ParaView (particles_<damper>.pvd, container_<damper>.pvd)"},
                      {"-o", "DIR", "write decay.csv, decay.gp/png/svg (dem: decay_dem.csv,\n"
                                    "                          decay_dem.gp/png/svg), decay.json and case_resolved.json\n"
                                    "                          into DIR, atomically (dem: decay_dem.checkpoint while running)"},
                      kJsonFlag},
                     kCheckpointFlags), 1},
       run_decay, true},
      optimize_command(),
  };
}

}  // namespace pdamp::cli
