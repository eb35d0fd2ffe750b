// Task kind frf (pdamp frf): the frequency response of a structure with its dampers, by the
// harmonic balance on the layers' loss models (formulas or field: every root, stability,
// branches, jumps, peaks, and the response without beds), by the DEM in the loop (a stepped
// sine up and down in frequency whose two directions an Executor spreads, or a linear sine
// sweep), or all three compared.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/structure_setup.hpp"
#include "pdamp/structure/dem_frequency_response.hpp"
#include "pdamp/structure/harmonic_balance.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/tasks/output_folder.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

enum class FrfMethod { kFormulas, kField, kDem, kCompare };

/// The DEM's part of an frf study (--method dem and --compare).
struct DemFrfOptions {
  int points = 9;                          ///< stepped sine: frequencies, linear over the band, [2, 1000]
  /// Stepped sine: frequencies run besides the linear grid (where a prediction puts a narrow
  /// peak between its points), merged in order; one within a quarter of the grid's spacing of
  /// a grid frequency is left out (the grid's own point stands for it).
  std::vector<double> extra_frequencies_hz;
  double min_frequency_hz = 0.0;           ///< the band, Hz (the task's by default), max > min > 0
  double max_frequency_hz = 0.0;
  /// The directions asked for, up first.
  std::vector<structure::SweepDirection> directions{structure::SweepDirection::kUp, structure::SweepDirection::kDown};
  bool linear_sweep = false;               ///< a linear sine sweep instead of the stepped sine
  std::optional<double> sweep_rate_hz_s;   ///< linear sweep: default quasi_stationary_sweep_rate at the formulas' resonance
  structure::SteadyStateSettling settling; ///< each frequency's settling to its steady state
};
/// The band and points of the case's frf task.
DemFrfOptions default_dem_frf_options(const case_file::Case& c);

struct FrfOptions {
  FrfMethod method = FrfMethod::kFormulas;
  DemFrfOptions dem;
};

/// The harmonic balance's response for one loss method.
struct HarmonicFrf {
  case_file::LossMethod method = case_file::LossMethod::kFormulas;
  structure::FrequencyResponse response;
  std::vector<std::string> damper_names;
  bool converged = true;
  surrogate::AxisSpacing spacing = surrogate::AxisSpacing::kLinear;  ///< of the task's frequencies
};

/// The stepped sine's branches (up first).
struct SteppedSineFrf {
  std::vector<structure::SteppedSineBranch> branches;
  std::vector<double> frequencies_hz;  ///< requested, ascending
  std::vector<std::string> damper_names;
  bool parallel = false;
  int analysed_periods = 0;
  double time_step_s = 0.0;
  double solve_time_s = 0.0;           ///< wall time of the whole sweep (both directions)
  structure::SteadyStateSettling settling;
  nlohmann::json mpi;                  ///< how the directions spread over processes, or null
};

/// The linear sine sweep's directions.
struct LinearSweepFrf {
  std::vector<structure::LinearSineSweep> sweeps;
  std::vector<std::string> damper_names;
  double rate_hz_s = 0.0, duration_s = 0.0, min_frequency_hz = 0.0, max_frequency_hz = 0.0;
  std::string rate_basis;  ///< "--dem-sweep-rate", or where the default came from
  bool parallel = false;
  double solve_time_s = 0.0;
};

/// A response's peak of one output, as a result shows it.
struct PeakSummary {
  std::string output;  ///< the output's name
  double frequency_hz = NAN, magnitude = NAN, damping_ratio = NAN, band_centre_hz = NAN;
  static const base::Fields<PeakSummary>& fields();
};
/// The peaks of `response` (`peaks` or `linear_peaks`) with their outputs' names.
std::vector<PeakSummary> peak_summaries(const std::vector<structure::ResponsePeak>& peaks,
                                        const std::vector<std::string>& output_names);

