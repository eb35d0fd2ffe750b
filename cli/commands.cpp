// The single-damper subcommands (optimum, size, loss, buffer, dem, field, sensitivity and
// their merges, validate), pdamp run, and the table of every command: flags to a task's
// options, the task, its files, the printout.
#include "commands.hpp"

#include <fstream>
#include <iostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "errors.hpp"
#include "flags.hpp"
#include "limits.hpp"
#include "output.hpp"
#include "pdamp/report/external_program.hpp"
#include "pdamp/report/task_files.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/surrogate/scattered_fit.hpp"
#include "pdamp/tasks/case_checks.hpp"
#include "pdamp/tasks/closed_forms.hpp"
#include "pdamp/tasks/damper_design.hpp"
#include "pdamp/tasks/dem_run.hpp"
#include "pdamp/tasks/field.hpp"
#include "pdamp/tasks/liggghts.hpp"
#include "pdamp/tasks/sensitivity.hpp"
#include "cli_hooks.hpp"
#include "structure_commands.hpp"
#include "version.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace fm = formulas;
using case_file::Case;

fm::DamperModel model_flag(const ParsedArgs& args, const std::vector<std::string>& allowed) {
  const std::string name = args.text("--model");
  for (const auto& a : allowed)
    if (a == name) return *fm::damper_model_from_string(name);
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
  throw InputError("--model", "", "'" + name + "' is not a model here (allowed: " + list + ")");
}

/// Calibration and inertia overrides shared by optimum, size and loss.
fm::ModelOptions model_options(const ParsedArgs& args, fm::DamperModel model) {
  fm::ModelOptions options;
  if (const auto kappa = args.optional_number("--inertia-factor", Range{0.0, 1.0, true})) options.rolling_inertia_factor = *kappa;
  if (const auto mu = args.optional_number("--friction", Range{0.0, 10.0})) options.base_friction = *mu;
  if (const auto c = args.optional_number("--calibration", Range{0.0, 2.0, true})) {
    if (model == fm::DamperModel::kBouncing) options.bouncing_calibration = *c;
    else options.rolling_calibration = *c;
  }
  if (const auto e_b = args.optional_number("--bed-restitution", Range{0.0, fm::kMaxBedRestitution}))
    options.bed_restitution = *e_b;
  if (const auto law = args.optional_text("--below-onset")) {
    const auto below = fm::below_onset_model_from_string(*law);
    if (!below) throw InputError("--below-onset", "", "'" + *law + "' is not allowed (one of: scattered_fit impact_map rolling_tail)");
    options.below_onset = *below;
  }
  if (const auto file = args.optional_text("--scattered-fit")) {
    try {
      options.scattered = surrogate::read_scattered_fit(*file).fit;
    } catch (const std::invalid_argument& e) {
      throw InputError("--scattered-fit", "", e.what());
    }
  }
  return options;
}

/// A result printed without files: the closed forms' (refused when not finite).
const ResultFiles kPrintOnly{"", nullptr, false, "files", false, true};

Rows optimum_rows(const fm::OptimumStroke& o) {
  return {{"model", std::string(fm::to_string(o.model))},
          {"clearance_m", format_number(o.clearance_m)},
          {"x_opt_m (design)", format_number(o.x_opt_m) + "  (= " + format_number(o.x_opt_m / o.clearance_m, 4) + " h)"},
          {"x_opt_ideal_m (peak)", format_number(o.x_opt_ideal_m) + "  (eta* = " + format_number(o.eta_star_peak, 4) + ")"},
          {"x_onset_m (cliff)", format_number(o.x_onset_m) + "  (eta* = " + format_number(o.eta_star_onset, 4) + ")"}};
}

int run_optimum(const ParsedArgs& args, CommandContext&) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double h = args.number("--clearance", limits::kClearance);
  const auto result = fm::optimum_stroke(model, h, model_options(args, model));
  json out = base::to_json(result);
  return finish(args, nullptr, out, length_scale_warnings(args, {"--clearance"}), optimum_rows(result), kPrintOnly);
}

int run_size(const ParsedArgs& args, CommandContext&) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double stroke = args.number("--stroke", limits::kStroke);
  const auto sizing = tasks::size_for_stroke(model, stroke, model_options(args, model));
  json out = base::to_json(sizing);
  return finish(args, nullptr, out, length_scale_warnings(args, {"--stroke"}),
                {{"model", std::string(fm::to_string(model))},
                 {"stroke_m", format_number(stroke)},
                 {"clearance_m", format_number(sizing.clearance_m)},
                 {"x_onset_m", format_number(sizing.at.x_onset_m) + "  (strokes below fall off the cliff)"}},
                kPrintOnly);
}

int run_loss(const ParsedArgs& args, CommandContext& context) {
  tasks::LossOptions options;
  options.model = model_flag(args, {"rolling", "bouncing", "scattered", "auto", "coulomb_block"});
  options.clearance_m = args.number("--clearance", limits::kClearance);
  options.amplitude_m = args.number("--amplitude", limits::kStroke);
  options.frequency_hz = args.number("--frequency", limits::kFrequency);
  options.bed_mass_kg = args.optional_number("--bed-mass", limits::kMass);
  options.model_options = model_options(args, options.model);
  auto files = output_dir(args, context);
  options.with_curve = files != nullptr;
  const auto study = tasks::run_loss(options);
  std::vector<std::string> warnings = length_scale_warnings(args, {"--clearance", "--amplitude"});
  warnings.insert(warnings.end(), study.warnings.begin(), study.warnings.end());
  if (files)
    for (auto& w : report::write_files(*files, study)) warnings.push_back(w);
  json out = tasks::to_json(study);
  const auto& loss = study.point.loss;
  return finish(args, files.get(), out, warnings,
                {{"model_used", std::string(fm::to_string(loss.model_used))},
                 {"regime", std::string(fm::to_string(loss.regime))},
                 {"eta_star", format_number(loss.eta_star)},
                 {"e_diss_j", format_number(study.point.e_diss_j)},
                 {"energy_per_cycle_j", format_number(study.point.energy_per_cycle_j)},
                 {"intensity", format_number(loss.intensity, 4)}},
                {"loss.json", nullptr, false, "files", false, true});
}

