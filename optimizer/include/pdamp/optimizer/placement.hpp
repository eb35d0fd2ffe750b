// Placement of a particle damper: where along a beam (or at which named point of
// imported modal data) the damper adds the most damping to chosen modes, from
// the mode shapes and the damper's amplitude dependence (docs/optimizer.md, "Placement").
//
// At a site x the damper moves along its drive by b_j(x) = Φ_j(x)·n per unit modal
// coordinate of mode j. The structure is taken to vibrate in mode j with a stated
// amplitude A_j at a reference point, so the modal amplitude is a_j = A_j/|Φ_j(ref)| and
// the damper's stroke X_j(x) = |b_j(x)|·a_j: near a node the stroke falls, η*(X) follows
// it (down the onset cliff into the scattered state), and the added damping ratio of the
// single-mode averaged model (structure::backbone_point),
// is what placement maximises. ζ_add,j is the backbone's Σ_dampers Σ_layers b_j² η* m_bed / (2 m_eff),
// ≈ ½ η* μ_j for a small modal mass ratio μ_j = b_j² m_bed/m_j (docs/theory.md §7.3).
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/base/record.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/summary.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::optimizer {

/// A mode whose damping placement serves, and the vibration level it is judged at.
struct PlacementTarget {
  int mode = 0;                    ///< index j in the modal model (ascending frequency), >= 0
  double weight = 1.0;             ///< w_j in the weighted mean, >= 0 (kWeightedMean only)
  std::string reference_point;     ///< named point whose amplitude is stated
  /// A_j: amplitude of the reference point's translation |Φ_j(ref)|·a_j in this mode, m, > 0.
  double reference_amplitude_m = 0.0;
};

enum class PlacementObjective {
  kWeightedMean,  ///< maximise Σ w_j ζ_add,j / Σ w_j
  kWorstMode,     ///< maximise min_j ζ_add,j (the weights are not used)
};
std::string_view to_string(PlacementObjective objective);  ///< "weighted_mean", "worst_mode"

struct PlacementOptions {
  /// The damper to place: drive, container and layers with their loss models; its `point`
  /// is replaced by each candidate site.
  structure::Damper damper;
  std::vector<structure::Damper> fixed_dampers;  ///< other dampers, where they are
  std::vector<PlacementTarget> targets;          ///< at least one, modes unique
  PlacementObjective objective = PlacementObjective::kWeightedMean;
  /// A site is flagged (and the chosen one warned about) where θ_j·L/2 > fraction·|b_j| for a
  /// target mode (structure::rotation_warnings; L = damper.length_along_drive_m), in (0, 10].
  double rotation_warning_fraction = 0.1;
  /// Frequency fixed point of the backbone point, relative tolerance, (0, 1e-3].
  double frequency_tolerance = 1e-10;
  /// One line per violated rule ("targets[1].reference_amplitude_m = 0: must be > 0"); the
  /// modes and points are checked against the model by the functions below.
  std::vector<std::string> validate() const;
};

/// A beam along which the damper's site moves continuously.
struct BeamPlacement {
  /// The beam without the placed damper (other dampers' weights may be carried weights);
  /// its named points must include every target's reference point.
  structure::BeamModel beam;
  int mode_count = 4;
  structure::ModalDamping damping;
  /// Weight of the placed damper (container and beds), kg, >= 0: when beam.geometric_stiffness
  /// is on (a standing beam) it is carried at the mesh node nearest the site (at most half an
  /// element off: the axial force, not the site, moves by that much), so the modes see it
  /// where it is. 0: not added.
  double carried_mass_kg = 0.0;
  double min_position_m = 0.0;   ///< search range along the beam axis, m, inside the beam
  double max_position_m = 0.0;   ///< > min_position_m
  int scan_positions = 101;      ///< evenly spaced positions of the scan, [3, 100000]
  std::vector<std::string> validate() const;
};

/// What one target mode gets from the damper at one site.
struct ModeAtSite {
  int mode = 0;
  double natural_frequency_hz = 0.0;   ///< backbone frequency with the damper (Ω_n/2π), Hz
  double drive_shape = 0.0;            ///< b_j = Φ_j(site)·n, m per unit q_j
  double modal_amplitude = 0.0;        ///< a_j = A_j/|Φ_j(ref)|, units of q_j
  double damper_amplitude_m = 0.0;     ///< X_j = |b_j| a_j, m
  double eta_star = 0.0;               ///< η* of the layers, bed-mass weighted mean
  double modal_mass_ratio = 0.0;       ///< μ_j = b_j² Σ m_bed / m_j
  double added_damping_ratio = 0.0;    ///< ζ_add,j
  /// θ_j·L/2 / |b_j|: how much stroke the container's ends gain or lose from the site's
  /// rotation, dimensionless (infinity at a translation node; 0 when L is unknown).
  double rotation_ratio = 0.0;
  bool rotation_flagged = false;       ///< rotation_ratio > options.rotation_warning_fraction
  std::uint32_t loss_warnings = 0;     ///< surrogate::LossWarning bits of the layers
  static const base::Fields<ModeAtSite>& fields();
};

struct PlacementPoint {
  std::string site;                    ///< named point (modal data), or the beam's placement point name
  double position_m = std::numeric_limits<double>::quiet_NaN();  ///< along the beam, m (NaN for modal data)
  std::vector<ModeAtSite> modes;       ///< in the order of options.targets
  double objective = 0.0;              ///< the maximised value (a damping ratio)
  static const base::Fields<PlacementPoint>& fields();
};

struct PlacementResult {
  std::vector<PlacementPoint> scan;    ///< every candidate evaluated by the scan, in order
  PlacementPoint best;                 ///< the chosen site (the refinement's, or the best scanned)
  /// The site of options.damper.point in the model given (modal data), or of the case's own
  /// site (beam, when `current_position_m` is given to the beam search); objective 0 if none.
  std::optional<PlacementPoint> current;
  Summary summary;                     ///< of the local refinement (beam), empty for modal data
  bool refined = false;                ///< the refinement ran (beam)
  int evaluations = 0;                 ///< sites evaluated in all (modal models built for a beam)
  double solve_time_s = 0.0;
  std::vector<std::string> warnings;
};

/// The damper at named point `site` of `model`, judged for every target. Throws
/// std::invalid_argument for invalid options, an unknown point or a mode out of range, and a
/// reference point that does not move in a target mode.
PlacementPoint evaluate_placement(const structure::ModalModel& model, const std::string& site,
                                  const PlacementOptions& options);

/// The beam's modal model with the shape at position x (m) as named point `site`
/// (structure::beam_point_shape: interpolated by the elements, no node added) and, when the
/// beam has geometric stiffness, the placed damper's weight carried at the node nearest x.
structure::ModalModel beam_model_with_site(const BeamPlacement& beam, double position_m, const std::string& site);

/// Solver settings of the refinement: no global stage (the scan is the global stage),
/// COBYLA (the objective has kinks where a stroke crosses the onset), the position to 1e-4
/// of the interval between the scan's neighbours, 40 evaluations at most.
Options placement_solver_options();

/// Scan of scan_positions evenly spaced positions, then a local refinement of the best one
/// by optimizer::solve (1 variable, global stage off, between the neighbouring scan
/// positions; NLopt COBYLA or Ipopt per solver.backend). `current_position_m` (the case's
/// site) is evaluated for comparison. Throws std::invalid_argument for invalid options.
PlacementResult optimize_placement_on_beam(const BeamPlacement& beam, const PlacementOptions& options,
                                           const Options& solver, std::optional<double> current_position_m = {});

/// Every named point of `candidates` evaluated on a fixed model (imported modal data, where
/// the shapes are known at the named points only); the best is chosen.
PlacementResult optimize_placement_at_points(const structure::ModalModel& model,
                                             const std::vector<std::string>& candidates,
                                             const PlacementOptions& options);

}  // namespace pdamp::optimizer
