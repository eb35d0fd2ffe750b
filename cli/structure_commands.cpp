// pdamp modes, frf and decay: read a format-2 case, build its structure and dampers
// (case_file::structure_setup), call the structure solvers, print and write the results
// (docs/structure_cli.md). The physics lives in structure/; here are flags, calls and output.
#include "structure_commands.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <iostream>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <chrono>
#include <exception>
#include <filesystem>
#include <functional>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "distributed.hpp"
#include "errors.hpp"
#include "output.hpp"
#include "output.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/strict_json/input_file.hpp"
#include "pdamp/strict_json/output_file.hpp"
#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/cosimulation.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/harmonic_balance.hpp"
#include "pdamp/structure/sampled_response.hpp"
#include "output.hpp"
#include "output.hpp"

namespace pdamp::cli {

const FlagSpec kMethodFlag{"--method", "M",
                           "source of each layer's eta*(f, X) and apparent mass: formulas (the closed\n"
                           "                          forms of its model and clearance; default), field (the\n"
                           "                          layer's field_file, made by pdamp field) or dem (frf and\n"
                           "                          decay only: the structure co-simulated in time with each\n"
                           "                          damper's bed as a DEM world, the case's dem settings)"};
const std::vector<FlagSpec> kDemSweepFlags{
    {"--dem-points", "N",
     "--method dem: frequencies of the stepped sine, linear over its band,\n"
     "                          [2, 1000] (default 9)"},
    {"--dem-min-frequency", "HZ", "--method dem: lowest frequency of the stepped sine, Hz, > 0\n"
                                  "                          (default: the task's min_frequency_hz)"},
    {"--dem-max-frequency", "HZ", "--method dem: highest frequency of the stepped sine, Hz, above the\n"
                                  "                          lowest (default: the task's max_frequency_hz)"},
    {"--dem-sweep", "D", "--method dem: up, down or both (default both: the two directions\n"
                         "                          run in parallel on a machine of two or more cores)"},
    {"--dem-signal", "S", "--method dem: stepped (a stepped sine, default) or linear (a linear sine\n"
                          "                          sweep over the band, from the steady state at its start)"},
    {"--dem-sweep-rate", "HZ/S", "--dem-signal linear: the sweep's rate, Hz/s, > 0 (default: 4 pi zeta^2 f^2 / 100\n"
                                 "                          at the formulas' resonance: quasi-stationary)"}};

case_file::LossMethod loss_method(const ParsedArgs& args) {
  const std::string name = args.optional_text("--method").value_or("formulas");
  if (name == "formulas") return case_file::LossMethod::kFormulas;
  if (name == "field") return case_file::LossMethod::kField;
  if (name == "dem")
    throw InputError("--method", "", "'dem': pdamp modes takes formulas or field (the DEM co-simulation runs in "
                                     "pdamp frf and pdamp decay)");
  throw InputError("--method", "", "'" + name + "': must be formulas, field or dem");
}

namespace {

using nlohmann::json;
namespace st = structure;
using case_file::Case;
using case_file::TaskKind;


const FlagSpec kJsonFlag{"--json", "", "print exactly one JSON object on stdout"};

/// Default backbone range when the case's task is not `modes`: 40 log-spaced damper
/// amplitudes from 1 mm to twice the largest clearance of the reference damper's layers.
constexpr int kDefaultBackbonePoints = 40;
constexpr double kDefaultBackboneMinM = 1e-3;
constexpr double kDefaultBackboneMaxOverClearance = 2.0;
/// A mode in which the reference damper moves less than this fraction of its largest
/// drive shape gets no backbone (its amplitude there would be meaningless).
constexpr double kNoMotionFraction = 1e-9;
/// Free-decay samples: about 50 per period of the first mode, at least 2000, at most 20000.
constexpr double kDecaySamplesPerPeriod = 50.0;
constexpr double kDecayMinSamples = 2000.0;
constexpr double kDecayMaxSamples = 20000.0;

/// Warnings collected once each, in order.
class Warnings {
 public:
  void add(const std::string& w) {
    if (seen_.insert(w).second) list_.push_back(w);
  }
  void add(const std::vector<std::string>& ws, const std::string& prefix = "") {
    for (const auto& w : ws) add(prefix + w);
  }
  const std::vector<std::string>& list() const { return list_; }
  /// One line each on stderr (made printable: a name with a newline cannot split it).
  void print() const {
    for (const auto& w : list_) std::cerr << "pdamp: warning: " << strict_json::printable(w) << "\n";
  }

