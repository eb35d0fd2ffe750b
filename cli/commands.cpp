// Subcommands: parse flags, call the libraries, print a table or one JSON object.
#include "commands.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <regex>
#include <mutex>
#include <sstream>

#include <nlohmann/json.hpp>

#include "distributed.hpp"
#include "errors.hpp"
#include "limits.hpp"
#include "output.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/strict_json/input_file.hpp"
#include "optimize_command.hpp"
#include "output.hpp"
#include "output.hpp"
#include "output.hpp"
#include "structure_commands.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/dem_reference/result_files.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "pdamp/surrogate/dem_evaluator.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/measured_import.hpp"
#include "pdamp/surrogate/scattered_fit.hpp"
#include "pdamp/surrogate/sweep.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace fm = formulas;
using case_file::Case;

/// The one damper of one layer that the closed-form and DEM commands take (a format-1
/// case, or a format-2 case with one damper of one layer).
struct SingleDamper {
  const case_file::DamperSpec& damper;
  const case_file::LayerSpec& layer;
};

SingleDamper single_damper(const Case& c, const std::string& command) {
  if (c.dampers.size() != 1 || c.dampers.front().layers.size() != 1)
    throw InputError(c.path, "/dampers",
                     command + " takes one damper of one layer (the case has " + std::to_string(c.dampers.size()) +
                         " dampers, the first with " + std::to_string(c.dampers.front().layers.size()) + " layers)");
  return {c.dampers.front(), c.dampers.front().layers.front()};
}

const FlagSpec kJsonFlag{"--json", "", "print exactly one JSON object on stdout"};
const FlagSpec kOutFlag{"-o", "DIR", "write result files (JSON, CSV, plots) into DIR, atomically"};

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
  if (const auto file = args.optional_text("--scattered-fit")) {
    try {
      options.scattered = surrogate::read_scattered_fit(*file).fit;
    } catch (const std::invalid_argument& e) {
      throw InputError("--scattered-fit", "", e.what());
    }
  }
  return options;
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << "pdamp: warning: " << w << "\n";
}

/// The JSON pointer of the first number in `value` that is not finite, if any.
std::optional<std::string> non_finite_number(const json& value, const std::string& at = "") {
  if (value.is_number_float() && !std::isfinite(value.get<double>())) return at.empty() ? "/" : at;
  if (value.is_object() || value.is_array()) {
    std::size_t i = 0;
    for (auto it = value.begin(); it != value.end(); ++it, ++i)
      if (auto bad = non_finite_number(*it, at + "/" + (value.is_object() ? it.key() : std::to_string(i)))) return bad;
  }
  return std::nullopt;
}

/// Prints the result: the JSON object with --json, else the readable table. A
/// closed-form result that is not finite (a formula at the edge of its range) is a
/// numerical failure, never printed as null or inf; a measured result (the DEM's) may
/// hold an undefined statistic, e.g. the standard error of one period (null).
int emit(const ParsedArgs& args, const json& result, const std::vector<std::pair<std::string, std::string>>& rows,
         bool closed_form = true) {
  if (const auto bad = closed_form ? non_finite_number(result) : std::nullopt)
    throw NumericalError("the result " + *bad + " is not finite: the inputs lie where the model cannot be evaluated");
  if (args.has("--json")) std::cout << result.dump(2) << "\n";
  else std::cout << key_value_table(rows);
  return kExitOk;
}

/// The -o directory, checked before any work (OutputDir), or none.
std::unique_ptr<OutputDir> output_dir(const ParsedArgs& args) {
  if (const auto dir = args.optional_text("-o")) return std::make_unique<OutputDir>(*dir);
  return nullptr;
}

json optimum_json(const fm::OptimumStroke& o) {
  return {{"model", fm::to_string(o.model)},          {"clearance_m", o.clearance_m},
          {"x_opt_m", o.x_opt_m},                     {"x_opt_ideal_m", o.x_opt_ideal_m},
          {"x_onset_m", o.x_onset_m},                 {"calibration_factor", o.calibration_factor},
          {"eta_star_peak", o.eta_star_peak},         {"eta_star_onset", o.eta_star_onset}};
}

std::vector<std::pair<std::string, std::string>> optimum_rows(const fm::OptimumStroke& o) {
  return {{"model", std::string(fm::to_string(o.model))},
          {"clearance_m", format_number(o.clearance_m)},
          {"x_opt_m (design)", format_number(o.x_opt_m) + "  (= " + format_number(o.x_opt_m / o.clearance_m, 4) + " h)"},
          {"x_opt_ideal_m (peak)", format_number(o.x_opt_ideal_m) + "  (eta* = " + format_number(o.eta_star_peak, 4) + ")"},
          {"x_onset_m (cliff)", format_number(o.x_onset_m) + "  (eta* = " + format_number(o.eta_star_onset, 4) + ")"}};
}

// ---------------------------------------------------------------- eta*(X) curve

std::vector<CurvePoint> eta_curve(fm::DamperModel model, double clearance_m, double frequency_hz,
                                  const fm::ModelOptions& options, double x_min, double x_max, int points) {
  std::vector<CurvePoint> curve;
  curve.reserve(points);
  for (int i = 0; i < points; ++i) {
    const double x = x_min + (x_max - x_min) * i / (points - 1);
    curve.push_back({x, fm::reduced_loss_factor(model, clearance_m, x, frequency_hz, options)});
  }
  return curve;
}

json loss_json(const fm::LossResult& loss, double bed_mass_kg, double frequency_hz) {
  const double e_diss = fm::dissipated_energy_measure(loss.eta_star, bed_mass_kg, loss.velocity_amplitude_m_s);
  return {{"model", fm::to_string(loss.model_requested)},
          {"model_used", fm::to_string(loss.model_used)},
          {"eta_star", loss.eta_star},
          {"e_diss_j", e_diss},
          {"energy_per_cycle_j", fm::energy_per_cycle(e_diss)},
          {"equivalent_damping_n_s_m", loss.eta_star * bed_mass_kg * 2.0 * fm::kPi * frequency_hz},
          {"regime", fm::to_string(loss.regime)},
          {"inertia_factor", loss.inertia_factor},
          {"intensity", loss.intensity},
          {"stroke_over_onset", loss.stroke_over_onset},
          {"velocity_amplitude_m_s", loss.velocity_amplitude_m_s},
          {"bed_mass_kg", bed_mass_kg},
          {"warnings", loss.warnings}};
}

// ---------------------------------------------------------------- commands

int run_optimum(const ParsedArgs& args) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double h = args.number("--clearance", limits::kClearance);
  const auto result = fm::optimum_stroke(model, h, model_options(args, model));
  json out = optimum_json(result);
  out["warnings"] = json::array();
  return emit(args, out, optimum_rows(result));
}

int run_size(const ParsedArgs& args) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double stroke = args.number("--stroke", limits::kStroke);
  const auto options = model_options(args, model);
  const double h = fm::clearance_for_stroke(model, stroke, options);
  const auto check = fm::optimum_stroke(model, h, options);
  json out = {{"model", fm::to_string(model)}, {"stroke_m", stroke}, {"clearance_m", h},
              {"x_opt_ideal_m", check.x_opt_ideal_m}, {"x_onset_m", check.x_onset_m}, {"warnings", json::array()}};
  return emit(args, out, {{"model", std::string(fm::to_string(model))},
                          {"stroke_m", format_number(stroke)},
                          {"clearance_m", format_number(h)},
                          {"x_onset_m", format_number(check.x_onset_m) + "  (strokes below fall off the cliff)"}});
}

int run_loss(const ParsedArgs& args) {
  const auto model = model_flag(args, {"rolling", "bouncing", "scattered", "auto"});
  const double h = args.number("--clearance", limits::kClearance);
  const double x = args.number("--amplitude", limits::kStroke);
  const double f = args.number("--frequency", limits::kFrequency);
  const double bed_mass = args.optional_number("--bed-mass", limits::kMass).value_or(1.0);
  const auto options = model_options(args, model);
  auto files = output_dir(args);
  const auto loss = fm::reduced_loss_factor(model, h, x, f, options);
  json out = loss_json(loss, bed_mass, f);
  out.update({{"clearance_m", h}, {"amplitude_m", x}, {"frequency_hz", f}});
  std::vector<std::string> warnings = loss.warnings;
  // eta* needs no mass, the energies do: say which mass they are for.
  if (!args.has("--bed-mass"))
    warnings.push_back("no --bed-mass given: e_diss_j, energy_per_cycle_j and equivalent_damping_n_s_m are for a 1 kg bed "
                       "(they scale with the bed mass; eta* does not)");
  if (files) {
    const auto family = loss.model_used;
    const auto landmarks = fm::optimum_stroke(family, h, options);
    const double x_max = std::max(1.5 * h, 1.2 * x);
    const auto curve = eta_curve(model, h, f, options, 0.02 * h, x_max, 301);
    for (auto& w : write_eta_curve(*files, curve, landmarks, f, "pdamp loss --model " + std::string(fm::to_string(model))))
      warnings.push_back(w);
    out["warnings"] = warnings;
    files->add_json("loss.json", out);
    out["files"] = files->commit();
  }
  out["warnings"] = warnings;
  print_warnings(warnings);
  return emit(args, out, {{"model_used", std::string(fm::to_string(loss.model_used))},
                          {"regime", std::string(fm::to_string(loss.regime))},
                          {"eta_star", format_number(loss.eta_star)},
                          {"e_diss_j", format_number(out["e_diss_j"].get<double>())},
                          {"energy_per_cycle_j", format_number(out["energy_per_cycle_j"].get<double>())},
                          {"intensity", format_number(loss.intensity, 4)}});
}