int run_buffer(const ParsedArgs& args, CommandContext&) {
  fm::BufferDesignInput in;
  in.frequency_hz = args.number("--frequency", limits::kFrequency);
  const auto amplitude = args.optional_number("--amplitude", limits::kStroke);
  const auto intensity = args.optional_number("--intensity", limits::kIntensity);
  if (amplitude.has_value() == intensity.has_value())
    throw InputError("--amplitude", "", "give exactly one of --amplitude M and --intensity G");
  in.amplitude_m = amplitude.value_or(0.0);
  in.intensity = intensity.value_or(0.0);
  in.particle_radius_m = args.number("--radius", limits::kParticleRadius);
  in.particle.density_kg_m3 = args.optional_number("--particle-density", limits::kDensity).value_or(in.particle.density_kg_m3);
  in.particle.youngs_modulus_pa = args.optional_number("--particle-modulus", limits::kModulus).value_or(in.particle.youngs_modulus_pa);
  in.particle.poisson_ratio = args.optional_number("--particle-poisson", limits::kPoisson).value_or(in.particle.poisson_ratio);
  in.layer.youngs_modulus_pa = args.number("--layer-modulus", limits::kModulus);
  in.layer.poisson_ratio =
      args.optional_number("--layer-poisson", limits::kPoisson).value_or(fm::kDefaultLayerPoissonRatio);
  in.model = case_file::buffer_model(args.optional_text("--layer-model").value_or("layered"), "--layer-model", "");
  in.allowable_strain =
      args.optional_number("--allowable-strain", limits::kAllowableStrain).value_or(fm::kDefaultAllowableStrain);
  in.particles_per_contact = args.optional_number("--particles-per-contact", Range{1.0, 1e9}).value_or(1.0);
  in.impact_velocity_m_s = args.optional_number("--impact-velocity", limits::kImpactSpeed).value_or(0.0);
  const auto problems = in.validate();
  if (!problems.empty()) throw InputError("pdamp buffer", "", problems.front());
  const auto design = fm::size_buffer_layer(in);
  json out = base::to_json(design);
  return finish(args, nullptr, out, design.warnings,
                {{"model", std::string(design.model == fm::BufferModel::kLayered ? "layered" : "half_space")},
                 {"layer_thickness_m", format_number(design.layer_thickness_m)},
                 {"allowable_strain", format_number(design.allowable_strain, 4) +
                                          (design.model == fm::BufferModel::kHalfSpace ? "  (half_space: t = delta_max)" : "")},
                 {"contact_radius/thickness", format_number(design.contact_radius_over_thickness, 3)},
                 {"half-space thickness", format_number(design.half_space_thickness_m) + "  (compressed to " +
                                              format_number(design.layered_compression_of_half_space_design, 3) +
                                              " of it by the design impact)"},
                 {"impact_velocity_m_s", format_number(design.impact_velocity_m_s)},
                 {"max_penetration_m", format_number(design.max_penetration_m)},
                 {"contact_time_s", format_number(design.contact_time_s)},
                 {"contact_time/period", format_number(design.contact_time_over_period, 4)},
                 {"max_force_n", format_number(design.max_force_n)}},
                kPrintOnly);
}

int run_damper_design(const ParsedArgs& args, CommandContext& context, const Case& c) {
  auto files = output_dir(args, context);
  const auto design = tasks::run_damper_design(c, context.executor);
  std::vector<std::string> warnings = design.warnings;
  if (files)
    for (auto& w : report::write_files(*files, design)) warnings.push_back(w);
  json result = tasks::to_json(design);
  Rows rows = optimum_rows(design.optimum);
  rows.insert(rows.begin(), {"case", c.name});
  rows.push_back({"eta* at design", format_number(design.eta_star_at_design, 4)});
  if (design.operating_point)
    rows.push_back({"eta* at operating X", format_number(design.operating_point->loss.eta_star, 4) + "  (X = " +
                                               format_number(design.operating_amplitude_m) + " m, " +
                                               std::string(fm::to_string(design.operating_point->loss.regime)) + ")"});
  if (design.sizing) rows.push_back({"clearance for target", format_number(design.sizing->clearance_m)});
  if (design.buffer) rows.push_back({"buffer layer_thickness_m", format_number(design.buffer->layer_thickness_m)});
  return finish(args, files.get(), result, warnings, rows,
                {"design.json", &c, context.report, "outputs", true, true}, &design);
}

int run_run(const ParsedArgs& args, CommandContext& context) {
  const Case c = case_file::load_case(args.positional().at(0));
  context.report = true;  // with -o DIR, the task also writes DIR/report.html
  const std::string kind(case_file::to_string(c.task.kind));
  if (args.has("--no-verify") && c.task.kind != case_file::TaskKind::kFillingRatios &&
      c.task.kind != case_file::TaskKind::kClearance)
    throw InputError("--no-verify", "", "applies to task kinds filling_ratios and clearance; this case's task is " + kind);
  if (args.has("--calibration-cache") && c.task.kind != case_file::TaskKind::kFillingRatios &&
      c.task.kind != case_file::TaskKind::kModes)
    throw InputError("--calibration-cache", "", "applies to task kinds filling_ratios and modes; this case's task is " + kind);
  if (c.task.kind != case_file::TaskKind::kFrf)
    refuse_flags(args, kDemSweepFlags, "applies to task kind frf (the DEM stepped sine); this case's task is " + kind);
  switch (c.task.kind) {
    case case_file::TaskKind::kDamperDesign:
      if (args.has("--method"))
        throw InputError("--method", "", "applies to the structure tasks (modes, frf, decay); this case's task is damper_design");
      return run_damper_design(args, context, c);
    case case_file::TaskKind::kFillingRatios:
    case case_file::TaskKind::kPlacement:
    case case_file::TaskKind::kClearance: return run_optimize_case(args, context, c);
    case case_file::TaskKind::kModes:
    case case_file::TaskKind::kFrf:
    case case_file::TaskKind::kDecay: return run_structure_case(args, context, c);
  }
  throw std::logic_error("pdamp run: unknown task kind");
}