 private:
  std::vector<std::string> list_;
  std::set<std::string> seen_;
};

/// A number, or null where the solver defines none (NaN: a half-power point outside the
/// grid, a decay that did not settle).
json number_or_null(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

/// `--method dem`: the DEM co-simulation (pdamp frf and decay only).
bool dem_method(const ParsedArgs& args) { return args.optional_text("--method").value_or("") == "dem"; }


/// The -o folder, or none; none on an MPI worker rank, which writes nothing (rank 0 checks
/// the folder and writes the results, distributed.hpp).
std::unique_ptr<OutputDir> output_dir(const ParsedArgs& args) {
  if (distributed::worker()) return nullptr;
  if (const auto dir = args.optional_text("-o")) return std::make_unique<OutputDir>(*dir);
  return nullptr;
}

/// The task a command needs, or exit 2 naming /task and what is missing.
void require_task(const Case& c, TaskKind kind, bool present, const std::string& needed) {
  if (c.task.kind == kind && present) return;
  const std::string name(case_file::to_string(kind));
  throw InputError(c.path, "/task",
                   "pdamp " + name + " needs a task of kind " + name + " (this case's task is '" +
                       std::string(case_file::to_string(c.task.kind)) + "'): give \"task\": {\"kind\": \"" + name +
                       "\", " + needed + "} (docs/cases.md, Format 2)");
}

/// A structure solver's std::invalid_argument is a property of the case: exit 2 naming it.
template <class F>
auto call_solver(const Case& c, const std::string& pointer, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    throw InputError(c.path, pointer, e.what());
  }
}

/// The case's structure and dampers, built for `method`, with the setup's warnings.
struct Setup {
  case_file::LossMethod method;
  case_file::StructureSetup s;
  Warnings warnings;
};

/// `rotation_check`: warn where a site rotates (the loss models assume pure translation;
/// the DEM co-simulation turns the container with the site and needs no such warning).
Setup make_setup(const Case& c, case_file::LossMethod method, bool rotation_check = true) {
  Setup out{method, case_file::structure_setup(c, method), {}};
  out.warnings.add(out.s.warnings);
  if (rotation_check) out.warnings.add(st::rotation_warnings(out.s.modal, out.s.dampers));
  if (out.s.rigid_modes_dropped > 0)
    out.warnings.add("the structure has " + std::to_string(out.s.rigid_modes_dropped) +
                     " rigid-body mode(s) at 0 Hz; they are not kept (docs/structures.md)");
  return out;
}

std::vector<std::string> damper_names(const Setup& setup) {
  std::vector<std::string> names;
  for (const auto& d : setup.s.dampers) names.push_back(d.name);
  return names;
}

std::vector<std::string> layer_names(const Setup& setup) {
  std::vector<std::string> names;
  for (const auto& d : setup.s.dampers)
    for (const auto& l : d.layers) names.push_back(d.name + "/" + l.name);
  return names;
}

std::vector<double> spaced(double lo, double hi, int n, bool log) {
  std::vector<double> v(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = n == 1 ? 0.0 : static_cast<double>(i) / (n - 1);
    v[static_cast<std::size_t>(i)] = log ? std::exp(std::log(lo) + s * (std::log(hi) - std::log(lo))) : lo + s * (hi - lo);
  }
  v.back() = hi;
  return v;
}

/// The common head of every structure result: what ran, on which case, with which method.
json result_head(const Case& c, const std::string& task, case_file::LossMethod method) {
  return {{"task", task}, {"case", c.name}, {"method", case_file::to_string(method)}};
}

/// Commits the files (with the result JSON and the resolved case), prints the warnings
/// and the result.
int finish(const ParsedArgs& args, const Case& c, OutputDir* files, const std::string& json_name, json& result,
           Warnings& warnings, const std::vector<std::pair<std::string, std::string>>& table) {
  json outputs = json::array();
  if (files) {
    result["warnings"] = warnings.list();
    files->add_json("case_resolved.json", c.resolved);
    files->add_json(json_name, result);
    stage_run_report(*files, c, result, warnings.list());
    outputs = files->commit();
  }
  result["warnings"] = warnings.list();
  result["outputs"] = outputs;
  warnings.print();
  if (args.has("--json")) {
    std::cout << result.dump(2) << "\n";
  } else {
    auto rows = table;
    rows.insert(rows.begin(), {"case", c.name});
    for (const auto& path : outputs) rows.push_back({"wrote", path.get<std::string>()});
    std::cout << key_value_table(rows);
  }
  return kExitOk;
}

std::string file_or_empty(const OutputDir* files, const std::string& name) {
  return files ? (files->dir() / name).string() : std::string();
}
json file_json(const OutputDir* files, const std::string& name) {
  return files ? json(file_or_empty(files, name)) : json(nullptr);
}

// ---------------------------------------------------------------- modes

int run_modes_case(const ParsedArgs& args, const Case& c) {
  const auto method = loss_method(args);
  auto files = output_dir(args);
  Setup setup = make_setup(c, method);
  const st::ModalModel& modal = setup.s.modal;
  const auto& dampers = setup.s.dampers;

  Eigen::Index mode_count = modal.mode_count();
  const bool from_task = c.task.kind == TaskKind::kModes && c.task.modes.has_value();
  if (from_task && c.task.modes->mode_count > 0) mode_count = std::min<Eigen::Index>(mode_count, c.task.modes->mode_count);

  // Backbone amplitudes of the reference damper (the first).
  double lo = kDefaultBackboneMinM, hi = 0.0;
  int points = kDefaultBackbonePoints;
  if (from_task) {
    lo = c.task.modes->backbone_min_amplitude_m;
    hi = c.task.modes->backbone_max_amplitude_m;
    points = c.task.modes->backbone_points;
  } else {
    for (const auto& layer : c.dampers.front().layers) hi = std::max(hi, kDefaultBackboneMaxOverClearance * layer.clearance_m);
    if (!(hi > lo)) lo = hi / 100.0;
  }
  const auto amplitudes = spaced(lo, hi, points, true);

  std::vector<st::Damper> containers = dampers;
  for (auto& d : containers) d.layers.clear();
  const auto empty = call_solver(c, "/dampers", [&] { return st::couple(modal, containers); });
  const auto coupled = call_solver(c, "/dampers", [&] { return st::couple(modal, dampers); });
  const Eigen::VectorXd with_containers = st::natural_frequencies_with_containers_hz(empty);

  // μ_dj = b_dj² Σ_l m_bed,l / m_j.
  Eigen::MatrixXd mass_ratio(mode_count, static_cast<Eigen::Index>(dampers.size()));
  for (Eigen::Index d = 0; d < mass_ratio.cols(); ++d) {
    double bed = 0.0;
    for (const auto& l : dampers[static_cast<std::size_t>(d)].layers) bed += l.bed_mass_kg;
    for (Eigen::Index j = 0; j < mode_count; ++j)
      mass_ratio(j, d) = coupled.drive_shapes(j, d) * coupled.drive_shapes(j, d) * bed / coupled.modal_masses_kg[j];
  }

  std::vector<st::Backbone> backbones;
  std::map<Eigen::Index, std::size_t> backbone_of_mode;
  const double largest_drive = coupled.drive_shapes.col(0).cwiseAbs().maxCoeff();
  bool all_converged = true;
  std::map<std::string, std::vector<Eigen::Index>> backbone_warnings;  // sentence -> modes (1-based)
  for (Eigen::Index j = 0; j < mode_count; ++j) {
    if (!(std::abs(coupled.drive_shapes(j, 0)) > kNoMotionFraction * largest_drive)) {
      setup.warnings.add("mode " + std::to_string(j + 1) + ": damper " + dampers.front().name +
                         " does not move along its drive in this mode: no backbone");
      continue;
    }
    st::BackboneOptions options;
    options.mode = static_cast<int>(j);
    options.reference_damper = 0;
    options.damper_amplitudes_m = amplitudes;
    auto b = call_solver(c, "/task", [&] { return st::backbone(modal, dampers, options); });
    for (const auto& p : b.points) all_converged = all_converged && p.converged;
    for (const auto& w : b.warnings) backbone_warnings[w].push_back(j + 1);
    backbone_of_mode[j] = backbones.size();
    backbones.push_back(std::move(b));
  }
  for (const auto& [sentence, modes] : backbone_warnings) {
    std::string list;
    for (const auto m : modes) list += (list.empty() ? "" : ", ") + std::to_string(m);
    setup.warnings.add("backbone (mode" + std::string(modes.size() > 1 ? "s " : " ") + list + "): " + sentence);
  }
  for (Eigen::Index j = 0; j < mode_count; ++j)
    if (!std::isfinite(with_containers[j]) || !std::isfinite(modal.natural_frequencies_hz[j]))
      throw NumericalError("pdamp modes: the natural frequency of mode " + std::to_string(j + 1) + " is not finite");

  json modes = json::array();
  std::vector<std::pair<std::string, std::string>> rows;
  for (Eigen::Index j = 0; j < mode_count; ++j) {
    json shapes = json::object();
    for (const auto& p : modal.points)
      shapes[p.name] = {{"translation_x", p.translation(0, j)}, {"translation_y", p.translation(1, j)},
                        {"rotation", p.rotation(j)}};
    json ratio_per_damper = json::object(), drive = json::object();
    double ratio_total = 0.0;
    for (std::size_t d = 0; d < dampers.size(); ++d) {
      const auto col = static_cast<Eigen::Index>(d);
      ratio_per_damper[dampers[d].name] = mass_ratio(j, col);
      drive[dampers[d].name] = coupled.drive_shapes(j, col);
      ratio_total += mass_ratio(j, col);
    }
    json mode = {{"mode", j + 1},
                 {"frequency_hz", with_containers[j]},
                 {"bare_frequency_hz", modal.natural_frequencies_hz[j]},
                 {"damping_ratio", modal.damping_ratios[j]},
                 {"modal_mass_kg", modal.modal_masses_kg[j]},
                 {"modal_mass_ratio", ratio_total},
                 {"modal_mass_ratio_per_damper", ratio_per_damper},
                 {"drive_shape_per_damper", drive},
                 {"shapes", shapes},
                 {"backbone", nullptr}};
    std::string row = format_number(with_containers[j], 6) + " Hz (bare " + format_number(modal.natural_frequencies_hz[j], 6) +
                      " Hz), mu = " + format_number(ratio_total, 4);
    if (const auto it = backbone_of_mode.find(j); it != backbone_of_mode.end()) {
      const auto& b = backbones[it->second];
      const auto best = std::max_element(b.points.begin(), b.points.end(), [](const auto& a, const auto& x) {
        return a.added_damping_ratio < x.added_damping_ratio;
      });
      double f_min = b.points.front().damped_frequency_hz, f_max = f_min;
      for (const auto& p : b.points) f_min = std::min(f_min, p.damped_frequency_hz), f_max = std::max(f_max, p.damped_frequency_hz);
      mode["backbone"] = {{"file", file_json(files.get(), "backbone_mode" + std::to_string(j + 1) + ".csv")},
                          {"points", b.points.size()},
                          {"modal_mass_ratio", b.modal_mass_ratio},
                          {"max_added_damping_ratio", best->added_damping_ratio},
                          {"max_added_damping_amplitude_m", best->damper_amplitude_m},
                          {"min_damped_frequency_hz", f_min},
                          {"max_damped_frequency_hz", f_max}};
      row += ", zeta_add max " + format_number(best->added_damping_ratio, 4) + " at X = " +
             format_number(best->damper_amplitude_m, 4) + " m";
    }
    rows.push_back({"mode " + std::to_string(j + 1), row});
    modes.push_back(std::move(mode));
  }

  if (files) {
    ModeTable table;
    for (Eigen::Index j = 0; j < mode_count; ++j) {
      table.frequency_hz.push_back(with_containers[j]);
      table.bare_frequency_hz.push_back(modal.natural_frequencies_hz[j]);
      table.damping_ratio.push_back(modal.damping_ratios[j]);
    }
    table.damper_names = damper_names(setup);
    table.mass_ratio = mass_ratio;
    table.points = modal.points;
    write_modes_table(*files, table);
    setup.warnings.add(write_backbone_files(*files, backbones, layer_names(setup),
                                            c.name + ": backbones (" + std::string(case_file::to_string(method)) + ")"));
  }
  if (!all_converged) setup.warnings.add("some backbone points did not converge (converged = 0 in backbone_mode<j>.csv)");

  json result = result_head(c, "modes", method);
  result["file"] = file_json(files.get(), "modes.csv");
  result["modes"] = modes;
  result["frequencies"] =
      "frequency_hz: natural frequencies with the empty containers attached (beds removed); bare_frequency_hz: "
      "the structure alone; damping_ratio: the structural modal damping ratio";
  result["rigid_modes_dropped"] = setup.s.rigid_modes_dropped;
  result["backbone"] = {{"reference_damper", dampers.front().name},
                        {"amplitude_source", from_task ? "task" : "default"},
                        {"min_amplitude_m", lo},
                        {"max_amplitude_m", hi},
                        {"points", points},
                        {"spacing", "log"},
                        {"plot", file_json(files.get(), "backbone.png")}};
  result["outcome"] = all_converged ? "converged" : "not_converged";
  rows.insert(rows.begin(), {"method", std::string(case_file::to_string(method))});
  return finish(args, c, files.get(), "modes.json", result, setup.warnings, rows);
}

// ---------------------------------------------------------------- frf

std::string_view branch_end_kind(st::BranchEnd::Kind kind) {
  switch (kind) {
    case st::BranchEnd::Kind::kFold: return "fold";
    case st::BranchEnd::Kind::kDiscontinuity: return "discontinuity";
    case st::BranchEnd::Kind::kStrokeRange: return "stroke_range";
  }
  return "";
}

json peaks_json(const std::vector<st::ResponsePeak>& peaks, const std::vector<std::string>& names) {
  json out = json::array();
  for (const auto& p : peaks)
    out.push_back({{"output", p.output < names.size() ? names[p.output] : std::to_string(p.output)},
                   {"frequency_hz", p.frequency_hz},
                   {"magnitude", p.magnitude},
                   {"damping_ratio", number_or_null(p.damping_ratio)},
                   {"band_centre_hz", number_or_null(p.band_centre_hz)}});
  return out;
}

int run_frf_dem(const ParsedArgs& args, const Case& c, OutputDir* files);
int run_frf_compare(const ParsedArgs& args, const Case& c);
int run_frf_dem_linear(const ParsedArgs& args, const Case& c, OutputDir* files);

/// The frf task's excitation, checked against the modal model (exit 2 naming /task/excitation).
st::Excitation task_excitation(const Case& c, const st::ModalModel& modal) {
  const auto& task = *c.task.frf;
  st::Excitation excitation;
  excitation.direction = {task.direction[0], task.direction[1]};
  if (task.excitation == case_file::FrfTask::Excitation::kBase) {
    excitation.kind = st::Excitation::Kind::kBaseTranslation;
    excitation.amplitude = task.base_amplitude_m;
  } else {
    excitation.kind = st::Excitation::Kind::kPointForce;
    excitation.amplitude = task.force_amplitude_n;
    excitation.point = task.force_point;
  }
  if (const auto problems = excitation.validate(modal); !problems.empty())
    throw InputError(c.path, "/task/excitation", problems.front());
  return excitation;
}

/// The harmonic balance over the frf task's frequencies for the setup's loss models.
st::FrequencyResponse task_harmonic_balance(const Case& c, const Setup& setup, const st::Excitation& excitation) {
  const auto& task = *c.task.frf;
  st::HarmonicBalanceOptions options;
  options.frequencies_hz = spaced(task.min_frequency_hz, task.max_frequency_hz, task.points,
                                  task.spacing == surrogate::AxisSpacing::kLog);
  return call_solver(c, "/task", [&] { return st::harmonic_balance(setup.s.modal, setup.s.dampers, excitation, options); });
}

int run_frf_case(const ParsedArgs& args, const Case& c) {
  require_task(c, TaskKind::kFrf, c.task.frf.has_value(),
               "\"min_frequency_hz\", \"max_frequency_hz\", \"excitation\"");
  if (args.has("--compare")) {
    if (args.optional_text("--method"))
      throw InputError("--compare", "", "runs every method (formulas, field, dem): give no --method with it");
    return run_frf_compare(args, c);
  }
  if (dem_method(args)) {
    auto dem_files = output_dir(args);
    return run_frf_dem(args, c, dem_files.get());
  }
  if (distributed::worker()) return kExitOk;  // the harmonic balance: rank 0 alone
  const auto method = loss_method(args);
  auto files = output_dir(args);
  Setup setup = make_setup(c, method);
  const auto& task = *c.task.frf;

  const st::Excitation excitation = task_excitation(c, setup.s.modal);
  const bool base = excitation.kind == st::Excitation::Kind::kBaseTranslation;
  const auto response = task_harmonic_balance(c, setup, excitation);

  std::size_t with_state = 0, held = 0;
  for (const auto& p : response.points) {
    if (!p.roots.empty() || !p.held_at_jump.empty()) ++with_state;
    if (!p.held_at_jump.empty()) ++held;
  }
  if (with_state == 0)
    throw NumericalError("pdamp frf: no first-harmonic response found at any frequency (" + response.brief_report() +
                         "); check the excitation amplitude against the layers' stroke range, or try --method formulas");
  for (const auto& p : response.peaks)
    if (!std::isfinite(p.frequency_hz) || !std::isfinite(p.magnitude))
      throw NumericalError("pdamp frf: a response peak is not finite (" + response.brief_report() + ")");
  setup.warnings.add(response.warnings);
  const bool converged = response.outcome == st::FrequencyResponse::Outcome::kConverged;
  if (!converged)
    setup.warnings.add("some roots did not converge (" + std::to_string(response.unconverged_starts) +
                       " Newton starts failed): the response may miss branches");

  // Branches: the frequency span and stability of each.
  struct BranchInfo {
    double f_min = INFINITY, f_max = -INFINITY, x_max = 0.0;
    std::size_t points = 0, stable = 0, unstable = 0, marginal = 0;
  };
  std::map<int, BranchInfo> info;
  for (const auto& p : response.points)
    for (const auto& r : p.roots) {
      auto& b = info[r.branch_id];
      b.f_min = std::min(b.f_min, p.frequency_hz);
      b.f_max = std::max(b.f_max, p.frequency_hz);
      if (!r.damper_amplitudes_m.empty()) b.x_max = std::max(b.x_max, r.damper_amplitudes_m.front());
      ++b.points;
      (r.stability == st::Stability::kStable ? b.stable : r.stability == st::Stability::kUnstable ? b.unstable : b.marginal)++;
    }
  json branches = json::array();
  for (const auto& [id, b] : info)
    branches.push_back({{"branch", id}, {"min_frequency_hz", b.f_min}, {"max_frequency_hz", b.f_max},
                        {"points", b.points}, {"stable_points", b.stable}, {"unstable_points", b.unstable},
                        {"marginal_points", b.marginal}, {"max_amplitude_m", b.x_max}});
  json jumps = json::array();
  for (const auto& e : response.branch_ends) {
    json j = {{"kind", branch_end_kind(e.kind)}, {"frequency_hz", e.frequency_hz}, {"amplitude_m", e.damper_amplitude_m},
              {"branch", e.branch_id}, {"branch_exists_below", e.ends_toward_higher_frequency}};
    if (e.kind == st::BranchEnd::Kind::kFold) j["other_branch"] = e.other_branch_id;
    jumps.push_back(std::move(j));
  }

  const std::string magnitude_label = base ? "transmissibility |X/U|" : "receptance |X/F| / (m/N)";
  if (files)
    setup.warnings.add(write_frf_files(*files, response, damper_names(setup), magnitude_label,
                                       c.name + ": frequency response (" + std::string(case_file::to_string(method)) + ")"));

  const json peaks = peaks_json(response.peaks, response.output_names);
  json frf = {{"file", file_json(files.get(), "frf.csv")},
              {"branches_file", file_json(files.get(), "frf_branches.csv")},
              {"plot", file_json(files.get(), "frf.png")},
              {"method", case_file::to_string(method)},
              {"outputs", response.output_names},
              {"magnitude", base ? "transmissibility |X/U| (absolute site motion over base amplitude)"
                                 : "receptance |X/F| in m/N"},
              {"excitation", base ? "base" : "force"},
              {"frequencies", {{"min_hz", response.points.front().frequency_hz},
                               {"max_hz", response.points.back().frequency_hz},
                               {"points", response.points.size()},
                               {"spacing", task.spacing == surrogate::AxisSpacing::kLog ? "log" : "linear"}}},
              {"peaks", peaks},
              {"linear_peaks", peaks_json(response.linear_peaks, response.output_names)},
              {"jumps", jumps},
              {"branches", branches},
              {"held_at_jump_points", held},
              {"outcome", converged ? "converged" : "some_roots_not_converged"},
              {"loss_evaluations", response.loss_evaluations},
              {"solve_time_s", response.solve_time_s},
              {"report", response.brief_report()},
              {"warnings", setup.warnings.list()}};
  json result = result_head(c, "frf", method);
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["branches"] = branches;
  result["frf"] = frf;

  std::vector<std::pair<std::string, std::string>> rows = {{"method", std::string(case_file::to_string(method))},
                                                            {"outcome", frf["outcome"].get<std::string>()}};
  for (const auto& p : response.peaks)
    rows.push_back({"peak " + response.output_names[p.output],
                    format_number(p.frequency_hz, 6) + " Hz, |out| = " + format_number(p.magnitude, 4) +
                        (std::isfinite(p.damping_ratio) ? ", zeta = " + format_number(p.damping_ratio, 4) : "")});
  for (const auto& p : response.linear_peaks)
    rows.push_back({"without beds " + response.output_names[p.output],
                    format_number(p.frequency_hz, 6) + " Hz, |out| = " + format_number(p.magnitude, 4)});
  for (const auto& e : response.branch_ends)
    if (e.kind != st::BranchEnd::Kind::kStrokeRange)
      rows.push_back({std::string(branch_end_kind(e.kind)), format_number(e.frequency_hz, 6) + " Hz, X = " +
                                                                 format_number(e.damper_amplitude_m, 4) + " m"});
  result["frf"]["warnings"] = setup.warnings.list();
  return finish(args, c, files.get(), "frf.json", result, setup.warnings, rows);
}

// ---------------------------------------------------------------- decay


/// The loss models' own sentences (with numbers) at one sample: each layer at its damper's
/// amplitude and the frequency the decay uses for the dominant mode there (its backbone's
/// natural frequency with containers and beds, structure::backbone_point).
void add_loss_messages(Warnings& warnings, const Setup& setup, const st::CoupledModel& coupled,
                       const st::DecaySample& s, const std::string& when) {
  Eigen::Index dominant = 0;
  s.modal_amplitudes.maxCoeff(&dominant);
  const double f =
      st::backbone_point(coupled, static_cast<int>(dominant), s.modal_amplitudes[dominant]).natural_frequency_hz;
  if (!std::isfinite(f)) return;
  for (std::size_t d = 0; d < setup.s.dampers.size(); ++d) {
    const double x = s.damper_amplitudes_m[d];
    if (!(x > 0.0)) continue;
    for (const auto& layer : setup.s.dampers[d].layers)
      for (const auto& m : layer.loss_model->warning_messages(f, x))
        warnings.add(when + ", " + setup.s.dampers[d].name + "/" + layer.name + " (X = " + format_number(x, 4) +
                     " m, f = " + format_number(f, 4) + " Hz): " + m);
  }
}

// ---------------------------------------------------------------- --method dem

/// --dem-points: frequencies of the stepped-sine DEM FRF (linear over the task's band).
constexpr int kDefaultDemPoints = 9;
constexpr long long kMaxDemPoints = 1000;
/// Stepped sine: at most this many transient periods per frequency; the transient ends
/// earlier once the period-to-period change of |ŷ| stays below kDemStableTolerance twice.
constexpr int kDemMaxTransientPeriods = 100;
constexpr double kDemStableTolerance = 1e-2;
/// --dem-signal linear: the longest sweep accepted, s (simulated), per direction.
constexpr double kMaxSweepDuration_s = 1e5;
/// Decay samples: as the other methods (50 per period of the first mode, 2000..20000).

/// One stderr line per progress report of the co-simulation (about twice a second).
void print_cosim_progress(const std::string& label, const st::CosimulationProgress& p) {
  char line[240];
  std::snprintf(line, sizeof line, "%s: %-9s t = %8.3f / %.3f s  %6.2f k steps/s", label.c_str(),
                std::string(p.stage).c_str(), p.simulated_time_s, p.end_time_s, p.steps_per_s * 1e-3);
  std::cerr << (std::string(line) + "\n") << std::flush;  // one write: runs on two threads do not split lines
}

/// The dampers of the case as co-simulation dampers (their beds as DEM worlds).
std::vector<st::CosimulationDamper> dem_dampers(const Case& c) {
  std::vector<st::CosimulationDamper> out;
  for (std::size_t d = 0; d < c.dampers.size(); ++d) out.push_back(case_file::cosimulation_damper(c, d));
  return out;
}

/// Runs the co-simulation: invalid inputs are exit 2 (naming /dem for the DEM's own
/// refusals, e.g. a step above its bound), a World that stops is exit 3 with its advice.
st::CosimulationResult run_cosimulation(const Case& c, const st::ModalModel& modal,
                                        const std::vector<st::CosimulationDamper>& dampers,
                                        const st::CosimulationOptions& options, const std::string& label,
                                        st::CosimulationState* state = nullptr) {
  if (const auto problems = options.validate(modal); !problems.empty()) throw InputError(c.path, "/task", problems.front());
  for (std::size_t d = 0; d < dampers.size(); ++d)
    if (const auto problems = dampers[d].validate(modal); !problems.empty())
      throw InputError(c.path, "/dampers/" + std::to_string(d), problems.front());
  st::CosimulationResult r;
  try {
    const auto report = [&](const st::CosimulationProgress& p) { print_cosim_progress(label, p); };
    r = state ? st::cosimulate(modal, dampers, options, *state, report) : st::cosimulate(modal, dampers, options, report);
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw InputError(c.path, "/dem", what);
  }
  if (r.outcome == dem_reference::Outcome::kUnstable)
    throw NumericalError(label + ": DEM unstable: " + r.message +
                         " (a smaller /dem/time_step_s, a larger /dem/steps_per_contact or /dem/max_impact_speed_m_s)");
  if (r.outcome != dem_reference::Outcome::kCompleted) throw NumericalError(label + ": DEM failed: " + r.message);
  return r;
}

json energy_json(const st::CosimulationEnergy& e) {
  return {{"excitation_work_j", e.excitation_work_j},
          {"structural_damping_j", e.structural_damping_j},
          {"delta_structure_kinetic_j", e.delta_structure_kinetic_j},
          {"delta_structure_potential_j", e.delta_structure_potential_j},
          {"dem_dissipated_j", e.dem_dissipated_j()},
          {"dem_normal_damping_j", e.dem_normal_damping_j},
          {"dem_friction_j", e.dem_friction_j},
          {"dem_rolling_j", e.dem_rolling_j},
          {"delta_bed_kinetic_j", e.delta_bed_kinetic_j},
          {"delta_bed_potential_j", e.delta_bed_potential_j},
          {"delta_bed_elastic_j", e.delta_bed_elastic_j},
          {"container_work_j", e.container_work_j},
          {"relative_error", e.relative_error}};
}

/// Static site displacement along the first damper's drive under the beds' weight along
/// the drives: the beds rest on their walls, so the free decay oscillates about
/// y_s = b_0ᵀ K⁻¹ Σ_d b_d m_bed,d (g_d·a_d), K = diag(m_j ω_j²).
double static_site_offset(const Case& c, const st::ModalModel& modal, const Eigen::MatrixXd& drive_shapes) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(modal.mode_count());
  for (std::size_t d = 0; d < c.dampers.size(); ++d) {
    const auto& spec = c.dampers[d];
    double bed = 0.0;
    for (const auto& l : spec.layers) bed += l.bed_mass_kg;
    load += drive_shapes.col(static_cast<Eigen::Index>(d)) * bed * spec.gravity_m_s2[static_cast<std::size_t>(spec.drive_axis)];
  }
  double y = 0.0;
  for (Eigen::Index j = 0; j < modal.mode_count(); ++j) {
    const double w = 2.0 * std::numbers::pi * modal.natural_frequencies_hz[j];
    y += drive_shapes(j, 0) * load[j] / (modal.modal_masses_kg[j] * w * w);
  }
  return y;
}

/// The settling of a simulated site displacement (SimulatedSettling, structure_commands.hpp).
SimulatedSettling simulated_settling(const std::vector<double>& t, const Eigen::VectorXd& y, double offset,
                                     double period_s, double initial_m, double threshold_m, double fallback_frequency_hz) {
  SimulatedSettling out;
  const std::size_t n = t.size();
  std::size_t i = 0;
  for (int k = 0;; ++k) {
    const double end = (k + 1) * period_s;
    if (end > t.back() + 1e-12 * period_s) break;
    double peak = -1.0, at = 0.0;
    for (; i < n && t[i] < end; ++i) {
      const double r = std::abs(y[static_cast<Eigen::Index>(i)] - offset);
      if (r > peak) peak = r, at = t[i];
    }
    if (peak < 0.0) break;
    out.envelope_time_s.push_back(at);
    out.envelope_m.push_back(peak);
  }
  const std::size_t m = out.envelope_m.size();
  std::optional<std::size_t> last_above;
  for (std::size_t k = 0; k < m; ++k)
    if (out.envelope_m[k] >= threshold_m) last_above = k;
  if (m > 0 && !last_above) out.settling_time_s = 0.0;
  if (last_above && *last_above + 1 < m) {
    const std::size_t a = *last_above, b = a + 1;
    const double la = std::log(out.envelope_m[a]), lb = std::log(std::max(out.envelope_m[b], 1e-300));
    const double s = la > lb ? (la - std::log(threshold_m)) / (la - lb) : 0.0;
    out.settling_time_s = out.envelope_time_s[a] + std::clamp(s, 0.0, 1.0) * (out.envelope_time_s[b] - out.envelope_time_s[a]);
  }
  // The envelope at every sample (for the CSV and the plot).
  out.sample_envelope_m.resize(n, NAN);
  std::size_t k = 0;
  for (std::size_t s = 0; s < n && m > 0; ++s) {
    while (k + 1 < m && out.envelope_time_s[k + 1] <= t[s]) ++k;
    if (t[s] <= out.envelope_time_s.front()) out.sample_envelope_m[s] = out.envelope_m.front();
    else if (k + 1 >= m) out.sample_envelope_m[s] = out.envelope_m.back();
    else {
      const double w = (t[s] - out.envelope_time_s[k]) / (out.envelope_time_s[k + 1] - out.envelope_time_s[k]);
      out.sample_envelope_m[s] = std::exp((1.0 - w) * std::log(std::max(out.envelope_m[k], 1e-300)) +
                                          w * std::log(std::max(out.envelope_m[k + 1], 1e-300)));
    }
  }
  // Frequency from the zero crossings of y − y_s (interpolated), up to the settling time.
  const double until = std::isfinite(out.settling_time_s) && out.settling_time_s > 0.0 ? out.settling_time_s : t.back();
  std::vector<double> crossings;
  for (std::size_t s = 1; s < n && t[s] <= until; ++s) {
    const double r0 = y[static_cast<Eigen::Index>(s - 1)] - offset, r1 = y[static_cast<Eigen::Index>(s)] - offset;
    if ((r0 < 0.0) != (r1 < 0.0) && r0 != r1) crossings.push_back(t[s - 1] + (t[s] - t[s - 1]) * r0 / (r0 - r1));
  }
  out.frequency_hz = crossings.size() >= 3
                         ? 0.5 * static_cast<double>(crossings.size() - 1) / (crossings.back() - crossings.front())
                         : fallback_frequency_hz;
  if (std::isfinite(out.settling_time_s) && out.settling_time_s > 0.0) {
    const double decrement = std::log(initial_m / threshold_m) / (out.frequency_hz * out.settling_time_s);
    out.damping_ratio = decrement / std::sqrt(4.0 * std::numbers::pi * std::numbers::pi + decrement * decrement);
  }
  return out;
}

}  // namespace

