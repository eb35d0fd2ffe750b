// pdamp optimize (and pdamp run on task kind filling_ratios): the case's first damper's
// layers as candidates -> optimizer::optimize_filling_ratios -> designs, solver summary,
// CSV and a decay plot of the chosen design against the single-layer baseline.
#include "optimize_command.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "distributed.hpp"
#include "errors.hpp"
#include "output.hpp"
#include "placement_command.hpp"
#include "output.hpp"
#include "structure_commands.hpp"
#include "pdamp/case_file/filling_ratio_problem.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/formulas/bed_packing.hpp"
#include "pdamp/optimizer/filling_ratios.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::cli {

const FlagSpec kNoVerifyFlag{"--no-verify", "",
                             "skip the DEM verification the task's verify block asks for (the optimisation only)"};

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


/// The optimiser's description of the case (case_file::filling_ratio_problem).
using Problem = case_file::FillingRatioProblem;
Problem make_problem(const Case& c) { return case_file::filling_ratio_problem(c); }

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


// ---------------------------------------------------------------- DEM verification

const FlagSpec kVerifyFlag{"--verify", "",
                           "run the DEM verification (the task's verify settings, or their defaults when the\n"
                           "                          task has none): DEM-in-the-loop free decay of the chosen and the\n"
                           "                          baseline design against the closed forms (docs/optimizer.md)"};

/// The case with the first damper's layers holding design `d`'s whole slabs (layers of
/// 0 slabs left out) and the verification's further softening on every DEM material: what
/// the DEM builds for that design. The lattice is the case's (auto or explicit transverse
/// counts), n slabs along the drive, so h = L − n·2r as the optimiser has it.
Case design_case(const Case& c, const opt::FillingDesign& d, double softening) {
  const FillingRatiosTask& task = *c.task.filling_ratios;
  Case out = c;
  case_file::DamperSpec& damper = out.dampers.front();
  std::vector<case_file::LayerSpec> kept;
  for (std::size_t k = 0; k < damper.layers.size(); ++k) {
    const long slabs = std::lround(d.layers.at(k).slabs);
    if (slabs <= 0) continue;
    case_file::LayerSpec layer = damper.layers[k];
    layer.particle_count = static_cast<int>(slabs) * task.spheres_per_slab.at(k);
    if (layer.packing.lattice_counts) {
      (*layer.packing.lattice_counts)[static_cast<std::size_t>(damper.drive_axis)] = static_cast<int>(slabs);
      layer.compartment.lattice_counts.assign(layer.packing.lattice_counts->begin(), layer.packing.lattice_counts->end());
    }
    try {
      layer.bed = formulas::collected_lattice(layer.container, layer.particle_count, layer.particle_radius_m, layer.packing);
    } catch (const std::invalid_argument& e) {
      throw InputError(c.path, "/dampers/0/layers/" + std::to_string(k) + "/particles",
                       "the verified design's " + std::to_string(layer.particle_count) + " spheres: " + e.what());
    }
    layer.clearance_m = layer.bed.settled_clearance_m;
    layer.bed_mass_kg = d.layers[k].bed_mass_kg;
    layer.compartment.particles.front().count = layer.particle_count;
    kept.push_back(std::move(layer));
  }
  damper.layers = std::move(kept);
  for (auto& m : out.dem.simulation.world.materials) m.material.youngs_modulus_pa *= softening;
  return out;
}

/// ½∫e² dt of sampled values (trapezoid), m²·s.
double half_integral_square(const std::vector<double>& t, const std::vector<double>& e) {
  double sum = 0.0;
  for (std::size_t i = 1; i < t.size() && i < e.size(); ++i)
    sum += 0.25 * (t[i] - t[i - 1]) * (e[i] * e[i] + e[i - 1] * e[i - 1]);
  return sum;
}

