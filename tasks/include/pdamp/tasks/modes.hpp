// Task kind modes (pdamp modes): natural frequencies with the empty containers and bare,
// mode shapes at the named points, the beds' modal mass ratios, and the backbones f(X),
// zeta_add(X) of each mode with the dampers' loss models.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/modal_model.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/base/run_hooks.hpp"
#include "pdamp/tasks/mode_decay.hpp"
#include "pdamp/tasks/output_folder.hpp"

namespace pdamp::tasks {

struct ModesOptions {
  case_file::LossMethod method = case_file::LossMethod::kFormulas;  ///< formulas or field
  /// The calibrated modes take the DEM's bed (the task's `calibration`, or its defaults):
  /// std::nullopt: when the task has a `calibration`.
  std::optional<bool> calibrated;
  std::filesystem::path calibration_cache;  ///< empty: default_calibration_cache()
};

/// One mode's calibrated bed (case_file::ModesCalibrationSpec): the first damper's bed as a
/// DEM effective field over two frequencies, the mode's with the bed carried whole (m_app =
/// m_bed) and with the containers empty (m_app = 0), each widened by 1 %, and the backbone's
/// amplitudes (log-spaced); every point comes down from 25 % above the largest (the
/// descending branch a decay follows, docs/dem.md "Approach"). Cached like the filling-ratio beds, in a
/// field file of its own under a key of the physics it depends on.
struct ModeCalibration {
  int mode = 0;  ///< 0-based
  double min_frequency_hz = 0.0, max_frequency_hz = 0.0;
  double min_amplitude_m = 0.0, max_amplitude_m = 0.0;
  int amplitude_points = 0;
  std::string key;               ///< 16 hex digits of the physics the field depends on
  std::filesystem::path file;    ///< its cache file
  bool cached = false;           ///< read from the cache (not run now)
  double wall_time_s = 0.0;      ///< of its DEM points (when they ran)
  /// Strokes at which its two frequencies found the bed in different motion modes: both take
  /// the point of the smaller η* there (the lower branch; the cached file keeps the DEM's).
  std::vector<double> lower_branch_strokes_m;
  surrogate::EffectiveField field;
  static constexpr std::string_view kWhat =
      "for each calibrated mode, the first damper's bed as a DEM effective field from steady states between the mode's "
      "frequency with the bed carried whole and with the containers empty, over the backbone's strokes, each approached "
      "from 25 % above the largest; that mode's backbone and dem_check prediction use it";
  static const base::Fields<ModeCalibration>& fields();
};

/// One candidate of the search (case_file::ModesClearanceSearch): a clearance (and a buffered
/// wall's lining thickness), its calibrated bed, the mode's added damping at the search's
/// strokes, and, when verified, its DEM decays.
struct ModeClearanceCandidate {
  double clearance_m = 0.0;     ///< the layer's clearance h (free length along the drive minus the lattice's extent)
  double inner_length_m = 0.0;  ///< the container's inner length along the drive
  double wall_layer_thickness_m = 0.0;  ///< the buffered wall's lining t (0: none)
  /// δ_max/t of the lining under the case's buffer design impact (NaN: no lining or no buffer).
  double layer_tip_strain = NAN;
  /// false: the strain exceeds the buffer's allowable strain; not calibrated, never chosen.
  bool buildable = true;
  std::vector<double> added_damping_ratios;  ///< ζ_add at the search's strokes (the backbone's)
  double objective = NAN;       ///< their mean, or the smallest (the search's objective)
  bool converged = true;        ///< every backbone point converged
  ModeCalibration calibration;
  /// The verify decays (the chosen clearance and its neighbours; empty otherwise), and the mean
  /// ζ_add over them by the prediction and by the DEM.
  std::vector<ModeDecayCheck> checks;
  double predicted_check_mean = NAN, dem_check_mean = NAN;
  bool checks_passed = false;  ///< every decay's whole ζ within the tolerance
  static const base::Fields<ModeClearanceCandidate>& fields();
};

struct ModeClearanceSearchResult {
  case_file::ModesClearanceSearch settings;
  std::vector<double> amplitudes_m;  ///< the strokes the objective takes (log-spaced)
  /// In the search's order: ascending t, and within each t ascending h.
  std::vector<ModeClearanceCandidate> candidates;
  std::size_t chosen = 0;  ///< the largest objective among the buildable candidates
  /// The DEM verification (settings.verify): the chosen candidate's decays pass, and no
  /// neighbour's DEM mean ζ_add beats the chosen's by more than the tolerance on the whole ζ
  /// (bare plus added; the DEM does not contradict the choice). The neighbours: the next
  /// clearances at the chosen thickness, and the next buildable thicknesses at its clearance.
  bool verified = false, chosen_agrees = false, ranking_agrees = false, passed = false;
};

struct ModesResult {
  std::string case_name;
  case_file::LossMethod method = case_file::LossMethod::kFormulas;
  structure::ModalModel modal;                     ///< the structure's modes (bare frequencies, shapes at points)
  Eigen::Index mode_count = 0;                     ///< modes reported
  Eigen::VectorXd frequencies_with_containers_hz;  ///< the empty containers attached
  Eigen::MatrixXd drive_shapes;                    ///< modes x dampers, along each damper's drive
  Eigen::MatrixXd mass_ratio;                      ///< modes x dampers: μ_dj = b_dj² Σ_l m_bed,l / m_j
  std::vector<std::string> damper_names;
  std::vector<std::string> layer_names;            ///< "damper/layer"
  std::vector<structure::Backbone> backbones;      ///< of the modes in which the first damper moves
  std::map<Eigen::Index, std::size_t> backbone_of_mode;
  double backbone_min_amplitude_m = 0.0, backbone_max_amplitude_m = 0.0;
  int backbone_points = 0;
  bool backbone_from_task = false;                 ///< the task's range, else the default
  int rigid_modes_dropped = 0;
  bool converged = true;                           ///< every backbone point converged
  /// The task's dem_check: each mode's decay from each amplitude, by the loss models and the
  /// DEM in the loop (mode by mode, amplitudes ascending); empty without one.
  std::vector<ModeDecayCheck> dem_checks;
  /// Each check passes when its mode's whole damping ratio (structural plus added) by the
  /// prediction lies within this fraction of the DEM's (the task's tolerance_relative).
  double dem_check_tolerance = 0.15;
  /// The calibrated modes' beds (in the calibration's order); empty without a calibration.
  std::vector<ModeCalibration> calibrations;
  std::filesystem::path calibration_cache;  ///< where they are cached (with calibrations)
  /// The task's clearance_search (its candidates calibrated whatever the method), if any.
  std::optional<ModeClearanceSearchResult> clearance_search;
  std::vector<std::string> warnings;
  /// The prediction of check k within dem_check_tolerance of the DEM (whole damping ratios).
  bool dem_check_passed(std::size_t k) const;
  /// Every check passed (false without checks).
  bool dem_checks_passed() const;
  /// Mode j's calibration, if it has one.
  const ModeCalibration* calibration_of(Eigen::Index mode) const;
  /// Mode j's μ_j summed over the dampers, in their order.
  double modal_mass_ratio(Eigen::Index mode) const {
    double total = 0.0;
    for (Eigen::Index d = 0; d < mass_ratio.cols(); ++d) total += mass_ratio(mode, d);
    return total;
  }
};

/// A mode's backbone in brief: where the beds add the most damping, over which frequencies.
struct BackboneSummary {
  std::size_t points = 0;
  double modal_mass_ratio = NAN;
  double max_added_damping_ratio = NAN, max_added_damping_amplitude_m = NAN;
  double min_damped_frequency_hz = NAN, max_damped_frequency_hz = NAN;
  static const base::Fields<BackboneSummary>& fields();
};
/// Mode j's backbone (0-based), if it has one.
std::optional<BackboneSummary> backbone_summary(const ModesResult& result, Eigen::Index mode);

/// The modes study of a format-2 case (any task kind: the backbone range is the modes
/// task's, else 40 log-spaced amplitudes from 1 mm to twice the largest clearance), with the
/// task's calibration (calibrated modes: their backbones and dem_check predictions from the
/// calibrated bed) and dem_check (the DEM runs report through `hooks`). It runs on the primary
/// process alone (on another: base::JobsServedElsewhere). InputError for a calibration asked
/// of a case without a modes task or modes to calibrate, or a cache folder that cannot be written.
ModesResult run_modes(const case_file::Case& c, const ModesOptions& options, base::RunHooks& hooks = base::silent_hooks(),
                      base::Executor& executor = base::local_executor());
/// The result keys (task, case, method, file, modes, frequencies, backbone, outcome, ...).
nlohmann::json to_json(const ModesResult& result, const OutputFolder& folder);

}  // namespace pdamp::tasks
