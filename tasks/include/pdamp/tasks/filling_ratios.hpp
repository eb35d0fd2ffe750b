// Task kind filling_ratios (pdamp optimize, pdamp run): how many whole slabs each layer of
// the first damper holds for the fastest free decay under a particle-mass budget (NLopt or
// Ipopt on the closed forms), the whole-slab designs and the best single layer, the decays
// that compare them, and the DEM verification of the chosen design against the baseline.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case.hpp"
#include "pdamp/case_file/filling_ratio_problem.hpp"
#include "pdamp/optimizer/filling_ratios.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/sampled_decay.hpp"
#include "pdamp/tasks/bed_calibration.hpp"
#include "pdamp/base/executor.hpp"
#include "pdamp/base/record.hpp"
#include "pdamp/tasks/output_folder.hpp"
#include "pdamp/base/run_hooks.hpp"

namespace pdamp::tasks {

struct FillingRatiosOptions {
  std::optional<optimizer::Backend> backend;  ///< default: the task's
  /// The DEM verification: the task's verify block when present; `force_verify` runs it
  /// with its defaults when the task has none; `skip_verify` runs none.
  bool force_verify = false;
  bool skip_verify = false;
  /// The verification's checkpoints, verify_<design>.checkpoint in this folder (empty: none).
  std::filesystem::path checkpoint_dir;
  bool resume = false;  ///< continue the verification's decays from their checkpoints
  /// The beds' models: true calibrated (the task's calibration block, or its defaults),
  /// false the closed forms; default: calibrated when the task has a calibration block.
  std::optional<bool> calibrated;
  /// Where calibrated beds are cached (empty: default_calibration_cache()).
  std::filesystem::path calibration_cache;
};

/// What the verification keeps of a design's DEM decay: what it compares, reports and plots.
struct VerifiedDecay {
  std::vector<double> time_s;               ///< the co-simulation's samples, s
  std::vector<double> site_displacement_m;  ///< y − y_s at the first damper's site, per sample
  structure::SampledSettling settling;
  double threshold_m = 0.0, initial_envelope_m = 0.0;
  double energy_error = 0.0, dem_dissipated_j = 0.0, structural_dissipated_j = 0.0;
  std::int64_t steps = 0;
  double time_step_s = 0.0, wall_time_s = 0.0;
  std::vector<std::string> warnings;
  double objective = NAN;       ///< settling time (NaN: not settled) or ½∫e² dt, as the task's objective
  double end_envelope_m = NAN;  ///< the envelope at the end of the record, m
  /// A design check's "dem" (a job's result in full).
  static const base::Fields<VerifiedDecay>& fields();
  /// The softening check's shorter "dem".
  static const base::Fields<VerifiedDecay>& summary_fields();
};

/// What an agreement compared: the objectives (both settled, or ½∫e² dt), the envelopes at
/// the end (neither settled), or nothing (only one settled: they disagree).
enum class Compared { kObjective, kEndEnvelope, kSettledOnlyOne };
/// "objective", "end_envelope", "settled_only_one".
std::string_view to_string(Compared compared);

/// How one objective agrees with a reference: the objectives (settling time or ½∫e² dt),
/// or, when neither settled, the envelopes at the end.
struct Agreement {
  Compared compared = Compared::kSettledOnlyOne;
  double relative_difference = NAN;  ///< (value − reference)/reference
  bool within = false;               ///< |relative_difference| <= the tolerance
};

/// The same DEM decay with contacts ten times stiffer (VerifySpec::softening_check): the
/// softening has converged on the objective when the two agree within the tolerance.
struct SofteningCheck {
  double stiffness_softening = NAN;  ///< the stiffer run's verify softening (10x, at most full)
  VerifiedDecay dem;
  Agreement agreement;               ///< the judged run against the stiffer one
  static const base::Fields<SofteningCheck>& fields();
};

/// One design checked by the DEM: the prediction over the verification's duration and the
/// DEM's decay over the same time.
struct DesignCheck {
  std::string name;               ///< "chosen" or "baseline"
  optimizer::FillingDesign design;
  optimizer::FillingDesign predicted;   ///< the closed forms over verify.duration_s
  double predicted_objective = NAN;     ///< its settling time or ½∫e² dt
  double predicted_end_envelope_m = NAN;
  std::vector<double> predicted_envelope_m;  ///< at the DEM's sample times
  VerifiedDecay dem;
  Agreement agreement;            ///< the DEM against the prediction
  bool passed = false;            ///< agreement.within, and the softening check's if run
  std::optional<SofteningCheck> softening_check;
  int particles = 0;
  static const base::Fields<DesignCheck>& fields();
};

/// The verification's check of its softened contacts.
enum class SofteningCheckKind {
  kOff,            ///< VerifySpec::softening_check false
  kFullStiffness,  ///< the judged runs are at full stiffness: nothing to check
  kTwoSoftenings,  ///< each design also ran ten times stiffer
};
/// "off", "full_stiffness", "two_softenings".
std::string_view to_string(SofteningCheckKind kind);

struct Verification {
  case_file::VerifySpec spec;
  double dem_stiffness_softening = 1.0;  ///< the case's /dem softening (the runs use it times spec's)
  bool settling_objective = true;
  std::vector<DesignCheck> designs;  ///< chosen, baseline
  bool predicted_chosen_ahead = false;
  bool dem_chosen_ahead = false;
  bool ranking_passed = false;
  SofteningCheckKind softening_check = SofteningCheckKind::kOff;
  bool softening_converged = false;  ///< every design's check agreed (true at full stiffness)
  bool passed = false;
  double wall_time_s = 0.0;
  nlohmann::json mpi;  ///< how the two decays spread over processes, or null
  /// What the verification runs, in words.
  static constexpr std::string_view kWhat =
      "DEM-in-the-loop free decay (structure::cosimulate) of the chosen and baseline designs on the optimiser's modal "
      "model, from the task's initial state, against the prediction (the optimiser's bed models) over the same time";
  static const base::Fields<Verification>& fields();
};

/// The closed-form envelopes of the chosen, baseline and starting designs on one time grid
/// (decay_compare.csv).
struct DesignComparison {
  std::vector<structure::FreeDecay> decays;  ///< chosen, baseline, initial, bare (no particles)
};

/// One round of the design loop: the designs verified and how they agreed.
struct VerificationRound {
  int round = 1;
  struct Design {
    std::string name;  ///< "chosen", "baseline"
    std::vector<double> slabs;
    double predicted_objective = NAN, dem_objective = NAN;  ///< NaN: not settled
    double predicted_end_envelope_m = NAN, dem_end_envelope_m = NAN;
    Compared compared = Compared::kSettledOnlyOne;
    double relative_difference = NAN;
    bool passed = false;
    static const base::Fields<Design>& fields();
  };
  std::vector<Design> designs;
  bool ranking_passed = false;
  bool passed = false;
  /// The beds recalibrated after this round (empty: the loop ended here).
  std::vector<std::string> recalibrated;
  static const base::Fields<VerificationRound>& fields();
};

/// How the design loop ended.
enum class LoopOutcome {
  kAgreed,                ///< a round's verification passed
  kRoundsExhausted,       ///< the last round allowed failed
  kNothingToRecalibrate,  ///< a round failed and no bed of the chosen design could be recalibrated
};
/// "agreed", "rounds_exhausted", "nothing_to_recalibrate".
std::string_view to_string(LoopOutcome outcome);

struct FillingRatiosResult {
  std::string case_name;
  case_file::FillingRatioProblem problem;
  double mass_budget_kg = 0.0;
  std::optional<BedCalibration> calibration;  ///< the calibrated beds the optimiser used, if any
  optimizer::FillingRatioResult optimum;
  DesignComparison comparison;
  std::optional<Verification> verification;  ///< of the last round
  std::vector<VerificationRound> rounds;     ///< every round of the design loop (one without calibration)
  std::optional<LoopOutcome> loop_outcome;   ///< none without a verification
  std::vector<std::filesystem::path> checkpoints;  ///< the verification's files, to remove once its results are kept
  std::vector<std::string> warnings;
};

/// The filling-ratio study of a case whose task is kind filling_ratios. The beds'
/// calibration, each round's verification and the recalibrations are batches of jobs of
/// `executor`, whose results every process gets (each goes on alike to the next batch);
/// without DEM runs the study runs on the primary process alone (on another:
/// base::JobsServedElsewhere). The runs' progress and checkpoints go through `hooks`.
FillingRatiosResult run_filling_ratios(const case_file::Case& c, const FillingRatiosOptions& options, base::RunHooks& hooks,
                                       base::Executor& executor);
/// The result keys (task, case, method, design, designs, solver, verification, ...).
nlohmann::json to_json(const FillingRatiosResult& result);

}  // namespace pdamp::tasks