/// A DEM direction's resonance of one output (structure::SampledPeak), NaN where not found.
struct DemPeak {
  std::string output;
  structure::SweepDirection sweep = structure::SweepDirection::kUp;
  double frequency_hz = NAN, largest_point_frequency_hz = NAN, magnitude = NAN;
  double magnitude_standard_error = NAN;  ///< the first output's (its per-period amplitudes are recorded)
  double band_low_hz = NAN, band_high_hz = NAN, band_centre_hz = NAN;
  double indistinguishable_low_hz = NAN, indistinguishable_high_hz = NAN;
  double maximum_low_hz = NAN, maximum_high_hz = NAN;  ///< structure::SampledPeak's bracket of the maximum
  double damping_ratio = NAN;
  static const base::Fields<DemPeak>& fields();
  /// A linear sweep's peak (no single largest point, no indistinguishable range).
  static const base::Fields<DemPeak>& sweep_fields();
};

/// How a method's largest peak of the first output agrees with a DEM direction's.
struct PeakAgreement {
  double frequency_hz = NAN, band_centre_hz = NAN, magnitude = NAN;
  /// (method − dem)/dem of the peak (argmax) frequency, the 0.9 band's centre and the magnitude.
  double frequency_relative_difference = NAN, band_centre_relative_difference = NAN, magnitude_relative_difference = NAN;
  double damping_ratio = NAN, dem_damping_ratio = NAN;
  /// The method's peak frequency lies among the DEM points that cannot be told from the largest.
  bool frequency_within_dem_indistinguishable = false;
  /// The method's peak frequency lies where the DEM's sampled maximum can be: between the
  /// points either side of those (the DEM's resolution in frequency, the agreement to ask for).
  bool frequency_within_dem_maximum = false;
  static const base::Fields<PeakAgreement>& fields();
};

/// --compare: the formulas' and the field's agreement with one DEM direction (none: the
/// method has no peak of the first output, or no field).
struct BranchAgreement {
  structure::SweepDirection sweep = structure::SweepDirection::kUp;
  std::optional<PeakAgreement> formulas, field;
  static const base::Fields<BranchAgreement>& fields();
};

struct FrfResult {
  std::string case_name;
  FrfMethod method = FrfMethod::kFormulas;
  bool base_excitation = true;  ///< transmissibility |X/U|, else receptance |X/F|
  std::optional<HarmonicFrf> harmonic;  ///< kFormulas, kField; kCompare: the formulas'
  std::optional<HarmonicFrf> field;     ///< kCompare: when every layer has a field_file
  std::optional<SteppedSineFrf> stepped;  ///< kDem (stepped), kCompare
  std::optional<LinearSweepFrf> linear;   ///< kDem with linear_sweep
  /// kDem: the structure without particles (the containers empty; linear, so the harmonic
  /// balance is exact) over the task's band, for the plots.
  std::optional<structure::FrequencyResponse> without_beds;
  std::vector<BranchAgreement> agreement;  ///< kCompare: per DEM direction
  std::vector<std::string> warnings;
};

/// The frf study of a case whose task is kind frf (InputError naming /task otherwise). The
/// stepped sine's directions (--method dem, --compare) are a batch of jobs of `executor`,
/// whose results every process gets; the other methods run on the primary process alone
/// (on another: base::JobsServedElsewhere).
FrfResult run_frf(const case_file::Case& c, const FrfOptions& options, base::RunHooks& hooks, base::Executor& executor);
/// The result keys (task, case, method, file, peaks, branches, frf or compare, ...); "warnings"
/// and "outputs" are the caller's.
nlohmann::json to_json(const FrfResult& result, const OutputFolder& folder);
/// "transmissibility |X/U|" or "receptance |X/F| / (m/N)": the magnitude's axis label.
std::string magnitude_label(const FrfResult& result);
/// What the magnitude is, in words (the result's frf.magnitude).
std::string magnitude_description(const FrfResult& result);
/// Each output's peaks as the result reports them: the harmonic balance's, or each DEM
/// direction's (stepped sine or sweep, NaN where a sweep found none); none for --compare.
std::vector<PeakSummary> response_peaks(const FrfResult& result);
/// The largest peak of the first output, or nullptr.
const structure::ResponsePeak* first_output_peak(const structure::FrequencyResponse& response);
/// "fold", "discontinuity" or "stroke_range".
std::string_view branch_end_kind(structure::BranchEnd::Kind kind);

}  // namespace pdamp::tasks
