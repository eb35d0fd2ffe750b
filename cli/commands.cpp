// Subcommands: parse flags, call the libraries, print a table or one JSON object.
#include "commands.hpp"

#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "case_io.hpp"
#include "errors.hpp"
#include "output.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/hertz_impact.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace fm = formulas;
constexpr double kInf = std::numeric_limits<double>::infinity();

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
  if (const auto kappa = args.optional_number("--inertia-factor", 0.0, 1.0)) options.rolling_inertia_factor = *kappa;
  if (const auto c = args.optional_number("--calibration", 0.0, 2.0)) {
    if (model == fm::DamperModel::kBouncing) options.bouncing_calibration = *c;
    else options.rolling_calibration = *c;
  }
  return options;
}

void print_warnings(const std::vector<std::string>& warnings) {
  for (const auto& w : warnings) std::cerr << "pdamp: warning: " << w << "\n";
}

/// Prints the result: the JSON object with --json, else the readable table.
int emit(const ParsedArgs& args, const json& result, const std::vector<std::pair<std::string, std::string>>& rows) {
  if (args.has("--json")) std::cout << result.dump(2) << "\n";
  else std::cout << key_value_table(rows);
  return kExitOk;
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

struct CurvePoint {
  double stroke_m;
  fm::LossResult loss;
};

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

/// eta_curve.csv and its plot (PNG, SVG) with onset, ideal peak and design stroke marked.
std::vector<std::string> write_eta_curve(OutputDir& out, const std::vector<CurvePoint>& curve,
                                         const fm::OptimumStroke& landmarks, double frequency_hz,
                                         const std::string& title) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "stroke_m,stroke_over_clearance,intensity,eta_star,regime,model_used\n";
  for (const auto& p : curve)
    csv << p.stroke_m << ',' << p.stroke_m / landmarks.clearance_m << ',' << p.loss.intensity << ','
        << p.loss.eta_star << ',' << fm::to_string(p.loss.regime) << ',' << fm::to_string(p.loss.model_used) << '\n';
  out.add("eta_curve.csv", csv.str());

  const double h = landmarks.clearance_m;
  std::ostringstream gp;
  gp << "# eta*(X) of pdamp's closed forms; run: gnuplot eta_curve.gp\n"
     << "set datafile separator ','\n"
     << "set xlabel 'stroke X / clearance h'\nset ylabel 'reduced loss factor {/Symbol h}*'\n"
     << "set title \"" << title << " (h = " << format_number(h * 1e3, 4) << " mm, f = " << format_number(frequency_hz, 4)
     << " Hz)\" noenhanced\n"
     << "set grid\nset key top right\nset yrange [0:*]\n"
     << "set arrow 1 from " << landmarks.x_onset_m / h << ", graph 0 to " << landmarks.x_onset_m / h
     << ", graph 1 nohead dt 2 lc rgb 'gray40'\n"
     << "set label 1 'onset' at " << landmarks.x_onset_m / h << ", graph 0.95 right offset -0.5,0\n"
     << "set arrow 2 from " << landmarks.x_opt_ideal_m / h << ", graph 0 to " << landmarks.x_opt_ideal_m / h
     << ", graph 1 nohead dt 3 lc rgb 'gray40'\n"
     << "set label 2 'ideal peak' at " << landmarks.x_opt_ideal_m / h << ", graph 0.88 left offset 0.5,0\n"
     << "set arrow 3 from " << landmarks.x_opt_m / h << ", graph 0 to " << landmarks.x_opt_m / h
     << ", graph 1 nohead lw 2 lc rgb 'dark-green'\n"
     << "set label 3 'design' at " << landmarks.x_opt_m / h << ", graph 0.80 left offset 0.5,0 tc rgb 'dark-green'\n"
     << "regime(r) = (stringcolumn(5) eq r) ? $4 : 1/0\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'eta_curve.svg' : 'eta_curve.png'\n"
     << "  plot 'eta_curve.csv' using 2:(regime('collect_and_collide')) with lines lw 2 lc rgb 'blue' title 'collect and collide', \\\n"
     << "       '' using 2:(regime('sub_peak')) with lines lw 2 lc rgb 'orange' title 'sub-peak orbit', \\\n"
     << "       '' using 2:(regime('scattered')) with lines lw 2 dt 4 lc rgb 'red' title 'scattered (fit)'\n"
     << "}\n";
  return out.add_plot("eta_curve.gp", gp.str(), {"eta_curve.png", "eta_curve.svg"});
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
          {"intensity", loss.intensity},
          {"stroke_over_onset", loss.stroke_over_onset},
          {"velocity_amplitude_m_s", loss.velocity_amplitude_m_s},
          {"bed_mass_kg", bed_mass_kg},
          {"warnings", loss.warnings}};
}