/// What the verification keeps of a design's DEM decay (run_dem_decay): what it compares,
/// reports and plots. Plain data, so that it travels between MPI ranks (encode_decay).
struct VerifiedDecay {
  std::vector<double> time_s;               ///< the co-simulation's samples, s
  std::vector<double> site_displacement_m;  ///< y − y_s at the first damper's site, per sample
  SimulatedSettling settling;
  double threshold_m = 0.0, initial_envelope_m = 0.0;
  double energy_error = 0.0, dem_dissipated_j = 0.0, structural_dissipated_j = 0.0;
  std::int64_t steps = 0;
  double time_step_s = 0.0, wall_time_s = 0.0;
  std::vector<std::string> warnings;
};

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

/// A decay as CBOR for the MPI farm (distributed.hpp): doubles exact, NaN kept; read back
/// only by decode_decay of the same build.
std::string encode_decay(const VerifiedDecay& v) {
  const auto& s = v.settling;
  const auto bytes = json::to_cbor(json{v.time_s, v.site_displacement_m, s.envelope_time_s, s.envelope_m,
                                        s.sample_envelope_m, s.settling_time_s, s.frequency_hz, s.damping_ratio,
                                        v.threshold_m, v.initial_envelope_m, v.energy_error, v.dem_dissipated_j,
                                        v.structural_dissipated_j, v.steps, v.time_step_s, v.wall_time_s, v.warnings});
  return std::string(bytes.begin(), bytes.end());
}

VerifiedDecay decode_decay(const std::string& bytes) {
  const json j = json::from_cbor(bytes);
  VerifiedDecay v;
  auto& s = v.settling;
  j.at(0).get_to(v.time_s);
  j.at(1).get_to(v.site_displacement_m);
  j.at(2).get_to(s.envelope_time_s);
  j.at(3).get_to(s.envelope_m);
  j.at(4).get_to(s.sample_envelope_m);
  j.at(5).get_to(s.settling_time_s);
  j.at(6).get_to(s.frequency_hz);
  j.at(7).get_to(s.damping_ratio);
  j.at(8).get_to(v.threshold_m);
  j.at(9).get_to(v.initial_envelope_m);
  j.at(10).get_to(v.energy_error);
  j.at(11).get_to(v.dem_dissipated_j);
  j.at(12).get_to(v.structural_dissipated_j);
  j.at(13).get_to(v.steps);
  j.at(14).get_to(v.time_step_s);
  j.at(15).get_to(v.wall_time_s);
  j.at(16).get_to(v.warnings);
  return v;
}

/// One design checked by the DEM: the prediction over the verification's duration and the
/// DEM's decay over the same time.
struct DesignCheck {
  std::string name;               ///< "chosen" or "baseline"
  const opt::FillingDesign* design = nullptr;
  opt::FillingDesign predicted;   ///< the closed forms over verify.duration_s
  double predicted_end_envelope_m = NAN;
  std::vector<double> predicted_envelope_m;  ///< at the DEM's sample times
  VerifiedDecay dem;
  double dem_objective = NAN;     ///< settling time (NaN: not settled) or ½∫e² dt
  double dem_end_envelope_m = NAN;
  std::string compared;           ///< "objective", "end_envelope" or "settled_only_one"
  double relative_difference = NAN;
  bool passed = false;
  int particles = 0;
};

bool settling_objective(const Problem& p) { return p.options.objective == opt::FillingObjective::kSettlingTime; }

double predicted_objective(const Problem& p, const DesignCheck& d) {
  return settling_objective(p) ? d.predicted.settling_time_s : d.predicted.integral_square_m2_s;
}

/// a ahead of b (settles sooner, or the smaller objective): settled beats not settled; two
/// unsettled decays rank by their envelopes at the end.
bool ahead(double objective_a, double end_a, double objective_b, double end_b) {
  if (std::isfinite(objective_a) && std::isfinite(objective_b)) return objective_a < objective_b;
  if (std::isfinite(objective_a) != std::isfinite(objective_b)) return std::isfinite(objective_a);
  return end_a < end_b;
}