json buffer_json(const fm::BufferDesign& b) {
  return {{"model", b.model == fm::BufferModel::kLayered ? "layered" : "half_space"},
          {"layer_thickness_m", b.layer_thickness_m},   {"impact_velocity_m_s", b.impact_velocity_m_s},
          {"max_penetration_m", b.max_penetration_m},   {"contact_time_s", b.contact_time_s},
          {"contact_time_over_period", b.contact_time_over_period},
          {"effective_mass_kg", b.effective_mass_kg},   {"max_force_n", b.max_force_n},
          {"contact_radius_m", b.contact_radius_m},
          {"contact_radius_over_thickness", b.contact_radius_over_thickness},
          {"half_space_thickness_m", b.half_space_thickness_m},
          {"layered_compression_of_half_space_design", b.layered_compression_of_half_space_design},
          {"assumptions", b.assumptions},
          {"warnings", b.warnings}};
}

int run_buffer(const ParsedArgs& args) {
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
  in.particles_per_contact = args.optional_number("--particles-per-contact", Range{1.0, 1e9}).value_or(1.0);
  in.impact_velocity_m_s = args.optional_number("--impact-velocity", limits::kImpactSpeed).value_or(0.0);
  const auto problems = in.validate();
  if (!problems.empty()) throw InputError("pdamp buffer", "", problems.front());
  const auto design = fm::size_buffer_layer(in);
  print_warnings(design.warnings);
  return emit(args, buffer_json(design),
              {{"model", std::string(design.model == fm::BufferModel::kLayered ? "layered" : "half_space")},
               {"layer_thickness_m", format_number(design.layer_thickness_m)},
               {"contact_radius/thickness", format_number(design.contact_radius_over_thickness, 3)},
               {"half-space thickness", format_number(design.half_space_thickness_m) + "  (compressed to " +
                                            format_number(design.layered_compression_of_half_space_design, 3) +
                                            " of it by the design impact)"},
               {"impact_velocity_m_s", format_number(design.impact_velocity_m_s)},
               {"max_penetration_m", format_number(design.max_penetration_m)},
               {"contact_time_s", format_number(design.contact_time_s)},
               {"contact_time/period", format_number(design.contact_time_over_period, 4)},
               {"max_force_n", format_number(design.max_force_n)}});
}


/// `auto` in a design: rolling when the base friction keeps the spheres rolling at its
/// design stroke (Γ <= Γ_slip, formulas::slip_intensity), else bouncing.
fm::DamperModel design_family(const SingleDamper& single, const Case& c) {
  if (single.damper.model != fm::DamperModel::kAuto) return single.damper.model;
  const auto& options = single.damper.model_options;
  if (!options.gravity_across_drive) return fm::DamperModel::kBouncing;
  const auto rolling = fm::optimum_stroke(fm::DamperModel::kRolling, single.layer.clearance_m, options);
  const double omega = 2.0 * fm::kPi * c.excitation.frequency_hz;
  return rolling.x_opt_m * omega * omega / fm::kStandardGravity <= fm::slip_intensity(options) ? fm::DamperModel::kRolling
                                                                                                : fm::DamperModel::kBouncing;
}

/// The damper_design task's numbers (no files): what `pdamp run` prints and writes.
struct DamperDesign {
  json result;
  std::vector<std::string> warnings;
  fm::OptimumStroke optimum;
  double eta_star_at_design = 0.0;
  std::vector<CurvePoint> curve;
};

/// Computes the damper_design task. A closed form that refuses the case's numbers
/// (std::invalid_argument) is bad input of that case file; a result that is not finite
/// is refused as well, so `pdamp validate` catches whatever `pdamp run` would.
DamperDesign damper_design(const Case& c) {
  DamperDesign out;
  const SingleDamper single = single_damper(c, "the damper_design task");
  try {
    const auto& d = single.damper;
    const auto& layer = single.layer;
    const auto family = design_family(single, c);
    const double f = c.excitation.frequency_hz;
    out.optimum = fm::optimum_stroke(family, layer.clearance_m, d.model_options);
    json& result = out.result;
    result = {{"task", case_file::to_string(c.task.kind)}, {"case", c.name}, {"model", fm::to_string(family)},
              {"clearance_m", layer.clearance_m}, {"bed_mass_kg", layer.bed_mass_kg}, {"optimum", optimum_json(out.optimum)}};
    auto& warnings = out.warnings;
    warnings = case_file::settled_bed_warnings(c);
    const auto design_point = fm::reduced_loss_factor(family, layer.clearance_m, out.optimum.x_opt_m, f, d.model_options);
    out.eta_star_at_design = design_point.eta_star;
    result["optimum"]["eta_star_at_design"] = design_point.eta_star;
    result["optimum"]["intensity_at_design"] = design_point.intensity;
    warnings.insert(warnings.end(), design_point.warnings.begin(), design_point.warnings.end());
    if (c.design.target_stroke_m) {
      const double h = fm::clearance_for_stroke(family, *c.design.target_stroke_m, d.model_options);
      result["sizing"] = {{"target_stroke_m", *c.design.target_stroke_m},
                          {"clearance_m", h},
                          {"container_inner_length_along_drive_m", layer.bed.bed_extent_m + h}};
    }
    if (c.excitation.amplitude_m) {
      const auto op = fm::reduced_loss_factor(d.model, layer.clearance_m, *c.excitation.amplitude_m, f, d.model_options);
      result["operating_point"] = loss_json(op, layer.bed_mass_kg, f);
      result["operating_point"]["amplitude_m"] = *c.excitation.amplitude_m;
      warnings.insert(warnings.end(), op.warnings.begin(), op.warnings.end());
    }
    if (c.buffer) {
      const auto design = fm::size_buffer_layer(c.buffer->input);
      result["buffer"] = buffer_json(design);
      result["buffer"]["layer_material"] = c.buffer->layer_material;
      warnings.insert(warnings.end(), design.warnings.begin(), design.warnings.end());
    }
    out.curve = eta_curve(d.model == fm::DamperModel::kAuto ? fm::DamperModel::kAuto : family, layer.clearance_m, f,
                          d.model_options, c.design.sweep_min_over_clearance * layer.clearance_m,
                          c.design.sweep_max_over_clearance * layer.clearance_m, c.design.sweep_points);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "", std::string("the closed forms refuse this case: ") + e.what());
  }
  if (const auto bad = non_finite_number(out.result))
    throw InputError(c.path, "", "the design result " + *bad + " is not finite: the case lies outside the closed forms");
  return out;
}

int run_damper_design(const ParsedArgs& args, const Case& c) {
  auto files = output_dir(args);
  DamperDesign design = damper_design(c);
  json& result = design.result;
  auto& warnings = design.warnings;
  json outputs = json::array();
  if (files) {
    for (auto& w : write_eta_curve(*files, design.curve, design.optimum, c.excitation.frequency_hz, c.name))
      warnings.push_back(w);
    files->add_json("case_resolved.json", c.resolved);
    result["warnings"] = warnings;
    files->add_json("design.json", result);
    stage_run_report(*files, c, result, warnings);
    outputs = files->commit();
  }
  result["warnings"] = warnings;
  result["outputs"] = outputs;
  print_warnings(warnings);
  auto rows = optimum_rows(design.optimum);
  rows.insert(rows.begin(), {"case", c.name});
  rows.push_back({"eta* at design", format_number(design.eta_star_at_design, 4)});
  if (result.contains("operating_point"))
    rows.push_back({"eta* at operating X", format_number(result["operating_point"]["eta_star"].get<double>(), 4) + "  (X = " +
                                               format_number(*c.excitation.amplitude_m) + " m, " +
                                               result["operating_point"]["regime"].get<std::string>() + ")"});
  if (result.contains("sizing"))
    rows.push_back({"clearance for target", format_number(result["sizing"]["clearance_m"].get<double>())});
  if (result.contains("buffer"))
    rows.push_back({"buffer layer_thickness_m", format_number(result["buffer"]["layer_thickness_m"].get<double>())});
  for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
  return emit(args, result, rows);
}

