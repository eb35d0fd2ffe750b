// Forced response of a modal model with particle dampers by first-order harmonic balance:
// every root of the amplitude equations per frequency, their slow-flow stability, the
// branches, folds and jumps, and the peaks (docs/theory.md §7.4, docs/structure_coupling.md §3-5).
#pragma once

#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// Harmonic excitation at frequency Ω.
struct Excitation {
  enum class Kind {
    kBaseTranslation,  ///< every support moves as u_b = U·e·sin(Ωt) (needs ModalModel::base_participation)
    kPointForce,       ///< a force F·e·sin(Ωt) at `point`
  };
  Kind kind = Kind::kBaseTranslation;
  Eigen::Vector2d direction{1.0, 0.0};  ///< unit vector e in the x-y plane
  double amplitude = 0.0;               ///< U in m (base) or F in N (force), > 0
  std::string point;                    ///< kPointForce: named point of the model
  std::vector<std::string> validate(const ModalModel& model) const;
};

/// A displacement the FRF reports: the named point's translation along `direction`,
/// absolute (base motion included), divided by the excitation amplitude: a transmissibility
/// |X/U| for base excitation, a receptance in m/N for a force.
struct ResponseOutput {
  std::string name;                     ///< label
  std::string point;                    ///< named point of the model
  Eigen::Vector2d direction{1.0, 0.0};  ///< unit vector
};

struct HarmonicBalanceOptions {
  std::vector<double> frequencies_hz;  ///< drive frequencies, Hz, > 0, strictly ascending
  /// Outputs; empty = one per damper: its site along its drive ("<damper name>").
  std::vector<ResponseOutput> outputs;
  /// Stroke range scanned for roots, m: 0 = the union of the layers' stroke_range_m().
  double stroke_min_m = 0.0;
  double stroke_max_m = 0.0;
  /// Log-spaced scan points per decade of stroke on each smooth piece, >= 4. Two roots
  /// closer than one scan cell are missed unless they sit next to a fold the frequency
  /// grid brackets (then the fold search finds the pair).
  int scan_points_per_decade = 24;
  /// Root tolerance on the stroke, relative, in (0, 1e-3].
  double stroke_tolerance = 1e-13;
  /// Several dampers: Newton iterations per start, >= 1, and the damped fixed-point
  /// fallback's relaxation, (0, 1].
  int max_newton_iterations = 60;
  double fixed_point_relaxation = 0.3;
  /// Locate folds and onset jumps between grid frequencies (one damper only).
  bool refine_branch_ends = true;
  CouplingOptions coupling;
  std::vector<std::string> validate() const;
};

enum class Stability {
  kStable,    ///< every slow-flow eigenvalue has Re λ < 0
  kUnstable,  ///< some Re λ > 0
  kMarginal,  ///< max Re λ within round-off of 0 (at a fold)
};
std::string_view to_string(Stability stability);

/// One root of the amplitude equations at one frequency.
struct HarmonicRoot {
  std::vector<double> damper_amplitudes_m;            ///< X_d, absolute site amplitude along the drive, m
  std::vector<std::complex<double>> outputs;          ///< complex output per unit excitation (phase: sin reference)
  std::vector<double> layer_eta_star;                 ///< η* per layer, dampers' layers in order
  Stability stability = Stability::kStable;
  double max_growth_rate_1_s = 0.0;                   ///< largest Re λ of the slow flow, 1/s
  int branch_id = -1;                                 ///< segment of a response curve (see BranchEnd)
  int piece = 0;                                      ///< one damper: smooth piece of the loss model (0 below the first jump)
  std::uint32_t loss_warnings = 0;                    ///< OR of the layers' LossWarning bits
};

/// The amplitude equation drives the response onto a jump from both sides (|y|/X − 1 > 0 just
/// below it, < 0 just above): no first-harmonic root exists, the bed alternates between the
/// two states (scattered and collect-and-collide at the onset) and the amplitude stays at the
/// jump. Taken as a Filippov equilibrium: the layer's impedance is the convex combination
/// (1 − λ)Z(X⁻) + λZ(X⁺) with the λ in (0, 1) that closes |y| = X (docs §4). It attracts the
/// amplitude from both sides by construction; its phase stability is not evaluated.
struct JumpHeldState {
  double damper_amplitude_m = 0.0;             ///< the jump's stroke, m
  double upper_state_fraction = 0.0;           ///< λ: share of the state above the jump
  std::vector<std::complex<double>> outputs;   ///< per unit excitation, as HarmonicRoot::outputs
};