/// The DEM-in-the-loop decay of `design` over the verification's duration (the task's
/// decay from its initial state, the verification's softening), resumable from its
/// checkpoint in the -o folder.
VerifiedDecay verification_decay(const Case& c, const Problem& p, const case_file::VerifySpec& verify,
                                 const std::string& name, const opt::FillingDesign& design, const ParsedArgs& args) {
  const Case dc = design_case(c, design, verify.stiffness_softening);
  std::vector<st::CosimulationDamper> dem_dampers;
  for (std::size_t d = 0; d < dc.dampers.size(); ++d) dem_dampers.push_back(case_file::cosimulation_damper(dc, d));
  std::vector<st::Damper> containers = {p.options.damper};
  containers.insert(containers.end(), p.options.fixed_dampers.begin(), p.options.fixed_dampers.end());
  case_file::DecayTask decay = c.task.filling_ratios->decay;
  decay.duration_s = verify.duration_s;
  DemCheckpoint checkpoint = dem_checkpoint(args, "verify_" + name, "verify_" + name);
  std::ostringstream design_text;
  for (double n : slabs_of(design)) design_text << ' ' << n;
  design_text << "; softening " << verify.stiffness_softening;
  checkpoint.settings = "design" + design_text.str();
  // A design that completed before the interruption left no checkpoint: it runs again.
  if (checkpoint.resume && !std::filesystem::exists(checkpoint.file)) {
    checkpoint.resume = false;
    std::cerr << "pdamp: warning: no checkpoint of the " + name + " design's verification: it runs from the start\n";
  }
  return verified_decay(run_dem_decay(dc, p.modal, containers, dem_dampers, p.initial_modal_displacements, decay,
                                      "pdamp optimize --verify (" + name + ")", "/task/verify/duration_s", checkpoint));
}

/// The design against its DEM decay `dem`.
DesignCheck check_design(const Problem& p, const case_file::VerifySpec& verify, const std::string& name,
                         const opt::FillingDesign& design, VerifiedDecay dem) {
  DesignCheck out;
  out.name = name;
  out.design = &design;
  for (const auto& l : design.layers) out.particles += static_cast<int>(std::lround(l.particles));
  const std::vector<double> slabs = slabs_of(design);
  opt::FillingRatioOptions options = p.options;
  options.decay.duration_s = verify.duration_s;
  out.predicted = opt::evaluate_filling_design(p.modal, options, slabs);
  out.dem = std::move(dem);
  const auto& settle = out.dem.settling;
  out.dem_end_envelope_m = settle.envelope_m.empty() ? NAN : settle.envelope_m.back();
  out.dem_objective = settling_objective(p) ? settle.settling_time_s
                                            : half_integral_square(out.dem.time_s, settle.sample_envelope_m);

  // The prediction at the DEM's instants (its envelope for the plot and the end value).
  st::FreeDecayOptions at_samples = options.decay;
  at_samples.sample_times_s = out.dem.time_s;
  at_samples.sample_times_s.front() = 0.0;
  for (auto& t : at_samples.sample_times_s) t = std::clamp(t, 0.0, verify.duration_s);
  at_samples.sample_times_s.back() = verify.duration_s;
  std::vector<st::Damper> dampers = {opt::filling_damper(options, slabs)};
  dampers.insert(dampers.end(), options.fixed_dampers.begin(), options.fixed_dampers.end());
  const st::FreeDecay curve = st::free_decay(p.modal, dampers, at_samples);
  for (const auto& s : curve.samples) out.predicted_envelope_m.push_back(s.threshold_measure_m);
  out.predicted_end_envelope_m = out.predicted_envelope_m.empty() ? NAN : out.predicted_envelope_m.back();

  const double predicted = predicted_objective(p, out);
  if (std::isfinite(predicted) && std::isfinite(out.dem_objective)) {
    out.compared = "objective";
    out.relative_difference = (out.dem_objective - predicted) / predicted;
  } else if (!std::isfinite(predicted) && !std::isfinite(out.dem_objective)) {
    out.compared = "end_envelope";  // neither settled: how far each got
    out.relative_difference = (out.dem_end_envelope_m - out.predicted_end_envelope_m) / out.predicted_end_envelope_m;
  } else {
    out.compared = "settled_only_one";
  }
  out.passed = std::isfinite(out.relative_difference) && std::abs(out.relative_difference) <= verify.tolerance_relative;
  return out;
}

