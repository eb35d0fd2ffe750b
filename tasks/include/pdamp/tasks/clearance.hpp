// Task kind clearance (pdamp optimize, pdamp run): the clearance h of a single-layer damper
// on a base-excited structure that gives the lowest resonant peak |X/U| over a band (or runs
// the damper at its design stroke at the peak), on the harmonic balance with the layer's
// closed form; with `verify`, the DEM-in-the-loop stepped sine at the chosen h and at its
// neighbours, each against the prediction at that clearance (docs/optimizer.md,
// "Clearance on a structure").
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/base/run_hooks.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/tasks/frf.hpp"

namespace pdamp::tasks {

struct ClearanceOptions {
  std::optional<optimizer::Backend> backend;  ///< default: the task's
  bool skip_verify = false;   ///< the sizing only, even with the task's verify block
  bool force_verify = false;  ///< verify with the defaults when the task has no verify block
};

/// Where the DEM puts a neighbour's peak against the chosen clearance's: above or below it by
/// more than twice their combined standard error (over the analysed periods), or not told
/// apart.
enum class DemRanking { kChosen, kHigher, kIndistinguishable, kLower };
std::string_view to_string(DemRanking ranking);  ///< "chosen", "higher", "indistinguishable", "lower"

/// One clearance of the verification: the prediction (the sizing's objective, and the case at
/// that clearance as pdamp frf --method formulas) and the DEM stepped sine up and down
/// (pdamp frf --method dem) over the verification's grid and, besides it, at the predicted
/// peak frequency (a narrow predicted peak would fall between the grid's points). The DEM's
/// peak is the larger of the two directions' (the worst the structure reaches, on either
/// branch).
struct ClearanceCheck {
  double factor = 1.0;       ///< on the chosen clearance (1: the chosen one)
  double clearance_m = 0.0;
  /// The prediction: the sizing's objective at this clearance (the largest non-unstable or
  /// held |X/U| over the band, optimizer::clearance_response) and its frequency, and the
  /// 0.9-band centre of the harmonic balance's largest peak (NaN: no peak found).
  double predicted_peak = NAN, predicted_frequency_hz = NAN, predicted_band_centre_hz = NAN;
  /// What slow sweeps reach on the predicted branches: the larger peak of an up and a down
  /// sweep over the band (predicted_sweep_peak). Below predicted_peak where the worst case
  /// lies on an upper branch beside a lower one that a sweep from the band's ends stays on.
  double predicted_sweep_peak = NAN;
  structure::SweepDirection dem_sweep = structure::SweepDirection::kUp;  ///< the direction of the larger DEM peak
  double dem_peak = NAN, dem_peak_standard_error = NAN, dem_frequency_hz = NAN, dem_band_centre_hz = NAN;
  /// (predicted sweep peak − DEM)/DEM of the peak |X/U| (the DEM's stepped sines are sweeps),
  /// and (predicted − DEM)/DEM of the 0.9-band centre (NaN without a predicted peak).
  double peak_relative_difference = NAN, band_centre_relative_difference = NAN;
  DemRanking ranking = DemRanking::kChosen;  ///< a neighbour's DEM peak against the chosen clearance's
  int unconverged_points = 0;  ///< DEM points whose transient had not converged (analysed anyway)
  double wall_time_s = 0.0;    ///< the DEM stepped sine (both directions)
  FrfResult formulas;          ///< the prediction's response (for the files)
  FrfResult dem;               ///< the stepped sine (for the files)
  static const base::Fields<ClearanceCheck>& fields();
};

/// The largest |X/U| of the first output that a slow sweep reaches on the harmonic balance's
/// states: from each end of the band (up from the lowest frequency, down from the highest)
/// the sweep starts on the smallest non-unstable root or held state and at each next
/// frequency takes the one nearest in ln |X/U| to where it was (it stays on its branch, and
/// jumps to the nearest state where its branch ends); the larger of the two sweeps' maxima.
/// NaN without any state.
double predicted_sweep_peak(const structure::FrequencyResponse& response);

struct ClearanceVerification {
  case_file::ClearanceVerifySpec settings;
  std::vector<ClearanceCheck> checks;  ///< the chosen clearance first, then the neighbours in the case's order
  /// The chosen clearance's DEM peak and band centre within tolerance_relative of the prediction.
  bool chosen_agrees = false;
  /// The DEM contradicts no predicted ranking: no neighbour is kLower by the DEM where its
  /// predicted sweep peak lies above the chosen clearance's.
  bool ranking_agrees = false;
  /// Every neighbour's DEM peak lies above the chosen clearance's beyond the scatter (kHigher
  /// everywhere): the DEM confirms the ranking, not only does not contradict it.
  bool ranking_resolved = false;
  /// Every neighbour's DEM peak lies within tolerance_relative of its predicted sweep peak
  /// (reported; the verdict is on the chosen clearance and the ranking).
  bool neighbours_agree = false;
  bool passed = false;  ///< chosen_agrees, and ranking_agrees where require_ranking
  static const base::Fields<ClearanceVerification>& fields();
};

struct ClearanceStudy {
  std::string case_name;
  std::string damper;
  int mode = 0;  ///< 0-based
  optimizer::ClearanceObjective objective = optimizer::ClearanceObjective::kLowestPeak;
  double base_amplitude_m = 0.0;
  optimizer::ClearanceOnStructureResult sizing;
  optimizer::ClearanceResponse current;  ///< at the case's own clearance
  /// The peak against h: kScanPoints clearances evenly spaced in ln h over the search range
  /// (the picture of the objective, its onset cliff and its high-amplitude branch).
  std::vector<optimizer::ClearanceResponse> scan;
  static constexpr int kScanPoints = 41;
  std::optional<ClearanceVerification> verification;
  std::vector<std::string> warnings;
};

/// The clearance study of a case whose task is kind clearance (InputError naming /task
/// otherwise). The sizing runs on the primary process; the verification's stepped sines
/// spread their two directions over `executor`.
ClearanceStudy run_clearance(const case_file::Case& c, const ClearanceOptions& options, base::RunHooks& hooks,
                             base::Executor& executor = base::local_executor());
/// The result keys (task, case, damper, mode, objective, design, current, estimate, solver,
/// verification, solve_time_s).
nlohmann::json to_json(const ClearanceStudy& study);

}  // namespace pdamp::tasks