int run_run(const ParsedArgs& args) {
  const Case c = case_file::load_case(args.positional().at(0));
  // Under mpirun the DEM parts of frf and filling_ratios tasks are spread over the ranks
  // (distributed.hpp); every other task runs on rank 0 alone.
  if (distributed::worker() && c.task.kind != case_file::TaskKind::kFrf &&
      c.task.kind != case_file::TaskKind::kFillingRatios)
    return kExitOk;
  const RunReportScope report;  // with -o DIR, the task also stages DIR/report.html
  if (c.task.kind == case_file::TaskKind::kDamperDesign) {
    if (args.has("--method"))
      throw InputError("--method", "", "applies to the structure tasks (modes, frf, decay); this case's task is damper_design");
    return run_damper_design(args, c);
  }
  if (c.task.kind == case_file::TaskKind::kFillingRatios || c.task.kind == case_file::TaskKind::kPlacement)
    return run_optimize_task(args, c);
  // modes, frf, decay: exactly as pdamp modes, frf and decay (structure_commands.cpp).
  return run_structure_task(args, c);
}

/// One progress line on stderr: rewritten in place on a terminal, else a line every 10 s.
class ProgressLine {
 public:
  explicit ProgressLine(std::string label) : label_(std::move(label)), tty_(::isatty(STDERR_FILENO) == 1) {}
  ~ProgressLine() {
    if (tty_ && printed_) std::cerr << "\n";
  }
  void operator()(const dem_reference::Progress& p) {
    const auto now = std::chrono::steady_clock::now();
    if (!tty_ && printed_ && now - last_ < std::chrono::seconds(10)) return;
    last_ = now;
    printed_ = true;
    char line[200];
    const std::string eta = std::isfinite(p.eta_s) ? std::to_string(static_cast<long long>(p.eta_s)) + " s" : "?";
    if (p.stage == "setup")  // before the first step: no rate yet
      std::snprintf(line, sizeof line, "%s: setup     building the bed and its contact lists, ETA %s", label_.c_str(),
                    eta.c_str());
    else
      std::snprintf(line, sizeof line, "%s: %-9s t = %7.3f / %.3f s  %6.2f M steps/s  ETA %s", label_.c_str(),
                    std::string(p.stage).c_str(), p.simulated_time_s, p.end_time_s, p.steps_per_s * 1e-6, eta.c_str());
    std::cerr << (tty_ ? "\r" : "") << line << (tty_ ? "" : "\n") << std::flush;
  }

 private:
  std::string label_;
  bool tty_;
  bool printed_ = false;
  std::chrono::steady_clock::time_point last_;
};

json dem_json(const dem_reference::DamperResult& r) {
  const auto& e = r.energy;
  const auto& m = r.indicators;
  return {{"eta_star", r.eta_star},
          {"eta_star_stderr", r.eta_star_stderr},
          {"eta_star_energy_balance", r.eta_star_energy_balance},
          {"e_diss_j", r.e_diss_j},
          {"energy_per_cycle_j", r.energy_per_cycle_j},
          {"apparent_mass_kg", r.apparent_mass_kg},
          {"apparent_mass_fraction", r.apparent_mass_kg / r.bed_mass_kg},
          {"energy_balance_error", r.energy_balance_error},
          {"particle_steps_per_s", r.particle_steps_per_s},
          {"motion_mode", dem_reference::to_string(r.motion_mode)},
          {"clearance_m", r.clearance_m},
          {"bed_mass_kg", r.bed_mass_kg},
          {"intensity", r.intensity},
          {"velocity_amplitude_m_s", r.velocity_amplitude_m_s},
          {"time_step_s", r.time_step_s},
          {"steps_per_period", r.steps_per_period},
          {"eta_star_per_period", r.eta_star_per_period},
          {"energy",
           {{"container_work_j", e.container_work_j}, {"normal_damping_j", e.normal_damping_j},
            {"friction_j", e.friction_j}, {"rolling_j", e.rolling_j}, {"delta_kinetic_j", e.delta_kinetic_j},
            {"delta_potential_j", e.delta_potential_j}, {"delta_elastic_j", e.delta_elastic_j}}},
          {"motion_indicators",
           {{"relative_stroke_over_clearance", m.relative_stroke_over_clearance},
            {"period_correlation", m.period_correlation}, {"eta_star_variation", m.eta_star_variation},
            {"apparent_mass_fraction", m.apparent_mass_fraction}, {"base_contact_fraction", m.base_contact_fraction},
            {"airborne_fraction", m.airborne_fraction}, {"spread_over_packed", m.spread_over_packed},
            {"phase_locked_stroke", m.phase_locked_stroke}, {"phase_coherence", m.phase_coherence},
            {"phase_lag_deg", m.phase_lag_deg}, {"crossing_fraction", m.crossing_fraction},
            {"settled_base_contact_fraction", m.settled_base_contact_fraction}, {"mobile_fraction", m.mobile_fraction}}},
          {"run",
           {{"outcome", dem_reference::to_string(r.summary.outcome)}, {"steps", r.summary.steps},
            {"particles", r.summary.particles}, {"wall_time_s", r.summary.wall_time_s},
            {"neighbour_rebuilds", r.summary.neighbour_rebuilds}}}};
}

/// Memory this process may still use, bytes: MemAvailable of /proc/meminfo, lowered to
/// what a cgroup v2 limit leaves (a container or a batch job's slot). Infinity when
/// neither can be read.
double available_memory_bytes() {
  double available = std::numeric_limits<double>::infinity();
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kib = 0.0;
    meminfo >> kib;
    if (key == "MemAvailable:") available = kib * 1024.0;
    meminfo.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  std::ifstream limit("/sys/fs/cgroup/memory.max"), current("/sys/fs/cgroup/memory.current");
  double max_bytes = 0.0, used = 0.0;
  if (limit >> max_bytes && current >> used) available = std::min(available, max_bytes - used);  // "max": no limit
  return available;
}

std::string megabytes(double bytes) {
  return bytes >= 1e9 ? format_number(bytes / 1e9, 3) + " GB" : format_number(bytes / 1e6, 3) + " MB";
}

/// The DEM would not fit: exit 2 naming the keys that set its memory.
[[noreturn]] void refuse_memory(const Case& c, std::size_t damper, const dem_reference::RunEstimate& e, double runs_at_once,
                                double available) {
  const std::string counts = c.format_version == 1 ? "/damper/particles/count"
                                                   : "/dampers/" + std::to_string(damper) + "/layers/*/particles/count";
  throw InputError(c.path, "/dem",
                   "the DEM needs about " + megabytes(runs_at_once * static_cast<double>(e.memory_bytes)) + " (" +
                       std::to_string(e.particles) + " particles, " + std::to_string(e.recorded_samples) +
                       " recorded samples = samples_per_period x analysed_periods, " + std::to_string(e.snapshots) +
                       " snapshots" + (runs_at_once > 1 ? ", " + format_number(runs_at_once, 3) + " runs at once" : "") +
                       "), more than the " + megabytes(available) +
                       " available: reduce /dem/samples_per_period, /dem/analysed_periods, /dem/snapshots or " + counts);
}

/// A DEM run's options and cost, checked before it starts (issue 8: no job that cannot
/// finish is started silently): every option in range (the case's JSON pointer named),
/// the time step below its bound, the memory within what is available. `damper` is the
/// index of the case's damper the options are of.
dem_reference::RunEstimate check_dem_run(const Case& c, std::size_t damper,
                                         const dem_reference::DamperSimulationOptions& options) {
  const auto problems = options.validate("");
  if (!problems.empty()) throw case_file::dem_case_error(c, damper, problems.front());
  dem_reference::RunEstimate e;
  try {
    e = dem_reference::estimate_run(options);
  } catch (const std::invalid_argument& error) {  // the time step above its bound
    const std::string what = error.what();
    throw case_file::dem_case_error(c, damper, what.substr(0, what.find('\n')));
  }
  const double available = available_memory_bytes();
  if (static_cast<double>(e.memory_bytes) > available) refuse_memory(c, damper, e, 1.0, available);
  return e;
}

/// The DEM's initial bed built as a run would build it (inner structures, wall layers),
/// so a bed that does not fit is refused before any output (and by `pdamp validate`).
void check_dem_placement(const Case& c, std::size_t damper, const dem_reference::DamperSimulationOptions& options) {
  try {
    dem_reference::check_initial_placement(options);
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    throw case_file::dem_case_error(c, damper, what.substr(0, what.find('\n')));
  }
}