std::string seconds_or_not_settled(double t) {
  return std::isfinite(t) ? format_number(t, 4) + " s" : std::string("not settled");
}

struct Verification {
  std::vector<DesignCheck> designs;  ///< chosen, baseline
  bool predicted_chosen_ahead = false;
  bool dem_chosen_ahead = false;
  bool ranking_passed = false;
  bool passed = false;
  double wall_time_s = 0.0;
  json result;
};

json verification_json(const Problem& p, const case_file::VerifySpec& verify, double dem_softening, const Verification& v) {
  json designs = json::object();
  for (const auto& d : v.designs) {
    designs[d.name] = {
        {"slabs", slabs_of(*d.design)},
        {"particles", d.particles},
        {"bed_mass_kg", d.design->total_mass_kg},
        {"predicted", {{"settled", d.predicted.settled},
                       {"settling_time_s", number_or_null(d.predicted.settling_time_s)},
                       {"objective", number_or_null(predicted_objective(p, d))},
                       {"end_envelope_m", number_or_null(d.predicted_end_envelope_m)}}},
        {"dem", {{"settled", std::isfinite(d.dem.settling.settling_time_s)},
                 {"outcome", std::isfinite(d.dem.settling.settling_time_s) ? "settled" : "not_settled"},
                 {"settling_time_s", number_or_null(d.dem.settling.settling_time_s)},
                 {"objective", number_or_null(d.dem_objective)},
                 {"end_envelope_m", number_or_null(d.dem_end_envelope_m)},
                 {"damping_ratio", number_or_null(d.dem.settling.damping_ratio)},
                 {"threshold_m", d.dem.threshold_m},
                 {"initial_envelope_m", d.dem.initial_envelope_m},
                 {"energy_error", d.dem.energy_error},
                 {"dem_dissipated_energy_j", d.dem.dem_dissipated_j},
                 {"structural_dissipated_energy_j", d.dem.structural_dissipated_j},
                 {"steps", d.dem.steps},
                 {"time_step_s", d.dem.time_step_s},
                 {"solve_time_s", d.dem.wall_time_s}}},
        {"compared", d.compared},
        {"relative_difference", number_or_null(d.relative_difference)},
        {"passed", d.passed}};
  }
  return {{"method", "dem"},
          {"what", "DEM-in-the-loop free decay (structure::cosimulate) of the chosen and baseline designs on the "
                   "optimiser's modal model, from the task's initial state, against the closed forms over the same time"},
          {"objective", std::string(opt::to_string(p.options.objective))},
          {"duration_s", verify.duration_s},
          {"tolerance_relative", verify.tolerance_relative},
          {"stiffness_softening", verify.stiffness_softening},
          {"dem_stiffness_softening", dem_softening},
          {"effective_stiffness_softening", dem_softening * verify.stiffness_softening},
          {"require_ranking", verify.require_ranking},
          {"designs", designs},
          {"ranking", {{"predicted_chosen_ahead", v.predicted_chosen_ahead},
                       {"dem_chosen_ahead", v.dem_chosen_ahead},
                       {"passed", v.ranking_passed}}},
          {"passed", v.passed},
          {"wall_time_s", v.wall_time_s}};
}

/// The design's slabs as one number, exact for up to five layers of < 1000 slabs: an MPI
/// worker checks that its own optimisation chose the design rank 0 asks it to verify.
double design_fingerprint(const opt::FillingDesign& design) {
  double fingerprint = 0.0, place = 1.0;
  for (const double n : slabs_of(design)) fingerprint += n * place, place *= 1000.0;
  return fingerprint;
}

