// Private helpers of task kind modes: one mode's calibrated bed (modes.hpp, ModeCalibration)
// and the clearance search on calibrated beds (ModeClearanceSearchResult).
#pragma once

#include <filesystem>

#include "pdamp/base/run_hooks.hpp"
#include "pdamp/case_file/case.hpp"
#include "pdamp/tasks/modes.hpp"

namespace pdamp::tasks::detail {

/// Where a mode's bed is calibrated.
struct ModeCalibrationRange {
  int mode = 0;                       ///< 0-based
  double carried_frequency_hz = 0.0;  ///< the mode's with the first damper's bed carried whole
  double empty_frequency_hz = 0.0;    ///< with the containers empty
  double min_amplitude_m = 0.0, max_amplitude_m = 0.0;  ///< the damper's strokes (the backbone's)
};

/// The first damper's bed calibrated for one mode: its DEM field read from `cache_dir` when a
/// file there holds it, else run (its points through a resumable log in `cache_dir`) and
/// cached atomically. InputError for DEM settings the field refuses, NumericalError for
/// points that fail.
ModeCalibration calibrate_mode(const case_file::Case& c, const case_file::ModesCalibrationSpec& spec,
                               const ModeCalibrationRange& range, const std::filesystem::path& cache_dir,
                               base::RunHooks& hooks);

/// The task's clearance_search: each candidate a variant of `c` (its clearance, the search's
/// strokes as the backbone, its mode calibrated with the search's settings) through
/// run_modes, the best by the objective, and with `verify` the DEM decays of it and its
/// neighbours in the list. Calibrations cached in `cache_dir`; warnings appended to `warnings`.
/// InputError naming /task/clearance_search/clearances_m/k for a candidate the case refuses.
ModeClearanceSearchResult search_mode_clearance(const case_file::Case& c, const std::filesystem::path& cache_dir,
                                                base::RunHooks& hooks, std::vector<std::string>& warnings);

}  // namespace pdamp::tasks::detail
