// pdamp optimize (and pdamp run on task kind filling_ratios): the case's first damper's
// layers as candidates -> optimizer::optimize_filling_ratios -> designs, solver summary,
// CSV and a decay plot of the chosen design against the single-layer baseline.
#include "optimize_command.hpp"

#include <cmath>
#include <iostream>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "errors.hpp"
#include "output.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/optimizer/filling_ratios.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::cli {

namespace {

using nlohmann::json;
namespace opt = optimizer;
namespace st = structure;
using case_file::Case;
using case_file::FillingRatiosTask;

/// Instants of the comparison decays written with -o (decay_compare.csv).
constexpr int kPlotSamples = 2001;

const FlagSpec kBackendFlag{"--backend", "NAME",
                            "local stage of the relaxed solve: nlopt (ISRES global stage, then SLSQP)\n"
                            "                          or ipopt (the same global stage, then Ipopt: the hybrid);\n"
                            "                          default: the task's backend (nlopt)"};

json number_or_null(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }


/// The optimiser's description of the case: candidates from the first damper's layers.
struct Problem {
  st::ModalModel modal;
  opt::FillingRatioOptions options;
  std::vector<std::string> warnings;
};

Problem make_problem(const Case& c) {
  const FillingRatiosTask& task = *c.task.filling_ratios;
  Problem p;
  case_file::StructureSetup setup = case_file::structure_setup(c, case_file::LossMethod::kFormulas);
  const case_file::DamperSpec& spec = c.dampers.front();
  p.modal = setup.modal;
  p.options.damper = setup.dampers.front();
  p.options.fixed_dampers.assign(setup.dampers.begin() + 1, setup.dampers.end());
  p.options.model = spec.model;
  p.options.model_options = spec.model_options;
  p.options.mass_budget_kg = task.mass_budget_kg;
  p.options.objective = task.objective == FillingRatiosTask::Objective::kIntegralSquare
                            ? opt::FillingObjective::kIntegralSquare
                            : opt::FillingObjective::kSettlingTime;
  for (std::size_t k = 0; k < spec.layers.size(); ++k) {
    const case_file::LayerSpec& layer = spec.layers[k];
    const double r = layer.particle_radius_m;
    opt::LayerCandidate l;
    l.name = layer.name;
    l.inner_length_m = layer.container.inner_length(spec.drive_axis);
    l.slab_length_m = 2.0 * r;
    l.spheres_per_slab = task.spheres_per_slab.at(k);
    l.sphere_mass_kg = layer.bed_mass_kg / layer.particle_count;
    l.sphere_volume_m3 = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    l.cross_section_m2 = 1.0;
    for (int axis = 0; axis < 3; ++axis)
      if (axis != spec.drive_axis) l.cross_section_m2 *= layer.container.box_inner_size_m[static_cast<std::size_t>(axis)];
    const int whole = layer.particle_count / l.spheres_per_slab;
    if (layer.particle_count % l.spheres_per_slab != 0)
      p.warnings.push_back("layer " + layer.name + ": " + std::to_string(layer.particle_count) +
                           " particles are not whole slabs of " + std::to_string(l.spheres_per_slab) +
                           ": the starting design takes " + std::to_string(whole) + " slabs");
    l.initial_slabs = std::min(whole, l.max_slabs());
    p.options.layers.push_back(l);
  }
  const Eigen::VectorXd q0 = case_file::initial_modal_amplitudes(c, setup, task.decay);
  p.options.decay.initial_modal_amplitudes = q0.cwiseAbs();  // released from rest: a_j = |q_j(0)|
  if (!(p.options.decay.initial_modal_amplitudes.maxCoeff() > 0.0))
    throw InputError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  p.options.decay.duration_s = task.decay.duration_s;
  p.options.decay.threshold_fraction = task.decay.settling_threshold;
  // The coarsest RK4 rule free_decay allows (ln a changes <= 0.2 a step: local error about
  // 3e-6 of ln a): the search runs hundreds of decays; the comparison files use the same.
  p.options.decay.step_log_change = 0.2;
  if (const auto problems = p.options.validate(); !problems.empty()) throw InputError(c.path, "/task", problems.front());
  if (setup.beam)
    p.warnings.push_back("the beam's modes are those of the case's starting design (its bed weights load the beam's "
                         "geometric stiffness); designs of other bed masses reuse them");
  return p;
}

std::vector<double> slabs_of(const opt::FillingDesign& d) {
  std::vector<double> n;
  for (const auto& l : d.layers) n.push_back(l.slabs);
  return n;
}

json design_json(const opt::FillingDesign& d) {
  json layers = json::array();
  for (const auto& l : d.layers)
    layers.push_back({{"name", l.name},
                      {"slabs", l.slabs},
                      {"particles", l.particles},
                      {"filling_ratio", l.filling_ratio},
                      {"volume_fraction", l.volume_fraction},
                      {"clearance_m", l.clearance_m},
                      {"bed_mass_kg", l.bed_mass_kg}});
  return {{"layers", layers},
          {"total_mass_kg", d.total_mass_kg},
          {"feasible", d.feasible},
          {"settled", d.settled},
          {"settling_time_s", number_or_null(d.settling_time_s)},
          {"integral_square_m2_s", number_or_null(d.integral_square_m2_s)},
          {"objective", d.objective}};
}

std::string design_row(const opt::FillingDesign& d, bool whole) {
  std::string slabs;
  for (const auto& l : d.layers) slabs += (slabs.empty() ? "" : ", ") + (whole ? std::to_string(std::lround(l.slabs)) : format_number(l.slabs, 4));
  return "n = (" + slabs + "), " + format_number(d.total_mass_kg * 1e3, 4) + " g, settling " +
         (std::isfinite(d.settling_time_s) ? format_number(d.settling_time_s, 5) + " s" : "not settled") +
         ", objective " + format_number(d.objective, 6);
}

/// designs.csv (one row per design and layer), decay_compare.csv and its plot.
std::vector<std::string> write_files(OutputDir& files, const Case& c, const Problem& p,
                                     const opt::FillingRatioResult& r) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "design,layer,slabs,particles,filling_ratio,volume_fraction,clearance_m,bed_mass_kg,settling_time_s,objective\n";
  const std::vector<std::pair<std::string, const opt::FillingDesign*>> designs = {
      {"chosen", &r.chosen}, {"relaxed", &r.relaxed}, {"baseline", &r.baseline}, {"initial", &r.initial}};
  for (const auto& [name, d] : designs)
    for (const auto& l : d->layers)
      csv << name << ',' << l.name << ',' << l.slabs << ',' << l.particles << ',' << l.filling_ratio << ','
          << l.volume_fraction << ',' << l.clearance_m << ',' << l.bed_mass_kg << ','
          << (std::isfinite(d->settling_time_s) ? d->settling_time_s : -1.0) << ',' << d->objective << '\n';
  files.add("designs.csv", csv.str());