/// The DEM's advice names its options ("lower integration.time_step_s"): the user edits
/// the case keys they come from (/dem/time_step_s).
std::string case_key_names(const std::string& advice) {
  static const std::regex kOption(R"(\bintegration\.(\w+))");
  return std::regex_replace(advice, kOption, "/dem/$1");
}

/// The estimate of a DEM run, for stderr before it starts.
std::string estimate_line(const std::string& label, const dem_reference::RunEstimate& e) {
  return label + ": " + std::to_string(e.particles) + " particles, " + std::to_string(e.total_steps) + " steps of " +
         format_number(e.time_step_s, 3) + " s = " + format_number(e.particle_steps, 3) + " particle-steps, about " +
         format_number(e.wall_time_s, 2) + " s at " + format_number(e.particle_steps_per_s, 2) +
         " particle-steps/s; memory about " + megabytes(static_cast<double>(e.memory_bytes));
}

int run_dem(const ParsedArgs& args) {
  const std::string& path = args.positional().at(0);
  const Case c = case_file::load_case(path);
  const SingleDamper single = single_damper(c, "pdamp dem");
  const double f = args.optional_number("--frequency", limits::kFrequency).value_or(c.excitation.frequency_hz);
  const auto amplitude = args.optional_number("--amplitude", limits::kStroke);
  if (!amplitude && !c.excitation.amplitude_m)
    throw InputError(path, "/excitation/amplitude_m", "required by pdamp dem (or give --amplitude M)");
  const double x = amplitude.value_or(c.excitation.amplitude_m.value_or(0.0));
  auto options = case_file::dem_options(c, 0, x, f);
  if (const auto periods = args.optional_integer("--periods", 1, dem_reference::limits::kMaxPeriods)) options.analysed_periods = static_cast<int>(*periods);
  if (const auto threads = args.optional_integer("--threads", 0, dem_reference::limits::kMaxThreads)) options.world.threads = static_cast<int>(*threads);
  const auto estimate = check_dem_run(c, 0, options);
  check_dem_placement(c, 0, options);
  auto files = output_dir(args);

  // Checkpoints in the -o folder at period ends (docs/dem.md "Checkpoints"): every
  // --checkpoint-interval seconds and when a signal arrives (then pdamp ends by it).
  const DemCheckpoint cp = dem_checkpoint(args, "dem", "dem");
  dem_reference::CheckpointHeader header;
  header.kind = cp.kind;
  header.case_hash = case_file::physics_hash(c, "dem");
  header.physics_model_version = dem_reference::kPhysicsModelVersion;
  {
    std::ostringstream settings;
    settings.precision(17);
    settings << "amplitude_m " << x << "; frequency_hz " << f << "; transient_periods " << options.transient_periods
             << "; analysed_periods " << options.analysed_periods << "; samples_per_period " << options.samples_per_period
             << "; snapshots " << options.snapshots << "; threads " << options.world.threads;
    header.settings = settings.str();
  }
  header.end_time_s = (options.transient_periods + options.analysed_periods) / f;
  dem_reference::HarmonicCheckpoints hook;
  auto last_checkpoint = std::chrono::steady_clock::now();
  hook.due = [&] {
    return pending_interrupt() != 0 ||
           std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint).count() >= cp.interval_s;
  };
  hook.stop = [] { return pending_interrupt() != 0; };
  hook.write = [&](const std::string& state, double t) {
    header.simulated_time_s = t;
    write_checkpoint_file(cp, header, state);
    last_checkpoint = std::chrono::steady_clock::now();
  };
  if (cp.resume) hook.resume_state = read_checkpoint_payload(cp, header);  // refused before any output
  std::cerr << estimate_line("pdamp dem", estimate) << std::endl;
  if (cp.resume) {
    std::cerr << "pdamp dem: resuming from " << strict_json::printable(cp.file.string()) << std::endl;
  } else if (!cp.file.empty() && std::filesystem::exists(cp.file)) {
    print_warnings({strict_json::printable(cp.file.string()) + " of an earlier run is replaced (--resume continues it)"});
  }

  ProgressLine progress("pdamp dem");
  dem_reference::DamperResult result;
  {
    const std::optional<DeferredSignals> deferred = cp.file.empty() ? std::nullopt : std::make_optional<DeferredSignals>();
    try {
      result = dem_reference::run_harmonic(options, [&](const dem_reference::Progress& p) { progress(p); },
                                           cp.file.empty() ? nullptr : &hook);
    } catch (const std::invalid_argument& e) {  // e.g. a time step above the stable bound, a resume that does not fit
      throw InputError(cp.resume ? cp.file.string() : path, cp.resume ? "" : "/dem", e.what());
    }
    if (result.stopped) throw Interrupted(pending_interrupt(), checkpoint_advice(cp, header));
  }
  if (!cp.file.empty()) {
    std::error_code ignored;
    std::filesystem::remove(cp.file, ignored);  // complete: the results follow
  }
  if (result.summary.outcome == dem_reference::Outcome::kUnstable)
    throw NumericalError("DEM unstable: " + case_key_names(result.summary.message));
  if (result.summary.outcome != dem_reference::Outcome::kCompleted)  // a step threw (on any thread)
    throw NumericalError("DEM failed: " + case_key_names(result.summary.message));

  json out = dem_json(result);
  out.update({{"case", c.name}, {"amplitude_m", x}, {"frequency_hz", f}});
  // The closed form at the same point, for comparison (same model family as the case).
  const auto closed = fm::reduced_loss_factor(single.damper.model, result.clearance_m, x, f, single.damper.model_options);
  out["closed_form"] = {{"eta_star", closed.eta_star}, {"model_used", fm::to_string(closed.model_used)},
                        {"regime", fm::to_string(closed.regime)}};
  std::vector<std::string> warnings = result.warnings;
  if (files) {
    dem_reference::write_time_series_csv(files->staged_path("time_series.csv").string(), result.series);
    for (std::size_t i = 0; i < result.snapshots.size(); ++i) {
      char name[64];
      std::snprintf(name, sizeof name, "particles_%04zu.vtk", i);
      dem_reference::write_vtk_snapshot(files->staged_path(name).string(), result.snapshots[i]);
    }
    for (auto& w : write_force_velocity_plot(*files, c.name + ": X = " + format_number(x * 1e3, 4) + " mm, f = " +
                                                         format_number(f, 4) + " Hz"))
      warnings.push_back(w);
    out["warnings"] = warnings;
    files->add_json("summary.json", out);
    out["files"] = files->commit();
  }
  out["warnings"] = warnings;
  print_warnings(warnings);
  return emit(args, out,
              {{"case", c.name},
               {"eta_star", format_number(result.eta_star, 4) + " +- " + format_number(result.eta_star_stderr, 2)},
               {"eta_star (closed form)", format_number(closed.eta_star, 4) + "  (" + std::string(fm::to_string(closed.regime)) + ")"},
               {"apparent_mass_kg", format_number(result.apparent_mass_kg, 4) + "  (" +
                                        format_number(result.apparent_mass_kg / result.bed_mass_kg, 3) + " m_bed)"},
               {"e_diss_j", format_number(result.e_diss_j)},
               {"energy_balance_error", format_number(result.energy_balance_error, 3)},
               {"motion_mode", std::string(dem_reference::to_string(result.motion_mode))},
               {"clearance_m", format_number(result.clearance_m)},
               {"particle_steps_per_s", format_number(result.particle_steps_per_s, 3)},
               {"run", result.summary.brief_report()}},
              false);
}

// ---------------------------------------------------------------- effective fields

int write_field_outputs(const ParsedArgs& args, const Case& c, const surrogate::EffectiveField& field,
                        OutputDir& files, json out);

/// A test-rig field from CSV (docs/effective_fields.md) for the case's damper.
int import_measured_field(const ParsedArgs& args, const Case& c, OutputDir& files) {
  const SingleDamper single = single_damper(c, "pdamp field");
  surrogate::MeasuredImportOptions options;
  options.clearance_m = single.layer.clearance_m;
  options.bed_mass_kg = single.layer.bed_mass_kg;
  options.frequency_spacing = c.field.axis0.spacing;
  options.amplitude_spacing = c.field.axis1.spacing;
  options.case_hash = case_file::physics_hash(c, "measured");
  const std::string csv = args.text("--measured");
  surrogate::EffectiveField field;
  try {
    field = surrogate::import_measured_csv(csv, options);
  } catch (const std::invalid_argument& e) {
    throw InputError("--measured", "", e.what());
  }
  return write_field_outputs(args, c, field, files, json::object());
}

