// The case file format (docs/cases.md), formats 1 and 2: JSON -> the modules' option
// structs, checked against their own validate(), and the resolved case with every
// default filled in (`pdamp validate`).
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/case_file/case_error.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"
#include "pdamp/formulas/bed_packing.hpp"
#include "pdamp/formulas/collect_and_collide.hpp"
#include "pdamp/formulas/hertz_impact.hpp"
#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/optimizer/placement.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/structure/modal_model.hpp"
#include "pdamp/surrogate/grid.hpp"

namespace pdamp::case_file {

/// A direction in the structure's plane (x, y), a unit vector.
using PlaneVector = std::array<double, 2>;

/// One compartment of a damper: its container, its particles, their lattice and the
/// clearance (format 1: the whole damper; format 2: `dampers[i].layers[k]`).
struct LayerSpec {
  std::string name;  ///< format 2: `name` (default layer_<k>); format 1: layer_1
  /// Format 2: `field_file`, the layer's effective field (`pdamp field` output) for
  /// `--method field`, resolved against the case file's folder; empty: none.
  std::string field_file;
  formulas::Container container;
  int particle_count = 0;
  double particle_radius_m = 0.0;
  std::string particle_material = "steel";
  /// ISO 3290 lot variation of the ball diameter (dem_reference::ParticleGroupOptions), m.
  double lot_diameter_variation_m = dem_reference::ParticleGroupOptions{}.lot_diameter_variation_m;
  formulas::LatticePacking packing;
  /// The compartment as the DEM builds it: wall material, placement, inner structures,
  /// wall layer and offset (format 1: from `/dem`), particles and lattice from above.
  dem_reference::CompartmentOptions compartment;
  // Derived on load:
  formulas::LatticeBed bed;  ///< the collected lattice and its clearance
  double clearance_m = 0.0;  ///< the bed's h, or the explicit `clearance_m` override, m
  double bed_mass_kg = 0.0;  ///< particle mass of the layer, kg
};

/// A particle damper: its drive, gravity and closed-form constants, and its layers.
struct DamperSpec {
  std::string name;  ///< format 2: `name` (default damper_<i>); format 1: damper_1
  /// Format 2: the named point of the structure the container sits at ("" in format 1).
  std::string site;
  /// Format 2: the structure-plane direction the container's drive axis moves along
  /// (normalised on load); format 1: (1, 0).
  PlaneVector drive_direction{1.0, 0.0};
  /// Format 2: mass of the empty container, kg (0 in format 1, which has no structure).
  double container_mass_kg = 0.0;
  double container_rotary_inertia_kg_m2 = 0.0;  ///< about the out-of-plane axis at the site, kg·m² (0: neglected)
  formulas::DamperModel model = formulas::DamperModel::kAuto;
  int drive_axis = 0;  ///< the container-frame axis of the drive, 0..2 (x, y, z)
  formulas::Vec3 gravity_m_s2{0.0, 0.0, -formulas::kStandardGravity};  ///< container frame
  formulas::ModelOptions model_options;
  std::vector<LayerSpec> layers;  ///< at least one
};

struct ExcitationSpec {
  double frequency_hz = 0.0;
  std::optional<double> amplitude_m;  ///< the operating stroke, if the case has one
};

struct DesignSpec {
  std::optional<double> target_stroke_m;
  double sweep_min_over_clearance = 0.05;
  double sweep_max_over_clearance = 1.5;
  int sweep_points = 301;
};

struct BufferSpec {
  std::string layer_material;
  formulas::BufferDesignInput input;  ///< particle data filled from the (first) damper layer
};

/// The DEM numerics shared by every damper (docs/cases.md, `dem`). The options of one
/// run come from dem_options().
struct DemSpec {
  /// Materials, contact pairs, integration and run control; compartments, gravity,
  /// drive, amplitude and frequency are filled per damper and run by dem_options().
  dem_reference::DamperSimulationOptions simulation;
  double stiffness_softening = 1.0;  ///< factor on every Young's modulus in the DEM only
  double radius_spread = 0.0;        ///< polydispersity of every particle group, [0, 0.4999]
};

/// The effective-field grid of `pdamp field` (docs/cases.md, `field`).
struct FieldSpec {
  surrogate::GridAxes axes = surrogate::GridAxes::kFrequencyAmplitude;
  surrogate::AxisRange axis0;  ///< frequency_hz or intensity
  surrogate::AxisRange axis1;  ///< amplitude_m or stroke_over_clearance
  int threads = 2;             ///< DEM points run at once
};

/// Format 2 `structure`: a beam of finite elements or imported modal data.
struct StructureSpec {
  enum class Kind { kBeam, kModalData };
  Kind kind = Kind::kBeam;
  structure::BeamModel beam;        ///< kBeam
  int mode_count = 4;               ///< kBeam: modes kept, [1, 100]
  structure::ModalDamping damping;  ///< kBeam
  /// kModalData: the modal file, as a path (relative ones resolved against the case file).
  std::string modal_data_file;
  /// kModalData: the imported model (read on load once structure/ can parse it).
  std::optional<structure::ModalModel> modal_data;
  /// Every name a damper site or a task point may take (points and point masses).
  std::vector<std::string> point_names;
};

enum class TaskKind { kDamperDesign, kFrf, kDecay, kModes, kFillingRatios, kPlacement, kClearance };

/// `task` kind frf: the frequency response over a band.
struct FrfTask {
  double min_frequency_hz = 0.0;
  double max_frequency_hz = 0.0;
  int points = 400;  ///< frequencies, [2, 100000]
  surrogate::AxisSpacing spacing = surrogate::AxisSpacing::kLinear;
  enum class Excitation { kBase, kForce };
  Excitation excitation = Excitation::kBase;
  double base_amplitude_m = 0.0;       ///< kBase: amplitude of the support motion, m
  std::string force_point;             ///< kForce: the named point the force acts at
  double force_amplitude_n = 0.0;      ///< kForce, N
  PlaneVector direction{0.0, 1.0};     ///< of the base motion or the force, unit (normalised)
};

/// `task` kind decay: a free decay from an initial state.
struct DecayTask {
  enum class InitialState { kStaticLoad, kModalAmplitudes };
  InitialState initial_state = InitialState::kStaticLoad;
  std::string load_point;                 ///< kStaticLoad: where the force is released
  PlaneVector load_force_n{0.0, 0.0};     ///< kStaticLoad: (x, y) force, N
  std::vector<double> modal_amplitudes;   ///< kModalAmplitudes: q_j(0), one per mode at most
  double duration_s = 0.0;                ///< simulated time, s
  double settling_threshold = 0.05;       ///< settled below this fraction of the initial amplitude, (0, 1)
};

/// `dem_check` of task kind modes: the damping each mode gets against amplitude, by the DEM in
/// the loop at a few amplitudes of the first damper, beside the backbones (tasks/mode_decay.hpp).
struct ModesDemCheck {
  std::vector<int> modes;            ///< 0-based here (the case counts from 1), each once
  std::vector<double> amplitudes_m;  ///< the first damper's stroke at each decay's start, m, ascending
  int periods = 40;                  ///< each decay's length in periods of its mode, [4, 10000]
  double amplitude_fraction = 0.5;   ///< measured down to this fraction of the start, (0, 1)
  /// The DEM's bed driven this many periods in the mode's motion at the start amplitude before
  /// the release (a decay from steady forced vibration, as a shaker cut off), [0, 10000];
  /// 0: released from the bed as placed (the collected lattice, settled).
  int forced_start_periods = 0;
  /// A decay passes when the mode's whole damping ratio (bare plus added) by the prediction
  /// lies within this fraction of the DEM's, dimensionless, (0, 10].
  double tolerance_relative = 0.15;
};

/// `calibration` of task kind modes (docs/optimizer.md, "Damping against amplitude"): for each
/// listed mode, the first damper's bed as the DEM sees it: an effective field from DEM steady
/// states at the mode's frequency over the backbone's amplitudes, used in place of the loss
/// model for that mode's backbone and its dem_check prediction.
struct ModesCalibrationSpec {
  std::vector<int> modes;            ///< 0-based here (the case counts from 1); default the dem_check's
  int strokes_per_decade = 8;        ///< field nodes per decade of amplitude, [1, 100]
  double stiffness_softening = 1.0;  ///< factor on every Young's modulus of its runs, on top of /dem's, (0, 1]
};

/// `clearance_search` of task kind modes (docs/optimizer.md, "Clearance for a mode's damping"):
/// the clearance of the first damper's (one) layer that adds the most damping to one mode over
/// a range of the damper's strokes, each candidate's bed calibrated from DEM steady states (as
/// `calibration` does), with an optional DEM check of the chosen clearance and its neighbours.
struct ModesClearanceSearch {
  int mode = 0;                  ///< 0-based here (the case counts from 1)
  double min_amplitude_m = 0.0;  ///< the strokes over which the damping counts, m
  double max_amplitude_m = 0.0;  ///< (> min)
  int amplitude_points = 5;      ///< log-spaced strokes the objective takes, [2, 50]
  /// kMean: the mean added damping ratio over the strokes; kWorst: the smallest.
  enum class Objective { kMean, kWorst } objective = Objective::kMean;
  /// The candidates, m, ascending, >= 2: the layer's clearance h (inner length along the
  /// drive minus the collected lattice's extent); explicit, or log-spaced from min to max.
  std::vector<double> clearances_m;
  /// With a buffered wall on the layer's faces across the drive (its `wall_layer`), the
  /// lining thicknesses t searched with every clearance, m, ascending: each candidate is a
  /// pair (h, t), h the free length between the linings (the container 2t longer than
  /// without them). Empty: the layer as it is. With the case's `buffer`, a t whose tip strain
  /// under the buffer's design impact exceeds its allowable strain is not built (nor run).
  std::vector<double> wall_layer_thicknesses_m;
  /// `calibration`: each candidate's strokes per decade and softening (its modes: {mode}).
  ModesCalibrationSpec calibration;
  /// `verify`: the target mode's DEM decays at the chosen clearance and its neighbours in
  /// clearances_m (modes = {mode}); absent: none.
  std::optional<ModesDemCheck> verify;
};

/// `task` kind modes: natural frequencies, shapes and backbones.
struct ModesTask {
  int mode_count = 0;                       ///< modes reported, [1, the structure's mode_count]
  double backbone_min_amplitude_m = 0.0;    ///< lowest amplitude at the damper site, m
  double backbone_max_amplitude_m = 0.0;    ///< highest, m (> min)
  int backbone_points = 50;                 ///< [2, 10000]
  std::optional<ModesDemCheck> dem_check;   ///< `dem_check`: absent, none
  std::optional<ModesCalibrationSpec> calibration;  ///< `calibration`: absent, the loss models alone
  std::optional<ModesClearanceSearch> clearance_search;  ///< `clearance_search`: absent, none
};

/// `verify` of task kind filling_ratios: the DEM-in-the-loop free decay
/// (structure::cosimulate) of the chosen and of the baseline design, reported against the
/// closed forms' prediction with pass or fail (docs/optimizer.md, "DEM verification").
struct VerifySpec {
  /// A design passes when its DEM objective (settling time, or ½∫e² dt) lies within this
  /// fraction of the predicted one, |DEM − predicted| <= tolerance·predicted; both not
  /// settled: the envelopes at the end, the same way. Dimensionless, (0, 10].
  double tolerance_relative = 0.3;
  /// Simulated time of each DEM decay, s, (0, 1e5]; default the task's duration_s. The
  /// prediction is evaluated over the same time.
  double duration_s = 0.0;
  /// Further factor on every Young's modulus of the verification's DEM runs only, on top of
  /// /dem/stiffness_softening (the runs use E·dem·verify), (0, 1]: a softer contact takes a
  /// larger time step. 1 = the /dem settings unchanged.
  double stiffness_softening = 1.0;
  /// true: the verification fails unless the DEM ranks the designs as the prediction does
  /// (the chosen design ahead of the baseline).
  bool require_ranking = true;
  /// true: each design's DEM decay runs again with contacts ten times stiffer (the
  /// verification's softening times 10, at most full stiffness), and the verification fails
  /// unless the two objectives agree within tolerance_relative: the softening has converged
  /// on the quantity judged. Skipped when the runs are at full stiffness already.
  bool softening_check = true;
  /// With calibrated beds: rounds of the design loop, [1, 10]. A round that fails
  /// recalibrates the chosen design's beds where that design operates (docs/optimizer.md,
  /// "Calibrated beds"), optimises and verifies again; 1: no loop.
  int rounds = 3;
};

/// `calibration` of task kind filling_ratios: every candidate bed (each layer holding each
/// whole slab count alone) calibrated from a DEM-in-the-loop decay of the structure, its
/// per-period response gathered into a field the optimiser uses in place of the closed
/// forms (docs/optimizer.md, "Calibrated beds").
struct CalibrationSpec {
  /// Simulated time of each bed's decay, s, (0, 1e5]; default verify's duration_s, else the task's.
  double duration_s = 0.0;
  /// Factor on every Young's modulus of the calibration runs, on top of /dem's, (0, 1];
  /// default verify's stiffness_softening, else 1.
  double stiffness_softening = 1.0;
  int strokes_per_decade = 8;  ///< stroke bins of each bed's field per decade, [1, 100]
};

/// `task` kind filling_ratios: the whole slabs each layer of the first
/// damper holds, for the fastest free decay under a particle-mass budget (docs/optimizer.md).
/// The layers' containers and lattices give the candidates; their counts, the start.
struct FillingRatiosTask {
  enum class Objective { kSettlingTime, kIntegralSquare };
  Objective objective = Objective::kSettlingTime;
  double mass_budget_kg = 0.0;  ///< Σ particle mass of the first damper's layers, kg, > 0
  std::string backend = "nlopt";  ///< "nlopt" or "ipopt" (pdamp optimize --backend overrides)
  int global_evaluations = 300;   ///< free decays of the global (ISRES) stage, [1, max_evaluations)
  int max_evaluations = 1000;     ///< free decays of the relaxed solve, both stages, [2, 1000000]
  /// The free decay: initial state, duration and settling threshold, as task kind decay.
  DecayTask decay;
  /// `verify`: present when the task asks for the DEM verification (pdamp run and pdamp
  /// optimize run it; `pdamp optimize --verify` runs it with these defaults when absent).
  std::optional<VerifySpec> verify;
  /// `calibration`: present when the optimiser runs on calibrated beds (pdamp optimize
  /// --method overrides).
  std::optional<CalibrationSpec> calibration;
  // Derived on load, one per layer of the first damper:
  std::vector<int> spheres_per_slab;  ///< spheres in one full slab of the layer's lattice
  std::vector<int> spheres_per_lane;  ///< of a slab, stacked across gravity in one lane (LatticeBed)
};

/// `verify` of task kind placement: the DEM-in-the-loop free decay of each target mode, alone,
/// from its stated amplitude, with the damper at the chosen site and at one other, against
/// the same decay by the layers' loss models (docs/optimizer.md, "Placement").
struct PlacementVerifySpec {
  /// A site passes when its objective by the DEM lies within this fraction of the predicted
  /// one, dimensionless, (0, 10].
  double tolerance_relative = 0.15;
  /// The other site: a position along the beam, m (beam search), or a named point (points);
  /// default the scanned site nearest half the chosen one's objective, at least a quarter of
  /// the search range away from it (a beam), or the candidate point nearest it (points).
  std::optional<double> other_position_m;
  std::string other_point;
  /// Each decay lasts this many periods of its mode, [4, 10000]; the damping ratio is
  /// measured over its whole periods down to amplitude_fraction of the start.
  int periods = 40;
  double amplitude_fraction = 0.5;  ///< (0, 1)
  /// true: the verification fails unless the DEM's objective at the chosen site exceeds the
  /// other site's, as predicted.
  bool require_ranking = true;
};

/// `task` kind placement: where one damper adds the most damping to chosen
/// modes (docs/optimizer.md, "Placement"). On a beam the site moves continuously over
/// [min_position_m, max_position_m]; on modal data (or with candidate_points on a beam) the
/// named candidate points are compared.
struct PlacementTask {
  std::size_t damper_index = 0;  ///< `damper`: the damper placed, by name (default the first)
  optimizer::PlacementObjective objective = optimizer::PlacementObjective::kWeightedMean;
  std::string backend = "nlopt";  ///< local refinement on a beam: "nlopt" (COBYLA) or "ipopt"
  /// Modes 0-based here (the case counts them from 1), each with its weight and the
  /// amplitude of its reference point.
  std::vector<optimizer::PlacementTarget> targets;
  double min_position_m = 0.0;    ///< beam: search range along the axis, m (default the whole beam)
  double max_position_m = 0.0;
  int positions = 101;            ///< beam: positions of the scan, [3, 100000]
  std::vector<std::string> candidate_points;  ///< named points compared instead (required for modal data)
  double rotation_warning_fraction = 0.1;     ///< (0, 10]: optimizer::PlacementOptions
  /// `verify`: present when the task asks for the DEM check (pdamp run and pdamp optimize run
  /// it; `pdamp optimize --verify` runs it with these defaults when absent).
  std::optional<PlacementVerifySpec> verify;
};

/// `verify` of task kind clearance: the DEM-in-the-loop stepped sine (tasks/frf) at the
/// chosen clearance and at its neighbours, each against the prediction at that clearance
/// (docs/optimizer.md, "Clearance on a structure").
struct ClearanceVerifySpec {
  /// The neighbours checked besides the chosen h, as factors on it: each in [0.1, 10], not 1,
  /// at most 4 (each is a stepped sine of its own).
  std::vector<double> clearance_factors{0.7, 1.4};
  int dem_points = 7;  ///< stepped-sine frequencies, linear over the DEM band, [2, 1000]
  /// The DEM band, Hz: default the task's band (a DEM point costs seconds to minutes, so
  /// the band is best spent near the resonance); max > min.
  double dem_min_frequency_hz = 0.0;
  double dem_max_frequency_hz = 0.0;
  /// The chosen design passes when its DEM peak |X/U| and its 0.9-band centre lie within this
  /// fraction of the predicted ones, dimensionless, (0, 10].
  double tolerance_relative = 0.15;
  /// A point's transient has converged when the site amplitude changes by at most this
  /// fraction over the last 8 periods (pdamp frf --dem-tolerance), (0, 0.99].
  double dem_tolerance = 0.1;
  int dem_max_periods = 60;  ///< transient periods at most per point, [0, 100000]
  /// true: the verification fails unless the DEM's lowest peak is the chosen clearance's,
  /// as predicted.
  bool require_ranking = true;
};

/// `task` kind clearance: the clearance h of the first damper's single layer that minimises
/// the resonant peak |X/U| of the structure under a harmonic base motion over a band (or
/// that runs the damper at its design stroke at the peak), solved on the harmonic balance
/// with the layer's closed form (optimizer::size_clearance_on_structure).
struct ClearanceTask {
  /// The band, its points (the harmonic balance's grid, [5, 10000]) and the base motion
  /// (kind base only), as task kind frf.
  FrfTask band;
  int mode = 0;  ///< the mode tuned, 0-based here (the case counts from 1)
  optimizer::ClearanceObjective objective = optimizer::ClearanceObjective::kLowestPeak;
  /// Search range of h, m; default the closed-form estimate /3 and ·3.
  std::optional<double> min_clearance_m;
  std::optional<double> max_clearance_m;
  std::string backend = "nlopt";  ///< "nlopt" or "ipopt" (pdamp optimize --backend overrides)
  std::optional<ClearanceVerifySpec> verify;
};

/// What `pdamp run` does; the settings of the kind given (format 1: damper_design only).
struct TaskSpec {
  TaskKind kind = TaskKind::kDamperDesign;
  std::optional<FrfTask> frf;
  std::optional<DecayTask> decay;
  std::optional<ModesTask> modes;
  std::optional<FillingRatiosTask> filling_ratios;
  std::optional<PlacementTask> placement;
  std::optional<ClearanceTask> clearance;
};

/// Most values of one sensitivity parameter: every value is a case of its own (a DEM run);
/// a sensitivity study is a few values about the operating point, a finer scan a field.
inline constexpr std::size_t kMaxSensitivityValues = 50;

/// `sensitivity`: the parameters `pdamp sensitivity` varies one at a time
/// around the damper's operating point, each over the values given (docs/sensitivity.md).
struct SensitivityParameter {
  std::string name;            ///< friction, restitution, rolling_friction, particle_radius_m,
                               ///< particle_count, youngs_modulus_factor, tilt_x_deg, tilt_y_deg, tilt_z_deg
  std::vector<double> values;  ///< in the parameter's own unit (a factor for youngs_modulus_factor)
};
struct SensitivitySpec {
  double amplitude_m = 0.0;   ///< stroke X of the study, m (default: excitation.amplitude_m, else the design stroke)
  double frequency_hz = 0.0;  ///< f of the study, Hz (default: excitation.frequency_hz)
  /// The parameters and their values; empty: every parameter at its default values
  /// (sensitivity_variants).
  std::vector<SensitivityParameter> parameters;
  int threads = 2;            ///< DEM runs at once, [1, 256]
};

struct Case {
  std::string path;
  int format_version = 1;
  std::string name;
  std::string description;
  TaskSpec task;
  std::map<std::string, formulas::Material> materials;
  std::vector<DamperSpec> dampers;       ///< format 1: exactly one, with one layer
  std::optional<StructureSpec> structure;  ///< format 2 only
  ExcitationSpec excitation;
  DesignSpec design;
  std::optional<BufferSpec> buffer;
  std::optional<SensitivitySpec> sensitivity;  ///< `sensitivity`, when the case has one
  DemSpec dem;
  FieldSpec field;
  nlohmann::json resolved;  ///< the case with every default resolved and derived values added
  nlohmann::json document;  ///< the case as read (its variants and designs are read again from it)
};

/// Reads and validates a case file (format 1 or 2). CaseError names the file, the JSON
/// pointer and the rule broken (for a modal data file: that file and its pointer).
Case load_case(const std::string& path);
/// The same for a document already parsed (a variant of a case's JSON), read as if it were
/// the file at `path` (relative paths in it resolve against that file's folder).
Case load_case_document(const nlohmann::json& document, const std::string& path);

/// The case of a filling_ratios task with its first damper's layers holding `slabs[k]` whole
/// slabs each (a layer of 0 slabs left out; explicit lattices get the count along the drive)
/// and every DEM Young's modulus further times `stiffness_softening` (the verification's),
/// read again by the case reader from the case's document: the layers' beds, clearances and
/// masses, the resolved JSON and the physics hash are the design's own, and a design the
/// reader refuses is a CaseError naming the layer's key. Cases are not changed after loading:
/// a design is a new case. `other_seed`: the DEM's seed one further (the one below when the
/// seed is the largest allowed), another realisation of the ball lot (the calibration's runs,
/// so that no verification repeats one of them).
Case with_design(const Case& c, const std::vector<long>& slabs, double stiffness_softening = 1.0,
                 bool other_seed = false);

/// The case of a clearance task with its first damper's layer at clearance `clearance_m`
/// (the container longer or shorter along the drive by the change of h; an explicit
/// `clearance_m` moved with it) and its task the frf over the task's band and base motion,
/// read again by the case reader (CaseError naming the layer's key for a clearance the
/// reader refuses).
Case with_clearance(const Case& c, double clearance_m);
/// The merge patch (with_merge_patch) that gives the first damper's first layer of a format-2
/// case the clearance h: its inner length along the drive changed by h minus its clearance (a
/// box, or a cylinder along the drive; CaseError naming the axis otherwise), `clearance_m`
/// moved with it. The reader checks that the bed still fits.
nlohmann::json clearance_patch(const Case& c, double clearance_m);
/// The merge patch that gives the first damper's first layer of a format-2 case a wall layer
/// of thickness t (its `wall_layer` must exist; CaseError naming it otherwise), the container
/// unchanged: the clearance shrinks by twice the change where the lining covers the faces
/// across the drive (clearance_patch on the result restores it).
nlohmann::json wall_layer_patch(const Case& c, double thickness_m);

/// The case with `patch` merged into its document (RFC 7396: objects merge key by key, null
/// removes a key, anything else replaces), read again by the case reader (a CaseError names
/// the key the patch made wrong).
Case with_merge_patch(const Case& c, const nlohmann::json& patch);
/// The DEM's seed one further (the one below when the seed is the largest allowed): another
/// realisation of the ball lot, for calibration runs that no check may repeat.
long long other_seed(const Case& c);

/// One case of a sensitivity study: the parameter varied, its value, and the case with it.
struct SensitivityVariant {
  std::string parameter;  ///< "baseline" for the case as it is
  double value = 0.0;     ///< the parameter's value (the baseline's own for "baseline")
  std::string unit;       ///< of value ("" for dimensionless, "deg", "m", "factor")
  Case variant;
};
/// The baseline and every variant of the case's `sensitivity` study (defaults where it names
/// no parameters: friction ×0.5 and ×1.5, restitution ±0.1, particle radius ×0.9 and ×1.1,
/// particle count ×0.9 and ×1.1 (rounded), Young's modulus ×0.5 and ×2, tilts of ±5° about
/// each container axis). Each variant is the case's JSON with one value changed, read again
/// by the case reader: CaseError naming /sensitivity/parameters/i/values/j for a value the
/// case refuses; a default value the case refuses is left out and said in `skipped`.
/// Single-damper cases of one layer only (CaseError otherwise).
std::vector<SensitivityVariant> sensitivity_variants(const Case& c, std::vector<std::string>& skipped);
/// The baseline case's value of a sensitivity parameter (0 for the tilts, 1 for
/// youngs_modulus_factor), for the rows' reference.
double sensitivity_baseline_value(const Case& c, const std::string& parameter);

std::string_view to_string(TaskKind kind);

/// "layered" or "half_space" (the contact law of the buffer sizing); CaseError naming
/// `where` (a file or a flag) and `key` otherwise.
formulas::BufferModel buffer_model(const std::string& name, const std::string& where, const std::string& key);

/// The DEM options of damper `damper_index` of the case at one operating point
/// (stroke X, m; frequency f, Hz): one compartment per layer.
dem_reference::DamperSimulationOptions dem_options(const Case& c, std::size_t damper_index, double amplitude_m,
                                                   double frequency_hz);

/// A line of dem_reference's validate() or placement check ("integration.time_step_s =
/// 0.001: ...") for damper `damper_index` as the case's error: the internal option name
/// becomes the JSON pointer of the case key it comes from (/dem/time_step_s,
/// /dem/inner_structures/pins/0, /dampers/0/layers/1/particles, ...).
CaseError dem_case_error(const Case& c, std::size_t damper_index, const std::string& problem);

/// The closed forms' options of one layer: its damper's, with nested_bed set where the
/// layer's settled bed keeps spheres above its bottom rows (LatticeBed::settled_upper_spheres
/// > 0, docs/theory.md §3.3): those rest on two or more others and cannot rotate.
formulas::ModelOptions layer_model_options(const DamperSpec& damper, const LayerSpec& layer);

/// A layer of this many particles or fewer is no collected bed (settled_bed_warnings).
inline constexpr int kFewParticles = 3;

/// One sentence per layer whose bed is stacked across gravity (formulas::LatticeBed): its
/// clearance is the settled bed's (smaller than its lattice's), and where spheres stay
/// above the settled bottom rows the closed forms, which model one rolling layer, are
/// outside their validity (docs/collect_and_collide.md §8). One sentence per layer of one
/// particle per lane along the drive (one slab) or at most kFewParticles particles: the
/// collected-bed closed forms do not depend on restitution, single spheres rebound
/// (docs/theory.md §3.1).
std::vector<std::string> settled_bed_warnings(const Case& c);

/// The identity of the physics a field of `source` (formulas, dem, measured) depends
/// on: dampers, materials and, for dem, the DEM settings; not names or descriptions.
/// A format-1 case keeps the hash it always had, so shipped fields stay valid.
std::string physics_hash(const Case& c, const std::string& source);

}  // namespace pdamp::case_file