// ------------------------------------------------------------------ checkpointed decays

const std::vector<FlagSpec> kCheckpointFlags{
    {"--resume", "", "continue the DEM run from its checkpoint in the -o folder (left by a run that\n"
                     "                          was interrupted or killed; same case, settings and thread count)"},
    {"--checkpoint-interval", "S", "wall-clock seconds between checkpoints of a DEM run in the -o folder,\n"
                                   "                          >= 0 (default 60; 0: after every segment of about 2 s); one is\n"
                                   "                          also written when SIGINT, SIGTERM or SIGHUP arrives"}};

DemCheckpoint dem_checkpoint(const ParsedArgs& args, const std::string& name, const std::string& kind) {
  DemCheckpoint out;
  out.kind = kind;
  out.resume = args.has("--resume");
  if (args.has("--checkpoint-interval")) {
    out.interval_s = args.number("--checkpoint-interval", Range{0.0, 1e9});
  }
  const auto dir = args.optional_text("-o");
  if (!dir) {
    if (out.resume) throw InputError("--resume", "", "needs -o DIR: the checkpoint is in the output folder");
    return out;
  }
  out.file = std::filesystem::path(*dir) / (name + ".checkpoint");
  return out;
}

std::string read_checkpoint_payload(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& expected) {
  const std::string shown = strict_json::printable(cp.file.string());
  if (!std::filesystem::exists(cp.file))
    throw InputError("--resume", "", "no checkpoint " + shown + " to continue (the run completed, or never started)");
  auto decoded = dem_reference::decode_checkpoint(
      strict_json::read_input_file(cp.file.string(), dem_reference::kMaxCheckpointBytes), cp.file.string());
  const auto& h = decoded.header;
  const auto refuse = [&](const std::string& key, const std::string& saved, const std::string& here) {
    throw InputError(cp.file.string(), "/" + key,
                     "'" + saved + "' in the checkpoint, '" + here + "' for this run: it belongs to another " +
                         (key == "kind" ? "command" : key == "physics_model_version" ? "pdamp version" : "case or settings") +
                         " (run without --resume to start again)");
  };
  if (h.kind != expected.kind) refuse("kind", h.kind, expected.kind);
  if (h.case_hash != expected.case_hash) refuse("case_hash", h.case_hash, expected.case_hash);
  if (h.physics_model_version != expected.physics_model_version)
    refuse("physics_model_version", std::to_string(h.physics_model_version), std::to_string(expected.physics_model_version));
  if (h.settings != expected.settings) refuse("settings", h.settings, expected.settings);
  return std::move(decoded.payload);
}

void write_checkpoint_file(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& header,
                           const std::string& payload) {
  strict_json::write_file_atomically(cp.file, dem_reference::encode_checkpoint(header, payload));
}

std::string checkpoint_advice(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& header) {
  return "the run stopped at t = " + format_number(header.simulated_time_s, 6) + " of " +
         format_number(header.end_time_s, 6) + " s and wrote " + strict_json::printable(cp.file.string()) +
         ": run the same command with --resume to continue";
}

