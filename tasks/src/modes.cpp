// Task kind modes (modes.hpp).
#include "pdamp/tasks/modes.hpp"

#include <algorithm>

#include "pdamp/base/input_error.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "mode_calibration.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "pdamp/tasks/bed_calibration.hpp"
#include "structure_support.hpp"

namespace pdamp::tasks {

namespace st = structure;
using nlohmann::json;

namespace {

/// Default backbone range when the case's task is not `modes`: 40 log-spaced damper
/// amplitudes from 1 mm to twice the largest clearance of the reference damper's layers.
constexpr int kDefaultBackbonePoints = 40;
constexpr double kDefaultBackboneMinM = 1e-3;
constexpr double kDefaultBackboneMaxOverClearance = 2.0;
/// A mode in which the reference damper moves less than this fraction of its largest
/// drive shape gets no backbone (its amplitude there would be meaningless).
constexpr double kNoMotionFraction = 1e-9;

/// The calibration the run takes (ModesOptions::calibrated), if any: the task's, else
/// the defaults on the dem_check's modes.
std::optional<case_file::ModesCalibrationSpec> modes_calibration(const case_file::Case& c, const ModesOptions& options) {
  const case_file::ModesTask* task =
      c.task.kind == case_file::TaskKind::kModes && c.task.modes ? &*c.task.modes : nullptr;
  if (!options.calibrated.value_or(task != nullptr && task->calibration)) return std::nullopt;
  if (task == nullptr || (!task->calibration && !task->dem_check))
    throw base::InputError(c.path, "/task",
                           "a calibration needs task kind modes with a calibration or a dem_check (whose modes it calibrates)");
  // The DEM field is of one bed: the first damper's, of one layer.
  if (c.dampers.size() != 1 || c.dampers.front().layers.size() != 1)
    throw base::InputError(c.path, "/dampers",
                           "has " + std::to_string(c.dampers.size()) + " dampers, the first with " +
                               std::to_string(c.dampers.front().layers.size()) +
                               " layers: the calibration of task kind modes takes one damper of one layer");
  if (task->calibration) return task->calibration;
  case_file::ModesCalibrationSpec spec;
  spec.modes = task->dem_check->modes;
  return spec;
}

}  // namespace

ModesResult run_modes(const case_file::Case& c, const ModesOptions& options, base::RunHooks& hooks,
                      base::Executor& executor) {
  executor.primary_only();  // a few DEM decays at most, one after the other: nothing to spread
  detail::Setup setup = detail::make_setup(c, options.method);
  const st::ModalModel& modal = setup.s.modal;
  const auto& dampers = setup.s.dampers;
  ModesResult out;
  out.case_name = c.name;
  out.method = options.method;
  out.damper_names = detail::damper_names(setup);
  out.layer_names = detail::layer_names(setup);
  out.rigid_modes_dropped = setup.s.rigid_modes_dropped;

  Eigen::Index mode_count = modal.mode_count();
  const bool from_task = c.task.kind == case_file::TaskKind::kModes && c.task.modes.has_value();
  if (from_task && c.task.modes->mode_count > 0) mode_count = std::min<Eigen::Index>(mode_count, c.task.modes->mode_count);
  out.mode_count = mode_count;

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
  out.backbone_min_amplitude_m = lo;
  out.backbone_max_amplitude_m = hi;
  out.backbone_points = points;
  out.backbone_from_task = from_task;
  const auto amplitudes = detail::spaced(lo, hi, points, true);

  std::vector<st::Damper> containers = dampers;
  for (auto& d : containers) d.layers.clear();
  const auto empty = detail::call_solver(c, "/dampers", [&] { return st::couple(modal, containers); });
  const auto coupled = detail::call_solver(c, "/dampers", [&] { return st::couple(modal, dampers); });
  out.frequencies_with_containers_hz = st::natural_frequencies_with_containers_hz(empty);
  out.drive_shapes = coupled.drive_shapes;

  // μ_dj = b_dj² Σ_l m_bed,l / m_j.
  out.mass_ratio.resize(mode_count, static_cast<Eigen::Index>(dampers.size()));
  for (Eigen::Index d = 0; d < out.mass_ratio.cols(); ++d) {
    double bed = 0.0;
    for (const auto& l : dampers[static_cast<std::size_t>(d)].layers) bed += l.bed_mass_kg;
    for (Eigen::Index j = 0; j < mode_count; ++j)
      out.mass_ratio(j, d) = coupled.drive_shapes(j, d) * coupled.drive_shapes(j, d) * bed / coupled.modal_masses_kg[j];
  }

  const double largest_drive = coupled.drive_shapes.col(0).cwiseAbs().maxCoeff();
  const auto moves_damper = [&](Eigen::Index j) {
    return std::abs(coupled.drive_shapes(j, 0)) > kNoMotionFraction * largest_drive;
  };

  // The folder of the DEM-calibrated beds (the calibration's and the clearance search's), made
  // ready once; `pointer` names the block that needs it.
  const auto use_calibration_cache = [&](const std::string& pointer) {
    if (!out.calibration_cache.empty()) return;
    out.calibration_cache = options.calibration_cache.empty() ? default_calibration_cache() : options.calibration_cache;
    if (const std::string problem = prepare_calibration_cache(out.calibration_cache); !problem.empty())
      throw base::InputError(c.path, pointer, "the calibration cache " + problem);
  };

  // The calibrated modes: the first damper's bed as the DEM sees it around each one, between
  // the mode's frequency with the bed carried whole and with the containers empty.
  std::map<Eigen::Index, std::vector<st::Damper>> calibrated_dampers;
  if (const auto calibration = modes_calibration(c, options)) {
    use_calibration_cache("/task/calibration");
    std::vector<st::Damper> carried = containers;
    for (std::size_t d = 0; d < carried.size(); ++d)
      for (const auto& l : dampers[d].layers) carried[d].container_mass_kg += l.bed_mass_kg;
    const Eigen::VectorXd carried_hz = st::natural_frequencies_with_containers_hz(
        detail::call_solver(c, "/dampers", [&] { return st::couple(modal, carried); }));
    for (const int j : calibration->modes) {
      if (!moves_damper(j))
        throw base::InputError(c.path, "/task/calibration/modes",
                               "mode " + std::to_string(j + 1) + " does not move damper " + dampers.front().name +
                                   " along its drive: nothing to calibrate");
      const detail::ModeCalibrationRange range{j, carried_hz[j], out.frequencies_with_containers_hz[j], lo, hi};
      out.calibrations.push_back(detail::calibrate_mode(c, *calibration, range, out.calibration_cache, hooks));
      auto& calibrated = calibrated_dampers[j] = dampers;
      calibrated.front().layers.front().loss_model =
          std::make_shared<surrogate::EffectiveFieldLossModel>(out.calibrations.back().field);
    }
  }
  const auto dampers_of = [&](Eigen::Index j) -> const std::vector<st::Damper>& {
    const auto it = calibrated_dampers.find(j);
    return it == calibrated_dampers.end() ? dampers : it->second;
  };
  std::map<std::string, std::vector<Eigen::Index>> backbone_warnings;  // sentence -> modes (1-based)
  for (Eigen::Index j = 0; j < mode_count; ++j) {
    if (!moves_damper(j)) {
      setup.warnings.add("mode " + std::to_string(j + 1) + ": damper " + dampers.front().name +
                         " does not move along its drive in this mode: no backbone");
      continue;
    }
    st::BackboneOptions backbone;
    backbone.mode = static_cast<int>(j);
    backbone.reference_damper = 0;
    backbone.damper_amplitudes_m = amplitudes;
    auto b = detail::call_solver(c, "/task", [&] { return st::backbone(modal, dampers_of(j), backbone); });
    for (const auto& p : b.points) out.converged = out.converged && p.converged;
    for (const auto& w : b.warnings) backbone_warnings[w].push_back(j + 1);
    out.backbone_of_mode[j] = out.backbones.size();
    out.backbones.push_back(std::move(b));
  }
  for (const auto& [sentence, modes] : backbone_warnings) {
    std::string list;
    for (const auto m : modes) list += (list.empty() ? "" : ", ") + std::to_string(m);
    setup.warnings.add("backbone (mode" + std::string(modes.size() > 1 ? "s " : " ") + list + "): " + sentence);
  }
  for (Eigen::Index j = 0; j < mode_count; ++j)
    if (!std::isfinite(out.frequencies_with_containers_hz[j]) || !std::isfinite(modal.natural_frequencies_hz[j]))
      throw base::NumericalError("pdamp modes: the natural frequency of mode " + std::to_string(j + 1) + " is not finite");
  if (!out.converged) setup.warnings.add("some backbone points did not converge (converged = 0 in backbone_mode<j>.csv)");
  if (from_task && c.task.modes->dem_check) {
    const case_file::ModesDemCheck& check = *c.task.modes->dem_check;
    const ModeDecayWindow window{check.periods, check.amplitude_fraction, check.forced_start_periods};
    out.dem_check_tolerance = check.tolerance_relative;
    for (const int j : check.modes) {
      const double b = std::abs(coupled.drive_shapes(j, 0));
      if (!moves_damper(j))
        throw base::InputError(c.path, "/task/dem_check/modes",
                               "mode " + std::to_string(j + 1) + " does not move damper " + dampers.front().name +
                                   " along its drive: nothing to check");
      for (const double amplitude : check.amplitudes_m) {
        // The periods are the mode's with the empty containers: the beds' apparent mass moves
        // the frequency by a few per cent at most (backbone_mode<j>.csv), a fraction of a period over the decay.
        const std::string label = "pdamp modes (dem_check, mode " + std::to_string(j + 1) + ", X = " +
                                  base::format_number(amplitude * 1e3, 4) + " mm)";
        out.dem_checks.push_back(mode_decay_check(c, 0, modal, dampers_of(j).front(), dampers.front().point, j, amplitude / b,
                                                  out.frequencies_with_containers_hz[j], window, label,
                                                  "/task/dem_check/periods", hooks));
        // A decay cut short of its measure is fitted over fewer, earlier periods than the
        // check means (and the prediction alike): said, so that it is lengthened.
        if (const double left = out.dem_checks.back().dem_final_fraction; left > check.amplitude_fraction)
          setup.warnings.add(label + ": the DEM decay ended at " + base::format_number(left, 3) +
                             " of its start, above the " + base::format_number(check.amplitude_fraction, 3) +
                             " it is measured down to: its damping ratio is that of its first " +
                             std::to_string(check.periods) + " periods (a larger /task/dem_check/periods measures "
                             "it as meant)");
      }
    }
  }
  out.modal = modal;
  out.warnings = setup.warnings.list();
  if (from_task && c.task.modes->clearance_search) {
    const int j = c.task.modes->clearance_search->mode;
    if (!moves_damper(j))
      throw base::InputError(c.path, "/task/clearance_search/mode",
                             "mode " + std::to_string(j + 1) + " does not move damper " + dampers.front().name +
                                 " along its drive: no clearance changes its damping");
    use_calibration_cache("/task/clearance_search");
    out.clearance_search = detail::search_mode_clearance(c, out.calibration_cache, hooks, out.warnings);
  }
  return out;
}

bool ModesResult::dem_check_passed(std::size_t k) const {
  return std::abs(dem_checks.at(k).whole_relative_difference()) <= dem_check_tolerance;
}

bool ModesResult::dem_checks_passed() const {
  for (std::size_t k = 0; k < dem_checks.size(); ++k)
    if (!dem_check_passed(k)) return false;
  return !dem_checks.empty();
}

const ModeCalibration* ModesResult::calibration_of(Eigen::Index mode) const {
  for (const auto& m : calibrations)
    if (m.mode == mode) return &m;
  return nullptr;
}

const base::Fields<ModeCalibration>& ModeCalibration::fields() {
  using M = ModeCalibration;
  static const auto f =
      base::Fields<M>()
          .derived("mode", [](const M& m) { return m.mode + 1; }, "", "the mode, from 1")
          .field("min_frequency_hz", &M::min_frequency_hz, "Hz", "the field's lower frequency: the bed carried whole")
          .field("max_frequency_hz", &M::max_frequency_hz, "Hz", "its upper: the containers empty")
          .field("min_amplitude_m", &M::min_amplitude_m, "m", "the smallest stroke of its points")
          .field("max_amplitude_m", &M::max_amplitude_m, "m", "the largest, from which the others are approached")
          .field("amplitude_points", &M::amplitude_points, "", "strokes per frequency (log-spaced)")
          .field("key", &M::key, "", "16 hex digits of the physics it depends on")
          .derived("file", [](const M& m) { return m.file.string(); }, "", "its cache file")
          .field("cached", &M::cached, "", "read from the cache (not run now)")
          .field("lower_branch_strokes_m", &M::lower_branch_strokes_m, "m",
                 "strokes where its frequencies found different motion modes: the smaller eta* taken at both")
          .field("wall_time_s", &M::wall_time_s, "s", "of its DEM points (0 when cached)");
  return f;
}

const base::Fields<ModeClearanceCandidate>& ModeClearanceCandidate::fields() {
  using M = ModeClearanceCandidate;
  static const auto f =
      base::Fields<M>()
          .field("clearance_m", &M::clearance_m, "m", "the layer's clearance h (inner length minus the lattice's extent)")
          .field("inner_length_m", &M::inner_length_m, "m", "the container's inner length along the drive")
          .field("wall_layer_thickness_m", &M::wall_layer_thickness_m, "m", "the buffered wall's lining (0: none)")
          .field("layer_tip_strain", &M::layer_tip_strain, "1",
                 "delta_max/t of the lining under the buffer's design impact", base::kNullable)
          .field("buildable", &M::buildable, "", "the lining survives the buffer's design impact (else not run)")
          .field("added_damping_ratios", &M::added_damping_ratios, "1", "zeta_add of the mode at the search's strokes")
          .field("objective", &M::objective, "1", "their mean, or the smallest (the search's objective)", base::kNullable)
          .field("converged", &M::converged, "", "every backbone point converged")
          .field("predicted_check_mean", &M::predicted_check_mean, "1",
                 "mean zeta_add of its DEM-checked decays by the calibrated bed", base::kNullable)
          .field("dem_check_mean", &M::dem_check_mean, "1", "the same by the DEM in the loop", base::kNullable)
          .field("checks_passed", &M::checks_passed, "", "every checked decay's whole zeta within the tolerance");
  return f;
}

const base::Fields<BackboneSummary>& BackboneSummary::fields() {
  using B = BackboneSummary;
  static const auto f =
      base::Fields<B>()
          .field("points", &B::points, "", "amplitudes of the backbone")
          .field("modal_mass_ratio", &B::modal_mass_ratio, "1", "bed mass in the mode over its modal mass")
          .field("max_added_damping_ratio", &B::max_added_damping_ratio, "1", "the most damping the beds add")
          .field("max_added_damping_amplitude_m", &B::max_added_damping_amplitude_m, "m",
                 "the damper amplitude where they add it")
          .field("min_damped_frequency_hz", &B::min_damped_frequency_hz, "Hz", "the lowest damped frequency")
          .field("max_damped_frequency_hz", &B::max_damped_frequency_hz, "Hz", "the highest");
  return f;
}

std::optional<BackboneSummary> backbone_summary(const ModesResult& r, Eigen::Index j) {
  const auto it = r.backbone_of_mode.find(j);
  if (it == r.backbone_of_mode.end()) return std::nullopt;
  const auto& b = r.backbones[it->second];
  const auto best = std::max_element(b.points.begin(), b.points.end(), [](const auto& a, const auto& x) {
    return a.added_damping_ratio < x.added_damping_ratio;
  });
  BackboneSummary out;
  out.points = b.points.size();
  out.modal_mass_ratio = b.modal_mass_ratio;
  out.max_added_damping_ratio = best->added_damping_ratio;
  out.max_added_damping_amplitude_m = best->damper_amplitude_m;
  out.min_damped_frequency_hz = out.max_damped_frequency_hz = b.points.front().damped_frequency_hz;
  for (const auto& p : b.points) {
    out.min_damped_frequency_hz = std::min(out.min_damped_frequency_hz, p.damped_frequency_hz);
    out.max_damped_frequency_hz = std::max(out.max_damped_frequency_hz, p.damped_frequency_hz);
  }
  return out;
}

json to_json(const ModesResult& r, const OutputFolder& folder) {
  const st::ModalModel& modal = r.modal;
  json modes = json::array();
  for (Eigen::Index j = 0; j < r.mode_count; ++j) {
    json shapes = json::object();
    for (const auto& p : modal.points)
      shapes[p.name] = {{"translation_x", p.translation(0, j)}, {"translation_y", p.translation(1, j)},
                        {"rotation", p.rotation(j)}};
    json ratio_per_damper = json::object(), drive = json::object();
    for (std::size_t d = 0; d < r.damper_names.size(); ++d) {
      const auto col = static_cast<Eigen::Index>(d);
      ratio_per_damper[r.damper_names[d]] = r.mass_ratio(j, col);
      drive[r.damper_names[d]] = r.drive_shapes(j, col);
    }
    json mode = {{"mode", j + 1},
                 {"frequency_hz", r.frequencies_with_containers_hz[j]},
                 {"bare_frequency_hz", modal.natural_frequencies_hz[j]},
                 {"damping_ratio", modal.damping_ratios[j]},
                 {"modal_mass_kg", modal.modal_masses_kg[j]},
                 {"modal_mass_ratio", r.modal_mass_ratio(j)},
                 {"modal_mass_ratio_per_damper", ratio_per_damper},
                 {"drive_shape_per_damper", drive},
                 {"shapes", shapes},
                 {"backbone", nullptr},
                 {"loss_model", r.calibration_of(j) != nullptr ? "calibrated" : case_file::to_string(r.method)}};
    if (const auto backbone = backbone_summary(r, j)) {
      mode["backbone"] = base::to_json(*backbone);
      mode["backbone"]["file"] = folder.file("backbone_mode" + std::to_string(j + 1) + ".csv");
    }
    modes.push_back(std::move(mode));
  }
  json result = {{"task", "modes"}, {"case", r.case_name}, {"method", case_file::to_string(r.method)}};
  result["file"] = folder.file("modes.csv");
  result["modes"] = modes;
  result["frequencies"] =
      "frequency_hz: natural frequencies with the empty containers attached (beds removed); bare_frequency_hz: "
      "the structure alone; damping_ratio: the structural modal damping ratio";
  result["rigid_modes_dropped"] = r.rigid_modes_dropped;
  result["backbone"] = {{"reference_damper", r.damper_names.front()},
                        {"amplitude_source", r.backbone_from_task ? "task" : "default"},
                        {"min_amplitude_m", r.backbone_min_amplitude_m},
                        {"max_amplitude_m", r.backbone_max_amplitude_m},
                        {"points", r.backbone_points},
                        {"spacing", "log"},
                        {"plot", folder.file("backbone.png")}};
  result["outcome"] = r.converged ? "converged" : "not_converged";
  result["calibration"] = nullptr;
  if (!r.calibrations.empty()) {
    result["calibration"] = {{"cache", r.calibration_cache.string()}, {"what", ModeCalibration::kWhat}, {"modes", json::array()}};
    for (const auto& m : r.calibrations) result["calibration"]["modes"].push_back(base::to_json(m));
  }
  result["clearance_search"] = nullptr;
  if (const auto& search = r.clearance_search) {
    const auto& s = search->settings;
    json candidates = json::array();
    for (const auto& candidate : search->candidates) {
      json item = base::to_json(candidate);
      item["calibration"] = base::to_json(candidate.calibration);
      item["dem_check"] = json::array();
      for (const auto& check : candidate.checks) item["dem_check"].push_back(base::to_json(check));
      candidates.push_back(std::move(item));
    }
    result["clearance_search"] = {
        {"mode", s.mode + 1},
        {"objective", s.objective == case_file::ModesClearanceSearch::Objective::kWorst ? "worst" : "mean"},
        {"amplitudes_m", search->amplitudes_m},
        {"candidates", candidates},
        {"chosen_clearance_m", search->candidates[search->chosen].clearance_m},
        {"chosen_inner_length_m", search->candidates[search->chosen].inner_length_m},
        {"chosen_wall_layer_thickness_m", search->candidates[search->chosen].wall_layer_thickness_m},
        {"file", folder.file("clearance_search.csv")},
        {"plot", folder.file("clearance_search.png")},
        {"verification", nullptr}};
    if (search->verified)
      result["clearance_search"]["verification"] = {{"tolerance_relative", s.verify->tolerance_relative},
                                                    {"chosen_agrees", search->chosen_agrees},
                                                    {"ranking_agrees", search->ranking_agrees},
                                                    {"outcome", search->passed ? "passed" : "failed"}};
  }
  result["dem_check"] = nullptr;
  result["dem_check_outcome"] = nullptr;
  if (!r.dem_checks.empty()) {
    result["dem_check"] = json::array();
    for (std::size_t k = 0; k < r.dem_checks.size(); ++k) {
      json check = base::to_json(r.dem_checks[k]);
      check["passed"] = r.dem_check_passed(k);
      result["dem_check"].push_back(std::move(check));
    }
    result["dem_check_outcome"] = r.dem_checks_passed() ? "passed" : "failed";
    result["dem_check_tolerance_relative"] = r.dem_check_tolerance;
  }
  return result;
}

}  // namespace pdamp::tasks