/// The DEM verification of the chosen and baseline designs; nothing on an MPI worker rank,
/// which runs the decay rank 0 sends it.
std::optional<Verification> verify_designs(const Case& c, const Problem& p, const opt::FillingRatioResult& r,
                                           const case_file::VerifySpec& verify, const ParsedArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const std::pair<std::string, const opt::FillingDesign*> designs[] = {{"chosen", &r.chosen}, {"baseline", &r.baseline}};
  // The two DEM runs are independent (one World each, single-threaded by default): on two
  // threads, or on two ranks under mpirun (distributed.hpp). Every rank optimised the same
  // way (NLopt's seed is fixed), which the fingerprint in the request confirms.
  distributed::TaskFarm farm([&](const distributed::Request& request) {
    const auto& [name, design] = designs[static_cast<std::size_t>(request[0])];
    if (design_fingerprint(*design) != request[1])
      throw std::runtime_error("its optimisation chose another " + name + " design than rank 0's: the ranks differ");
    return encode_decay(verification_decay(c, p, verify, name, *design, args));
  });
  if (distributed::worker()) {
    farm.serve();
    return std::nullopt;
  }
  std::vector<VerifiedDecay> decays(2);
  distributed::run_concurrently(2, true, [&](std::size_t k) {
    decays[k] = decode_decay(farm.evaluate({static_cast<double>(k), design_fingerprint(*designs[k].second)}));
  });
  Verification v;
  for (std::size_t k = 0; k < 2; ++k)
    v.designs.push_back(check_design(p, verify, designs[k].first, *designs[k].second, std::move(decays[k])));
  const DesignCheck& a = v.designs[0];
  const DesignCheck& b = v.designs[1];
  v.predicted_chosen_ahead = ahead(predicted_objective(p, a), a.predicted_end_envelope_m, predicted_objective(p, b),
                                   b.predicted_end_envelope_m);
  v.dem_chosen_ahead = ahead(a.dem_objective, a.dem_end_envelope_m, b.dem_objective, b.dem_end_envelope_m);
  v.ranking_passed = v.dem_chosen_ahead;
  v.passed = a.passed && b.passed && (!verify.require_ranking || v.ranking_passed);
  v.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  v.result = verification_json(p, verify, c.dem.stiffness_softening, v);
  if (const json balance = farm.balance(); !balance.is_null()) v.result["mpi"] = balance;
  return v;
}

/// verify_decay.csv (one block per design: the DEM's site displacement and envelope and the
/// predicted envelope at the same instants) and its plot.
std::vector<std::string> write_verification_files(OutputDir& files, const Case& c, const Verification& v) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "# design, time_s, site_displacement_m (DEM), dem_envelope_m, predicted_envelope_m, threshold_m; "
         "one block per design (chosen, then baseline), blocks separated by two blank lines\n";
  csv << "design,time_s,site_displacement_m,dem_envelope_m,predicted_envelope_m,threshold_m\n";
  for (std::size_t k = 0; k < v.designs.size(); ++k) {
    const auto& d = v.designs[k];
    if (k > 0) csv << "\n\n";
    for (std::size_t i = 0; i < d.dem.time_s.size(); ++i)
      csv << d.name << ',' << d.dem.time_s[i] << ',' << d.dem.site_displacement_m[i] << ',' << d.dem.settling.sample_envelope_m[i] << ','
          << (i < d.predicted_envelope_m.size() ? d.predicted_envelope_m[i] : NAN) << ',' << d.dem.threshold_m << '\n';
  }
  files.add("verify_decay.csv", csv.str());
  std::ostringstream gp;
  gp << "# DEM verification of pdamp optimize: envelopes, DEM against the closed forms; run: gnuplot verify_decay.gp\n"
     << "set datafile separator ','\n"
     << "set title " << gnuplot_string(c.name + ": DEM verification (DEM in the loop vs closed forms)") << " noenhanced\n"
     << "set xlabel 'time t / s'\nset ylabel 'envelope at the damper site / mm'\nset grid\nset key top right\n"
     << "set logscale y\n"
     << "do for [t in 'pngcairo svg'] {\n"
     << "  set terminal t size 900,600 enhanced font 'Sans,11'\n"
     << "  set output (t eq 'svg') ? 'verify_decay.svg' : 'verify_decay.png'\n"
     << "  plot 'verify_decay.csv' index 0 using 2:($4*1e3) every ::1 with lines lw 2 lc rgb 'blue' title 'chosen, DEM', \\\n"
     << "       '' index 0 using 2:($5*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'blue' title 'chosen, closed forms', \\\n"
     << "       '' index 1 using 2:($4*1e3) every ::1 with lines lw 2 lc rgb 'red' title 'best single layer, DEM', \\\n"
     << "       '' index 1 using 2:($5*1e3) every ::1 with lines lw 1 dt 2 lc rgb 'red' title 'best single layer, closed forms', \\\n"
     << "       '' index 0 using 2:($6*1e3) every ::1 with lines lw 1 dt 3 lc rgb 'black' title 'threshold'\n"
     << "}\n";
  return files.add_plot("verify_decay.gp", gp.str(), {"verify_decay.png", "verify_decay.svg"});
}