  // The envelopes of the chosen, baseline and starting designs on one time grid.
  st::FreeDecayOptions decay = p.options.decay;
  decay.sample_times_s.resize(kPlotSamples);
  for (int i = 0; i < kPlotSamples; ++i) decay.sample_times_s[static_cast<std::size_t>(i)] = decay.duration_s * i / (kPlotSamples - 1);
  decay.sample_times_s.back() = decay.duration_s;
  std::vector<st::FreeDecay> runs;
  for (const auto* d : {&r.chosen, &r.baseline, &r.initial}) {
    std::vector<st::Damper> dampers = {opt::filling_damper(p.options, slabs_of(*d))};
    dampers.insert(dampers.end(), p.options.fixed_dampers.begin(), p.options.fixed_dampers.end());
    runs.push_back(st::free_decay(p.modal, dampers, decay));
  }
  std::ostringstream env;
  env.precision(10);
  env << "time_s,envelope_chosen_m,envelope_baseline_m,envelope_initial_m,threshold_m\n";
  for (std::size_t i = 0; i < runs.front().samples.size(); ++i)
    env << runs[0].samples[i].time_s << ',' << runs[0].samples[i].threshold_measure_m << ','
        << runs[1].samples[i].threshold_measure_m << ',' << runs[2].samples[i].threshold_measure_m << ','
        << runs[0].threshold_used_m << '\n';
  files.add("decay_compare.csv", env.str());
  std::ostringstream gp;
  gp << "# free-decay envelopes of pdamp optimize (filling ratios); run: gnuplot decay_compare.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(c.name + ": chosen multi-layer design vs best single layer") << " noenhanced\n"
     << "set xlabel 'time t / s'\nset ylabel 'envelope at the damper site / mm'\nset grid\nset key top right\n"
     << "set logscale y\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'decay_compare.svg' : 'decay_compare.png'\n"
     << "  plot 'decay_compare.csv' using 1:($2*1e3) every ::1 with lines lw 2 lc rgb 'blue' title 'chosen', \\\n"
     << "       '' using 1:($3*1e3) every ::1 with lines lw 2 lc rgb 'red' title 'best single layer', \\\n"
     << "       '' using 1:($4*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'gray40' title 'case start', \\\n"
     << "       '' using 1:($5*1e3) every ::1 with lines lw 1 dt 3 lc rgb 'black' title 'threshold'\n"
     << "}\n";
  return files.add_plot("decay_compare.gp", gp.str(), {"decay_compare.png", "decay_compare.svg"});
}