namespace {

/// Wall-clock seconds a segment aims at: short enough that an interrupted run stops soon,
/// long enough that its start (no allocation, a few vector copies) costs nothing.
constexpr double kSegmentWallSeconds = 2.0;
/// The first segment (settling included, no rate known yet): this fraction of the run.
constexpr double kFirstSegmentFraction = 0.01;
/// A segment is at most this many times the last one.
constexpr std::int64_t kSegmentGrowth = 4;

/// What must match for a resume besides the case's physics: the structure, the task, the
/// run's own settings (duration, sampling, q0, step) and the caller's (a design).
std::string decay_settings(const Case& c, const st::CosimulationOptions& o, double dt, const std::string& own) {
  std::ostringstream s;
  s.precision(17);
  s << "structure " << surrogate::case_hash(c.resolved.value("structure", json())) << "; task "
    << surrogate::case_hash(c.resolved.value("task", json())) << "; duration_s " << o.duration_s
    << "; sample_interval_s " << o.sample_interval_s << "; time_step_s " << dt << "; q0";
  for (Eigen::Index j = 0; j < o.initial_modal_displacements.size(); ++j) s << ' ' << o.initial_modal_displacements[j];
  if (!own.empty()) s << "; " << own;
  return s.str();
}

void write_checkpoint(const DemCheckpoint& cp, const dem_reference::CheckpointHeader& header,
                      const st::CosimulationState& state, const st::CosimulationResult& sum) {
  dem_reference::StateWriter out;
  st::save_cosimulation_state(state, out);
  st::save_cosimulation_result(sum, out);
  write_checkpoint_file(cp, header, out.bytes());
}

/// The decay of `options` in segments, checkpointed (DemCheckpoint).
st::CosimulationResult run_checkpointed_decay(const Case& c, const st::ModalModel& modal,
                                              const std::vector<st::CosimulationDamper>& dampers,
                                              const st::CosimulationOptions& options, const std::string& label,
                                              const DemCheckpoint& cp) {
  double dt = 0.0;
  try {
    dt = st::cosimulation_time_step(modal, dampers, options).time_step_s;
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw InputError(c.path, "/dem", what);
  }
  const std::int64_t sample_every = std::max<std::int64_t>(1, std::llround(options.sample_interval_s / dt));
  const std::int64_t total = std::llround(options.duration_s / dt);
  dem_reference::CheckpointHeader header;
  header.kind = cp.kind;
  header.case_hash = case_file::physics_hash(c, "dem");
  header.physics_model_version = dem_reference::kPhysicsModelVersion;
  header.settings = decay_settings(c, options, dt, cp.settings);
  header.end_time_s = static_cast<double>(total) * dt;
  const std::string shown = strict_json::printable(cp.file.string());

  st::CosimulationState state;
  st::CosimulationResult sum;
  std::int64_t done = 0;
  if (cp.resume) {
    const std::string payload = read_checkpoint_payload(cp, header);
    try {
      dem_reference::StateReader in(payload, "checkpoint state");
      state = st::restore_cosimulation_state(modal, dampers, in);
      sum = st::restore_cosimulation_result(in, modal.mode_count(), dampers.size());
      in.finish();
    } catch (const std::invalid_argument& e) {
      throw InputError(cp.file.string(), "", e.what());
    }
    done = sum.steps;
    if (done <= 0 || done > total || state.steps != done)
      throw InputError(cp.file.string(), "", "its step count " + std::to_string(done) + " does not fit this run's " +
                                                 std::to_string(total) + " steps");
    std::cerr << label << ": resuming at t = " << format_number(static_cast<double>(done) * dt, 6) << " s of "
              << format_number(header.end_time_s, 6) << " s from " << shown << "\n";
  } else if (std::filesystem::exists(cp.file)) {
    std::cerr << "pdamp: warning: " << shown << " of an earlier run is replaced (--resume continues it)\n";
  }

  // Signals wait for the segment's end: the checkpoint is written, then pdamp ends by them.
  const DeferredSignals deferred;
  auto last_checkpoint = std::chrono::steady_clock::now();
  std::int64_t segment = sample_every * std::max<std::int64_t>(1, std::llround(kFirstSegmentFraction *
                                                                                static_cast<double>(total / sample_every)));
  while (done < total) {
    const std::int64_t steps = std::min(segment, total - done);
    st::CosimulationOptions o = options;
    o.duration_s = static_cast<double>(steps) * dt;
    if (state.started()) o.initial_modal_displacements.resize(0), o.initial_modal_velocities.resize(0);
    const std::int64_t offset = done;
    const auto report = [&](const st::CosimulationProgress& p) {
      st::CosimulationProgress whole = p;
      whole.simulated_time_s += static_cast<double>(offset) * dt;
      whole.end_time_s = header.end_time_s;
      print_cosim_progress(label, whole);
    };
    const auto started = std::chrono::steady_clock::now();
    st::CosimulationResult part;
    try {
      part = st::cosimulate(modal, dampers, o, state, report);
    } catch (const std::invalid_argument& e) {
      std::string what = e.what();
      std::replace(what.begin(), what.end(), '\n', ' ');
      throw InputError(c.path, "/dem", what);
    }
    if (part.outcome == dem_reference::Outcome::kUnstable)
      throw NumericalError(label + ": DEM unstable: " + part.message +
                           " (a smaller /dem/time_step_s, a larger /dem/steps_per_contact or /dem/max_impact_speed_m_s)");
    if (part.outcome != dem_reference::Outcome::kCompleted) throw NumericalError(label + ": DEM failed: " + part.message);
    if (done == 0 && !cp.resume) {
      sum = std::move(part);
    } else {
      st::append_continuation(sum, part, state);
    }
    done += steps;
    // The next segment: about kSegmentWallSeconds at this segment's rate, whole sample
    // intervals, at most kSegmentGrowth times this one (a short first segment, settling and
    // all, measures its rate poorly).
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double rate = static_cast<double>(steps) / std::max(wall, 1e-3);
    // A progress line per segment (the segments' own lines come only from long ones).
    print_cosim_progress(label, st::CosimulationProgress{"decay", static_cast<double>(done) * dt, header.end_time_s, rate});
    segment = std::min(kSegmentGrowth * steps,
                       sample_every * std::max<std::int64_t>(1, std::llround(kSegmentWallSeconds * rate /
                                                                             static_cast<double>(sample_every))));
    segment = std::max(segment, sample_every);
    const int signal = pending_interrupt();
    const bool due = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint).count() >= cp.interval_s;
    // At the end a signal still gets a checkpoint: the results are not written yet.
    if (signal != 0 || (done < total && due)) {
      header.simulated_time_s = static_cast<double>(done) * dt;
      write_checkpoint(cp, header, state, sum);
      last_checkpoint = std::chrono::steady_clock::now();
    }
    if (signal != 0) throw Interrupted(signal, checkpoint_advice(cp, header));
  }
  std::error_code ignored;
  std::filesystem::remove(cp.file, ignored);  // complete: the results follow
  return sum;
}

}  // namespace

DemDecay run_dem_decay(const Case& c, const st::ModalModel& modal, std::vector<st::Damper> containers,
                       const std::vector<st::CosimulationDamper>& dampers, const Eigen::VectorXd& q0,
                       const case_file::DecayTask& task, const std::string& label,
                       const std::string& duration_pointer, const DemCheckpoint& checkpoint) {
  for (auto& d : containers) d.layers.clear();
  const auto empty = call_solver(c, "/dampers", [&] { return st::couple(modal, containers); });

  // The settling measure as the other methods: Σ_j |b_j| |q0_j| at the first damper's site.
  const Eigen::VectorXd weights = empty.drive_shapes.col(0).cwiseAbs();
  const double measure0 = weights.dot(q0.cwiseAbs());
  if (!(measure0 > 0.0))
    throw InputError(c.path, "/task/initial_state", "does not move the first damper's site along its drive");
  const double threshold = task.settling_threshold * measure0;
  Eigen::Index dominant = 0;
  weights.cwiseProduct(q0.cwiseAbs()).maxCoeff(&dominant);

  st::CosimulationOptions options;
  options.excitation.kind = st::CosimulationExcitationKind::kFreeDecay;
  options.initial_modal_displacements = q0;
  options.initial_modal_velocities = Eigen::VectorXd::Zero(q0.size());
  options.duration_s = task.duration_s;
  options.bed_settling_time_s = c.dem.simulation.settling_time_s;
  const double samples = std::clamp(std::ceil(kDecaySamplesPerPeriod * modal.natural_frequencies_hz[0] * task.duration_s),
                                    kDecayMinSamples, kDecayMaxSamples);
  options.sample_interval_s = task.duration_s / samples;
  DemDecay out;
  out.cosimulation = checkpoint.file.empty() ? run_cosimulation(c, modal, dampers, options, label)
                                             : run_checkpointed_decay(c, modal, dampers, options, label, checkpoint);
  const auto& r = out.cosimulation;
  out.warnings = r.warnings;

  const auto& h = r.history;
  if (h.time_s.size() < 2) throw NumericalError(label + ": the co-simulation returned no history");
  const Eigen::VectorXd y = h.site_displacement_m.col(0);
  if (!y.allFinite()) throw NumericalError(label + ": the site displacement is not finite");
  out.static_offset_m = static_site_offset(c, modal, empty.drive_shapes);
  out.dominant_mode = dominant;
  out.dominant_frequency_hz = r.frequencies_with_containers_hz[dominant];
  out.initial_envelope_m = measure0;
  out.threshold_m = threshold;
  out.settling = simulated_settling(h.time_s, y, out.static_offset_m, 1.0 / out.dominant_frequency_hz, measure0,
                                    threshold, out.dominant_frequency_hz);
  if (!std::isfinite(out.settling.settling_time_s))
    out.warnings.push_back("the decay did not settle within duration_s = " + format_number(task.duration_s) +
                           " s (envelope " +
                           format_number(out.settling.envelope_m.empty() ? NAN : out.settling.envelope_m.back(), 4) +
                           " m, threshold " + format_number(threshold, 4) + " m): lengthen " + duration_pointer);
  if (r.energy.relative_error > 0.01)
    out.warnings.push_back("the co-simulation's energy ledger closes to " + format_number(r.energy.relative_error, 3) +
                           " only (docs/cosimulation.md §4): a smaller /dem/time_step_s");
  return out;
}

namespace {

int run_decay_dem(const ParsedArgs& args, const Case& c, OutputDir* files) {
  const auto& task = *c.task.decay;
  Setup setup = make_setup(c, case_file::LossMethod::kFormulas, false);
  const st::ModalModel& modal = setup.s.modal;
  const Eigen::VectorXd q0 = case_file::initial_modal_amplitudes(c, setup.s, *c.task.decay);
  if (!(q0.cwiseAbs().maxCoeff() > 0.0))
    throw InputError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  const auto dampers = dem_dampers(c);
  const DemDecay decay = run_dem_decay(c, modal, setup.s.dampers, dampers, q0, task, "pdamp decay (dem)",
                                       "/task/duration_s", dem_checkpoint(args, "decay_dem", "decay_dem"));
  setup.warnings.add(decay.warnings);
  const auto& r = decay.cosimulation;
  const auto& h = r.history;
  const auto& settle = decay.settling;
  const double offset = decay.static_offset_m, threshold = decay.threshold_m, measure0 = decay.initial_envelope_m;
  const double f_dom = decay.dominant_frequency_hz;
  const Eigen::Index dominant = decay.dominant_mode;
  const bool settled = std::isfinite(settle.settling_time_s);

  if (files) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "time_s";
    for (const auto& d : dampers) csv << ",site_displacement_m_" << safe_file_name(d.name);
    csv << ",envelope_m";
    for (Eigen::Index j = 0; j < modal.mode_count(); ++j) csv << ",q_mode" << j + 1;
    for (const auto& d : dampers) csv << ",site_rotation_rad_" << safe_file_name(d.name);
    for (const auto& d : dampers) csv << ",bed_force_n_" << safe_file_name(d.name);
    csv << '\n';
    for (std::size_t s = 0; s < h.time_s.size(); ++s) {
      const auto row = static_cast<Eigen::Index>(s);
      csv << h.time_s[s];
      for (Eigen::Index d = 0; d < h.site_displacement_m.cols(); ++d) csv << ',' << h.site_displacement_m(row, d);
      csv << ',' << settle.sample_envelope_m[s];
      for (Eigen::Index j = 0; j < h.modal_displacements.cols(); ++j) csv << ',' << h.modal_displacements(row, j);
      for (Eigen::Index d = 0; d < h.site_rotation_rad.cols(); ++d) csv << ',' << h.site_rotation_rad(row, d);
      for (Eigen::Index d = 0; d < h.container_load_n.cols(); ++d) csv << ',' << h.container_load_n(row, d);
      csv << '\n';
    }
    files->add("decay_dem.csv", csv.str());
    setup.warnings.add(write_decay_dem_plot(*files, offset, threshold, settle.settling_time_s,
                                            dampers.size(), c.name + ": free decay (dem co-simulation)"));
  }

  std::vector<double> initial(q0.data(), q0.data() + q0.size());
  json envelope = json::array();
  for (std::size_t k = 0; k < settle.envelope_m.size(); ++k) envelope.push_back({settle.envelope_time_s[k], settle.envelope_m[k]});
  json d = {{"file", file_json(files, "decay_dem.csv")},
            {"plot", file_json(files, "decay_dem.png")},
            {"method", "dem"},
            {"settling_time_s", number_or_null(settle.settling_time_s)},
            {"damping_ratio", number_or_null(settle.damping_ratio)},
            {"dominant_mode", dominant + 1},
            {"outcome", settled ? "settled" : "not_settled"},
            {"threshold_point", setup.s.dampers.front().point},
            {"threshold_m", threshold},
            {"threshold_fraction", task.settling_threshold},
            {"initial_envelope_m", measure0},
            {"initial_modal_amplitudes", initial},
            {"static_offset_m", offset},
            {"envelope", "the largest |y - static_offset_m| of the first damper's site along its drive over each whole "
                         "period of the dominant mode (with the empty containers)"},
            {"envelope_period_s", 1.0 / f_dom},
            {"envelope_points", envelope},
            {"frequency_hz", settle.frequency_hz},
            {"final_time_s", h.time_s.back()},
            {"final_envelope_m", settle.envelope_m.empty() ? json(nullptr) : json(settle.envelope_m.back())},
            {"energy_error", r.energy.relative_error},
            {"energy", energy_json(r.energy)},
            {"structural_dissipated_energy_j", r.energy.structural_damping_j},
            {"dem_dissipated_energy_j", r.energy.dem_dissipated_j()},
            {"samples", h.time_s.size()},
            {"steps", r.steps},
            {"settling_steps", r.settling_steps},
            {"time_step_s", r.time_step_s},
            {"solve_time_s", r.wall_time_s},
            {"warnings", setup.warnings.list()}};
  json result = {{"task", "decay"}, {"case", c.name}, {"method", "dem"}};
  result["file"] = d["file"];
  result["settling_time_s"] = d["settling_time_s"];
  result["damping_ratio"] = d["damping_ratio"];
  result["energy_balance_error"] = r.energy.relative_error;
  result["decay"] = d;
  std::vector<std::pair<std::string, std::string>> rows = {
      {"method", "dem"},
      {"outcome", d["outcome"].get<std::string>()},
      {"settling_time_s", settled ? format_number(settle.settling_time_s, 6) : "not settled"},
      {"damping_ratio", std::isfinite(settle.damping_ratio) ? format_number(settle.damping_ratio, 4) : "-"},
      {"dominant mode", std::to_string(dominant + 1)},
      {"threshold_m", format_number(threshold, 4)},
      {"energy_error", format_number(r.energy.relative_error, 3)},
      {"DEM steps", std::to_string(r.steps) + " of " + format_number(r.time_step_s, 3) + " s in " +
                        format_number(r.wall_time_s, 3) + " s"}};
  result["decay"]["warnings"] = setup.warnings.list();
  return finish(args, c, files, "decay.json", result, setup.warnings, rows);
}