// ---------------------------------------------------------------- DEM

int run_dem(const ParsedArgs& args, CommandContext& context) {
  const Case c = case_file::load_case(args.positional().at(0));
  tasks::DemRunOptions options;
  options.frequency_hz = args.optional_number("--frequency", limits::kFrequency);
  options.amplitude_m = args.optional_number("--amplitude", limits::kStroke);
  if (const auto periods = args.optional_integer("--periods", 1, dem_reference::limits::kMaxPeriods))
    options.analysed_periods = static_cast<int>(*periods);
  if (const auto threads = args.optional_integer("--threads", 0, dem_reference::limits::kMaxThreads))
    options.threads = static_cast<int>(*threads);
  if (const auto snapshots = args.optional_integer("--snapshots", 0, dem_reference::limits::kMaxSnapshots))
    options.snapshots = static_cast<int>(*snapshots);
  const auto plan = tasks::plan_dem(c, options);
  auto files = output_dir(args, context);
  // Checkpoints in the -o folder at period ends (docs/dem.md "Checkpoints"): every
  // --checkpoint-interval seconds and when a signal arrives (then pdamp ends by it).
  const tasks::CheckpointFile checkpoint = checkpoint_file(args, "dem");
  CliHooks hooks(checkpoint_interval(args), args.has("--accept-long-run"));
  // Signals wait for a checkpoint during the run, then for the commit (dem_results_ready).
  const std::optional<report::DeferredSignals> deferred =
      checkpoint.path.empty() ? std::nullopt : std::make_optional<report::DeferredSignals>();
  tasks::DemRunResult result = tasks::run_dem(c, plan, checkpoint, hooks, context.executor);
  if (deferred) dem_results_ready(files.get());
  std::vector<std::string> warnings = result.warnings;
  if (files)
    for (auto& w : report::write_files(*files, result)) warnings.push_back(w);
  json out = tasks::to_json(result);
  const auto& r = result.dem;
  const int code = finish(
      args, files.get(), out, warnings,
      {{"case", c.name},
       {"eta_star", format_number(r.eta_star, 4) + " +- " + format_number(r.eta_star_stderr, 2)},
       {"eta_star (closed form)", format_number(result.closed_form.eta_star, 4) + "  (" +
                                      std::string(fm::to_string(result.closed_form.regime)) + ")"},
       {"apparent_mass_kg", format_number(r.apparent_mass_kg, 4) + "  (" + format_number(r.apparent_mass_kg / r.bed_mass_kg, 3) +
                                " m_bed)"},
       {"e_diss_j", format_number(r.e_diss_j)},
       {"energy_balance_error", format_number(r.energy_balance_error, 3)},
       {"motion_mode", std::string(dem_reference::to_string(r.motion_mode))},
       {"clearance_m", format_number(r.clearance_m)},
       {"particle_steps_per_s", format_number(r.particle_steps_per_s, 3)},
       {"run", r.summary.brief_report()}},
      {"summary.json", nullptr, false, "files", false, false});
  remove_checkpoints(files.get(), {checkpoint.path});
  return code;
}

// ---------------------------------------------------------------- LIGGGHTS (docs/liggghts.md)

/// `pdamp export liggghts CASE.json -o DIR`: the deck of pdamp dem's run for LIGGGHTS.
/// pdamp does not run it (no shell, no external DEM started): README.txt says how.
int run_export_liggghts(const ParsedArgs& args, CommandContext& context) {
  const Case c = case_file::load_case(args.positional().at(0));
  if (!args.has("-o")) throw InputError("-o", "", "required: the folder to write the LIGGGHTS deck into");
  tasks::DemRunOptions options;
  options.frequency_hz = args.optional_number("--frequency", limits::kFrequency);
  options.amplitude_m = args.optional_number("--amplitude", limits::kStroke);
  if (const auto periods = args.optional_integer("--periods", 1, dem_reference::limits::kMaxPeriods))
    options.analysed_periods = static_cast<int>(*periods);
  options.label = "pdamp export liggghts";
  const auto deck = tasks::export_liggghts(c, options, version());  // every check before the folder is touched
  auto files = output_dir(args, context);
  for (const auto& [name, content] : deck.files) files->add(name, content);
  std::vector<std::string> warnings = length_scale_warnings(args, {"--amplitude"});
  warnings.insert(warnings.end(), deck.warnings.begin(), deck.warnings.end());
  json out = deck.record;
  const auto& r = deck.record;
  return finish(args, files.get(), out, warnings,
                {{"case", c.name},
                 {"particles", std::to_string(r["particles"].get<int>()) + "  (" +
                                   format_number(r["bed_mass_kg"].get<double>(), 4) + " kg)"},
                 {"drive", "X = " + format_number(r["amplitude_m"].get<double>()) + " m, f = " +
                               format_number(r["frequency_hz"].get<double>()) + " Hz along " +
                               r["drive_axis"].get<std::string>()},
                 {"periods", std::to_string(r["transient_periods"].get<int>()) + " transient + " +
                                 std::to_string(r["analysed_periods"].get<int>()) + " analysed"},
                 {"time_step_s", format_number(r["time_step_s"].get<double>()) + "  (" +
                                     std::to_string(r["steps_per_period"].get<long long>()) + " steps a period)"},
                 {"run it", "cd " + files->dir().string() + " && liggghts -in " + tasks::kLiggghtsInputFile +
                                "  (or mpirun -np N liggghts ...; README.txt)"},
                 {"then", "pdamp import liggghts " + files->dir().string()}},
                {"", nullptr, false, "files", false, false});
}