opt::Backend backend_of(const ParsedArgs& args, const FillingRatiosTask& task) {
  if (const auto name = args.optional_text("--backend")) {
    if (const auto b = opt::backend_from_string(*name)) return *b;
    throw InputError("--backend", "", "'" + *name + "': must be nlopt or ipopt");
  }
  return *opt::backend_from_string(task.backend);
}

}  // namespace

int run_optimize_task(const ParsedArgs& args, const Case& c) {
  if (c.task.kind != case_file::TaskKind::kFillingRatios || !c.task.filling_ratios)
    throw InputError(c.path, "/task",
                     "pdamp optimize needs a task of kind filling_ratios (this case's task is '" +
                         std::string(case_file::to_string(c.task.kind)) +
                         "'): give \"task\": {\"kind\": \"filling_ratios\", \"mass_budget_kg\", \"initial_state\", "
                         "\"duration_s\"} (docs/cases.md, Format 2)");
  if (args.has("--method"))
    throw InputError("--method", "", "task kind filling_ratios uses the closed forms of each layer (formulas) only");
  const FillingRatiosTask& task = *c.task.filling_ratios;
  std::unique_ptr<OutputDir> files;
  if (const auto dir = args.optional_text("-o")) files = std::make_unique<OutputDir>(*dir);
  Problem p = make_problem(c);

  opt::Options solver;
  solver.backend = backend_of(args, task);
  solver.global_evaluations = task.global_evaluations;
  solver.max_evaluations = task.max_evaluations;
  opt::FillingRatioResult r;
  try {
    r = opt::optimize_filling_ratios(p.modal, p.options, solver);
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, "/task", e.what());
  }
  std::vector<std::string> warnings = p.warnings;
  warnings.insert(warnings.end(), r.warnings.begin(), r.warnings.end());
  for (const auto* d : {&r.chosen, &r.relaxed, &r.baseline})
    if (!std::isfinite(d->objective)) throw NumericalError("pdamp optimize: a design's objective is not finite");

  json neighbours = json::array();
  for (const auto& d : r.neighbours) {
    json n = {{"slabs", slabs_of(d)}, {"objective", d.objective}, {"settling_time_s", number_or_null(d.settling_time_s)},
              {"total_mass_kg", d.total_mass_kg}};
    neighbours.push_back(n);
  }
  const auto& s = r.summary;
  const std::string unit = p.options.objective == opt::FillingObjective::kSettlingTime ? "s" : "m2_s";
  json result = {
      {"task", "filling_ratios"},
      {"case", c.name},
      {"method", "formulas"},
      {"damper", p.options.damper.name},
      {"mass_budget_kg", task.mass_budget_kg},
      {"objective", {{"kind", std::string(opt::to_string(p.options.objective))}, {"unit", unit},
                     {"value", r.chosen.objective}}},
      {"design", design_json(r.chosen)},
      {"designs", {{"chosen", design_json(r.chosen)},
                   {"relaxed", design_json(r.relaxed)},
                   {"baseline", design_json(r.baseline)},
                   {"initial", design_json(r.initial)}}},
      {"baseline_layer", r.baseline_layer},
      {"baseline_evaluations", r.baseline_evaluations},
      {"rounding", {{"rule", "each relaxed n_k floored and ceiled (one value when within 1e-6 of a whole number); "
                             "every feasible point evaluated, the best chosen"},
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
  json outputs = json::array();
  if (files) {
    try {
      for (auto& w : write_files(*files, c, p, r)) warnings.push_back(w);
    } catch (const std::invalid_argument& e) {
      throw NumericalError(std::string("pdamp optimize: the comparison decays failed: ") + e.what());
    }
    result["file"] = (files->dir() / "optimize.json").string();
    result["warnings"] = warnings;
    files->add_json("case_resolved.json", c.resolved);
    files->add_json("optimize.json", result);
    outputs = files->commit();
  } else {
    result["file"] = nullptr;
  }
  result["warnings"] = warnings;
  result["outputs"] = outputs;
  for (const auto& w : warnings) std::cerr << "pdamp: warning: " << strict_json::printable(w) << "\n";
  if (args.has("--json")) {
    std::cout << result.dump(2) << "\n";
    return kExitOk;
  }
  std::vector<std::pair<std::string, std::string>> rows = {
      {"case", c.name},
      {"objective", std::string(opt::to_string(p.options.objective)) + " (" + unit + ")"},
      {"mass budget", format_number(task.mass_budget_kg * 1e3, 5) + " g"},
      {"relaxed optimum", design_row(r.relaxed, false)},
      {"rounded neighbours", std::to_string(r.neighbours_feasible) + " feasible of " + std::to_string(r.neighbours_total) +
                                 " evaluated"},
      {"chosen", design_row(r.chosen, true)},
      {"baseline (" + r.baseline_layer + ")", design_row(r.baseline, true)},
      {"case start", design_row(r.initial, true)},
      {"solver", s.brief_report()},
      {"time", format_number(r.solve_time_s, 4) + " s, " + std::to_string(r.decay_evaluations) + " free decays"}};
  for (const auto& l : r.chosen.layers)
    rows.push_back({"chosen " + l.name, std::to_string(std::lround(l.slabs)) + " slabs, phi = " +
                                            format_number(l.filling_ratio, 4) + ", h = " + format_number(l.clearance_m * 1e3, 4) +
                                            " mm, m = " + format_number(l.bed_mass_kg * 1e3, 4) + " g"});
  for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
  std::cout << key_value_table(rows);
  return kExitOk;
}

Command optimize_command() {
  return {{"optimize", "pdamp optimize CASE.json [--backend nlopt|ipopt] [-o DIR] [--json]",
           "optimise the case's task (kind filling_ratios: whole slabs per layer of the first damper\n"
           "for the fastest free decay under a particle-mass budget; relaxed solve, rounded\n"
           "neighbours, single-layer baseline; docs/optimizer.md)",
           {kBackendFlag,
            {"-o", "DIR", "write optimize.json, designs.csv, decay_compare.csv, decay_compare.gp/png/svg\n"
                          "                          and case_resolved.json into DIR, atomically"},
            {"--json", "", "print exactly one JSON object on stdout"}},
           1},
          [](const ParsedArgs& args) { return run_optimize_task(args, case_file::load_case(args.positional().at(0))); }};
}

}  // namespace pdamp::cli