struct FrequencyPoint {
  double frequency_hz = 0.0;
  std::vector<HarmonicRoot> roots;                    ///< ascending in the first damper's amplitude
  /// The outputs with the containers attached and the beds removed ("without dampers":
  /// empty containers, i.e. the structure the beds are added to), per unit excitation.
  std::vector<std::complex<double>> linear_outputs;
  bool converged = true;                              ///< false: some Newton start failed (several dampers)
  /// One damper: states held at a loss-model jump (see JumpHeldState); such a frequency can
  /// have no root at all.
  std::vector<JumpHeldState> held_at_jump;
};


/// Where a branch segment ends between two grid frequencies.
struct BranchEnd {
  enum class Kind {
    kFold,           ///< two roots merge (saddle-node): a jump in a frequency sweep
    kDiscontinuity,  ///< a root reaches a loss-model jump (the onset cliff): a jump, not a fold
    kStrokeRange,    ///< a root leaves the scanned stroke range
  };
  Kind kind = Kind::kFold;
  double frequency_hz = 0.0;       ///< refined to the stroke tolerance (kStrokeRange: grid value)
  double damper_amplitude_m = 0.0; ///< first damper's X at the end
  int branch_id = -1;              ///< segment that ends
  int other_branch_id = -1;        ///< kFold: the segment it merges with
  bool ends_toward_higher_frequency = true;  ///< the segment exists below frequency_hz
};

/// A peak of one output's response curve.
struct ResponsePeak {
  std::size_t output = 0;          ///< index into the outputs
  double frequency_hz = 0.0;       ///< parabolic fit through the grid maximum and its neighbours
  double magnitude = 0.0;          ///< |output| at the peak (grid maximum)
  /// Half-power: (f₂ − f₁)/(2 f_peak) with f₁, f₂ where the curve crosses |peak|/√2
  /// (linear interpolation between grid frequencies); NaN where a crossing is missing in
  /// the grid. Exact to O(ζ²) for an isolated linear mode.
  double damping_ratio = 0.0;
  /// Centre of the band where the curve stays ≥ kResonanceBandFraction × magnitude
  /// (sampled_response.hpp: a flat top's better-conditioned resonance frequency); NaN
  /// where an edge is missing in the grid.
  double band_centre_hz = 0.0;
};

struct FrequencyResponse {
  enum class Outcome { kConverged, kSomeRootsNotConverged };
  Outcome outcome = Outcome::kConverged;
  std::vector<std::string> output_names;
  std::vector<FrequencyPoint> points;   ///< one per options.frequencies_hz
  std::vector<BranchEnd> branch_ends;   ///< folds and cliffs: the jump frequencies
  /// Peaks of the largest stable (or jump-held) response per frequency (what a slow sweep
  /// that keeps to the highest stable branch meets), and of the linear FRF without beds.
  std::vector<ResponsePeak> peaks;
  std::vector<ResponsePeak> linear_peaks;
  std::size_t loss_evaluations = 0;
  std::size_t unconverged_starts = 0;
  double solve_time_s = 0.0;
  std::uint32_t loss_warnings = 0;      ///< OR over all roots
  std::vector<std::string> warnings;    ///< sentences (loss-model warnings, missing apparent mass)
  std::string brief_report() const;
};

/// The FRF with every root. One damper: complete scan of g(X) = |X_site(X)| − X on each
/// smooth piece (split at the loss models' jumps), Illinois refinement, branch linking and
/// fold/cliff location by bisection in frequency. Several dampers: vector Newton from the
/// previous frequency's roots and a grid of starts, damped fixed-point fallback; there
/// "every root" is not guaranteed. Throws std::invalid_argument for invalid inputs.
FrequencyResponse harmonic_balance(const ModalModel& model, const std::vector<Damper>& dampers,
                                   const Excitation& excitation, const HarmonicBalanceOptions& options);

}  // namespace pdamp::structure