// ---------------------------------------------------------------- commands

int run_optimum(const ParsedArgs& args) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double h = args.number("--clearance", 0.0, kInf);
  const auto result = fm::optimum_stroke(model, h, model_options(args, model));
  json out = optimum_json(result);
  out["warnings"] = json::array();
  return emit(args, out, optimum_rows(result));
}

int run_size(const ParsedArgs& args) {
  const auto model = model_flag(args, {"rolling", "bouncing"});
  const double stroke = args.number("--stroke", 0.0, kInf);
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
  const double h = args.number("--clearance", 0.0, kInf);
  const double x = args.number("--amplitude", 0.0, kInf);
  const double f = args.number("--frequency", 0.0, kInf);
  const double bed_mass = args.optional_number("--bed-mass", 0.0, kInf).value_or(1.0);
  const auto options = model_options(args, model);
  const auto loss = fm::reduced_loss_factor(model, h, x, f, options);
  json out = loss_json(loss, bed_mass, f);
  out.update({{"clearance_m", h}, {"amplitude_m", x}, {"frequency_hz", f}});
  std::vector<std::string> warnings = loss.warnings;
  if (const auto dir = args.optional_text("-o")) {
    const auto family = loss.model_used;
    const auto landmarks = fm::optimum_stroke(family, h, options);
    const double x_max = std::max(1.5 * h, 1.2 * x);
    OutputDir files(*dir);
    const auto curve = eta_curve(model, h, f, options, 0.02 * h, x_max, 301);
    for (auto& w : write_eta_curve(files, curve, landmarks, f, "pdamp loss --model " + std::string(fm::to_string(model))))
      warnings.push_back(w);
    out["warnings"] = warnings;
    files.add_json("loss.json", out);
    out["files"] = files.commit();
  }
  print_warnings(warnings);
  return emit(args, out, {{"model_used", std::string(fm::to_string(loss.model_used))},
                          {"regime", std::string(fm::to_string(loss.regime))},
                          {"eta_star", format_number(loss.eta_star)},
                          {"e_diss_j", format_number(out["e_diss_j"].get<double>())},
                          {"energy_per_cycle_j", format_number(out["energy_per_cycle_j"].get<double>())},
                          {"intensity", format_number(loss.intensity, 4)}});
}

json buffer_json(const fm::BufferDesign& b) {
  return {{"layer_thickness_m", b.layer_thickness_m},   {"impact_velocity_m_s", b.impact_velocity_m_s},
          {"max_penetration_m", b.max_penetration_m},   {"contact_time_s", b.contact_time_s},
          {"contact_time_over_period", b.contact_time_over_period},
          {"effective_mass_kg", b.effective_mass_kg},   {"max_force_n", b.max_force_n},
          {"contact_radius_m", b.contact_radius_m},     {"assumptions", b.assumptions},
          {"warnings", b.warnings}};
}