/// A DEM field's sweep checked before it starts: every point's run as check_dem_run,
/// the memory of field.threads runs at once. Returns the estimate of the work still
/// to do (the points already in the results file of `sweep` excluded), for stderr.
std::string check_dem_field(const Case& c, std::size_t damper, const surrogate::Grid& grid,
                            const surrogate::SweepOptions* sweep) {
  auto options = case_file::dem_options(c, damper, 1.0, 1.0);
  const double clearance_m = c.dampers.at(damper).layers.front().clearance_m;
  options.world.threads = 1;  // as the sweep runs each point
  // Up to 8 nodes per axis, evenly spread with both ends: the options are monotone in
  // the stroke and the frequency (the impact speed grows with both), so the corners
  // hold the extremes, and the work sums scale with the nodes (an estimate of a
  // million-node grid node by node took minutes).
  const auto sampled = [](std::size_t n) {
    std::vector<std::size_t> picks;
    const std::size_t m = std::min<std::size_t>(n, 8);
    for (std::size_t j = 0; j < m; ++j) picks.push_back(m == 1 ? 0 : j * (n - 1) / (m - 1));
    return picks;
  };
  double wall_time_s = 0.0, particle_steps = 0.0;
  std::size_t evaluated = 0;
  dem_reference::RunEstimate largest;
  for (const std::size_t i0 : sampled(grid.axis0.size())) {
    for (const std::size_t i1 : sampled(grid.axis1.size())) {
      const auto drive = surrogate::drive_point(grid, i0 * grid.axis1.size() + i1, clearance_m);
      options.amplitude_m = drive.amplitude_m;
      options.frequency_hz = drive.frequency_hz;
      const auto e = check_dem_run(c, damper, options);
      if (evaluated++ == 0) check_dem_placement(c, damper, options);  // the same bed at every node
      wall_time_s += e.wall_time_s;
      particle_steps += e.particle_steps;
      if (e.memory_bytes > largest.memory_bytes) largest = e;
    }
  }
  const double per_node = static_cast<double>(grid.size()) / static_cast<double>(evaluated);
  wall_time_s *= per_node;
  particle_steps *= per_node;
  const double at_once = std::min<double>(distributed::ranks() > 1 ? distributed::ranks() : c.field.threads,
                                          static_cast<double>(grid.size()));
  const double available = available_memory_bytes();
  if (at_once * static_cast<double>(largest.memory_bytes) > available) refuse_memory(c, damper, largest, at_once, available);
  std::size_t pending = grid.size();
  try {
    if (sweep != nullptr) pending = surrogate::pending_sweep_points(grid, *sweep);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "/field", e.what());
  }
  const double share = static_cast<double>(pending) / static_cast<double>(grid.size());
  return std::to_string(pending) + " of " + std::to_string(grid.size()) + " points to run, " +
         format_number(share * particle_steps, 3) + " particle-steps, about " +
         format_number(share * wall_time_s / at_once, 2) + " s with " + format_number(at_once, 3) +
         " points at once; memory about " + megabytes(at_once * static_cast<double>(largest.memory_bytes));
}

/// ", spread over N MPI ranks" for a sweep's first line under mpirun, else "".
std::string distributed_note() {
  return distributed::ranks() > 1 ? ", spread over " + std::to_string(distributed::ranks()) + " MPI ranks" : "";
}

/// The DEM sweep's results log, written point by point into the output folder (resume).
constexpr const char* kSweepLog = "field_sweep.jsonl";
/// What a `pdamp field --shard` run writes beside its log (the log is its result).
constexpr const char* kShardSummary = "shard.json";
/// The case file a shard ran, copied into its folder: pdamp field merge DIR... reads it back.
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

/// The sweep identity of the case's field for `source` (formulas or dem): what guards
/// the results log, so run_field and run_field_merge must agree on it.
surrogate::SweepOptions field_sweep_options(const Case& c, const std::string& source) {
  const SingleDamper single = single_damper(c, "pdamp field");
  const bool dem = source == "dem";
  surrogate::SweepOptions sweep;
  sweep.source = dem ? surrogate::FieldSource::kDem : surrogate::FieldSource::kFormulas;
  sweep.case_hash = case_file::physics_hash(c, source);
  sweep.model_version = dem ? surrogate::dem_model_version() : 0;
  sweep.clearance_m = single.layer.clearance_m;
  sweep.bed_mass_kg = single.layer.bed_mass_kg;
  sweep.threads = dem ? c.field.threads : 1;
  return sweep;
}

/// The default output folder of a field: one safe path component under out/, as the
/// case name must not steer it elsewhere ("../x", "/etc/x").
std::string default_field_dir(const Case& c, const std::string& source) {
  const std::string safe = safe_file_name(c.name);
  if (safe != c.name)
    print_warnings({"case name '" + strict_json::printable(c.name) + "' is not a safe folder name: writing to out/" +
                    safe + "_field_" + source});
  return "out/" + safe + "_field_" + source;
}

/// The case file as given, copied into a shard's folder: the merge reads it back (its
/// physics hash is the shards').
void copy_shard_case(OutputDir& files, const Case& c) {
  std::ifstream in(c.path, std::ios::binary);
  files.add(kShardCase, std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()));
}

int run_field(const ParsedArgs& args) {
  const Case c = case_file::load_case(args.positional().at(0));
  const SingleDamper single = single_damper(c, "pdamp field");
  const std::string source = args.text("--source");
  if (source != "formulas" && source != "dem" && source != "measured")
    throw InputError("--source", "", "'" + source + "': must be formulas, dem or measured");
  const bool dem = source == "dem";
  if (source != "measured" && args.has("--measured")) throw InputError("--measured", "", "goes with --source measured");
  if (source == "measured" && args.has("--shard"))
    throw InputError("--shard", "", "goes with --source dem or formulas (a measured field is imported whole)");
  const auto [shard_index, shard_count] = shard_flag(args);
  const bool sharded = args.has("--shard");
  std::string dir;
  if (const auto given = args.optional_text("-o")) {
    dir = *given;
  } else {
    dir = default_field_dir(c, source);
  }
  if (source == "measured") {
    if (distributed::worker()) return kExitOk;  // rank 0 imports it
    OutputDir files(dir);
    return import_measured_field(args, c, files);
  }
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);

  surrogate::SweepOptions sweep = field_sweep_options(c, source);
  sweep.shard_index = shard_index;
  sweep.shard_count = shard_count;
  std::mutex progress_mutex;
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  std::string estimate;
  // A shard's log is its result (pdamp field merge reads it), so a sharded formulas
  // sweep keeps one too; it also makes a rerun of the same shard command resume.
  if (dem || sharded) sweep.results_path = std::filesystem::path(dir) / kSweepLog;
  if (dem) {
    estimate = check_dem_field(c, 0, grid, &sweep);
  } else {
    try {
      (void)surrogate::pending_sweep_points(grid, sweep);  // a stale log: exit 2 before any work
    } catch (const std::invalid_argument& e) {
      throw InputError(c.path, "/field", e.what());
    }
  }
  surrogate::PointEvaluator evaluator;
  if (dem) {
    auto options = case_file::dem_options(c, 0, 1.0, 1.0);
    options.world.threads = 1;  // the sweep runs points in parallel instead
    evaluator = surrogate::dem_evaluator(options);
  } else {
    evaluator = surrogate::formula_evaluator(single.damper.model, single.layer.clearance_m, single.layer.bed_mass_kg,
                                             single.damper.model_options);
  }
  distributed::PointFarm farm([&](const distributed::Request& r) { return evaluator(r[0], r[1]); });
  if (distributed::worker()) {  // every check passed here too: evaluate what rank 0 sends
    farm.serve();
    return kExitOk;
  }
  sweep.threads = farm.threads(sweep.threads);
  OutputDir files(dir);
  if (!sweep.results_path.empty()) files.in_place(kSweepLog);
  if (dem) {
    std::cerr << "pdamp field: " << estimate << (sharded ? " (shard " + args.text("--shard") + ")" : "")
              << distributed_note() << std::endl;
    sweep.progress = [&](std::size_t done, std::size_t total, double eta_s) {
      std::lock_guard lock(progress_mutex);
      std::cerr << (tty ? "\r" : "") << "pdamp field: " << done << "/" << total << " points";
      if (std::isfinite(eta_s)) std::cerr << ", ETA " << static_cast<long>(eta_s) << " s";
      std::cerr << (tty ? "   " : "\n") << std::flush;
    };
  }
  const auto result = surrogate::run_sweep(
      grid, [&](double f, double x) { return farm.evaluate({f, x}); }, sweep);
  if (dem && tty) std::cerr << "\n";

  json out = {{"sweep", result.summary.brief_report()}, {"warnings", result.summary.warnings}};
  if (const json balance = farm.balance(); !balance.is_null()) out["mpi"] = balance;
  if (!sharded) return write_field_outputs(args, c, result.field, files, out);
  // A shard has no field of its own: its log waits for pdamp field merge.
  const std::string shard = std::to_string(shard_index) + "/" + std::to_string(shard_count);
  out.update({{"source", source}, {"shard", shard}, {"points", result.summary.points_total},
              {"points_in_grid", grid.size()}, {"file", (files.dir() / kSweepLog).string()}});
  files.add_json(kShardSummary, out);
  copy_shard_case(files, c);
  out["files"] = files.commit();
  print_warnings(result.summary.warnings);
  std::vector<std::pair<std::string, std::string>> rows = {
      {"source", source}, {"shard", shard}, {"sweep", out["sweep"].get<std::string>()},
      {"next", "pdamp field merge SHARD_DIR... -o DIR (all " + std::to_string(shard_count) + " shards)"}};
  for (const auto& path : out["files"]) rows.push_back({"wrote", path.get<std::string>()});
  return emit(args, out, rows, false);
}