std::vector<std::pair<std::string, std::string>> verification_rows(const Problem& p, const Verification& v,
                                                                   const case_file::VerifySpec& verify) {
  std::vector<std::pair<std::string, std::string>> rows;
  const bool settling = settling_objective(p);
  for (const auto& d : v.designs) {
    const double pred = predicted_objective(p, d);
    std::string line = settling ? "predicted " + seconds_or_not_settled(pred) + ", DEM " + seconds_or_not_settled(d.dem_objective)
                                : "predicted " + format_number(pred, 4) + " m2 s, DEM " + format_number(d.dem_objective, 4) + " m2 s";
    line += "; end envelope predicted " + format_number(d.predicted_end_envelope_m * 1e3, 4) + " mm, DEM " +
            format_number(d.dem_end_envelope_m * 1e3, 4) + " mm; energy error " +
            format_number(d.dem.energy_error, 2) + "; " +
            (d.compared == "settled_only_one" ? std::string("only one settled")
                                              : "difference " + format_number(100.0 * d.relative_difference, 3) + " %") +
            ": " + (d.passed ? "pass" : "FAIL");
    rows.push_back({"verify " + d.name, line});
  }
  rows.push_back({"verify ranking", std::string("chosen ahead of baseline: predicted ") +
                                        (v.predicted_chosen_ahead ? "yes" : "no") + ", DEM " +
                                        (v.dem_chosen_ahead ? "yes" : "no") + (v.ranking_passed ? ": pass" : ": FAIL")});
  rows.push_back({"verification", std::string(v.passed ? "PASS" : "FAIL") + " (tolerance " +
                                      format_number(100.0 * verify.tolerance_relative, 3) + " %, " +
                                      format_number(verify.duration_s, 4) + " s simulated each, " +
                                      format_number(v.wall_time_s, 4) + " s wall)"});
  return rows;
}

}  // namespace

