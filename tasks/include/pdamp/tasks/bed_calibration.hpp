// Calibrated beds for the filling-ratio optimiser: each candidate bed (one layer holding n
// whole slabs, the others empty) runs a DEM-in-the-loop free decay of the structure from the
// task's initial state; its response period by period (structure::bed_response_per_period)
// becomes the bed's field along a decay (surrogate::decay_field), which the optimiser uses in
// place of the closed forms. The calibration's DEM runs take the case's seed one further (another
// realisation of the ball lot): a verification never repeats one of them. Each bed is cached in a file of its own under a key of the
// physics it depends on, so a repeated or interrupted calibration runs only what is missing.
#pragma once

#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/filling_ratio_problem.hpp"
#include "pdamp/surrogate/decay_field.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

/// One calibrated bed.
struct CalibratedBed {
  std::string layer;
  int layer_index = 0;
  int slabs = 0;
  /// Damping ratio added to every mode of the structure in the bed's decay: 0 for the bed
  /// alone; in a recalibration (recalibrate_in_design) what a design's other beds add, so that
  /// the bed comes down at the design's rate.
  double extra_damping_ratio = 0.0;
  std::string key;                 ///< 16 hex digits of the physics the calibration depends on
  std::filesystem::path file;      ///< its cache file
  bool cached = false;             ///< read from the cache (not run now)
  surrogate::EffectiveField field;
  std::vector<surrogate::DecayPeriodResponse> periods;
  std::int64_t steps = 0;          ///< of its DEM decay
  double energy_error = 0.0;       ///< the DEM decay's energy-ledger error
  double wall_time_s = 0.0;        ///< of its DEM decay (when it ran)
  double stroke_min_m() const;     ///< the smallest stroke its periods passed (inf: none)
  double stroke_max_m() const;     ///< the largest (0: none)
  static const base::Fields<CalibratedBed>& fields();
};

struct BedCalibration {
  case_file::CalibrationSpec spec;
  std::filesystem::path cache_dir;
  std::vector<CalibratedBed> beds;  ///< layer by layer, slabs 1..max
  int runs = 0;                     ///< beds run now (the others came from the cache)
  double wall_time_s = 0.0;
  /// The beds as optimizer::FillingRatioOptions::bed_models ([layer][slabs], entry 0 empty).
  std::vector<std::vector<std::shared_ptr<const surrogate::LossModel>>> models() const;
  /// What the calibration runs, in words.
  static constexpr std::string_view kWhat =
      "each candidate bed alone in a DEM-in-the-loop free decay of the structure from the task's initial state; its "
      "response period by period binned into a field over the strokes the decay passed";
  static const base::Fields<BedCalibration>& fields();
};

/// The default cache folder: $XDG_CACHE_HOME/pdamp/bed_calibration, else
/// $HOME/.cache/pdamp/bed_calibration, else ./.pdamp-cache/bed_calibration.
std::filesystem::path default_calibration_cache();

/// A bed's key, 16 hex digits of the physics its calibration depends on: the design case's
/// structure, dampers (without their names), materials and DEM settings (the softening
/// included), the release, the duration, the binning, the DEM's model version and the cache
/// format; not names, descriptions or the budget.
std::string calibration_key(const case_file::Case& design, const case_file::CalibrationSpec& spec,
                            double extra_damping_ratio);
/// A bed's cache file, `<layer>_<slabs>_<key>.json` in cache_dir, the layer's name made a
/// safe file-name component (base::safe_file_name): no name leads it out of the folder.
std::filesystem::path calibration_cache_file(const std::filesystem::path& cache_dir, const std::string& layer, int slabs,
                                             const std::string& key);

/// Makes the cache folder (with its parents) and checks that a file can be written there:
/// "" when it can, else why not ("… exists and is not a folder", "cannot create it: …", "is
/// not writable: …"), so that a calibration is refused before its DEM work rather than after.
std::string prepare_calibration_cache(const std::filesystem::path& cache_dir);

/// Calibrates every candidate bed of the case's filling-ratio problem: cached beds are read,
/// the others run as jobs of `executor` (each writes its cache file atomically when done, so
/// an interrupted calibration keeps what finished). A cache file that cannot be read or holds
/// another key is run again, with a note. InputError for a cache folder that cannot be
/// written (prepare_calibration_cache) or refused DEM options, NumericalError
/// for a decay the DEM cannot run or a bed whose decay gives no field.
BedCalibration calibrate_beds(const case_file::Case& c, const case_file::FillingRatioProblem& p,
                              const case_file::CalibrationSpec& spec, const std::filesystem::path& cache_dir,
                              base::RunHooks& hooks, base::Executor& executor);

/// The average damping ratio of a decay from its envelope: ln(e_first/e_last)/(2πf·Δt); NaN
/// with fewer than two points or an envelope that is not positive.
double decay_damping_ratio(std::span<const double> time_s, std::span<const double> envelope_m, double frequency_hz);

/// The closing of the design loop (docs/optimizer.md, "Calibrated beds"): the beds of the
/// design of `slabs` calibrated again where that design operates: each bed's decay with every
/// mode's damping ratio raised by what the design's other beds add, so that the bed comes
/// down at about the design's rate: the design's equivalent damping ratio down to its
/// settling threshold `design_damping_ratio` (from its DEM verification) less the bed's own
/// alone over the same span, down to the stroke `design_threshold_m` (never below 0).
/// Replaces those beds in `calibration` (cached like the others) and returns one line per bed
/// replaced; none for a design of one bed (its calibration is that design already) or for a
/// design_damping_ratio that is not finite (a decay too short to give a rate).
std::vector<std::string> recalibrate_in_design(const case_file::Case& c, const case_file::FillingRatioProblem& p,
                                               BedCalibration& calibration, const std::vector<long>& slabs,
                                               double design_damping_ratio, double design_threshold_m, base::RunHooks& hooks,
                                               base::Executor& executor);

}  // namespace pdamp::tasks
