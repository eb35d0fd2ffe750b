// Filling ratios of a multi-layer particle damper for a transient (docs/theory.md
// §7.7): how many whole slabs of spheres each stacked layer holds so that the
// structure's free decay settles fastest under a particle-mass budget.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/base/record.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/optimizer/options.hpp"
#include "pdamp/optimizer/summary.hpp"
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/structure/free_decay.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::optimizer {

/// One candidate layer (a compartment of the container): a box of inner length L along
/// the drive holding n whole slabs of a lattice. A slab is one sphere row along the drive
/// (extent 2r) with `spheres_per_slab` spheres in lanes of `spheres_per_lane` stacked
/// across gravity. A stacked bed settles onto the base (formulas::LatticeBed::
/// settled_clearance_m): its n·spheres_per_lane spheres per lane lie in one row, so
///   m(n) = n·spheres_per_slab·sphere_mass,  h(n) = L − n·k·2r,  φ(n) = n·k·2r/L  (k = spheres_per_lane).
/// Only whole slabs count (a partial last slab is not a design here: it would occupy a
/// whole 2r of length with less mass). 0 <= n <= max_slabs() keeps h >= 2r > 0 with every
/// sphere on the base: the closed forms describe one layer rolling there (a bed that
/// settles more than one high is outside them; the DEM jams such beds, docs/optimizer.md).
struct LayerCandidate {
  std::string name;                  ///< unique, non-empty; reports name it
  double inner_length_m = 0.0;       ///< L, inner length along the drive, m, > 0
  double slab_length_m = 0.0;        ///< 2r, extent of one slab along the drive, m, in (0, L/2]
  int spheres_per_slab = 0;          ///< spheres in one full slab, >= 1
  int spheres_per_lane = 1;          ///< of a slab, stacked across gravity in one lane, in [1, spheres_per_slab]
  double sphere_mass_kg = 0.0;       ///< mass of one sphere, kg, > 0
  /// Inner cross-section normal to the drive, m², for the volume fraction only (0: not reported).
  double cross_section_m2 = 0.0;
  double sphere_volume_m3 = 0.0;     ///< one sphere's volume, m³ (volume fraction only)
  int initial_slabs = 0;             ///< the starting design (the case's counts), in [0, max_slabs()]
  /// floor((floor(L/2r) − 1)/spheres_per_lane) (relative tolerance 1e-9 on "fits"): the
  /// settled bed in one layer with at least 2r of travel left.
  int max_slabs() const;
  /// h(n) = L − n·spheres_per_lane·2r, m (the settled bed's travel).
  double clearance_m(double slabs) const { return inner_length_m - slabs * spheres_per_lane * slab_length_m; }
  double slab_mass_kg() const { return spheres_per_slab * sphere_mass_kg; }
};

enum class FillingObjective {
  /// Time for the settling measure of structure::free_decay to fall below its threshold,
  /// s. A decay that does not settle within the duration scores
  /// duration·(1 + ln(measure(end)/threshold)) (continuous at the boundary, > duration).
  kSettlingTime,
  /// ½∫₀ᵀ e(t)² dt of the settling measure's envelope e (≈ ∫x² dt of the oscillation),
  /// m²·s, by the trapezoidal rule over `integral_samples` instants.
  kIntegralSquare,
};
std::string_view to_string(FillingObjective objective);  ///< "settling_time", "integral_square"

struct FillingRatioOptions {
  std::vector<LayerCandidate> layers;  ///< the candidates, 1..10 (2^N rounded neighbours)
  /// Site, drive direction, container mass and length of the damper; its `layers` are
  /// ignored (built from the design: layers with n = 0 are left out).
  structure::Damper damper;
  /// Other dampers of the structure, held as they are (may be empty).
  std::vector<structure::Damper> fixed_dampers;
  formulas::DamperModel model = formulas::DamperModel::kRolling;  ///< closed form of every layer
  formulas::ModelOptions model_options;
  /// The free decay (initial amplitudes, duration, threshold, step rule); sample_times_s is
  /// set by the optimiser. The settling measure defaults to the damper's site (threshold_point "").
  structure::FreeDecayOptions decay;
  FillingObjective objective = FillingObjective::kSettlingTime;
  double mass_budget_kg = 0.0;  ///< Σ m_k <= budget, kg; 0 = no mass constraint (then max_total_slabs > 0)
  int max_total_slabs = 0;      ///< Σ n_k <= this; 0 = no slab constraint
  int integral_samples = 400;   ///< kIntegralSquare: instants, [10, 100000]
  /// Calibrated beds (tasks::calibrate_beds): bed_models[k][n] answers for layer k holding n
  /// whole slabs (n in [1, max_slabs()]; entry 0 unused) in place of the closed forms. Empty:
  /// the closed forms. Given, it holds every layer and slab count, designs are whole slabs
  /// only (a calibrated bed exists only there), and optimize_filling_ratios enumerates them all.
  std::vector<std::vector<std::shared_ptr<const surrogate::LossModel>>> bed_models;
  /// Largest number of whole-slab designs enumerated with bed_models (Π(max_slabs + 1)).
  static constexpr long kMaxEnumeratedDesigns = 100000;
  /// On the closed forms, every whole-slab design is evaluated when there are at most this
  /// many (Π(max_slabs + 1)), in [0, kMaxEnumeratedDesigns]: the objective jumps where a layer's
  /// onset crosses the release, so rounding the relaxed optimum can miss the best one. Above
  /// it, the rounded neighbours of the relaxed optimum only. Default 2000 (about 5 s of
  /// decays at 2.3 ms each).
  long max_enumerated_designs = 2000;
  /// One line per violated rule, naming the field ("layers[1].slab_length_m = 0: must be > 0"),
  /// including a budget below the lightest slab ("mass_budget_kg = ...").
  std::vector<std::string> validate() const;
};

/// One layer of a design.
struct LayerDesign {
  std::string name;
  double slabs = 0.0;             ///< n_k (whole for integer designs, real for the relaxed one)
  double filling_ratio = 0.0;     ///< φ = n·k·2r/L of the settled bed (k = spheres_per_lane)
  double volume_fraction = 0.0;   ///< n·spheres_per_slab·V_sphere/(L·A), 0 if A unknown
  double clearance_m = 0.0;       ///< h = L − n·k·2r, m
  double bed_mass_kg = 0.0;       ///< m = n·spheres_per_slab·m_sphere, kg
  double particles = 0.0;         ///< n·spheres_per_slab
  static const base::Fields<LayerDesign>& fields();
};

struct FillingDesign {
  std::vector<LayerDesign> layers;
  double total_mass_kg = 0.0;
  int total_slabs = 0;            ///< Σ round(n_k) (integer designs)
  bool feasible = false;          ///< within the mass budget and slab limit
  bool settled = false;
  double settling_time_s = 0.0;   ///< NaN when not settled within the duration
  double integral_square_m2_s = 0.0;  ///< ½∫e² dt, m²·s (kIntegralSquare only; else NaN)
  double objective = 0.0;         ///< the minimised value (s or m²·s)
  std::vector<double> slabs() const;  ///< n_k of each layer
  static const base::Fields<FillingDesign>& fields();
  /// A rounded neighbour's summary: slabs, objective, settling time, mass.
  static const base::Fields<FillingDesign>& neighbour_fields();
};

struct FillingRatioResult {
  FillingDesign initial;   ///< the starting design (LayerCandidate::initial_slabs)
  FillingDesign relaxed;   ///< continuous optimum of optimizer::solve (n_k real)
  /// The whole-slab designs evaluated, in order: every feasible one when they are
  /// enumerated (calibrated beds, or at most max_enumerated_designs), else the integer points
  /// around the relaxed optimum (each n_k floored or ceiled; one value where n_k is within
  /// 1e-6 of a whole number).
  std::vector<FillingDesign> neighbours;
  bool enumerated = false;       ///< neighbours holds every feasible whole-slab design
  int neighbours_total = 0;      ///< designs considered (enumerated, or 2^(number of fractional n_k))
  int neighbours_feasible = 0;   ///< of those, within the constraints (evaluated)
  FillingDesign chosen;          ///< best evaluated neighbour
  /// Best single-layer design with the same budget: all mass in one layer, best over the
  /// layer and its slab count (exhaustive).
  FillingDesign baseline;
  std::string baseline_layer;
  int baseline_evaluations = 0;
  /// The structure with the damper's containers empty (its own damping only).
  FillingDesign bare;
  /// The chosen design's particle mass in one compartment at its own best clearance
  /// (evaluate_single_compartment; one layer named kSingleCompartment): what the layering
  /// adds beyond the mass.
  FillingDesign same_mass;
  Summary summary;               ///< of the relaxed solve (variables "slabs_<layer>")
  int decay_evaluations = 0;     ///< free decays run in total (solve, neighbours, baseline)
  double solve_time_s = 0.0;     ///< wall-clock time of everything, s
  std::vector<std::string> warnings;
};

/// The damper of a design (n_k per layer, real allowed): closed-form layers of clearance
/// h_k and bed mass m_k (the calibrated bed of bed_models when given), named by the
/// candidates; layers with n_k <= 1e-9 left out. std::invalid_argument if slabs.size() !=
/// options.layers.size(), n_k out of bounds, or not whole with bed_models.
structure::Damper filling_damper(const FillingRatioOptions& options, std::span<const double> slabs);

/// Runs the free decay of one design and scores it (options must be valid).
FillingDesign evaluate_filling_design(const structure::ModalModel& model, const FillingRatioOptions& options,
                                      std::span<const double> slabs);

/// The layer name of a single-compartment design.
inline constexpr const char* kSingleCompartment = "single_compartment";

/// `mass_kg` of the candidates' spheres (`particles` of them) in one compartment of the
/// damper with clearance `clearance_m`, scored as evaluate_filling_design (slabs and
/// filling ratio NaN: the compartment is no candidate's).
FillingDesign evaluate_single_compartment(const structure::ModalModel& model, const FillingRatioOptions& options,
                                          double mass_kg, double particles, double clearance_m);

/// Relaxed solve (n_k real: mass and clearance linear in n_k; optimizer::solve with
/// `solver`), then every feasible rounded neighbour, then the single-layer baseline, the bare
/// structure and the same mass in one compartment (by the closed forms). With bed_models:
/// every feasible whole-slab design instead of the relaxed solve and its neighbours (all in
/// `neighbours`, `relaxed` the chosen one, the summary converged with the count in its message).
/// Throws std::invalid_argument for invalid options (every violation, one a line) and
/// what the free decay throws for an invalid model or initial state.
FillingRatioResult optimize_filling_ratios(const structure::ModalModel& model, const FillingRatioOptions& options,
                                           const Options& solver = {});

}  // namespace pdamp::optimizer
