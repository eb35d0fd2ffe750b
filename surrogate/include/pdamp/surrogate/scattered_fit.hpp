// Weighted least-squares fit of the empirical scattered-state law (docs/theory.md §4) to
// field points below the collect-and-collide onset, and its coefficient file.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/surrogate/effective_field.hpp"

namespace pdamp::surrogate {

/// One field point below the onset, in the variables of formulas::ScatteredFit.
struct ScatteredSample {
  double s = 0.0;                ///< X/X_onset of the family used, in (0, 1)
  double eta_star = 0.0;         ///< measured or simulated η*, dimensionless
  double eta_star_stderr = 0.0;  ///< its standard error, > 0 (weight 1/stderr²)
  double eta_star_onset = 0.0;   ///< η*_onset of the family used, > 0
};

/// The ok points of `field` with s = X/X_onset < 1. The family (and so X_onset and
/// η*_onset, formulas::optimum_stroke) is `model` for kRolling and kBouncing, and chosen
/// per point by Γ = XΩ²/g as in formulas::reduced_loss_factor for kAuto and kScattered
/// (Γ < 1 rolling, else bouncing). Standard errors are copied as they are (the fit
/// rejects missing ones). Throws std::invalid_argument for an invalid field or options.
std::vector<ScatteredSample> scattered_samples(const EffectiveField& field,
                                               formulas::DamperModel model = formulas::DamperModel::kAuto,
                                               const formulas::ModelOptions& options = {});

/// Fitted coefficients with their quality and range.
struct ScatteredFitResult {
  /// jump_fraction, exponent, the fitted range [s_min, s_max], provisional = false,
  /// source, and the fit's quality: reduced_chi_squared = χ²/(n − 2) (≈ 1 if the law
  /// fits within the standard errors), jump_fraction_stderr and exponent_stderr =
  /// √diag((JᵀWJ)⁻¹) at the optimum (NaN if not determined, e.g. when jump_fraction
  /// sits at 0), points = samples fitted. All travel with the law into ModelOptions, so
  /// evaluations outside the fitted range warn.
  formulas::ScatteredFit fit;
};

/// Fits η*(s) = jump_fraction·η*_onset·s^exponent by weighted least squares,
///   min Σ ((η*_i − J·η*_onset,i·s_i^p)/σ_i)²  over J in [0, 2], p in [0, 10]
/// (the ranges of formulas::ScatteredFit), with NLopt's bounded L-BFGS and the analytic
/// gradient, started from a weighted log-log regression. Needs at least 3 samples with
/// s in (0, 1), finite η*, η*_onset > 0 and σ > 0 finite (std::invalid_argument naming
/// the sample otherwise); std::runtime_error if NLopt fails. `source` describes the data.
ScatteredFitResult fit_scattered_law(std::span<const ScatteredSample> samples, std::string source);

/// Coefficient file for `pdamp loss --scattered-fit FILE`, written atomically:
/// {format "pdamp.scattered_fit", format_version 1, jump_fraction, exponent, s_min, s_max,
///  source, residual (= reduced χ²), points, jump_fraction_stderr, exponent_stderr}.
void write_scattered_fit(const ScatteredFitResult& result, const std::filesystem::path& path);
/// Reads a coefficient file strictly: jump_fraction, exponent, s_min, s_max, source and
/// residual required; format, format_version, points and the two *_stderr optional;
/// unknown or repeated keys, wrong types, values outside formulas::ScatteredFit's ranges
/// (jump_fraction in [0, 2], exponent in [0, 10], s_min in [0, 1)), s_max outside
/// [s_min, 1], residual < 0, points < 3, negative *_stderr or a source with control
/// characters throw std::invalid_argument("<path>: <pointer>: <rule>"); so do a missing
/// file, a directory or a FIFO ("<path>: <reason>", at once).
/// The returned fit has provisional = false; pass result.fit as ModelOptions::scattered.
ScatteredFitResult read_scattered_fit(const std::filesystem::path& path);

}  // namespace pdamp::surrogate