// ---------------------------------------------------------------- sensitivity studies

constexpr const char* kSensitivityLog = "sensitivity_sweep.jsonl";

/// The study's drive: the section's, else the excitation's stroke, else the design stroke.
std::pair<double, double> sensitivity_drive(const Case& c) {
  const SingleDamper single = single_damper(c, "pdamp sensitivity");
  const double f = c.sensitivity ? c.sensitivity->frequency_hz : c.excitation.frequency_hz;
  double x = c.sensitivity ? c.sensitivity->amplitude_m : c.excitation.amplitude_m.value_or(0.0);
  if (!(x > 0.0)) {
    const auto family = single.damper.model == fm::DamperModel::kBouncing ? fm::DamperModel::kBouncing
                                                                           : fm::DamperModel::kRolling;
    x = fm::optimum_stroke(family, single.layer.clearance_m, single.damper.model_options).x_opt_m;
  }
  return {f, x};
}

/// sensitivity.csv and the tornado plot: per parameter the lowest and highest η* of its
/// values, sorted by that range, about the baseline's η*.
std::vector<std::string> write_sensitivity_files(OutputDir& files, const Case& c, const json& rows, double baseline) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "parameter,value,unit,eta_star,eta_star_stderr,delta_eta_star,motion_mode,apparent_mass_fraction,"
         "closed_form_eta_star,clearance_m,bed_mass_kg,status\n";
  const auto num = [](const json& v) { return v.is_number() ? v.get<double>() : NAN; };
  for (const auto& r : rows)
    csv << r["parameter"].get<std::string>() << ',' << num(r["value"]) << ',' << r["unit"].get<std::string>() << ','
        << num(r["eta_star"]) << ',' << num(r["eta_star_stderr"]) << ',' << num(r["delta_eta_star"]) << ','
        << r["motion_mode"].get<std::string>() << ',' << num(r["apparent_mass_fraction"]) << ','
        << num(r["closed_form_eta_star"]) << ',' << num(r["clearance_m"]) << ',' << num(r["bed_mass_kg"]) << ','
        << r["status"].get<std::string>() << '\n';
  files.add("sensitivity.csv", csv.str());

  struct Bar {
    std::string parameter;
    double low = INFINITY, high = -INFINITY, low_value = NAN, high_value = NAN;
  };
  std::vector<Bar> bars;
  for (const auto& r : rows) {
    const std::string name = r["parameter"].get<std::string>();
    if (name == "baseline" || !r["eta_star"].is_number()) continue;
    auto it = std::find_if(bars.begin(), bars.end(), [&](const Bar& b) { return b.parameter == name; });
    if (it == bars.end()) it = bars.insert(bars.end(), Bar{name});
    const double eta = r["eta_star"].get<double>(), value = r["value"].get<double>();
    if (eta < it->low) it->low = eta, it->low_value = value;
    if (eta > it->high) it->high = eta, it->high_value = value;
  }
  std::sort(bars.begin(), bars.end(), [](const Bar& a, const Bar& b) { return a.high - a.low < b.high - b.low; });
  std::ostringstream tornado;
  tornado.precision(10);
  tornado << "parameter,eta_star_low,eta_star_high,value_at_low,value_at_high\n";
  for (const auto& b : bars) tornado << b.parameter << ',' << b.low << ',' << b.high << ',' << b.low_value << ',' << b.high_value << '\n';
  files.add("sensitivity_tornado.csv", tornado.str());
  std::ostringstream gp;
  gp << "# tornado plot of pdamp sensitivity: eta* over each parameter's values; run: gnuplot sensitivity.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(c.name + ": sensitivity of eta* (one parameter at a time)") << " noenhanced\n"
     << "set xlabel 'reduced loss factor {/Symbol h}*'\nset ytics noenhanced\nset grid x\nset key bottom right\n"
     << "set offsets 0, 0, 0.5, 0.5\nset style fill solid 0.6 border -1\n"
     << "set arrow from " << baseline << ", graph 0 to " << baseline << ", graph 1 nohead lc rgb 'black' dt 2\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900," << 200 + 45 * static_cast<int>(bars.size()) << " enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'sensitivity.svg' : 'sensitivity.png'\n"
     << "  plot 'sensitivity_tornado.csv' every ::1 using (($2+$3)/2):($0):2:3:($0-0.3):($0+0.3):ytic(1) "
        "with boxxyerror lc rgb 'steelblue' title 'range over the values', \\\n"
     << "       NaN with lines dt 2 lc rgb 'black' title " << gnuplot_string("baseline " + format_number(baseline, 4)) << "\n"
     << "}\n";
  return files.add_plot("sensitivity.gp", gp.str(), {"sensitivity.png", "sensitivity.svg"});
}

/// A sensitivity study of a case: its drive, its variants and the sweep's points.
struct SensitivityStudy {
  double frequency_hz = 0.0, amplitude_m = 0.0;
  std::vector<case_file::SensitivityVariant> variants;
  surrogate::SweepPoints points;
  std::vector<std::string> warnings;
};

SensitivityStudy sensitivity_study(const Case& c) {
  (void)single_damper(c, "pdamp sensitivity");  // one damper of one layer, refused otherwise
  SensitivityStudy study;
  std::tie(study.frequency_hz, study.amplitude_m) = sensitivity_drive(c);
  study.variants = case_file::sensitivity_variants(c, study.warnings);
  study.points.identity = json::array();
  for (const auto& v : study.variants) {
    study.points.drives.push_back({study.frequency_hz, study.amplitude_m});
    study.points.identity.push_back({{"parameter", v.parameter}, {"value", v.value}});
  }
  return study;
}

std::string sensitivity_source(const ParsedArgs& args, const std::string& fallback) {
  const std::string source = args.optional_text("--source").value_or(fallback);
  if (source != "formulas" && source != "dem") throw InputError("--source", "", "'" + source + "': must be dem or formulas");
  return source;
}

/// The table, CSV, tornado plot and JSON of a study's points (a run's, a shard's or a merge's).
int write_sensitivity_outputs(const ParsedArgs& args, const Case& c, const SensitivityStudy& study,
                              const surrogate::PointSweepResult& result, const std::string& source, OutputDir& files,
                              json out) {
  const double f = study.frequency_hz, x = study.amplitude_m;
  std::vector<std::string> warnings = study.warnings;
  warnings.insert(warnings.end(), result.summary.warnings.begin(), result.summary.warnings.end());
  const auto nullable = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  const surrogate::FieldPoint& base = result.points.front();
  json rows = json::array();
  for (std::size_t k = 0; k < study.variants.size(); ++k) {
    const auto& v = study.variants[k];
    const auto& p = result.points[k];
    const SingleDamper d = single_damper(v.variant, "pdamp sensitivity");
    const auto closed = fm::reduced_loss_factor(d.damper.model, d.layer.clearance_m, x, f, d.damper.model_options);
    const bool ok = p.status == surrogate::PointStatus::kOk;
    rows.push_back({{"parameter", v.parameter},
                    {"value", k == 0 ? json(nullptr) : json(v.value)},
                    {"unit", v.unit},
                    {"status", std::string(surrogate::to_string(p.status))},
                    {"eta_star", ok ? nullable(p.eta_star) : json(nullptr)},
                    {"eta_star_stderr", ok ? nullable(p.eta_star_stderr) : json(nullptr)},
                    {"delta_eta_star", ok && base.status == surrogate::PointStatus::kOk ? nullable(p.eta_star - base.eta_star)
                                                                                         : json(nullptr)},
                    {"motion_mode", p.motion_mode},
                    {"apparent_mass_fraction", nullable(p.apparent_mass_fraction)},
                    {"closed_form_eta_star", nullable(closed.eta_star)},
                    {"closed_form_regime", std::string(fm::to_string(closed.regime))},
                    {"clearance_m", d.layer.clearance_m},
                    {"bed_mass_kg", d.layer.bed_mass_kg},
                    {"intensity", x * std::pow(2.0 * fm::kPi * f, 2) / fm::kStandardGravity}});
  }
  out.update({{"case", c.name},
              {"source", source},
              {"frequency_hz", f},
              {"amplitude_m", x},
              {"rows", rows},
              {"file", (files.dir() / "sensitivity.json").string()}});
  const double baseline_eta = base.status == surrogate::PointStatus::kOk ? base.eta_star : NAN;
  for (auto& w : write_sensitivity_files(files, c, rows, baseline_eta)) warnings.push_back(w);
  out["warnings"] = warnings;
  files.add_json("case_resolved.json", c.resolved);
  files.add_json("sensitivity.json", out);
  out["outputs"] = files.commit();
  print_warnings(warnings);
  std::vector<std::pair<std::string, std::string>> table = {
      {"case", c.name}, {"drive", "f = " + format_number(f) + " Hz, X = " + format_number(x) + " m"},
      {"sweep", out["sweep"].get<std::string>()}};
  for (const auto& r : rows) {
    std::string line = r["eta_star"].is_number() ? format_number(r["eta_star"].get<double>(), 4) : std::string("-");
    if (r["eta_star_stderr"].is_number()) line += " +- " + format_number(r["eta_star_stderr"].get<double>(), 2);
    line += "  " + r["motion_mode"].get<std::string>();
    if (r["closed_form_eta_star"].is_number()) line += "  (closed form " + format_number(r["closed_form_eta_star"].get<double>(), 4) + ")";
    const std::string name = r["parameter"].get<std::string>();
    table.push_back({name == "baseline" ? name : name + " = " + format_number(r["value"].get<double>(), 5), line});
  }
  for (const auto& path : out["outputs"]) table.push_back({"wrote", path.get<std::string>()});
  return emit(args, out, table, false);
}