int run_buffer(const ParsedArgs& args) {
  fm::BufferDesignInput in;
  in.frequency_hz = args.number("--frequency", 0.0, kInf);
  const auto amplitude = args.optional_number("--amplitude", 0.0, kInf);
  const auto intensity = args.optional_number("--intensity", 0.0, kInf);
  if (amplitude.has_value() == intensity.has_value())
    throw InputError("--amplitude", "", "give exactly one of --amplitude M and --intensity G");
  in.amplitude_m = amplitude.value_or(0.0);
  in.intensity = intensity.value_or(0.0);
  in.particle_radius_m = args.number("--radius", 0.0, kInf);
  in.particle.density_kg_m3 = args.optional_number("--particle-density", 0.0, kInf).value_or(in.particle.density_kg_m3);
  in.particle.youngs_modulus_pa = args.optional_number("--particle-modulus", 0.0, kInf).value_or(in.particle.youngs_modulus_pa);
  in.particle.poisson_ratio = args.optional_number("--particle-poisson", 0.0, 0.4999, false).value_or(in.particle.poisson_ratio);
  in.layer.youngs_modulus_pa = args.number("--layer-modulus", 0.0, kInf);
  in.layer.poisson_ratio = args.optional_number("--layer-poisson", 0.0, 0.4999, false).value_or(0.45);
  in.particles_per_contact = args.optional_number("--particles-per-contact", 1.0, kInf, false).value_or(1.0);
  in.impact_velocity_m_s = args.optional_number("--impact-velocity", 0.0, kInf).value_or(0.0);
  const auto problems = in.validate();
  if (!problems.empty()) throw InputError("pdamp buffer", "", problems.front());
  const auto design = fm::size_buffer_layer(in);
  print_warnings(design.warnings);
  return emit(args, buffer_json(design),
              {{"layer_thickness_m", format_number(design.layer_thickness_m)},
               {"impact_velocity_m_s", format_number(design.impact_velocity_m_s)},
               {"max_penetration_m", format_number(design.max_penetration_m)},
               {"contact_time_s", format_number(design.contact_time_s)},
               {"contact_time/period", format_number(design.contact_time_over_period, 4)},
               {"max_force_n", format_number(design.max_force_n)}});
}

int run_validate(const ParsedArgs& args) {
  const Case c = load_case(args.positional().at(0));
  std::cout << c.resolved.dump(2) << "\n";
  return kExitOk;
}

/// `auto` in a design: rolling when its design stroke at the case frequency is below
/// 1 g (PHYSICS.md §3: low intensity), else bouncing.
fm::DamperModel design_family(const Case& c) {
  if (c.damper.model != fm::DamperModel::kAuto) return c.damper.model;
  const auto rolling = fm::optimum_stroke(fm::DamperModel::kRolling, c.damper.clearance_m, c.damper.model_options);
  const double omega = 2.0 * fm::kPi * c.excitation.frequency_hz;
  return rolling.x_opt_m * omega * omega < fm::kStandardGravity ? fm::DamperModel::kRolling : fm::DamperModel::kBouncing;
}

int run_damper_design(const ParsedArgs& args, const Case& c) {
  const auto& d = c.damper;
  const auto family = design_family(c);
  const double f = c.excitation.frequency_hz;
  const auto optimum = fm::optimum_stroke(family, d.clearance_m, d.model_options);
  json result = {{"task", to_string(c.task)}, {"case", c.name}, {"model", fm::to_string(family)},
                 {"clearance_m", d.clearance_m}, {"bed_mass_kg", d.bed_mass_kg}, {"optimum", optimum_json(optimum)}};
  std::vector<std::string> warnings;
  const auto design_point = fm::reduced_loss_factor(family, d.clearance_m, optimum.x_opt_m, f, d.model_options);
  result["optimum"]["eta_star_at_design"] = design_point.eta_star;
  result["optimum"]["intensity_at_design"] = design_point.intensity;
  warnings.insert(warnings.end(), design_point.warnings.begin(), design_point.warnings.end());
  if (c.design.target_stroke_m) {
    const double h = fm::clearance_for_stroke(family, *c.design.target_stroke_m, d.model_options);
    result["sizing"] = {{"target_stroke_m", *c.design.target_stroke_m},
                        {"clearance_m", h},
                        {"container_inner_length_along_drive_m", d.bed.bed_extent_m + h}};
  }
  if (c.excitation.amplitude_m) {
    const auto op = fm::reduced_loss_factor(d.model, d.clearance_m, *c.excitation.amplitude_m, f, d.model_options);
    result["operating_point"] = loss_json(op, d.bed_mass_kg, f);
    result["operating_point"]["amplitude_m"] = *c.excitation.amplitude_m;
    warnings.insert(warnings.end(), op.warnings.begin(), op.warnings.end());
  }
  if (c.buffer) {
    const auto design = fm::size_buffer_layer(c.buffer->input);
    result["buffer"] = buffer_json(design);
    result["buffer"]["layer_material"] = c.buffer->layer_material;
    warnings.insert(warnings.end(), design.warnings.begin(), design.warnings.end());
  }

  const auto curve = eta_curve(d.model == fm::DamperModel::kAuto ? fm::DamperModel::kAuto : family, d.clearance_m, f,
                               d.model_options, c.design.sweep_min_over_clearance * d.clearance_m,
                               c.design.sweep_max_over_clearance * d.clearance_m, c.design.sweep_points);
  json outputs = json::array();
  if (const auto dir = args.optional_text("-o")) {
    OutputDir files(*dir);
    for (auto& w : write_eta_curve(files, curve, optimum, f, c.name)) warnings.push_back(w);
    files.add_json("case_resolved.json", c.resolved);
    result["warnings"] = warnings;
    files.add_json("design.json", result);
    outputs = files.commit();
  }
  result["warnings"] = warnings;
  result["outputs"] = outputs;
  print_warnings(warnings);
  auto rows = optimum_rows(optimum);
  rows.insert(rows.begin(), {"case", c.name});
  rows.push_back({"eta* at design", format_number(design_point.eta_star, 4)});
  if (result.contains("sizing"))
    rows.push_back({"clearance for target", format_number(result["sizing"]["clearance_m"].get<double>())});
  if (result.contains("buffer"))
    rows.push_back({"buffer layer_thickness_m", format_number(result["buffer"]["layer_thickness_m"].get<double>())});
  for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
  return emit(args, result, rows);
}