/// One frequency of the stepped-sine DEM FRF.
struct DemPoint {
  std::string sweep;  ///< "up" or "down"
  double f = 0.0, requested_f = 0.0;
  std::vector<double> magnitude, phase_deg;
  std::vector<double> bed_eta_star, bed_apparent_mass_fraction;  ///< per damper, in the loop (Level II measure)
  double spread = NAN;          ///< sample standard deviation of the analysed periods' |ŷ|, per unit excitation
  double standard_error = NAN;  ///< spread/√(analysed periods): periods taken as independent
  double energy_error = 0.0;
  int transient = 0;
  bool stable = false;
  std::int64_t steps = 0;
  double dt = 0.0, wall = 0.0;
};
/// One direction of the stepped sine: its points in the order run, its warnings.
struct DemBranch {
  std::string sweep;
  std::vector<DemPoint> points;
  std::vector<std::string> warnings;
  double solve_time = 0.0;
};
struct DemSweep {
  bool worker = false;              ///< an MPI worker rank that ran its part: it reports nothing
  std::vector<DemBranch> branches;  ///< up first, then down (those asked for)
  std::vector<double> frequencies;  ///< requested, ascending
  std::vector<st::CosimulationDamper> dampers;
  bool base = false;
  bool parallel = false;
  int analysed_periods = 0;
  double solve_time = 0.0;  ///< wall time of the whole sweep (both directions)
  double time_step_s = 0.0;
  json mpi;  ///< the farm's balance under mpirun (ranks, directions per rank), else null
};

/// The points of one branch in ascending frequency, and its resonance measures
/// (sampled_response.hpp) of one output. The standard errors are the first output's (its
/// per-period amplitudes are recorded); the others' peaks have none.
struct DemBranchPeak {
  std::vector<const DemPoint*> ascending;
  st::SampledPeak peak;
  std::size_t output = 0;
};
DemBranchPeak dem_branch_peak(const DemBranch& branch, std::size_t output = 0) {
  DemBranchPeak out;
  out.output = output;
  for (const auto& p : branch.points) out.ascending.push_back(&p);
  std::sort(out.ascending.begin(), out.ascending.end(), [](const DemPoint* a, const DemPoint* b) { return a->f < b->f; });
  std::vector<double> f, m, se;
  for (const DemPoint* p : out.ascending) {
    f.push_back(p->f);
    m.push_back(p->magnitude.at(output));
    se.push_back(output == 0 && std::isfinite(p->standard_error) ? p->standard_error : 0.0);
  }
  out.peak = st::sampled_peak(f, m, se);
  return out;
}

/// One direction of the stepped sine: each frequency continues the previous one's final
/// state (bed included); the bed is settled once, before the first.
DemBranch run_dem_branch(const Case& c, const st::ModalModel& modal, const std::vector<st::CosimulationDamper>& dampers,
                         st::CosimulationOptions options, const std::vector<double>& frequencies, const std::string& sweep,
                         double sweep_dt) {
  DemBranch branch;
  branch.sweep = sweep;
  st::CosimulationState state;  // the bed, the modes and the drive's phase, carried over
  for (std::size_t i = 0; i < frequencies.size(); ++i) {
    options.excitation.frequency_hz = frequencies[i];
    options.time_step_s = state.started() ? 0.0 : sweep_dt;
    const std::string label = "pdamp frf (dem) " + sweep + " " + std::to_string(i + 1) + "/" +
                              std::to_string(frequencies.size()) + " " + format_number(frequencies[i], 5) + " Hz";
    const auto r = run_cosimulation(c, modal, dampers, options, label, &state);
    for (const auto& w : r.warnings) branch.warnings.push_back(w);
    branch.solve_time += r.wall_time_s;
    const auto& ss = r.steady_state;
    DemPoint p;
    p.sweep = sweep;
    p.f = ss.frequency_hz;
    p.requested_f = frequencies[i];
    for (std::size_t d = 0; d < dampers.size(); ++d) {
      p.magnitude.push_back(ss.site_amplitude_per_excitation.at(d));
      p.phase_deg.push_back(std::arg(ss.site_amplitudes_m.at(d)) * 180.0 / std::numbers::pi);
      p.bed_eta_star.push_back(ss.bed_reduced_loss_factor.at(d));
      p.bed_apparent_mass_fraction.push_back(ss.bed_apparent_mass_fraction.at(d));
    }
    // Spread: sample standard deviation of the analysed periods' |ŷ| of the first site, per unit excitation.
    const auto& per = ss.period_site_amplitudes_m;
    const std::size_t na = static_cast<std::size_t>(std::max(ss.analysed_periods, 0));
    if (na >= 2 && per.size() >= na) {
      double mean = 0.0, var = 0.0;
      for (std::size_t k = per.size() - na; k < per.size(); ++k) mean += per[k];
      mean /= static_cast<double>(na);
      for (std::size_t k = per.size() - na; k < per.size(); ++k) var += (per[k] - mean) * (per[k] - mean);
      p.spread = std::sqrt(var / static_cast<double>(na - 1)) / options.excitation.amplitude;
      p.standard_error = p.spread / std::sqrt(static_cast<double>(na));
    }
    p.energy_error = r.energy.relative_error;
    p.transient = ss.transient_periods;
    p.stable = ss.stable;
    p.steps = r.steps;
    p.dt = r.time_step_s;
    p.wall = r.wall_time_s;
    for (double m : p.magnitude)
      if (!std::isfinite(m)) throw NumericalError(label + ": the steady-state amplitude is not finite");
    if (!p.stable)
      branch.warnings.push_back(sweep + " sweep at " + format_number(p.f, 5) + " Hz: the period-to-period change of the "
                                "site amplitude did not stay below " + format_number(kDemStableTolerance) + " within " +
                                std::to_string(kDemMaxTransientPeriods) +
                                " transient periods: the analysed periods may still carry the transient");
    if (p.energy_error > 0.01)
      branch.warnings.push_back(sweep + " sweep at " + format_number(p.f, 5) + " Hz: the co-simulation's energy ledger "
                                "closes to " + format_number(p.energy_error, 3) + " only: a smaller /dem/time_step_s");
    branch.points.push_back(std::move(p));
  }
  return branch;
}

/// A branch as CBOR for the MPI farm (distributed.hpp): doubles exact, NaN kept. The
/// layout is this file's own, read back only by decode_branch of the same build.
std::string encode_branch(const DemBranch& branch) {
  json points = json::array();
  for (const auto& p : branch.points)
    points.push_back({p.sweep, p.f, p.requested_f, p.magnitude, p.phase_deg, p.bed_eta_star, p.bed_apparent_mass_fraction,
                      p.spread, p.standard_error, p.energy_error, p.transient, p.stable, p.steps, p.dt, p.wall});
  const auto bytes = json::to_cbor(json{branch.sweep, points, branch.warnings, branch.solve_time});
  return std::string(bytes.begin(), bytes.end());
}

DemBranch decode_branch(const std::string& bytes) {
  const json j = json::from_cbor(bytes);
  DemBranch branch;
  j.at(0).get_to(branch.sweep);
  for (const auto& q : j.at(1)) {
    DemPoint p;
    q.at(0).get_to(p.sweep);
    q.at(1).get_to(p.f);
    q.at(2).get_to(p.requested_f);
    q.at(3).get_to(p.magnitude);
    q.at(4).get_to(p.phase_deg);
    q.at(5).get_to(p.bed_eta_star);
    q.at(6).get_to(p.bed_apparent_mass_fraction);
    q.at(7).get_to(p.spread);
    q.at(8).get_to(p.standard_error);
    q.at(9).get_to(p.energy_error);
    q.at(10).get_to(p.transient);
    q.at(11).get_to(p.stable);
    q.at(12).get_to(p.steps);
    q.at(13).get_to(p.dt);
    q.at(14).get_to(p.wall);
    branch.points.push_back(std::move(p));
  }
  j.at(2).get_to(branch.warnings);
  j.at(3).get_to(branch.solve_time);
  return branch;
}

/// The band and the directions of --method dem (--dem-min/max-frequency, default the task's).
struct DemBand {
  double f_min = 0.0, f_max = 0.0;
  std::vector<std::string> directions;  ///< "up", "down" (those asked for, up first)
};
DemBand dem_band(const ParsedArgs& args, const case_file::FrfTask& task) {
  DemBand band;
  band.f_min = args.optional_number("--dem-min-frequency", {0.0, 1e6, true}).value_or(task.min_frequency_hz);
  band.f_max = args.optional_number("--dem-max-frequency", {0.0, 1e6, true}).value_or(task.max_frequency_hz);
  if (!(band.f_max > band.f_min))
    throw InputError("--dem-max-frequency", "", format_number(band.f_max) + " Hz: must exceed the lowest frequency " +
                                                    format_number(band.f_min) + " Hz (--dem-min-frequency or the task's)");
  const std::string direction = args.optional_text("--dem-sweep").value_or("both");
  if (direction != "up" && direction != "down" && direction != "both")
    throw InputError("--dem-sweep", "", "'" + direction + "': must be up, down or both");
  if (direction != "down") band.directions.push_back("up");
  if (direction != "up") band.directions.push_back("down");
  return band;
}

/// The frf task's harmonic co-simulation options (excitation, settling to a steady state at
/// each frequency, the case's DEM settings), the excitation checked (exit 2 naming /task/excitation).
st::CosimulationOptions dem_frf_options(const Case& c, const st::ModalModel& modal) {
  const auto& task = *c.task.frf;
  const bool base = task.excitation == case_file::FrfTask::Excitation::kBase;
  st::CosimulationOptions options;
  options.excitation.kind = base ? st::CosimulationExcitationKind::kBaseTranslation : st::CosimulationExcitationKind::kPointForce;
  options.excitation.direction = {task.direction[0], task.direction[1]};
  options.excitation.amplitude = base ? task.base_amplitude_m : task.force_amplitude_n;
  options.excitation.point = base ? std::string() : task.force_point;
  options.transient_periods = kDemMaxTransientPeriods;
  options.analysed_periods = c.dem.simulation.analysed_periods;
  options.settle_until_stable = true;
  options.stable_tolerance = kDemStableTolerance;
  options.bed_settling_time_s = c.dem.simulation.settling_time_s;
  // The drive is U sin(Ω(t − t_i) + π/2) from each frequency's start t_i: every run ends on
  // whole periods, so each junction is at the turning point, base (or force) at its
  // amplitude with zero rate on both sides: displacement and velocity of the base continue.
  options.excitation_phase_rad = std::numbers::pi / 2.0;
  task_excitation(c, modal);  // the excitation's own checks first
  return options;
}

/// The co-simulation's step for these options (exit 2 naming /task or /dem).
double dem_time_step(const Case& c, const st::ModalModel& modal, const std::vector<st::CosimulationDamper>& dampers,
                     const st::CosimulationOptions& options) {
  if (const auto problems = options.validate(modal); !problems.empty()) throw InputError(c.path, "/task", problems.front());
  try {
    return st::cosimulation_time_step(modal, dampers, options).time_step_s;
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw InputError(c.path, "/dem", what);
  }
}

/// The stepped sine of --method dem (and of --compare): up and down in frequency over the
/// band, the two directions on two threads when the machine has two cores (each DEM world
/// then on one thread), or under mpirun on two ranks (distributed.hpp; a direction is one
/// task: each frequency continues from the previous one's state, so a direction cannot be
/// split). On an MPI worker rank it runs what rank 0 sends and returns {worker = true}.
DemSweep dem_frf_sweep(const ParsedArgs& args, const Case& c, Setup& setup) {
  const int points = static_cast<int>(args.optional_integer("--dem-points", 2, kMaxDemPoints).value_or(kDefaultDemPoints));
  const DemBand band = dem_band(args, *c.task.frf);
  const st::ModalModel& modal = setup.s.modal;
  auto dampers = dem_dampers(c);
  const bool base = c.task.frf->excitation == case_file::FrfTask::Excitation::kBase;
  const st::CosimulationOptions options = dem_frf_options(c, modal);
  const auto frequencies = spaced(band.f_min, band.f_max, points, false);

  // One step for the whole sweep (the carried worlds keep theirs): the smallest automatic
  // step over the frequencies, each period then the nearest whole number of it.
  double sweep_dt = INFINITY;
  for (const double f : frequencies) {
    st::CosimulationOptions o = options;
    o.excitation.frequency_hz = f;
    sweep_dt = std::min(sweep_dt, dem_time_step(c, modal, dampers, o));
  }
  std::vector<std::pair<std::string, std::vector<double>>> directions;
  for (const auto& d : band.directions)
    directions.push_back({d, d == "up" ? frequencies : std::vector<double>(frequencies.rbegin(), frequencies.rend())});

  DemSweep out;
  out.frequencies = frequencies;
  out.base = base;
  out.analysed_periods = options.analysed_periods;
  out.time_step_s = sweep_dt;
  out.parallel = directions.size() > 1 && (distributed::ranks() > 1 || std::thread::hardware_concurrency() >= 2);
  // Two sweeps on two cores: one thread each (the worlds' own OpenMP would oversubscribe).
  // Under MPI too, so that a rank's branch is the serial run's bit for bit.
  if (out.parallel)
    for (auto& d : dampers) d.world.threads = 1;
  distributed::TaskFarm farm([&](const distributed::Request& r) {
    const auto k = static_cast<std::size_t>(r[0]);
    return encode_branch(run_dem_branch(c, modal, dampers, options, directions.at(k).second, directions.at(k).first, sweep_dt));
  });
  if (distributed::worker()) {  // every check passed here too: run the direction rank 0 sends
    farm.serve();
    out.worker = true;
    return out;
  }
  if (distributed::ranks() > 1)
    std::cerr << "pdamp frf (dem): " << directions.size() << " sweep direction(s) over " << distributed::ranks()
              << " MPI ranks; progress lines only of a direction run on rank 0" << std::endl;
  out.branches.resize(directions.size());
  const auto started = std::chrono::steady_clock::now();
  distributed::run_concurrently(directions.size(), out.parallel, [&](std::size_t k) {
    out.branches[k] = decode_branch(farm.evaluate({static_cast<double>(k), 0.0}));
  });
  out.solve_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  out.mpi = farm.balance();
  for (const auto& b : out.branches) setup.warnings.add(b.warnings);
  out.dampers = std::move(dampers);
  return out;
}