/// `pdamp import liggghts DIR`: pdamp dem's measures from the deck's LIGGGHTS output.
int run_import_liggghts(const ParsedArgs& args, CommandContext& context) {
  const std::filesystem::path deck = args.positional().at(0);
  if (const auto out_dir = args.optional_text("-o")) {
    // The deck's folder belongs to the export: a commit there would remove its files.
    std::error_code e1, e2;
    if (std::filesystem::weakly_canonical(*out_dir, e1) == std::filesystem::weakly_canonical(deck, e2))
      throw InputError("-o", "", std::string("'").append(base::printable(*out_dir)) +
                                     "' is the deck's folder (pdamp export liggghts owns it): write the summary elsewhere");
  }
  const auto result = tasks::import_liggghts(deck);  // refused before -o is touched
  auto files = output_dir(args, context);
  json out = tasks::to_json(result);
  const auto& m = result.measures;
  return finish(args, files.get(), out, result.warnings,
                {{"case", result.case_name},
                 {"eta_star", format_number(m.eta_star, 4) + " +- " + format_number(m.eta_star_stderr, 2) + "  (LIGGGHTS)"},
                 {"apparent_mass_kg", format_number(m.apparent_mass_kg, 4) + "  (" +
                                          format_number(m.apparent_mass_kg / result.bed_mass_kg, 3) + " m_bed)"},
                 {"e_diss_j", format_number(m.e_diss_j)},
                 {"energy_per_cycle_j", format_number(m.energy_per_cycle_j)}},
                {"summary.json", nullptr, false, "files", false, false});
}

// ---------------------------------------------------------------- effective fields and sensitivity

/// The DEM sweep's results log, written point by point into the output folder (resume).
constexpr const char* kSweepLog = "field_sweep.jsonl";
constexpr const char* kSensitivityLog = "sensitivity_sweep.jsonl";
/// The case file a shard ran, copied into its folder: a merge of shard folders reads it back.
constexpr const char* kShardCase = "shard_case.json";

/// `--shard I/N`: this run's part of the sweep, {0, 1} (the whole grid) when absent.
std::pair<int, int> shard_flag(const ParsedArgs& args) {
  const auto text = args.optional_text("--shard");
  if (!text) return {0, 1};
  const std::string allowed = "'" + *text + "': must be I/N with whole numbers 0 <= I < N <= " +
                              std::to_string(surrogate::kMaxShards) + " (e.g. 3/8 for task 3 of an array of 8)";
  const auto whole = [&](const std::string& part) {
    // Digits only (no sign, no exponent), and few enough that stoll cannot overflow.
    if (part.empty() || part.size() > 6 || part.find_first_not_of("0123456789") != std::string::npos)
      throw InputError("--shard", "", allowed);
    return std::stoll(part);
  };
  const std::size_t slash = text->find('/');
  if (slash == std::string::npos) throw InputError("--shard", "", allowed);
  const long long index = whole(text->substr(0, slash)), count = whole(text->substr(slash + 1));
  if (count < 1 || count > surrogate::kMaxShards || index >= count) throw InputError("--shard", "", allowed);
  return {static_cast<int>(index), static_cast<int>(count)};
}

/// The default output folder of a study: one safe path component under out/, as the case
/// name must not steer it elsewhere ("../x", "/etc/x").
std::string default_dir(const Case& c, const std::string& suffix) {
  const std::string safe = report::safe_file_name(c.name);
  if (safe != c.name)
    print_warnings({"case name '" + base::printable(c.name) + "' is not a safe folder name: writing to out/" + safe +
                    suffix});
  return "out/" + safe + suffix;
}

/// The field's files and printout: field.json, the scattered-state fit, tables and pictures.
int field_outputs(const ParsedArgs& args, const Case& c, const tasks::FieldResult& result, report::OutputDir& files,
                  json out) {
  std::vector<std::string> warnings = result.warnings;
  const std::string source(surrogate::to_string(result.field.provenance.source));
  out.update({{"source", source}, {"points", result.field.grid.size()}, {"file", (files.dir() / "field.json").string()}});
  Rows rows = {{"source", source}, {"points", std::to_string(result.field.grid.size())}};
  if (out.contains("sweep")) rows.push_back({"sweep", out["sweep"].get<std::string>()});
  if (result.scattered_fit) {
    const auto& fit = result.scattered_fit->fit;
    out["scattered_fit"] = {{"jump_fraction", fit.jump_fraction}, {"exponent", fit.exponent}, {"s_min", fit.s_min},
                            {"s_max", fit.s_max}, {"reduced_chi_squared", fit.reduced_chi_squared}, {"points", fit.points}};
    rows.push_back({"scattered fit", "jump_fraction = " + format_number(fit.jump_fraction, 4) +
                                         ", exponent = " + format_number(fit.exponent, 4)});
  }
  for (auto& w : report::write_files(files, result, c)) warnings.push_back(w);
  return finish(args, &files, out, warnings, rows, {"", nullptr, false, "files", false, false});
}