int run_optimize_task(const ParsedArgs& args, const Case& c) {
  // Under mpirun only the verification's DEM runs are spread over the ranks.
  if (distributed::worker() && c.task.kind != case_file::TaskKind::kFillingRatios) return kExitOk;
  if (c.task.kind == case_file::TaskKind::kPlacement && c.task.placement) return run_placement_task(args, c);
  if (c.task.kind != case_file::TaskKind::kFillingRatios || !c.task.filling_ratios)
    throw InputError(c.path, "/task",
                     "pdamp optimize needs a task of kind filling_ratios or placement (this case's task is '" +
                         std::string(case_file::to_string(c.task.kind)) +
                         "'): give \"task\": {\"kind\": \"filling_ratios\", \"mass_budget_kg\", \"initial_state\", "
                         "\"duration_s\"} or {\"kind\": \"placement\", \"targets\"} (docs/cases.md, Format 2)");
  if (args.has("--method"))
    throw InputError("--method", "", "task kind filling_ratios uses the closed forms of each layer (formulas) only");
  const FillingRatiosTask& task = *c.task.filling_ratios;
  std::unique_ptr<OutputDir> files;  // none on an MPI worker rank: rank 0 writes
  if (const auto dir = args.optional_text("-o"); dir && !distributed::worker()) files = std::make_unique<OutputDir>(*dir);
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

  // The DEM verification: the task's verify block, or --verify with its defaults.
  if (args.has("--verify") && args.has("--no-verify"))
    throw InputError("--verify", "", "and --no-verify exclude each other");
  std::optional<case_file::VerifySpec> verify = task.verify;
  if (!verify && args.has("--verify")) {
    verify = case_file::VerifySpec{};
    verify->duration_s = task.decay.duration_s;
  }
  if (args.has("--no-verify")) verify.reset();
  std::optional<Verification> verification;
  if (!verify)
    for (const auto& flag : kCheckpointFlags)
      if (args.has(flag.name)) throw InputError(flag.name, "", "applies to the DEM verification (--verify)");
  if (distributed::worker() && !verify) return kExitOk;  // rank 0 alone
  if (verify) {
    verification = verify_designs(c, p, r, *verify, args);
    if (!verification) return kExitOk;  // an MPI worker: rank 0 reports
    for (const auto& d : verification->designs)
      for (const auto& w : d.dem.warnings) warnings.push_back("verify (" + d.name + "): " + w);
    if (!verification->passed)
      warnings.push_back("the DEM verification failed (tolerance " + format_number(verify->tolerance_relative, 3) +
                         (verification->ranking_passed ? "" : "; the DEM does not rank the chosen design ahead of the baseline") +
                         "): see verification in the result");
  }

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
  result["verification"] = verification ? verification->result : json(nullptr);
  json outputs = json::array();
  if (files) {
    try {
      for (auto& w : write_files(*files, c, p, r)) warnings.push_back(w);
      if (verification)
        for (auto& w : write_verification_files(*files, c, *verification)) warnings.push_back(w);
    } catch (const std::invalid_argument& e) {
      throw NumericalError(std::string("pdamp optimize: the comparison decays failed: ") + e.what());
    }
    result["file"] = (files->dir() / "optimize.json").string();
    result["warnings"] = warnings;
    files->add_json("case_resolved.json", c.resolved);
    files->add_json("optimize.json", result);
    stage_run_report(*files, c, result, warnings);
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
  if (verification)
    for (auto& row : verification_rows(p, *verification, *verify)) rows.push_back(std::move(row));
  for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
  std::cout << key_value_table(rows);
  return kExitOk;
}

Command optimize_command() {
  return {{"optimize", "pdamp optimize CASE.json [--backend nlopt|ipopt] [--method formulas|field] [--verify|--no-verify] [--resume] [-o DIR] [--json]",
           "optimise the case's task (kind filling_ratios: whole slabs per layer of the first damper\n"
           "for the fastest free decay under a particle-mass budget; relaxed solve, rounded\n"
           "neighbours, single-layer baseline; with the task's verify block or --verify, the\n"
           "DEM-in-the-loop check of the chosen and baseline designs. Kind placement: the site\n"
           "along a beam, or among named points, where the damper adds the most damping to the\n"
           "target modes; docs/optimizer.md)",
           concat_flags({kBackendFlag,
            {"--method", "M", "placement only: each layer's eta*(f, X) from formulas (the closed forms;\n"
                              "                          default) or field (its field_file); filling_ratios uses formulas"},
            kVerifyFlag, kNoVerifyFlag,
            {"-o", "DIR", "write optimize.json, designs.csv, decay_compare.csv, decay_compare.gp/png/svg,\n"
                          "                          case_resolved.json and with the verification verify_decay.csv,\n"
                          "                          verify_decay.gp/png/svg into DIR, atomically (placement:\n"
                          "                          placement.json, placement.csv, placement.gp/png/svg; the verification's\n"
                          "                          verify_chosen.checkpoint, verify_baseline.checkpoint while running)"},
            {"--json", "", "print exactly one JSON object on stdout"}}, kCheckpointFlags),
           1},
          [](const ParsedArgs& args) { return run_optimize_task(args, case_file::load_case(args.positional().at(0))); },
          true};
}

}  // namespace pdamp::cli