/// A branch's resonance measures of the first output as JSON (sampled_response.hpp).
json dem_peak_json(const std::string& output, const DemBranch& branch, const DemBranchPeak& bp) {
  const DemPoint& top = *bp.ascending[bp.peak.index];
  return {{"output", output},
          {"sweep", branch.sweep},
          {"frequency_hz", bp.peak.frequency_hz},
          {"largest_point_frequency_hz", top.f},
          {"magnitude", bp.peak.magnitude},
          {"magnitude_standard_error", bp.output == 0 ? number_or_null(top.standard_error) : json(nullptr)},
          {"band_low_hz", number_or_null(bp.peak.band.low_hz)},
          {"band_high_hz", number_or_null(bp.peak.band.high_hz)},
          {"band_centre_hz", number_or_null(bp.peak.band_centre_hz)},
          {"indistinguishable_low_hz", bp.peak.indistinguishable_low_hz},
          {"indistinguishable_high_hz", bp.peak.indistinguishable_high_hz},
          {"damping_ratio", number_or_null(bp.peak.damping_ratio)}};
}

const char* const kDemPeakNote =
    "frequency_hz: vertex of the parabola through the largest point and its neighbours; band: where the points "
    "stay >= 0.9 of the largest (linear between points), its centre a flat top's better-conditioned resonance "
    "frequency; indistinguishable: the points within two standard errors of the largest (the argmax lies among "
    "them); standard error = spread/sqrt(analysed periods); damping_ratio: half-power width (f2 - f1)/(2 f) "
    "between the points (null where a side does not fall to 1/sqrt(2) of the largest)";

std::string dem_peak_row(const DemBranchPeak& bp, std::size_t points) {
  const DemPoint& top = *bp.ascending[bp.peak.index];
  return format_number(bp.peak.frequency_hz, 5) + " Hz (largest of " + std::to_string(points) + " points at " +
         format_number(top.f, 5) + " Hz), |out| = " + format_number(bp.peak.magnitude, 4) +
         (bp.output == 0 && std::isfinite(top.standard_error) ? " +- " + format_number(top.standard_error, 2) : "") +
         ", 0.9 band centre " + format_number(bp.peak.band_centre_hz, 5) + " Hz, argmax within [" +
         format_number(bp.peak.indistinguishable_low_hz, 4) + ", " + format_number(bp.peak.indistinguishable_high_hz, 4) +
         "] Hz, half-power zeta " + format_number(bp.peak.damping_ratio, 3);
}

int run_frf_dem(const ParsedArgs& args, const Case& c, OutputDir* files) {
  const std::string signal = args.optional_text("--dem-signal").value_or("stepped");
  if (signal == "linear") return distributed::worker() ? kExitOk : run_frf_dem_linear(args, c, files);  // rank 0 alone
  if (signal != "stepped") throw InputError("--dem-signal", "", "'" + signal + "': must be stepped or linear");
  Setup setup = make_setup(c, case_file::LossMethod::kFormulas, false);
  const DemSweep sweep = dem_frf_sweep(args, c, setup);
  if (sweep.worker) return kExitOk;  // rank 0 reports
  const auto& frequencies = sweep.frequencies;
  const auto& dampers = sweep.dampers;
  const bool base = sweep.base;
  const std::size_t outputs = dampers.size();

  json peaks = json::array();
  std::vector<std::pair<std::string, std::string>> rows = {{"method", "dem"}};
  json list = json::array();
  for (const auto& branch : sweep.branches) {
    for (std::size_t d = 0; d < outputs; ++d) {
      const DemBranchPeak bp = dem_branch_peak(branch, d);
      peaks.push_back(dem_peak_json(dampers[d].name, branch, bp));
      rows.push_back({"peak " + branch.sweep + " " + dampers[d].name, dem_peak_row(bp, branch.points.size())});
    }
    for (const auto& p : branch.points) {
      json magnitude = json::object(), phase = json::object(), eta = json::object(), mass = json::object();
      for (std::size_t d = 0; d < outputs; ++d) {
        magnitude[dampers[d].name] = p.magnitude[d], phase[dampers[d].name] = p.phase_deg[d];
        eta[dampers[d].name] = number_or_null(p.bed_eta_star[d]);
        mass[dampers[d].name] = number_or_null(p.bed_apparent_mass_fraction[d]);
      }
      list.push_back({{"sweep", p.sweep}, {"frequency_hz", p.f}, {"requested_frequency_hz", p.requested_f},
                      {"magnitude", magnitude}, {"phase_deg", phase},
                      {"bed_eta_star", eta}, {"bed_apparent_mass_fraction", mass},
                      {"magnitude_spread", number_or_null(p.spread)},
                      {"magnitude_standard_error", number_or_null(p.standard_error)}, {"energy_error", p.energy_error},
                      {"transient_periods", p.transient}, {"stable", p.stable}, {"steps", p.steps},
                      {"time_step_s", p.dt}, {"solve_time_s", p.wall}});
      rows.push_back({branch.sweep + " " + format_number(p.f, 6) + " Hz",
                      "|out| = " + format_number(p.magnitude.front(), 4) +
                          (std::isfinite(p.standard_error) ? " +- " + format_number(p.standard_error, 2) : "") +
                          ", bed eta* " + format_number(p.bed_eta_star.front(), 3) + ", m_app/m_bed " +
                          format_number(p.bed_apparent_mass_fraction.front(), 3) + ", energy error " +
                          format_number(p.energy_error, 2)});
    }
  }
  const std::string magnitude_label = base ? "transmissibility |X/U|" : "receptance |X/F| / (m/N)";
  if (files) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "sweep,frequency_hz";
    for (const auto& d : dampers) csv << ",magnitude_" << safe_file_name(d.name) << ",phase_deg_" << safe_file_name(d.name);
    csv << ",magnitude_spread_" << safe_file_name(dampers.front().name) << ",magnitude_standard_error_"
        << safe_file_name(dampers.front().name) << ",bed_eta_star_" << safe_file_name(dampers.front().name)
        << ",bed_apparent_mass_fraction_" << safe_file_name(dampers.front().name)
        << ",energy_error,transient_periods,stable,steps,time_step_s\n";
    for (const auto& branch : sweep.branches)
      for (const DemPoint* p : dem_branch_peak(branch).ascending) {
        csv << p->sweep << ',' << p->f;
        for (std::size_t d = 0; d < outputs; ++d) csv << ',' << p->magnitude[d] << ',' << p->phase_deg[d];
        csv << ',' << (std::isfinite(p->spread) ? p->spread : 0.0) << ','
            << (std::isfinite(p->standard_error) ? p->standard_error : 0.0) << ',' << p->bed_eta_star.front() << ','
            << p->bed_apparent_mass_fraction.front() << ',' << p->energy_error << ',' << p->transient << ','
            << (p->stable ? 1 : 0) << ',' << p->steps << ',' << p->dt << '\n';
      }
    files->add("frf_dem.csv", csv.str());
    std::vector<std::string> names;
    for (const auto& d : dampers) names.push_back(d.name);
    setup.warnings.add(write_frf_dem_plot(*files, names, magnitude_label, c.name + ": stepped-sine DEM co-simulation"));
  }
  const std::string bed_state =
      "each direction (up, down) continues from frequency to frequency with the previous one's final state: modes "
      "(q, dq/dt), the bed (particles and contacts) and the drive's phase; the bed is settled once, before a "
      "direction's first frequency";
  json sweeps = json::array();
  for (const auto& b : sweep.branches) sweeps.push_back(b.sweep);
  json frf = {{"file", file_json(files, "frf_dem.csv")},
              {"plot", file_json(files, "frf_dem.png")},
              {"method", "dem"},
              {"outputs", [&] { json n = json::array(); for (const auto& d : dampers) n.push_back(d.name); return n; }()},
              {"magnitude", base ? "transmissibility |X/U| (absolute site motion over base amplitude), first harmonic"
                                 : "receptance |X/F| in m/N, first harmonic"},
              {"excitation", base ? "base" : "force"},
              {"frequencies", {{"min_hz", frequencies.front()}, {"max_hz", frequencies.back()},
                               {"points", frequencies.size()}, {"spacing", "linear"}}},
              {"points", list},
              {"peaks", peaks},
              {"peak_note", kDemPeakNote},
              {"bed_carried_over", true},
              {"stepped_sine", {{"sweeps", sweeps},
                                {"parallel", sweep.parallel},
                                {"bed_state", bed_state}, {"bed_carried_over", true},
                                {"drive", "sin(2 pi f (t - t_i) + pi/2) from each frequency's start t_i: the junctions "
                                          "are at the turning point, the base displacement and velocity (or the "
                                          "force) continuous"},
                                {"time_step_s", sweep.time_step_s},
                                {"max_transient_periods", kDemMaxTransientPeriods},
                                {"stable_tolerance", kDemStableTolerance},
                                {"analysed_periods", sweep.analysed_periods}}},
              {"solve_time_s", sweep.solve_time},
              {"warnings", setup.warnings.list()}};
  rows.push_back({"DEM wall time", format_number(sweep.solve_time, 4) + " s (" +
                                       (sweep.parallel ? "directions in parallel" : "one after the other") + ")"});
  json result = {{"task", "frf"}, {"case", c.name}, {"method", "dem"}};
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["branches"] = json::array();
  result["bed_carried_over"] = true;
  result["frf"] = frf;
  result["frf"]["warnings"] = setup.warnings.list();
  if (!sweep.mpi.is_null()) result["mpi"] = sweep.mpi;
  return finish(args, c, files, "frf.json", result, setup.warnings, rows);
}

// ---------------------------------------------------------------- --compare

/// The harmonic-balance FRF of the task for one loss method (formulas or field), as pdamp frf.
st::FrequencyResponse task_response(const Case& c, Setup& setup) {
  auto response = task_harmonic_balance(c, setup, task_excitation(c, setup.s.modal));
  for (const auto& p : response.peaks)
    if (!std::isfinite(p.frequency_hz) || !std::isfinite(p.magnitude))
      throw NumericalError("pdamp frf --compare: a response peak is not finite (" + response.brief_report() + ")");
  const std::string method(case_file::to_string(setup.method));
  setup.warnings.add(response.warnings, method + ": ");
  if (response.outcome != st::FrequencyResponse::Outcome::kConverged)
    setup.warnings.add(method + ": some roots did not converge (" + std::to_string(response.unconverged_starts) +
                       " Newton starts failed): the response may miss branches");
  return response;
}

/// The largest peak of the first output, or nullptr.
const st::ResponsePeak* first_output_peak(const st::FrequencyResponse& r) {
  const st::ResponsePeak* best = nullptr;
  for (const auto& p : r.peaks)
    if (p.output == 0 && (!best || p.magnitude > best->magnitude)) best = &p;
  return best;
}

// ---------------------------------------------------------------- --dem-signal linear

/// The default sweep rate: the quasi-stationary ratio (docs/cosimulation.md §6) — the time
/// spent in the half-power band over the response time, 4πζ²f²/r — at this value for the
/// formulas' resonance (f, ζ of its half-power band). The cycles' lag error is first order in
/// 1/ratio: 2.2% at 63 on a linear mode, halving with the rate
/// (tests/structure/test_cosimulation_sweep.cpp), so about 1.4% at 100, below the DEM bed's
/// own cycle-to-cycle scatter (3-4%).
constexpr double kQuasiStationaryRatio = 100.0;
/// The peak of a sweep is read off the means of this many consecutive cycles (the window of
/// amplitudes_settled), their standard error the window's spread over its root.
constexpr std::size_t kSweepWindowCycles = st::kSettledWindowPeriods;

/// One output's resonance measures over a sweep, read off the moving means of
/// kSweepWindowCycles consecutive cycles (ascending frequency); none with fewer cycles.
struct SweepPeak {
  std::vector<double> window_frequency_hz, window_magnitude, window_standard_error;
  st::SampledPeak peak;
  bool found() const { return !window_magnitude.empty(); }
  double standard_error() const { return found() ? window_standard_error[peak.index] : NAN; }
};

/// One direction of --dem-signal linear: the steady state at the start frequency, then the
/// sweep to the other end of the band.
struct DemLinearSweep {
  std::string sweep;
  double start_hz = 0.0, end_hz = 0.0, rate_hz_s = 0.0, duration_s = 0.0;
  int start_transient_periods = 0;
  bool start_stable = false;
  std::vector<st::CosimulationSweepCycle> cycles;
  double energy_error = 0.0, time_step_s = 0.0, wall = 0.0;
  std::int64_t steps = 0;
  std::vector<std::string> warnings;
  std::vector<SweepPeak> peaks;  ///< per output
};

SweepPeak sweep_peak(const std::vector<st::CosimulationSweepCycle>& cycles, std::size_t output) {
  SweepPeak out;
  std::vector<std::pair<double, double>> fm;
  for (const auto& c : cycles) fm.push_back({c.frequency_hz, c.site_amplitude_per_excitation.at(output)});
  std::sort(fm.begin(), fm.end());
  const std::size_t w = kSweepWindowCycles;
  for (std::size_t i = 0; i + w <= fm.size(); ++i) {
    double f = 0.0, m = 0.0, ss = 0.0;
    for (std::size_t k = i; k < i + w; ++k) f += fm[k].first, m += fm[k].second;
    f /= static_cast<double>(w);
    m /= static_cast<double>(w);
    for (std::size_t k = i; k < i + w; ++k) ss += (fm[k].second - m) * (fm[k].second - m);
    out.window_frequency_hz.push_back(f);
    out.window_magnitude.push_back(m);
    out.window_standard_error.push_back(std::sqrt(ss / static_cast<double>(w - 1)) / std::sqrt(static_cast<double>(w)));
  }
  if (out.found()) out.peak = st::sampled_peak(out.window_frequency_hz, out.window_magnitude, out.window_standard_error);
  return out;
}

