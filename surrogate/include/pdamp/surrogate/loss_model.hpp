// The damper's characteristic as seen by structures and optimisers: one small
// lookup interface that both the closed forms and the effective fields satisfy.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/surrogate/field_lookup.hpp"

namespace pdamp::surrogate {

/// Warning bits of a DamperResponse (allocation-free; LossModel::warning_messages gives
/// the sentences). 0 = the model answered inside its own validity range.
enum LossWarning : std::uint32_t {
  kLossOutsideFieldGrid = 1u << 0,       ///< field queried outside its grid: edge value, derivative 0
  kLossRescaledClearance = 1u << 1,      ///< field of another clearance reused at equal Γ and X/h
  kLossOutsideClosedForm = 1u << 2,      ///< a validity rule of the closed form is violated (formulas' warnings)
  kLossScatteredState = 1u << 3,         ///< below the onset: empirical scattered fit, no orbit
  kLossApparentMassMissing = 1u << 4,    ///< the source gives no apparent mass (NaN returned)
  kLossApparentMassAssumed = 1u << 5,    ///< apparent mass from a stated assumption, not derived or measured
};

/// The damper's response at one operating point (docs/theory.md §1).
struct DamperResponse {
  double eta_star = 0.0;                ///< reduced loss factor η*, dimensionless
  double apparent_mass_fraction = 1.0;  ///< m_app/m_bed, dimensionless; NaN where the source does not give it
  double d_eta_star_d_stroke_1_m = 0.0;  ///< ∂η*/∂X at fixed f, 1/m (of the piece X lies on; 0 where clamped)
  double d_apparent_mass_fraction_d_stroke_1_m = 0.0;  ///< ∂(m_app/m_bed)/∂X, 1/m; NaN with the value
  std::uint32_t warnings = 0;           ///< LossWarning bits
  /// Motion regime or mode label. It views storage owned by the model (or static): valid
  /// as long as the model lives; copy it into a std::string to keep it longer.
  std::string_view regime;
};

/// Strokes a model covers at one frequency, m: [min_m, max_m], 0 < min_m <= max_m.
struct StrokeRange {
  double min_m = 0.0;
  double max_m = 0.0;
};

/// η* and friends as a function of drive frequency (Hz) and stroke (m).
///
/// Smoothness contract: at fixed frequency the response is continuous and differentiable
/// in the stroke between the strokes that discontinuities_stroke_m() lists. Root finders
/// and continuation must treat each piece separately: a sign change of a residual across
/// a listed stroke is a jump (the end of a branch), not a root.
class LossModel {
 public:
  virtual ~LossModel() = default;
  /// The response at (f, X); f > 0 and X > 0 finite. No allocation where the response has
  /// no warning (implementations state their exceptions).
  virtual DamperResponse evaluate(double frequency_hz, double stroke_m) const = 0;
  /// The response of a bed that has come down from above the onset (a free decay released
  /// above it, docs/theory.md §3.4): below the onset it may differ from a bed driven there
  /// from rest. Default: evaluate (a field or a model without that history).
  virtual DamperResponse evaluate_from_above(double frequency_hz, double stroke_m) const;
  /// Strokes at which the response jumps at frequency f (the onset cliff of
  /// collect-and-collide), ascending, m. Default: none (a continuous model).
  virtual std::vector<double> discontinuities_stroke_m(double frequency_hz) const;
  /// The stroke range the model is meant for at frequency f (a field's grid, a closed
  /// form's validity), m: a structure solver scans its roots inside it.
  virtual StrokeRange stroke_range_m(double frequency_hz) const = 0;
  /// One sentence per warning the response at (f, X) carries (allocates; for reports).
  virtual std::vector<std::string> warning_messages(double frequency_hz, double stroke_m) const;
};

/// One sentence per LossWarning bit, generic (without the numbers a model can add).
std::vector<std::string> describe_loss_warnings(std::uint32_t warnings);

/// LossModel from the closed forms of formulas/ for one clearance.
///
/// Apparent mass (docs/structure_coupling.md §2, derived from the same ideal orbits): the
/// force the container applies to the bed is m_bed·dv_bed/dt, so with container velocity
/// V cos φ and the bed velocity's first harmonic v̂ (v ≈ Re(v̂ e^{iφ})):
///   η* = −Im(v̂)/V,   m_app/m_bed = Re(v̂)/V.
/// Free block (κ = 0): collect-and-collide (impact at φ* <= π)
///   m_app/m_bed = (π − φ* + 2 sin φ* − sin φ* cos φ*)/π   (1 as φ* → 0, 0 at the peak φ* = π),
/// sub-peak orbit (impact at π + ψ): m_app/m_bed = −(2/π) sin 2ψ (−8/(π²+4) = −0.577 at the onset).
/// Rolling spheres (κ > 0) move as v_c + u_block/(1+κ):  m_app/m_bed = (κ + m_block)/(1+κ).
/// Below the onset (no orbit, scattered fit for η*) the assumption is the no-impact
/// limit κ/(1+κ) (2/7 for rolling solid spheres, docs/theory.md §3; 0 for a free block),
/// flagged kLossApparentMassAssumed. Come down from above (evaluate_from_above, options'
/// below_onset_from_above: the rolling tail by default), a rolling bed below the onset
/// rolls without impacts: η* and m_app/m_bed of formulas::rolling_tail. Derivatives in X are analytic (chain rule through the
/// impact phase and, for auto's friction-limited sliding, through κ_eff(Γ)). They diverge
/// like 1/√(X − X_onset) just above the onset (a saddle-node, docs §3): the onset is a jump
/// listed by discontinuities_stroke_m().
///
/// evaluate() calls formulas::reduced_loss_factor (one source of truth for η*), which
/// allocates its warning sentences: a response with kLossOutsideClosedForm or
/// kLossScatteredState under a provisional fit allocates, one without warnings does not.
class ClosedFormLossModel final : public LossModel {
 public:
  /// Throws std::invalid_argument for clearance_m not > 0 and finite or invalid options.
  ClosedFormLossModel(formulas::DamperModel model, double clearance_m, formulas::ModelOptions options = {});
  DamperResponse evaluate(double frequency_hz, double stroke_m) const override;
  DamperResponse evaluate_from_above(double frequency_hz, double stroke_m) const override;
  /// The onset stroke of the block that answers at f (kRolling/kBouncing: (1+κ)h/√(π²+4);
  /// kAuto: the fixed point X = (1+κ_eff(Γ(X)))h/√(π²+4)); none for kScattered.
  std::vector<double> discontinuities_stroke_m(double frequency_hz) const override;
  /// [10⁻³ h, 10 h]: above 10 h the closed forms warn (X/h > 10); below, η* is negligible.
  StrokeRange stroke_range_m(double frequency_hz) const override;
  std::vector<std::string> warning_messages(double frequency_hz, double stroke_m) const override;
  double clearance_m() const { return clearance_m_; }