int run_run(const ParsedArgs& args) {
  const Case c = load_case(args.positional().at(0));
  switch (c.task) {
    case Task::kDamperDesign: return run_damper_design(args, c);
  }
  return kExitOther;
}

const FlagSpec kModelOverrides[] = {
    {"--calibration", "C", "design factor c in x_opt = c*x_opt_ideal (default 0.8976 rolling, 1.0 bouncing)"},
    {"--inertia-factor", "K", "rolling spheres' I/(m r^2) (default 0.4, solid spheres)"}};

}  // namespace

const std::vector<Command>& commands() {
  static const std::vector<Command> all = {
      {{"run", "pdamp run CASE.json [-o DIR] [--json]",
        "the main job: what the case's `task` asks (damper_design: optimum stroke, clearance\n"
        "for a target stroke, eta* curve over stroke, buffered-wall sizing)",
        {kOutFlag, kJsonFlag}, 1},
       run_run},
      {{"optimum", "pdamp optimum --model rolling|bouncing --clearance M [--json]",
        "optimal container stroke for a clearance: design value, ideal peak and onset",
        {{"--model", "MODEL", "rolling (low intensity, A < g) or bouncing (high intensity)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"}, kModelOverrides[0], kModelOverrides[1],
         kJsonFlag}},
       run_optimum},
      {{"size", "pdamp size --model rolling|bouncing --stroke M [--json]",
        "clearance h whose design stroke equals the target stroke (inverse of optimum)",
        {{"--model", "MODEL", "rolling or bouncing"}, {"--stroke", "M", "target container stroke X, m (> 0)"},
         kModelOverrides[0], kModelOverrides[1], kJsonFlag}},
       run_size},
      {{"loss", "pdamp loss --model M --clearance M --amplitude M --frequency HZ [--bed-mass KG] [-o DIR] [--json]",
        "closed-form reduced loss factor eta* at one operating point (with -o: eta* over stroke)",
        {{"--model", "MODEL", "rolling | bouncing | scattered | auto (auto: Gamma < 1 rolling, else bouncing;\n"
                              "                          below the onset the scattered fit)"},
         {"--clearance", "M", "free travel h of the collected bed, m (> 0)"},
         {"--amplitude", "M", "container stroke X, m (> 0)"},
         {"--frequency", "HZ", "drive frequency f, Hz (> 0)"},
         {"--bed-mass", "KG", "bed mass for e_diss_j and energy_per_cycle_j, kg (default 1)"},
         kModelOverrides[0], kModelOverrides[1], kOutFlag, kJsonFlag}},
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
         {"--layer-poisson", "NU", "layer Poisson ratio (default 0.45)"},
         {"--particles-per-contact", "N", "particles whose momentum drives one contact (default 1)"},
         {"--impact-velocity", "M_S", "impact speed, m/s (default 2*X*Omega, the bouncing optimum)"},
         kJsonFlag}},
       run_buffer},
      {{"validate", "pdamp validate CASE.json",
        "check a case file and print it as JSON with every default resolved and the derived\n"
        "bed clearance, extent and mass",
        {kJsonFlag}, 1},
       run_validate},
  };
  return all;
}

}  // namespace pdamp::cli