/// The default rate from the formulas' harmonic balance (its largest first-output peak), or
/// from the lightest-damped mode in the band when that peak has no half-power band.
double default_sweep_rate(const Case& c, Setup& formulas, const DemBand& band, std::string& basis) {
  const auto response = task_harmonic_balance(c, formulas, task_excitation(c, formulas.s.modal));
  double f = NAN, zeta = NAN;
  if (const st::ResponsePeak* p = first_output_peak(response); p && std::isfinite(p->damping_ratio) && p->damping_ratio > 0)
    f = p->frequency_hz, zeta = p->damping_ratio, basis = "the formulas' resonance";
  if (!std::isfinite(zeta)) {
    const auto& modal = formulas.s.modal;
    for (Eigen::Index j = 0; j < modal.mode_count(); ++j) {
      const double fj = modal.natural_frequencies_hz[j], zj = std::max(modal.damping_ratios[j], 1e-4);
      if (fj >= band.f_min && fj <= band.f_max && !(zj >= zeta)) f = fj, zeta = zj;
    }
    basis = "the lightest-damped bare mode in the band";
  }
  if (!std::isfinite(zeta))
    throw InputError("--dem-sweep-rate", "", "not given, and neither a resonance of the formulas nor a mode lies in [" +
                                                 format_number(band.f_min) + ", " + format_number(band.f_max) +
                                                 "] Hz: give the rate in Hz/s");
  basis += " (" + format_number(f, 4) + " Hz, zeta " + format_number(zeta, 3) + ")";
  return 4.0 * std::numbers::pi * zeta * zeta * f * f / kQuasiStationaryRatio;
}

/// pdamp frf --method dem --dem-signal linear: per direction, the bed settled and the
/// structure brought to its steady state at the band's start (a stepped-sine point), then a
/// linear sine sweep to the other end continuing from it; the directions in parallel.
int run_frf_dem_linear(const ParsedArgs& args, const Case& c, OutputDir* files) {
  Setup setup = make_setup(c, case_file::LossMethod::kFormulas, false);
  const DemBand band = dem_band(args, *c.task.frf);
  const st::ModalModel& modal = setup.s.modal;
  auto dampers = dem_dampers(c);
  const bool base = c.task.frf->excitation == case_file::FrfTask::Excitation::kBase;
  const st::CosimulationOptions steady = dem_frf_options(c, modal);
  std::string rate_basis = "--dem-sweep-rate";
  const auto given_rate = args.optional_number("--dem-sweep-rate", {0.0, 1e6, true});
  const double rate = given_rate ? *given_rate : default_sweep_rate(c, setup, band, rate_basis);
  const double duration = (band.f_max - band.f_min) / rate;
  if (!(duration <= kMaxSweepDuration_s))
    throw InputError("--dem-sweep-rate", "", format_number(rate) + " Hz/s: the sweep over [" + format_number(band.f_min) +
                                                 ", " + format_number(band.f_max) + "] Hz would take " +
                                                 format_number(duration) + " s (at most " +
                                                 format_number(kMaxSweepDuration_s) + " s): a faster rate or a narrower band");
  std::vector<DemLinearSweep> sweeps(band.directions.size());
  for (std::size_t k = 0; k < sweeps.size(); ++k) {
    auto& s = sweeps[k];
    s.sweep = band.directions[k];
    s.start_hz = s.sweep == "up" ? band.f_min : band.f_max;
    s.end_hz = s.sweep == "up" ? band.f_max : band.f_min;
    s.rate_hz_s = rate;
    s.duration_s = duration;
  }
  const bool parallel = sweeps.size() > 1 && std::thread::hardware_concurrency() >= 2;
  if (parallel)
    for (auto& d : dampers) d.world.threads = 1;
  const auto started = std::chrono::steady_clock::now();
  distributed::run_concurrently(sweeps.size(), parallel, [&](std::size_t k) {
    auto& s = sweeps[k];
    st::CosimulationOptions sweep = steady;
    sweep.excitation.frequency_hz = s.start_hz;
    sweep.sweep_end_frequency_hz = s.end_hz;
    sweep.duration_s = s.duration_s;
    st::CosimulationOptions start = steady;  // the steady state at the start, on the sweep's step
    start.excitation.frequency_hz = s.start_hz;
    start.time_step_s = dem_time_step(c, modal, dampers, sweep);
    st::CosimulationState state;
    const std::string label = "pdamp frf (dem) linear " + s.sweep;
    const auto first = run_cosimulation(c, modal, dampers, start, label + " start " + format_number(s.start_hz, 5) + " Hz", &state);
    s.start_transient_periods = first.steady_state.transient_periods;
    s.start_stable = first.steady_state.stable;
    const auto r = run_cosimulation(c, modal, dampers, sweep, label + " sweep", &state);
    for (const auto* run : {&first, &r})
      for (const auto& w : run->warnings) s.warnings.push_back(s.sweep + " sweep: " + w);
    s.cycles = r.sweep_cycles;
    s.energy_error = r.energy.relative_error;
    s.time_step_s = r.time_step_s;
    s.steps = first.steps + r.steps;
    s.wall = first.wall_time_s + r.wall_time_s;
    for (const auto& cycle : s.cycles)
      for (double m : cycle.site_amplitude_per_excitation)
        if (!std::isfinite(m)) throw NumericalError(label + ": a cycle's amplitude is not finite");
    if (!s.start_stable)
      s.warnings.push_back(s.sweep + " sweep: the steady state at " + format_number(s.start_hz, 5) +
                           " Hz was not reached within " + std::to_string(kDemMaxTransientPeriods) +
                           " periods: the sweep's first cycles may carry the transient");
    if (s.energy_error > 0.01)
      s.warnings.push_back(s.sweep + " sweep: the co-simulation's energy ledger closes to " +
                           format_number(s.energy_error, 3) + " only: a smaller /dem/time_step_s");
    for (std::size_t d = 0; d < dampers.size(); ++d) s.peaks.push_back(sweep_peak(s.cycles, d));
  });
  const double solve_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (const auto& s : sweeps) setup.warnings.add(s.warnings);

  const std::size_t outputs = dampers.size();
  const std::string first_name = dampers.front().name;
  std::vector<std::pair<std::string, std::string>> rows = {
      {"method", "dem, linear sine sweep"},
      {"sweep rate", format_number(rate, 4) + " Hz/s over [" + format_number(band.f_min, 5) + ", " +
                         format_number(band.f_max, 5) + "] Hz (" + format_number(duration, 4) + " s; " + rate_basis + ")"}};
  json peaks = json::array(), list = json::array(), runs = json::array();
  for (const auto& s : sweeps) {
    for (std::size_t d = 0; d < outputs; ++d) {
      const SweepPeak& sp = s.peaks[d];
      const auto value = [&](double v) { return sp.found() ? number_or_null(v) : json(nullptr); };
      peaks.push_back({{"output", dampers[d].name},
                       {"sweep", s.sweep},
                       {"frequency_hz", value(sp.peak.frequency_hz)},
                       {"magnitude", value(sp.peak.magnitude)},
                       {"magnitude_standard_error", value(sp.standard_error())},
                       {"band_low_hz", value(sp.peak.band.low_hz)},
                       {"band_high_hz", value(sp.peak.band.high_hz)},
                       {"band_centre_hz", value(sp.peak.band_centre_hz)},
                       {"damping_ratio", value(sp.peak.damping_ratio)}});
      rows.push_back(
          {"peak " + s.sweep + " " + dampers[d].name,
           sp.found() ? format_number(sp.peak.frequency_hz, 5) + " Hz, |out| = " + format_number(sp.peak.magnitude, 4) +
                            " +- " + format_number(sp.standard_error(), 2) + ", 0.9 band centre " +
                            (std::isfinite(sp.peak.band_centre_hz) ? format_number(sp.peak.band_centre_hz, 5) + " Hz"
                                                                   : std::string("outside the band")) +
                            ", half-power zeta " + format_number(sp.peak.damping_ratio, 3)
                      : "fewer than " + std::to_string(kSweepWindowCycles) + " cycles"});
    }
    runs.push_back({{"sweep", s.sweep}, {"start_hz", s.start_hz}, {"end_hz", s.end_hz}, {"rate_hz_per_s", s.rate_hz_s},
                    {"duration_s", s.duration_s}, {"cycles", s.cycles.size()},
                    {"start_transient_periods", s.start_transient_periods}, {"start_stable", s.start_stable},
                    {"energy_error", s.energy_error}, {"steps", s.steps}, {"time_step_s", s.time_step_s},
                    {"solve_time_s", s.wall}});
    rows.push_back({s.sweep + " sweep", std::to_string(s.cycles.size()) + " cycles, energy error " +
                                            format_number(s.energy_error, 2) + ", " + std::to_string(s.steps) +
                                            " steps of " + format_number(s.time_step_s, 3) + " s"});
    for (const auto& cycle : s.cycles) {
      json magnitude = json::object(), phase = json::object(), eta = json::object(), mass = json::object();
      for (std::size_t d = 0; d < outputs; ++d) {
        magnitude[dampers[d].name] = cycle.site_amplitude_per_excitation[d];
        phase[dampers[d].name] = std::arg(cycle.site_amplitudes_m[d]) * 180.0 / std::numbers::pi;
        eta[dampers[d].name] = number_or_null(cycle.bed_reduced_loss_factor[d]);
        mass[dampers[d].name] = number_or_null(cycle.bed_apparent_mass_fraction[d]);
      }
      list.push_back({{"sweep", s.sweep}, {"time_s", cycle.time_s}, {"frequency_hz", cycle.frequency_hz},
                      {"magnitude", magnitude}, {"phase_deg", phase}, {"bed_eta_star", eta},
                      {"bed_apparent_mass_fraction", mass}});
    }
  }
  const std::string magnitude_label = base ? "transmissibility |X/U|" : "receptance |X/F| / (m/N)";
  if (files) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "sweep,time_s,frequency_hz";
    for (const auto& d : dampers) csv << ",magnitude_" << safe_file_name(d.name) << ",phase_deg_" << safe_file_name(d.name);
    csv << ",bed_eta_star_" << safe_file_name(first_name) << ",bed_apparent_mass_fraction_" << safe_file_name(first_name)
        << '\n';
    for (const auto& s : sweeps)
      for (const auto& cycle : s.cycles) {
        csv << s.sweep << ',' << cycle.time_s << ',' << cycle.frequency_hz;
        for (std::size_t d = 0; d < outputs; ++d)
          csv << ',' << cycle.site_amplitude_per_excitation[d] << ','
              << std::arg(cycle.site_amplitudes_m[d]) * 180.0 / std::numbers::pi;
        csv << ',' << cycle.bed_reduced_loss_factor.front() << ',' << cycle.bed_apparent_mass_fraction.front() << '\n';
      }
    files->add("frf_dem_sweep.csv", csv.str());
    std::vector<std::string> names;
    for (const auto& d : dampers) names.push_back(d.name);
    setup.warnings.add(write_frf_dem_sweep_plot(*files, names, magnitude_label, c.name + ": linear-sweep DEM co-simulation"));
  }
  json frf = {{"file", file_json(files, "frf_dem_sweep.csv")},
              {"plot", file_json(files, "frf_dem_sweep.png")},
              {"method", "dem"},
              {"signal", "linear_sweep"},
              {"outputs", [&] { json n = json::array(); for (const auto& d : dampers) n.push_back(d.name); return n; }()},
              {"magnitude", base ? "transmissibility |X/U| (absolute site motion over base amplitude), first harmonic "
                                   "of each drive cycle"
                                 : "receptance |X/F| in m/N, first harmonic of each drive cycle"},
              {"excitation", base ? "base" : "force"},
              {"rate_hz_per_s", rate},
              {"rate_basis", rate_basis},
              {"quasi_stationary_ratio_default", kQuasiStationaryRatio},
              {"sweeps", runs},
              {"parallel", parallel},
              {"points", list},
              {"peaks", peaks},
              {"peak_note", "the peak is read off moving means of " + std::to_string(kSweepWindowCycles) +
                                " consecutive cycles (standard error: their spread over the root of the count); a "
                                "sweep's response lags its drive by about a response time, so an up sweep's peak "
                                "sits above the steady one and a down sweep's below, by about rate x response time"},
              {"solve_time_s", solve_time},
              {"warnings", setup.warnings.list()}};
  rows.push_back({"DEM wall time", format_number(solve_time, 4) + " s (" +
                                       (parallel ? "directions in parallel" : "one after the other") + ")"});
  json result = {{"task", "frf"}, {"case", c.name}, {"method", "dem"}, {"signal", "linear_sweep"}};
  result["file"] = frf["file"];
  result["peaks"] = peaks;
  result["frf"] = frf;
  result["frf"]["warnings"] = setup.warnings.list();
  return finish(args, c, files, "frf.json", result, setup.warnings, rows);
}

/// Relative differences of a method's largest first-output peak from a DEM branch's, for
/// the peak (argmax) frequency, the 0.9 band's centre and the magnitude.
json agreement_json(const st::ResponsePeak* peak, const st::SampledPeak& dem) {
  if (!peak) return nullptr;
  const auto relative = [](double a, double b) { return number_or_null((a - b) / b); };
  return {{"frequency_hz", peak->frequency_hz},
          {"band_centre_hz", number_or_null(peak->band_centre_hz)},
          {"magnitude", peak->magnitude},
          {"frequency_relative_difference", relative(peak->frequency_hz, dem.frequency_hz)},
          {"band_centre_relative_difference", relative(peak->band_centre_hz, dem.band_centre_hz)},
          {"magnitude_relative_difference", relative(peak->magnitude, dem.magnitude)},
          {"damping_ratio", number_or_null(peak->damping_ratio)},
          {"dem_damping_ratio", number_or_null(dem.damping_ratio)},
          {"frequency_within_dem_indistinguishable",
           peak->frequency_hz >= dem.indistinguishable_low_hz && peak->frequency_hz <= dem.indistinguishable_high_hz}};
}