int run_sensitivity(const ParsedArgs& args) {
  const Case c = case_file::load_case(args.positional().at(0));
  const std::string source = sensitivity_source(args, "dem");
  const bool dem = source == "dem";
  const SensitivityStudy study = sensitivity_study(c);
  const double f = study.frequency_hz, x = study.amplitude_m;
  const auto& variants = study.variants;
  const std::string dir = args.optional_text("-o").value_or("out/" + safe_file_name(c.name) + "_sensitivity");

  surrogate::SweepOptions sweep = field_sweep_options(c, source);
  sweep.threads = dem ? (c.sensitivity ? c.sensitivity->threads : c.field.threads) : 1;
  const auto [shard_index, shard_count] = shard_flag(args);
  sweep.shard_index = shard_index;
  sweep.shard_count = shard_count;
  if (dem || args.has("--shard")) sweep.results_path = std::filesystem::path(dir) / kSensitivityLog;

  // Every variant's DEM checked and costed before any work (exit 2 naming its key).
  std::vector<surrogate::PointEvaluator> evaluators;
  double wall_time_s = 0.0, particle_steps = 0.0;
  for (const auto& v : variants) {
    const SingleDamper d = single_damper(v.variant, "pdamp sensitivity");
    if (dem) {
      auto options = case_file::dem_options(v.variant, 0, x, f);
      options.world.threads = 1;  // the study runs variants in parallel instead
      const auto e = check_dem_run(v.variant, 0, options);
      check_dem_placement(v.variant, 0, options);
      wall_time_s += e.wall_time_s;
      particle_steps += e.particle_steps;
      evaluators.push_back(surrogate::dem_evaluator(options));
    } else {
      evaluators.push_back(surrogate::formula_evaluator(d.damper.model, d.layer.clearance_m, d.layer.bed_mass_kg,
                                                        d.damper.model_options));
    }
  }
  std::size_t pending = 0;
  try {
    pending = surrogate::pending_point_sweep(study.points, sweep);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "/sensitivity", e.what());
  }
  distributed::PointFarm farm(
      [&](const distributed::Request& r) { return evaluators.at(static_cast<std::size_t>(r[0]))(f, x); });
  if (distributed::worker()) {  // every check passed here too: evaluate what rank 0 sends
    farm.serve();
    return kExitOk;
  }
  sweep.threads = farm.threads(sweep.threads);
  OutputDir files(dir);
  if (!sweep.results_path.empty()) files.in_place(kSensitivityLog);
  std::mutex progress_mutex;
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  if (dem) {
    const double at_once = std::min<double>(sweep.threads, static_cast<double>(variants.size()));
    std::cerr << "pdamp sensitivity: " << variants.size() << " DEM runs at f = " << format_number(f) << " Hz, X = "
              << format_number(x) << " m (" << pending << " to run), about "
              << format_number(particle_steps * static_cast<double>(pending) / static_cast<double>(variants.size()), 3)
              << " particle-steps, " << format_number(wall_time_s * static_cast<double>(pending) /
                                                      static_cast<double>(variants.size()) / at_once, 3)
              << " s on " << at_once << " threads" << distributed_note() << std::endl;
    sweep.progress = [&](std::size_t done, std::size_t total, double eta_s) {
      std::lock_guard lock(progress_mutex);
      std::cerr << (tty ? "\r" : "") << "pdamp sensitivity: " << done << "/" << total << " runs";
      if (std::isfinite(eta_s)) std::cerr << ", ETA " << static_cast<long>(eta_s) << " s";
      std::cerr << (tty ? "   " : "\n") << std::flush;
    };
  }
  const auto result = surrogate::run_point_sweep(
      study.points, [&](std::size_t k) { return farm.evaluate({static_cast<double>(k), 0.0}); }, sweep);
  if (dem && tty) std::cerr << "\n";

  json out = {{"sweep", result.summary.brief_report()}};
  if (const json balance = farm.balance(); !balance.is_null()) out["mpi"] = balance;
  if (args.has("--shard")) {
    out["shard"] = args.text("--shard");
    out["note"] = "a shard's rows are its own variants; the other shards' are missing (join them with pdamp sensitivity merge)";
    copy_shard_case(files, c);
  }
  return write_sensitivity_outputs(args, c, study, result, source, files, out);
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

/// `pdamp sensitivity merge SHARD...`: the shards of one study joined into the table a
/// serial pdamp sensitivity writes.
int run_sensitivity_merge(const ParsedArgs& args) {
  const auto inputs = merge_inputs(args, "pdamp sensitivity merge", kSensitivityLog);
  const Case c = case_file::load_case(inputs.case_path.string());
  const std::string dir = args.optional_text("-o").value_or("out/" + safe_file_name(c.name) + "_sensitivity");
  refuse_output_in_shard(inputs, dir);
  const std::string source = sensitivity_source(args, shard_log_source(inputs.logs.front()));
  const SensitivityStudy study = sensitivity_study(c);
  OutputDir files(dir);
  surrogate::PointSweepResult result;
  try {
    result = surrogate::merge_point_sweep_shards(study.points, field_sweep_options(c, source), inputs.logs, c.path);
  } catch (const std::invalid_argument&) {
    throw;  // std::invalid_argument naming the files already: exit 2
  }
  json out = {{"sweep", "merged " + std::to_string(inputs.logs.size()) + " shard files: " +
                            std::to_string(result.summary.points_total) + " variants (" +
                            std::to_string(result.summary.points_failed) + " failed)"},
              {"shards", inputs.logs.size()}};
  return write_sensitivity_outputs(args, c, study, result, source, files, out);
}

/// `pdamp field merge SHARD...` (INTERFACE.md): the shards' logs joined into the field a
/// serial `pdamp field` writes. The case, which gives the identity every shard must carry
/// and the damper that write_field_outputs needs (scattered fit, pictures), is the first
/// shard folder's shard_case.json (the case file the shard ran, copied), the source its log's; `pdamp field merge CASE.json
/// [--source SRC] SHARD...` names them instead.
int run_field_merge(const ParsedArgs& args) {
  const auto inputs = merge_inputs(args, "pdamp field merge", kSweepLog);
  const Case c = case_file::load_case(inputs.case_path.string());
  (void)single_damper(c, "pdamp field merge");
  const std::string source = args.optional_text("--source").value_or(shard_log_source(inputs.logs.front()));
  if (source != "formulas" && source != "dem")
    throw InputError("--source", "", "'" + source + "': must be formulas or dem (the source the shards ran)");
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  const std::string dir = args.optional_text("-o").value_or(default_field_dir(c, source));
  refuse_output_in_shard(inputs, dir);
  const auto& logs = inputs.logs;
  OutputDir files(dir);
  surrogate::SweepResult result;
  try {
    result = surrogate::merge_sweep_shards(grid, field_sweep_options(c, source), logs, c.path);
  } catch (const std::invalid_argument&) {
    throw;  // std::invalid_argument naming the files already: exit 2
  }
  json out = {{"sweep", "merged " + std::to_string(logs.size()) + " shard files: " +
                            std::to_string(result.summary.points_total) + " points (" +
                            std::to_string(result.summary.points_failed) + " failed)"},
              {"shards", logs.size()},
              {"warnings", result.summary.warnings}};
  return write_field_outputs(args, c, result.field, files, out);
}