int run_field(const ParsedArgs& args, CommandContext& context) {
  const Case c = case_file::load_case(args.positional().at(0));
  (void)tasks::field_sweep_options(c, "formulas");  // one damper of one layer, refused otherwise
  const std::string source = args.text("--source");
  if (source != "formulas" && source != "dem" && source != "measured")
    throw InputError("--source", "", "'" + source + "': must be formulas, dem or measured");
  if (source != "measured" && args.has("--measured")) throw InputError("--measured", "", "goes with --source measured");
  if (source != "dem") refuse_flags(args, {kAcceptLongRunFlag}, "applies to --source dem (the DEM runs)");
  if (source == "measured" && args.has("--shard"))
    throw InputError("--shard", "", "goes with --source dem or formulas (a measured field is imported whole)");
  const auto [shard_index, shard_count] = shard_flag(args);
  const std::string dir = args.optional_text("-o").value_or(default_dir(c, "_field_" + source));
  if (source == "measured") {
    const auto files = study_dir(dir, context);
    const auto result = tasks::import_measured_field(c, args.text("--measured"), context.executor);
    return field_outputs(args, c, result, *files, json::object());
  }
  tasks::FieldOptions options;
  options.source = source;
  options.accept_long_runs = args.has("--accept-long-run");
  options.sharded = args.has("--shard");
  options.shard_index = shard_index;
  options.shard_count = shard_count;
  // A shard's log is its result (pdamp field merge reads it), so a sharded formulas sweep
  // keeps one too; it also makes a rerun of the same shard command resume.
  if (source == "dem" || options.sharded) options.results_log = std::filesystem::path(dir) / kSweepLog;
  const auto plan = tasks::plan_field(c, options, context.executor);
  const auto files = study_dir(dir, context, options.results_log.empty() ? "" : kSweepLog);
  CliHooks hooks;
  const auto result = tasks::run_field(c, plan, hooks, context.executor);
  json out = {{"sweep", result.sweep_report}, {"warnings", result.warnings}};
  if (!result.mpi.is_null()) out["mpi"] = result.mpi;
  if (!options.sharded) return field_outputs(args, c, result, *files, out);
  // A shard has no field of its own: its log waits for pdamp field merge.
  const std::string shard = std::to_string(shard_index) + "/" + std::to_string(shard_count);
  out.update({{"source", source}, {"shard", shard}, {"points", result.summary.points_total},
              {"points_in_grid", plan.grid.size()}, {"file", (files->dir() / kSweepLog).string()}});
  report::write_shard_files(*files, out, c);
  return finish(args, files.get(), out, result.warnings,
                {{"source", source}, {"shard", shard}, {"sweep", result.sweep_report},
                 {"next", "pdamp field merge SHARD_DIR... -o DIR (all " + std::to_string(shard_count) + " shards)"}},
                {"", nullptr, false, "files", false, false});
}

/// The "source" of a shard log's header line (formulas or dem), for a merge not told it.
std::string shard_log_source(const std::filesystem::path& log) {
  std::ifstream in(log);
  std::string header;
  if (!in || !std::getline(in, header))
    throw InputError(log.string(), "", "cannot be read (a shard's sweep log, or its folder)");
  try {
    const json h = json::parse(header);
    const std::string source = h.at("source").get<std::string>();
    if (source == "formulas" || source == "dem") return source;
  } catch (const std::exception&) {
  }
  throw InputError(log.string(), "line 1", "is not the header of a pdamp sweep log (source formulas or dem)");
}

/// The inputs of a merge (pdamp field merge, pdamp sensitivity merge): the case (given
/// first, else the first shard folder's shard_case.json) and the shards' logs (a folder
/// stands for the log `log_name` in it).
struct MergeInputs {
  std::filesystem::path case_path;
  std::vector<std::filesystem::path> logs;
};

MergeInputs merge_inputs(const ParsedArgs& args, const std::string& command, const std::string& log_name) {
  const auto& positional = args.positional();
  std::error_code error;
  const auto shard_log = [&](const std::filesystem::path& given) {  // a folder is what a job array leaves
    return std::filesystem::is_directory(given, error) ? given / log_name : given;
  };
  const std::filesystem::path first = positional.at(0);
  const bool case_given = first.extension() == ".json" && std::filesystem::is_regular_file(first, error);
  const std::size_t first_shard = case_given ? 1 : 0;
  if (first_shard >= positional.size())
    throw InputError(command, "", "no shard given: " + command + " SHARD_DIR... (or CASE.json SHARD...)");
  MergeInputs inputs{first, {}};
  if (!case_given) {
    inputs.case_path = shard_log(first).parent_path() / kShardCase;
    if (!std::filesystem::is_regular_file(inputs.case_path, error))
      throw InputError(first.string(), "", std::string("holds no ") + kShardCase + " (a shard's folder has one): " +
                                           "give the case first, " + command + " CASE.json SHARD...");
  }
  for (std::size_t k = first_shard; k < positional.size(); ++k) inputs.logs.push_back(shard_log(positional[k]));
  return inputs;
}

/// Refuses a merge's output folder that holds a shard's log: committing there would
/// replace that shard's files (OutputDir drops what the previous run wrote), the log included.
void refuse_output_in_shard(const MergeInputs& inputs, const std::string& dir) {
  std::error_code error;
  const auto out_dir = std::filesystem::weakly_canonical(dir, error);
  for (const auto& log : inputs.logs) {
    if (!out_dir.empty() && std::filesystem::weakly_canonical(log, error).parent_path() == out_dir)
      throw InputError("-o", "", "'" + dir + "' holds the shard file " + log.string() +
                                     ": merge into another folder (the merge would replace the shard's files)");
  }
}

std::string merge_source(const ParsedArgs& args, const MergeInputs& inputs, const std::string& allowed) {
  const std::string source = args.optional_text("--source").value_or(shard_log_source(inputs.logs.front()));
  if (source != "formulas" && source != "dem") throw InputError("--source", "", "'" + source + "': " + allowed);
  return source;
}

/// `pdamp field merge SHARD...`: the shards' logs joined into the field a serial `pdamp
/// field` writes.
int run_field_merge(const ParsedArgs& args, CommandContext&) {
  const auto inputs = merge_inputs(args, "pdamp field merge", kSweepLog);
  const Case c = case_file::load_case(inputs.case_path.string());
  (void)tasks::field_sweep_options(c, "formulas");  // one damper of one layer, refused otherwise
  const std::string source = merge_source(args, inputs, "must be formulas or dem (the source the shards ran)");
  const std::string dir = args.optional_text("-o").value_or(default_dir(c, "_field_" + source));
  refuse_output_in_shard(inputs, dir);
  report::OutputDir files(dir);
  const auto result = tasks::merge_field(c, source, inputs.logs);
  json out = {{"sweep", result.sweep_report}, {"shards", inputs.logs.size()}, {"warnings", result.warnings}};
  return field_outputs(args, c, result, files, out);
}