/// pdamp frf --compare: formulas, field (when every layer has a field_file) and the DEM
/// stepped sine on one case, one figure and one table.
int run_frf_compare(const ParsedArgs& args, const Case& c) {
  auto files = output_dir(args);
  Setup formulas = make_setup(c, case_file::LossMethod::kFormulas);
  const st::FrequencyResponse f_response = task_response(c, formulas);
  Warnings& warnings = formulas.warnings;

  bool every_field = true;
  for (const auto& d : c.dampers)
    for (const auto& l : d.layers) every_field = every_field && !l.field_file.empty();
  std::optional<st::FrequencyResponse> field_response;
  if (every_field) {
    Setup field = make_setup(c, case_file::LossMethod::kField);
    field_response = task_response(c, field);
    warnings.add(field.warnings.list());
  } else {
    warnings.add("--compare: the field curve is skipped: not every layer has a field_file (make one with pdamp field)");
  }

  Setup dem_setup = make_setup(c, case_file::LossMethod::kFormulas, false);
  const DemSweep sweep = dem_frf_sweep(args, c, dem_setup);
  if (sweep.worker) return kExitOk;  // rank 0 reports
  warnings.add(dem_setup.warnings.list(), "dem: ");
  if (sweep.branches.empty() || sweep.branches.front().points.empty())
    throw NumericalError("pdamp frf --compare: the DEM sweep returned no points");

  const std::vector<std::string>& names = f_response.output_names;
  const std::string output = names.empty() ? std::string() : names.front();
  const std::string magnitude_label = sweep.base ? "transmissibility |X/U|" : "receptance |X/F| / (m/N)";
  std::vector<CompareDemPoint> dem_points;
  json dem_list = json::array(), dem_peaks = json::array(), agreement = json::array();
  std::vector<std::pair<std::string, std::string>> rows = {{"method", "compare (formulas, field, dem)"}};
  const auto row = [&](const std::string& name, const json& a) {
    if (a.is_null()) {
      rows.push_back({name, "-"});
      return;
    }
    const auto percent = [](const json& v) { return v.is_null() ? std::string("-") : format_number(100.0 * v.get<double>(), 3); };
    rows.push_back({name, format_number(a["frequency_hz"].get<double>(), 5) + " Hz, |out| = " +
                              format_number(a["magnitude"].get<double>(), 4) + " (vs dem: f " +
                              percent(a["frequency_relative_difference"]) + "%, 0.9 band centre " +
                              percent(a["band_centre_relative_difference"]) + "%, |out| " +
                              percent(a["magnitude_relative_difference"]) + "%; zeta " +
                              (a["damping_ratio"].is_null() ? std::string("-") : format_number(a["damping_ratio"].get<double>(), 3)) +
                              " vs " +
                              (a["dem_damping_ratio"].is_null() ? std::string("-") : format_number(a["dem_damping_ratio"].get<double>(), 3)) +
                              ")"});
  };
  for (const auto& branch : sweep.branches) {
    const DemBranchPeak bp = dem_branch_peak(branch);
    for (const DemPoint* p : bp.ascending) {
      dem_points.push_back({p->f, p->magnitude.front(), std::isfinite(p->spread) ? p->spread : 0.0, branch.sweep});
      dem_list.push_back({{"sweep", branch.sweep}, {"frequency_hz", p->f}, {"magnitude", p->magnitude.front()},
                          {"magnitude_spread", number_or_null(p->spread)},
                          {"magnitude_standard_error", number_or_null(p->standard_error)},
                          {"energy_error", p->energy_error}, {"stable", p->stable}});
    }
    dem_peaks.push_back(dem_peak_json(output, branch, bp));
    const json a_formulas = agreement_json(first_output_peak(f_response), bp.peak);
    const json a_field = field_response ? agreement_json(first_output_peak(*field_response), bp.peak) : json(nullptr);
    agreement.push_back({{"reference", "dem " + branch.sweep}, {"formulas", a_formulas}, {"field", a_field}});
    rows.push_back({"peak dem " + branch.sweep, dem_peak_row(bp, branch.points.size())});
    row("peak formulas vs " + branch.sweep, a_formulas);
    row("peak field vs " + branch.sweep, a_field);
  }
  if (files)
    warnings.add(write_frf_compare_files(*files, f_response, field_response ? &*field_response : nullptr, dem_points,
                                         magnitude_label,
                                         c.name + (field_response ? ": formulas, field and DEM" : ": formulas and DEM (no field)")));

  const json f_peaks = peaks_json(f_response.peaks, names);
  const json field_peaks = field_response ? peaks_json(field_response->peaks, field_response->output_names) : json(nullptr);
  json compare = {
      {"output", output},
      {"formulas", {{"peaks", f_peaks}}},
      {"field", field_response ? json{{"peaks", field_peaks}} : json(nullptr)},
      {"dem", {{"peaks", dem_peaks}, {"points", dem_list}, {"bed_carried_over", true}, {"peak_note", kDemPeakNote}}},
      {"agreement_definition", "(method - dem) / dem of the largest peak of the first output, per DEM sweep direction"},
      {"agreement", agreement},
      {"file", file_json(files.get(), "frf_compare.csv")},
      {"plot", file_json(files.get(), "frf_compare.png")},
      {"dem_solve_time_s", sweep.solve_time}};
  json result = {{"task", "frf"}, {"case", c.name}, {"method", "compare"}};
  result["file"] = compare["file"];
  result["peaks"] = f_peaks;  // the contract's peaks: the formulas' (compare holds all three)
  result["branches"] = json::array();
  result["compare"] = compare;
  return finish(args, c, files.get(), "frf.json", result, warnings, rows);
}

int run_decay_case(const ParsedArgs& args, const Case& c) {
  require_task(c, TaskKind::kDecay, c.task.decay.has_value(), "\"initial_state\", \"duration_s\"");
  if (dem_method(args)) {
    auto dem_files = output_dir(args);
    return run_decay_dem(args, c, dem_files.get());
  }
  for (const auto& flag : kCheckpointFlags)
    if (args.has(flag.name)) throw InputError(flag.name, "", "applies to --method dem (the DEM runs checkpoint)");
  const auto method = loss_method(args);
  auto files = output_dir(args);
  Setup setup = make_setup(c, method);
  const auto& task = *c.task.decay;
  const auto& modal = setup.s.modal;

  const Eigen::VectorXd q0 = case_file::initial_modal_amplitudes(c, setup.s, *c.task.decay);
  st::FreeDecayOptions options;
  options.initial_modal_amplitudes = q0.cwiseAbs();  // released from rest: a_j = |q_j(0)|
  if (!(options.initial_modal_amplitudes.maxCoeff() > 0.0))
    throw InputError(c.path, "/task/initial_state", "gives no modal amplitude (the load does not excite any kept mode)");
  options.duration_s = task.duration_s;
  options.threshold_fraction = task.settling_threshold;
  const double samples = std::clamp(std::ceil(kDecaySamplesPerPeriod * modal.natural_frequencies_hz[0] * task.duration_s),
                                    kDecayMinSamples, kDecayMaxSamples);
  options.sample_times_s = spaced(0.0, task.duration_s, static_cast<int>(samples) + 1, false);
  if (const auto problems = options.validate(modal.mode_count()); !problems.empty())
    throw InputError(c.path, "/task", problems.front());
  const auto decay = call_solver(c, "/task", [&] { return st::free_decay(modal, setup.s.dampers, options); });

  for (const auto& s : decay.samples)
    if (!std::isfinite(s.threshold_measure_m) || !std::isfinite(s.mechanical_energy_j))
      throw NumericalError("pdamp decay: the envelope is not finite at t = " + format_number(s.time_s) + " s (" +
                           decay.brief_report() + ")");
  if (decay.samples.empty()) throw NumericalError("pdamp decay: the solver returned no samples (" + decay.brief_report() + ")");
  setup.warnings.add(decay.warnings);
  const bool settled = decay.outcome == st::FreeDecay::Outcome::kSettled;
  const auto coupled = call_solver(c, "/dampers", [&] { return st::couple(modal, setup.s.dampers); });
  add_loss_messages(setup.warnings, setup, coupled, decay.samples.front(), "at the start");
  if (settled) {
    const auto at = std::lower_bound(decay.samples.begin(), decay.samples.end(), decay.settling_time_s,
                                     [](const st::DecaySample& s, double t) { return s.time_s < t; });
    add_loss_messages(setup.warnings, setup, coupled, at == decay.samples.end() ? decay.samples.back() : *at, "at settling");
  } else {
    setup.warnings.add("the decay did not settle within duration_s = " + format_number(task.duration_s) +
                       " s (envelope " + format_number(decay.samples.back().threshold_measure_m, 4) + " m, threshold " +
                       format_number(decay.threshold_used_m, 4) + " m): lengthen /task/duration_s");
  }
  if (files)
    setup.warnings.add(write_decay_files(*files, decay, damper_names(setup),
                                         c.name + ": free decay (" + std::string(case_file::to_string(method)) + ")"));

  const auto& first = decay.samples.front();
  const auto& last = decay.samples.back();
  json layers = json::array();
  double dissipated = last.structural_dissipated_energy_j;
  for (double e : last.layer_dissipated_energy_j) dissipated += e;
  for (std::size_t l = 0; l < decay.layer_names.size(); ++l)
    layers.push_back({{"name", decay.layer_names[l]},
                      {"dissipated_energy_j", last.layer_dissipated_energy_j[l]},
                      {"share", dissipated > 0.0 ? last.layer_dissipated_energy_j[l] / dissipated : 0.0}});
  std::vector<double> initial(q0.data(), q0.data() + q0.size());
  json d = {{"file", file_json(files.get(), "decay.csv")},
            {"plot", file_json(files.get(), "decay.png")},
            {"method", case_file::to_string(method)},
            {"settling_time_s", number_or_null(decay.settling_time_s)},
            {"damping_ratio", number_or_null(decay.equivalent_damping_ratio)},
            {"dominant_mode", decay.dominant_mode + 1},
            {"outcome", settled ? "settled" : "not_settled"},
            {"threshold_point", setup.s.dampers.front().point},
            {"threshold_m", decay.threshold_used_m},
            {"threshold_fraction", task.settling_threshold},
            {"initial_envelope_m", first.threshold_measure_m},
            {"initial_modal_amplitudes", initial},
            {"initial_energy_j", first.mechanical_energy_j},
            {"final_time_s", last.time_s},
            {"final_envelope_m", last.threshold_measure_m},
            {"final_energy_j", last.mechanical_energy_j},
            {"structural_dissipated_energy_j", last.structural_dissipated_energy_j},
            {"layers", layers},
            {"samples", decay.samples.size()},
            {"steps", decay.steps},
            {"solve_time_s", decay.solve_time_s},
            {"report", decay.brief_report()},
            {"warnings", setup.warnings.list()}};
  json result = result_head(c, "decay", method);
  result["file"] = d["file"];
  result["settling_time_s"] = d["settling_time_s"];
  result["damping_ratio"] = d["damping_ratio"];
  result["decay"] = d;
  std::vector<std::pair<std::string, std::string>> rows = {
      {"method", std::string(case_file::to_string(method))},
      {"outcome", d["outcome"].get<std::string>()},
      {"settling_time_s", settled ? format_number(decay.settling_time_s, 6) : "not settled"},
      {"damping_ratio", std::isfinite(decay.equivalent_damping_ratio) ? format_number(decay.equivalent_damping_ratio, 4) : "-"},
      {"dominant mode", std::to_string(decay.dominant_mode + 1)},
      {"threshold_m", format_number(decay.threshold_used_m, 4)}};
  for (const auto& l : layers)
    rows.push_back({"dissipated by " + l["name"].get<std::string>(),
                    format_number(l["dissipated_energy_j"].get<double>(), 4) + " J (" +
                        format_number(100.0 * l["share"].get<double>(), 3) + "%)"});
  result["decay"]["warnings"] = setup.warnings.list();
  return finish(args, c, files.get(), "decay.json", result, setup.warnings, rows);
}

int run_modes(const ParsedArgs& args) { return run_modes_case(args, case_file::load_case(args.positional().at(0))); }
int run_frf(const ParsedArgs& args) { return run_frf_case(args, case_file::load_case(args.positional().at(0))); }
int run_decay(const ParsedArgs& args) { return run_decay_case(args, case_file::load_case(args.positional().at(0))); }

}  // namespace

int run_structure_task(const ParsedArgs& args, const Case& c) {
  switch (c.task.kind) {
    case TaskKind::kModes: return run_modes_case(args, c);
    case TaskKind::kFrf: return run_frf_case(args, c);
    case TaskKind::kDecay: return run_decay_case(args, c);
    case TaskKind::kDamperDesign:
    case TaskKind::kFillingRatios:
    case TaskKind::kPlacement: break;
  }
  throw std::logic_error("run_structure_task: not a structure task");
}

std::vector<Command> structure_commands() {
  return {
      {{"modes", "pdamp modes CASE.json [--method formulas|field] [-o DIR] [--json]",
        "natural frequencies (with the empty containers attached, and bare), mode shapes at the\n"
        "named points, modal mass ratio per damper and backbones f(X), zeta_add(X) per mode",
        {kMethodFlag, {"-o", "DIR", "write modes.csv, backbone_mode<j>.csv, backbone.gp/png/svg, modes.json\n"
                                    "                          and case_resolved.json into DIR, atomically"},
         kJsonFlag}, 1},
       run_modes},
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
      {{"decay", "pdamp decay CASE.json [--method formulas|field|dem] [--resume] [--checkpoint-interval S] [-o DIR] [--json]",
        "free decay of the structure with its dampers (task kind decay): envelope, settling time,\n"
        "equivalent damping ratio and the energy each layer dissipates",
        concat_flags({kMethodFlag, {"-o", "DIR", "write decay.csv, decay.gp/png/svg (dem: decay_dem.csv,\n"
                                                  "                          decay_dem.gp/png/svg), decay.json and case_resolved.json\n"
                                                  "                          into DIR, atomically (dem: decay_dem.checkpoint while running)"},
                      kJsonFlag},
                     kCheckpointFlags), 1},
       run_decay},
  };
}

}  // namespace pdamp::cli
