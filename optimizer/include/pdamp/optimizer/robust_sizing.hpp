// Robust clearance sizing on the closed forms: the clearance h that
// maximises the worst-case (or mean) η* over a range of operating strokes and
// frequencies, with every operating stroke above the onset by a margin.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/summary.hpp"

namespace pdamp::optimizer {

enum class RobustCriterion {
  /// maximise min_k η*(X_k, f_k; h), as the smooth epigraph problem
  /// max t s.t. t <= η*_k(h) for every sample k (variables h and t)
  kWorstCase,
  kMean,  ///< maximise the mean of η*(X_k, f_k; h) over the samples
};

/// The operating range is the rectangle [stroke_min_m, stroke_max_m] ×
/// [frequency_min_hz, frequency_max_hz], sampled geometrically (ends included; one
/// sample on an axis whose range is a point): a stroke range at one frequency, a
/// frequency band at one stroke, or both.
struct RobustSizingOptions {
  /// kRolling, kBouncing or kAuto (kScattered has no orbit to size).
  formulas::DamperModel model = formulas::DamperModel::kRolling;
  formulas::ModelOptions model_options;
  double stroke_min_m = 0.0;        ///< least operating stroke X_min, m, > 0
  double stroke_max_m = 0.0;        ///< largest operating stroke, m, >= stroke_min_m
  double frequency_min_hz = 0.0;    ///< Hz, > 0
  double frequency_max_hz = 0.0;    ///< Hz, >= frequency_min_hz
  int stroke_samples = 9;           ///< samples of the stroke range, in [2, 1000] (1 used for a point)
  int frequency_samples = 5;        ///< samples of the frequency band, in [2, 1000] (1 used for a point)
  /// Search range of h, m; default stroke_min_m/10 and 10·stroke_max_m.
  std::optional<double> clearance_min_m;
  std::optional<double> clearance_max_m;
  /// Every operating stroke stays at X >= (1 + onset_margin)·X_onset(h), X_onset the
  /// onset of the family the closed form uses there (docs/theory.md §2-3); in [0, 1].
  double onset_margin = 0.1;
  RobustCriterion criterion = RobustCriterion::kWorstCase;
  /// One line per violated rule ("stroke_min_m = 0: must be > 0 and finite"), the
  /// model options' lines prefixed "model_options."; empty if valid.
  std::vector<std::string> validate() const;
};

struct RobustSizing {
  double clearance_m = 0.0;
  double worst_eta_star = 0.0;  ///< min of η* over the samples at clearance_m
  double mean_eta_star = 0.0;   ///< mean of η* over the samples at clearance_m
  /// min over the samples of X/X_onset(h): >= 1 + onset_margin (to the solver's
  /// constraint tolerance, relative)
  double least_stroke_over_onset = 0.0;
  Summary summary;  ///< of the solve; variables "clearance_m" (and "worst_eta_star")
};

/// Solves the sizing problem with solve(problem, solver_options); η* slopes by forward
/// differences, the margin constraint "onset_margin" with its exact slope. Throws
/// std::invalid_argument for invalid options (every violation, one a line) and when
/// the margin cannot hold inside the clearance range (naming "onset_margin").
RobustSizing size_clearance_robustly(const RobustSizingOptions& options, const Options& solver_options = {});

}  // namespace pdamp::optimizer