Rows sensitivity_rows(const tasks::SensitivityResult& r) {
  Rows table = {{"case", r.case_name},
                {"drive", "f = " + format_number(r.frequency_hz) + " Hz, X = " + format_number(r.amplitude_m) + " m"},
                {"sweep", r.sweep_report}};
  for (const auto& row : r.rows) {
    std::string line = std::isfinite(row.eta_star) ? format_number(row.eta_star, 4) : std::string("-");
    if (std::isfinite(row.eta_star_stderr)) line += " +- " + format_number(row.eta_star_stderr, 2);
    line += "  " + row.motion_mode;
    if (std::isfinite(row.closed_form_eta_star)) line += "  (closed form " + format_number(row.closed_form_eta_star, 4) + ")";
    table.push_back({row.parameter == "baseline" ? row.parameter : row.parameter + " = " + format_number(row.value, 5), line});
  }
  return table;
}

/// The table, CSV, tornado plot and JSON of a study (a run's, a shard's or a merge's).
int sensitivity_outputs(const ParsedArgs& args, const Case& c, const tasks::SensitivityResult& result,
                        report::OutputDir& files, json extra) {
  std::vector<std::string> warnings = result.warnings;
  json out = tasks::to_json(result);
  out.update(extra);
  out["file"] = (files.dir() / "sensitivity.json").string();
  for (auto& w : report::write_files(files, result)) warnings.push_back(w);
  return finish(args, &files, out, warnings, sensitivity_rows(result), {"sensitivity.json", &c, false, "outputs", true, false});
}

std::string sensitivity_source(const ParsedArgs& args, const std::string& fallback) {
  const std::string source = args.optional_text("--source").value_or(fallback);
  if (source != "formulas" && source != "dem") throw InputError("--source", "", "'" + source + "': must be dem or formulas");
  return source;
}