 private:
  DamperResponse respond(const formulas::ModelOptions& options, double frequency_hz, double stroke_m) const;
  DamperResponse rebounding_response(const formulas::LossResult& loss, double stroke_m, double d_kappa) const;
  DamperResponse coulomb_response(const formulas::LossResult& loss, double frequency_hz, double stroke_m) const;
  DamperResponse tail_response(const formulas::LossResult& loss, double frequency_hz, double stroke_m) const;
  formulas::DamperModel model_;
  double clearance_m_;
  formulas::ModelOptions options_;
  /// options_ with below_onset = below_onset_from_above.
  formulas::ModelOptions from_above_options_;
};

/// LossModel from an effective field (DEM, formulas or measured): η* and the apparent-mass
/// fraction interpolated bilinearly (FieldLookup, derivatives included), the regime label of
/// the nearest node. Clamped or rescaled lookups set kLossOutsideFieldGrid /
/// kLossRescaledClearance; a field without apparent mass returns NaN with
/// kLossApparentMassMissing. Lookups near missing points and, with kError, outside the grid
/// throw std::invalid_argument. Bilinear interpolation is continuous: no discontinuities.
class EffectiveFieldLossModel final : public LossModel {
 public:
  /// Throws std::invalid_argument if the field or the options do not validate.
  explicit EffectiveFieldLossModel(const EffectiveField& field, const LookupOptions& options = {});
  /// η* at (f, X); apparent_mass_fraction NaN when the field does not give it at every ok point.
  DamperResponse evaluate(double frequency_hz, double stroke_m) const override;
  /// The field's stroke axis mapped to the looked-up damper at f (for (Γ, X/h) fields
  /// X = s·h, independent of f).
  StrokeRange stroke_range_m(double frequency_hz) const override;
  std::vector<std::string> warning_messages(double frequency_hz, double stroke_m) const override;
  /// η* lookup with derivatives and warning bits, for optimisers.
  const FieldLookup& lookup() const { return eta_star_; }

 private:
  FieldLookup eta_star_;
  std::optional<FieldLookup> apparent_mass_fraction_;  ///< absent when the field does not give it
  std::vector<std::string> motion_modes_;              ///< per grid node, storage order
  StrokeRange strokes_m_;                              ///< the field's stroke axis, looked-up damper, m
};

}  // namespace pdamp::surrogate