/// field.json, the scattered-state fit (DEM and measured fields), tables and pictures.
int write_field_outputs(const ParsedArgs& args, const Case& c, const surrogate::EffectiveField& field,
                        OutputDir& files, json out) {
  const auto& damper = single_damper(c, "pdamp field").damper;
  const std::string source(surrogate::to_string(field.provenance.source));
  std::vector<std::string> warnings = out.value("warnings", std::vector<std::string>{});
  out.update({{"source", source}, {"points", field.grid.size()}});
  surrogate::write_effective_field(field, files.staged_path("field.json"));
  out["file"] = (files.dir() / "field.json").string();
  if (field.provenance.source != surrogate::FieldSource::kFormulas) {
    try {
      const auto samples = surrogate::scattered_samples(field, damper.model, damper.model_options);
      const auto fit = surrogate::fit_scattered_law(samples, "pdamp field --source " + source + ", case " + c.name);
      surrogate::write_scattered_fit(fit, files.staged_path("scattered_fit.json"));
      out["scattered_fit"] = {{"jump_fraction", fit.fit.jump_fraction}, {"exponent", fit.fit.exponent},
                              {"s_min", fit.fit.s_min}, {"s_max", fit.fit.s_max},
                              {"reduced_chi_squared", fit.fit.reduced_chi_squared}, {"points", fit.fit.points}};
    } catch (const std::exception& e) {
      warnings.push_back(std::string("scattered-state fit not made: ") + e.what());
    }
  }
  for (auto& w : write_field_pictures(files, field, c.name, damper)) warnings.push_back(w);
  out["files"] = files.commit();
  out["warnings"] = warnings;
  print_warnings(warnings);
  std::vector<std::pair<std::string, std::string>> rows = {{"source", source}, {"points", std::to_string(field.grid.size())}};
  if (out.contains("sweep")) rows.push_back({"sweep", out["sweep"].get<std::string>()});
  if (out.contains("scattered_fit"))
    rows.push_back({"scattered fit", "jump_fraction = " + format_number(out["scattered_fit"]["jump_fraction"].get<double>(), 4) +
                                         ", exponent = " + format_number(out["scattered_fit"]["exponent"].get<double>(), 4)});
  for (const auto& path : out["files"]) rows.push_back({"wrote", path.get<std::string>()});
  return emit(args, out, rows, false);
}

/// Every check that run, dem and field make on a case, without the work.
int run_validate(const ParsedArgs& args) {
  const Case c = case_file::load_case(args.positional().at(0));
  if (c.task.kind == case_file::TaskKind::kDamperDesign) (void)damper_design(c);
  const auto grid = surrogate::Grid::from_ranges(c.field.axes, c.field.axis0, c.field.axis1);
  for (std::size_t i = 0; i < c.dampers.size(); ++i) {
    if (c.excitation.amplitude_m)
      (void)check_dem_run(c, i, case_file::dem_options(c, i, *c.excitation.amplitude_m, c.excitation.frequency_hz));
    // check_dem_field places the bed as every DEM run of the case would.
    (void)check_dem_field(c, i, grid, nullptr);
  }
  std::cout << c.resolved.dump(2) << "\n";
  return kExitOk;
}

const FlagSpec kModelOverrides[] = {
    {"--calibration", "C", "design factor c in x_opt = c*x_opt_ideal (default 0.8976 rolling, 1.0 bouncing)"},
    {"--inertia-factor", "K", "rolling spheres' I/(m r^2) (default 0.4, solid spheres)"},
    {"--friction", "MU", "sphere-base friction: auto rolls up to Gamma = MU(1+K)/K (default 0.3)"}};

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> all = [] {
    std::vector<Command> list = {
      {{"run", "pdamp run CASE.json [--method formulas|field|dem] [--dem-points N] [--dem-sweep D] [--resume] [-o DIR] [--json]",
        "the main job: what the case's `task` asks (damper_design: optimum stroke, clearance\n"
        "for a target stroke, eta* curve over stroke, buffered-wall sizing; modes, frf, decay:\n"
        "as pdamp modes, frf and decay; filling_ratios and placement: as pdamp optimize)",
        concat_flags(concat_flags({kMethodFlag, kNoVerifyFlag, kOutFlag, kJsonFlag}, kDemSweepFlags), kCheckpointFlags), 1},
       run_run, true},
      {{"optimum", "pdamp optimum --model rolling|bouncing --clearance M [--json]",
        "optimal container stroke for a clearance: design value, ideal peak and onset",
        {{"--model", "MODEL", "rolling (low intensity, A < g) or bouncing (high intensity)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"}, kModelOverrides[0], kModelOverrides[1], kModelOverrides[2],
         kJsonFlag}},
       run_optimum},
      {{"size", "pdamp size --model rolling|bouncing --stroke M [--json]",
        "clearance h whose design stroke equals the target stroke (inverse of optimum)",
        {{"--model", "MODEL", "rolling or bouncing"}, {"--stroke", "M", "target container stroke X, m (> 0)"},
         kModelOverrides[0], kModelOverrides[1], kModelOverrides[2], kJsonFlag}},
       run_size},
      {{"loss", "pdamp loss --model M --clearance M --amplitude M --frequency HZ [--bed-mass KG] [-o DIR] [--json]",
        "closed-form reduced loss factor eta* at one operating point (with -o: eta* over stroke)",
        {{"--model", "MODEL", "rolling | bouncing | scattered | auto (auto: Gamma < 1 rolling, else bouncing;\n"
                              "                          below the onset the scattered fit)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"},
         {"--amplitude", "M", "container stroke X, m (> 0)"},
         {"--frequency", "HZ", "drive frequency f, Hz (> 0)"},
         {"--bed-mass", "KG", "bed mass for e_diss_j and energy_per_cycle_j, kg (default 1)"},
         {"--scattered-fit", "FILE", "fitted scattered-state coefficients (scattered_fit.json of\n"
                                     "                          pdamp field --source dem); default: provisional"},
         kModelOverrides[0], kModelOverrides[1], kModelOverrides[2], kOutFlag, kJsonFlag}},
       run_loss},
      {{"buffer",
        "pdamp buffer --frequency HZ (--amplitude M | --intensity G) --radius M --layer-modulus PA [options] [--json]",
        "Hertz sizing of a buffered (polymer-coated) wall: the layer thickness that the design\n"
        "impact just compresses fully (PHYSICS.md section 5)",
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
         {"--particles-per-contact", "N", "particles whose momentum drives one contact (default 1)"},
         {"--impact-velocity", "M_S", "impact speed, m/s (default 2*X*Omega, the bouncing optimum)"},
         kJsonFlag}},
       run_buffer},
      {{"dem", "pdamp dem CASE.json [--amplitude M] [--frequency HZ] [--resume] [-o DIR] [--json]",
        "reference DEM of the case's damper under harmonic motion x = X sin(2 pi f t): eta*,\n"
        "its standard error, apparent mass, energy balance, motion mode (docs/dem.md)",
        concat_flags({{"--amplitude", "M", "stroke X, m (default: the case's excitation.amplitude_m)"},
                      {"--frequency", "HZ", "frequency f, Hz (default: the case's excitation.frequency_hz)"},
                      {"--periods", "N", "analysed periods (default: the case's dem.analysed_periods)"},
                      {"--threads", "N", "OpenMP threads, 0 = all (default: the case's dem.threads)"},
                      {"-o", "DIR", "write summary.json, time_series.csv, particles_*.vtk (ParaView) and\n"
                                    "                          force_velocity.png/.svg into DIR, atomically (and\n"
                                    "                          dem.checkpoint while the run lasts: --resume)"},
                      kJsonFlag},
                     kCheckpointFlags), 1},
       run_dem},
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
         kJsonFlag}, 1},
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
         kJsonFlag}, 1},
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
      {{"validate", "pdamp validate CASE.json",
        "check a case file and print it as JSON with every default resolved and the derived\n"
        "bed clearance, extent and mass",
        {kJsonFlag}, 1},
       run_validate},
    };
    // Level III after the damper commands, before validate.
    auto structure = structure_commands();
    list.insert(list.end() - 1, structure.begin(), structure.end());
    list.insert(list.end() - 1, optimize_command());
    return list;
  }();
  return all;
}

}  // namespace pdamp::cli