int run_sensitivity(const ParsedArgs& args, CommandContext& context) {
  const Case c = case_file::load_case(args.positional().at(0));
  tasks::SensitivityOptions options;
  options.source = sensitivity_source(args, "dem");
  if (options.source != "dem") refuse_flags(args, {kAcceptLongRunFlag}, "applies to --source dem (the DEM runs)");
  options.accept_long_runs = args.has("--accept-long-run");
  const std::string dir = args.optional_text("-o").value_or("out/" + report::safe_file_name(c.name) + "_sensitivity");
  std::tie(options.shard_index, options.shard_count) = shard_flag(args);
  options.sharded = args.has("--shard");
  if (options.source == "dem" || options.sharded) options.results_log = std::filesystem::path(dir) / kSensitivityLog;
  const auto plan = tasks::plan_sensitivity(c, options, context.executor);
  const auto files = study_dir(dir, context, options.results_log.empty() ? "" : kSensitivityLog);
  CliHooks hooks;
  const auto result = tasks::run_sensitivity(c, plan, hooks, context.executor);
  json extra = json::object();
  if (!result.mpi.is_null()) extra["mpi"] = result.mpi;
  if (options.sharded) {
    extra["shard"] = args.text("--shard");
    extra["note"] = "a shard's rows are its own variants; the other shards' are missing (join them with pdamp sensitivity merge)";
    std::ifstream in(c.path, std::ios::binary);
    files->add(kShardCase, std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
  }
  return sensitivity_outputs(args, c, result, *files, extra);
}

/// `pdamp sensitivity merge SHARD...`: the shards of one study joined into the table a
/// serial pdamp sensitivity writes.
int run_sensitivity_merge(const ParsedArgs& args, CommandContext&) {
  const auto inputs = merge_inputs(args, "pdamp sensitivity merge", kSensitivityLog);
  const Case c = case_file::load_case(inputs.case_path.string());
  const std::string dir = args.optional_text("-o").value_or("out/" + report::safe_file_name(c.name) + "_sensitivity");
  refuse_output_in_shard(inputs, dir);
  const std::string source = sensitivity_source(args, shard_log_source(inputs.logs.front()));
  (void)tasks::sensitivity_study(c);  // one damper of one layer, refused before the folder
  report::OutputDir files(dir);
  const auto result = tasks::merge_sensitivity(c, source, inputs.logs);
  return sensitivity_outputs(args, c, result, files, {{"shards", inputs.logs.size()}});
}

/// Every check that run, dem and field make on a case, without the work.
int run_validate(const ParsedArgs& args, CommandContext&) {
  const Case c = case_file::load_case(args.positional().at(0));
  CliHooks hooks(60.0, args.has("--accept-long-run"));
  tasks::check_case(c, hooks);
  std::cout << c.resolved.dump(2) << "\n";
  return kExitOk;
}

const FlagSpec kModelOverrides[] = {
    {"--calibration", "C", "design factor c in x_opt = c*x_opt_ideal (default 0.8976 rolling, 1.0 bouncing)"},
    {"--inertia-factor", "K", "rolling spheres' I/(m r^2) (default 0.4, solid spheres)"},
    {"--friction", "MU", "sphere-base friction: auto rolls up to Gamma = MU(1+K)/K (default 0.3)"},
    {"--bed-restitution", "E", "collective restitution e_b of the bed at a wall, [0, 0.9] (default 0: plastic)"}};

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> all = [] {
    std::vector<Command> list = {
      {{"run", "pdamp run CASE.json [--method formulas|field|dem|calibrated] [--dem-points N] [--dem-sweep D] [--no-verify] [--calibration-cache DIR] [--resume] [-o DIR] [--json]",
        "the main job: what the case's `task` asks (damper_design: optimum stroke, clearance\n"
        "for a target stroke, eta* curve over stroke, buffered-wall sizing; modes, frf, decay:\n"
        "as pdamp modes, frf and decay; filling_ratios and placement: as pdamp optimize)",
        concat_flags(concat_flags({kMethodFlag, kNoVerifyFlag, kCalibrationCacheFlag, kOutFlag, kJsonFlag}, kDemSweepFlags),
                     kCheckpointFlags),
        1},
       run_run, true},
      {{"optimum", "pdamp optimum --model rolling|bouncing --clearance M [--json]",
        "optimal container stroke for a clearance: design value, ideal peak and onset",
        {{"--model", "MODEL", "rolling (low intensity, A < g) or bouncing (high intensity)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"}, kModelOverrides[0], kModelOverrides[1], kModelOverrides[2],
         kModelOverrides[3], kJsonFlag}},
       run_optimum},
      {{"size", "pdamp size --model rolling|bouncing --stroke M [--json]",
        "clearance h whose design stroke equals the target stroke (inverse of optimum)",
        {{"--model", "MODEL", "rolling or bouncing"}, {"--stroke", "M", "target container stroke X, m (> 0)"},
         kModelOverrides[0], kModelOverrides[1], kModelOverrides[2], kModelOverrides[3], kJsonFlag}},
       run_size},
      {{"loss", "pdamp loss --model M --clearance M --amplitude M --frequency HZ [--bed-mass KG] [-o DIR] [--json]",
        "closed-form reduced loss factor eta* at one operating point (with -o: eta* over stroke)",
        {{"--model", "MODEL", "rolling | bouncing | scattered | auto | coulomb_block (auto: Gamma < 1 rolling,\n"
                              "                          else bouncing; below the onset the scattered fit;\n"
                              "                          coulomb_block: a nested bed on its base, friction --friction)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"},
         {"--amplitude", "M", "container stroke X, m (> 0)"},
         {"--frequency", "HZ", "drive frequency f, Hz (> 0)"},
         {"--bed-mass", "KG", "bed mass for e_diss_j and energy_per_cycle_j, kg (default 1)"},
         {"--scattered-fit", "FILE", "fitted scattered-state coefficients (scattered_fit.json of\n"
                                     "                          pdamp field --source dem); default: provisional"},
         {"--below-onset", "LAW",
          "scattered_fit (default), impact_map (the plastic block's map) or rolling_tail (a rolling bed come down "
          "from collect-and-collide)"},
         kModelOverrides[0], kModelOverrides[1], kModelOverrides[2], kModelOverrides[3], kOutFlag, kJsonFlag}},
       run_loss},
      {{"buffer",
        "pdamp buffer --frequency HZ (--amplitude M | --intensity G) --radius M --layer-modulus PA [options] [--json]",
        "sizing of a buffered (polymer-coated) wall: the layer thickness whose tip strain under the\n"
        "design impact is the allowable strain (docs/theory.md section 5)",
        {{"--frequency", "HZ", "design frequency, Hz (> 0)"},
         {"--amplitude", "M", "design stroke X, m (> 0); or give --intensity"},
         {"--intensity", "G", "design intensity Gamma = X Omega^2/g (> 0)"},
         {"--radius", "M", "particle radius, m (> 0)"},
         {"--particle-density", "KG_M3", "particle density, kg/m^3 (default 7850, steel)"},
         {"--particle-modulus", "PA", "particle Young's modulus, Pa (default 210e9, steel)"},
         {"--particle-poisson", "NU", "particle Poisson ratio (default 0.3)"},
         {"--layer-modulus", "PA", "layer Young's modulus at the design frequency and temperature, Pa"},
         {"--layer-poisson", "NU", "layer Poisson ratio, [0, 0.5] (default 0.48, polyurethane; 0.5 incompressible)"},
         {"--layer-model", "LAW", "layered (default: sphere on a layer bonded to the wall, exact for any\n"
                                  "                          contact radius/thickness) or half_space (the source study's Hertz rule)"},
         {"--allowable-strain", "EPS", "allowable tip strain delta_max/t of the layer, (0, 1] (default 0.3,\n"
                                       "                          polyurethane; 1: the design impact compresses it fully)"},
         {"--particles-per-contact", "N", "particles whose momentum drives one contact (default 1)"},
         {"--impact-velocity", "M_S", "impact speed, m/s (default 2*X*Omega, the bouncing optimum)"},
         kJsonFlag}},
       run_buffer},
      {{"dem", "pdamp dem CASE.json [--amplitude M] [--frequency HZ] [--snapshots N] [--resume] [-o DIR] [--json]",
        "reference DEM of the case's damper under harmonic motion x = X sin(2 pi f t): eta*,\n"
        "its standard error, apparent mass, energy balance, motion mode (docs/dem.md)",
        concat_flags({{"--amplitude", "M", "stroke X, m (default: the case's excitation.amplitude_m)"},
                      {"--frequency", "HZ", "frequency f, Hz (default: the case's excitation.frequency_hz)"},
                      {"--periods", "N", "analysed periods (default: the case's dem.analysed_periods)"},
                      {"--threads", "N", "OpenMP threads, 0 = all (default: the case's dem.threads)"},
                      {"--snapshots", "N", "particle snapshots for ParaView, evenly over the analysed periods\n"
                                           "                          (default: the case's dem.snapshots)"},
                      {"-o", "DIR", "write summary.json, time_series.csv, particles.pvd with particles_*.vtp\n"
                                    "                          (ParaView: VTK XML, docs/dem.md) and\n"
                                    "                          force_velocity.png/.svg into DIR, atomically (and\n"
                                    "                          dem.checkpoint while the run lasts: --resume)"},
                      kJsonFlag},
                     kCheckpointFlags), 1},
       run_dem, true},
      {{"field", "pdamp field CASE.json --source formulas|dem|measured [--measured FILE] [-o DIR] [--json]",
        "effective field: eta*, E_diss, apparent mass and motion mode over the case's grid\n"
        "(frequency x amplitude or intensity x X/h); DEM sweeps resume where they stopped",
        {{"--source", "SRC", "formulas (closed forms, microseconds) or dem (one DEM run per point,\n"
                             "                          field.threads at once, saved as each finishes) or\n"
                             "                          measured (a test-rig CSV, see --measured)"},
         {"--measured", "FILE", "CSV with columns frequency_hz, amplitude_m, eta_star [, eta_star_stderr,\n"
                                "                          apparent_mass_kg, motion_mode] on a full grid"},
         {"--shard", "I/N", "compute only shard I of N (grid nodes k with k % N == I), for job\n"
                            "                          arrays; writes field_sweep.jsonl and shard.json, no field:\n"
                            "                          join the N shards with pdamp field merge"},
         {"-o", "DIR", "output folder (default out/<case name>_field_<source>): field.json,\n"
                       "                          field_table.csv, heat map and cuts (PNG, SVG); dem: also\n"
                       "                          field_sweep.jsonl (resume) and scattered_fit.json"},
         kAcceptLongRunFlag, kJsonFlag}, 1},
       run_field, true},
      {{"sensitivity", "pdamp sensitivity CASE.json [--source dem|formulas] [--shard I/N] [-o DIR] [--json]",
        "eta* and the motion mode of the damper with one parameter changed at a time (friction,\n"
        "restitution, rolling friction, particle radius and count, Young's modulus, tilt about\n"
        "each container axis), the case's `sensitivity` values or defaults; a tornado plot",
        {{"--source", "SRC", "dem (default: one DEM run per variant, sensitivity.threads at once,\n"
                             "                          saved as each finishes, resumed after a kill) or formulas"},
         {"--shard", "I/N", "run only the variants k with k % N == I (job arrays)"},
         {"-o", "DIR", "output folder (default out/<case name>_sensitivity): sensitivity.json,\n"
                       "                          sensitivity.csv, sensitivity_tornado.csv, sensitivity.png/svg,\n"
                       "                          sensitivity_sweep.jsonl (resume)"},
         kAcceptLongRunFlag, kJsonFlag}, 1},
       run_sensitivity, true},
      {{"field merge", "pdamp field merge SHARD_DIR... [-o DIR] [--json]  (or CASE.json [--source SRC] SHARD...)",
        "join the shards of one pdamp field --shard I/N sweep into its field (the same\n"
        "values as one serial run); refuses shards of another case, model version or grid.\n"
        "SHARD: a shard's folder or its field_sweep.jsonl; the case is the first folder's\n"
        "shard_case.json (the case the shard ran) unless given first",
        {{"--source", "SRC", "formulas or dem: the source the shards ran (default: the first shard log's)"},
         {"-o", "DIR", "output folder (default out/<case name>_field_<source>), not a shard's:\n"
                       "                          the outputs of pdamp field (field.json, pictures, ...)"},
         kJsonFlag}, 1, true},
       run_field_merge},
      {{"sensitivity merge", "pdamp sensitivity merge SHARD_DIR... [-o DIR] [--json]  (or CASE.json [--source SRC] SHARD...)",
        "join the shards of one pdamp sensitivity --shard I/N study into its table and tornado\n"
        "plot (the same values as one serial run); refuses shards of another case, model\n"
        "version or list of variants. SHARD: a shard's folder or its sensitivity_sweep.jsonl",
        {{"--source", "SRC", "formulas or dem: the source the shards ran (default: the first shard log's)"},
         {"-o", "DIR", "output folder (default out/<case name>_sensitivity), not a shard's"},
         kJsonFlag}, 1, true},
       run_sensitivity_merge},
      {{"export liggghts", "pdamp export liggghts CASE.json -o DIR [--amplitude M] [--frequency HZ] [--periods N] [--json]",
        "write a LIGGGHTS-PUBLIC 3.8 input deck that runs the case's damper as pdamp dem does (the\n"
        "bed at pdamp's initial positions, materials, Hertz-Mindlin contacts, time step, settling,\n"
        "x = X sin(2 pi f t)), for a domain-decomposed run on a cluster (docs/liggghts.md);\n"
        "pdamp does not start LIGGGHTS: DIR/README.txt says how",
        {{"--amplitude", "M", "stroke X, m (default: the case's excitation.amplitude_m)"},
         {"--frequency", "HZ", "frequency f, Hz (default: the case's excitation.frequency_hz)"},
         {"--periods", "N", "analysed periods (default: the case's dem.analysed_periods)"},
         {"-o", "DIR", "the deck's folder (required): in.pdamp, particles.data, container.stl,\n"
                       "                          README.txt, pdamp_export.json; LIGGGHTS writes force.txt and\n"
                       "                          energy.txt there"},
         kJsonFlag}, 1},
       run_export_liggghts},
      {{"import liggghts", "pdamp import liggghts DIR [-o OUT] [--json]",
        "pdamp dem's measures (eta*, its standard error over the periods, apparent mass,\n"
        "E_diss, the container's work) from a LIGGGHTS run of the deck pdamp export liggghts\n"
        "wrote into DIR, computed with pdamp dem's own drive-bin measure (docs/liggghts.md)",
        {{"-o", "OUT", "write summary.json (the --json object) into OUT, atomically"}, kJsonFlag}, 1},
       run_import_liggghts},
      {{"validate", "pdamp validate CASE.json",
        "check a case file and print it as JSON with every default resolved and the derived\n"
        "bed clearance, extent and mass",
        {kAcceptLongRunFlag, kJsonFlag}, 1},
       run_validate},
    };
    // Level III after the damper commands, before validate.
    auto structure = structure_commands();
    list.insert(list.end() - 1, structure.begin(), structure.end());
    // Every command that writes a folder takes --overwrite (report::OutputDir's owner check).
    for (auto& command : list)
      if (std::any_of(command.spec.flags.begin(), command.spec.flags.end(), [](const FlagSpec& f) { return f.name == "-o"; }))
        command.spec.flags.push_back(kOverwriteFlag);
    return list;
  }();
  return all;
}

}  // namespace pdamp::cli
