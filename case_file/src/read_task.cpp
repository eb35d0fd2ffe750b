// Format 2 `task`: what `pdamp run` does, with the settings of its kind.
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "readers.hpp"

namespace pdamp::case_file::detail {

namespace {

/// The number of modes the structure keeps (a beam's mode_count, or the modal file's).
int available_modes(const Case& c) {
  return c.structure->kind == StructureSpec::Kind::kBeam ? c.structure->mode_count
                                                         : static_cast<int>(c.structure->modal_data->mode_count());
}

FrfTask read_frf(ObjectReader& r, const Case& c) {
  FrfTask t;
  t.min_frequency_hz = r.number("min_frequency_hz", std::nullopt, limits::kFrequency, " Hz");
  t.max_frequency_hz = r.number("max_frequency_hz", std::nullopt, limits::kFrequency, " Hz");
  if (!(t.max_frequency_hz > t.min_frequency_hz)) r.fail("max_frequency_hz", "must be > min_frequency_hz");
  t.points = r.integer("points", FrfTask{}.points, 2, 100000);
  t.spacing = r.text("spacing", std::string("linear"), {"linear", "log"}) == "log" ? surrogate::AxisSpacing::kLog
                                                                                  : surrogate::AxisSpacing::kLinear;
  r.object("excitation", true, [&](ObjectReader& e) {
    const std::string kind = e.text("kind", std::nullopt, {"base", "force"});
    if (kind == "base") {
      t.excitation = FrfTask::Excitation::kBase;
      t.base_amplitude_m = e.number("amplitude_m", std::nullopt, limits::kStroke, " m");
    } else {
      t.excitation = FrfTask::Excitation::kForce;
      t.force_point = read_point_name(e, "point", c);
      t.force_amplitude_n = e.number("amplitude_n", std::nullopt, {0.0, limits::kForce.max, true}, " N");
    }
    t.direction = read_plane_direction(e, "direction", PlaneVector{0.0, 1.0});
  });
  return t;
}

DecayTask read_decay(ObjectReader& r, const Case& c) {
  DecayTask t;
  r.object("initial_state", true, [&](ObjectReader& s) {
    const std::string kind = s.text("kind", std::nullopt, {"static_load", "modal_amplitudes"});
    if (kind == "static_load") {
      t.initial_state = DecayTask::InitialState::kStaticLoad;
      t.load_point = read_point_name(s, "point", c);
      const auto force = s.number_array("force_n", limits::kForce, " N", 2);
      if (force.size() != 2) s.fail("force_n", "has " + std::to_string(force.size()) + " entries: must be [x, y]");
      if (force[0] == 0.0 && force[1] == 0.0) s.fail("force_n", "must not be zero (nothing would move)");
      t.load_force_n = {force[0], force[1]};
    } else {
      t.initial_state = DecayTask::InitialState::kModalAmplitudes;
      t.modal_amplitudes = s.number_array("values", {-10.0, 10.0}, "", 1);
    }
  });
  t.duration_s = r.number("duration_s", std::nullopt, limits::kDuration, " s");
  t.settling_threshold = r.number("settling_threshold", DecayTask{}.settling_threshold, {0.0, 1.0, true});
  if (t.settling_threshold >= 1.0) r.fail("settling_threshold", "must be < 1 (a fraction of the initial amplitude)");
  return t;
}

/// `modes`: whole mode numbers from 1 to mode_count, each once; 0-based in the result.
std::vector<int> read_mode_list(ObjectReader& r, int mode_count) {
  std::vector<int> out;
  const auto modes = r.number_array("modes", {1.0, static_cast<double>(mode_count)}, "", 1);
  for (std::size_t i = 0; i < modes.size(); ++i) {
    if (modes[i] != std::floor(modes[i])) r.fail("modes/" + std::to_string(i), "must be a whole mode number");
    const int mode = static_cast<int>(modes[i]) - 1;  // counted from 1 in the case
    if (std::find(out.begin(), out.end(), mode) != out.end())
      r.fail("modes/" + std::to_string(i), "= " + std::to_string(mode + 1) + ": given twice");
    out.push_back(mode);
  }
  return out;
}

/// A calibration's settings (its modes are the caller's).
void read_calibration_settings(ObjectReader& b, ModesCalibrationSpec& spec) {
  spec.strokes_per_decade = b.integer("strokes_per_decade", spec.strokes_per_decade, 1, 100);
  spec.stiffness_softening = b.number("stiffness_softening", spec.stiffness_softening, {1e-6, 1.0});
}

ModesCalibrationSpec read_modes_calibration(ObjectReader& b, const ModesTask& t) {
  ModesCalibrationSpec spec;
  spec.modes = b.has("modes") || !t.dem_check ? read_mode_list(b, t.mode_count) : t.dem_check->modes;
  read_calibration_settings(b, spec);
  return spec;
}

/// The DEM decays of `dem_check` (of `modes`) and of clearance_search's `verify`.
ModesDemCheck read_mode_decays(ObjectReader& d, const Case& c, std::vector<int> modes) {
  ModesDemCheck check;
  check.modes = std::move(modes);
  check.amplitudes_m = d.number_array("amplitudes_m", limits::kStroke, " m", 1);
  if (check.amplitudes_m.size() > 20)
    d.fail("amplitudes_m", "has " + std::to_string(check.amplitudes_m.size()) + " entries: at most 20 (each is a DEM decay)");
  if (!std::is_sorted(check.amplitudes_m.begin(), check.amplitudes_m.end())) d.fail("amplitudes_m", "must be ascending");
  check.periods = d.integer("periods", check.periods, 4, 10000);
  check.amplitude_fraction = d.number("amplitude_fraction", check.amplitude_fraction, {0.0, 1.0, true});
  if (check.amplitude_fraction >= 1.0) d.fail("amplitude_fraction", "must be < 1 (a fraction of the start)");
  check.tolerance_relative = d.number("tolerance_relative", check.tolerance_relative, {0.0, 10.0, true});
  check.forced_start_periods = d.integer("forced_start_periods", check.forced_start_periods, 0, 10000);
  if (c.dampers.size() != 1)
    throw CaseError(d.file(), "/dampers", "has " + std::to_string(c.dampers.size()) +
                                              " dampers: the DEM check of task kind modes takes a case of one damper");
  return check;
}

ModesClearanceSearch read_clearance_search(ObjectReader& r, const Case& c, const ModesTask& t) {
  ModesClearanceSearch s;
  const auto mode = r.number("mode", std::nullopt, {1.0, static_cast<double>(t.mode_count)}, "");
  if (mode != std::floor(mode)) r.fail("mode", "must be a whole mode number");
  s.mode = static_cast<int>(mode) - 1;
  s.min_amplitude_m = r.number("min_amplitude_m", std::nullopt, limits::kStroke, " m");
  s.max_amplitude_m = r.number("max_amplitude_m", std::nullopt, limits::kStroke, " m");
  if (!(s.max_amplitude_m > s.min_amplitude_m)) r.fail("max_amplitude_m", "must be > min_amplitude_m");
  s.amplitude_points = r.integer("amplitude_points", s.amplitude_points, 2, 50);
  s.objective = r.text("objective", std::string("mean"), {"mean", "worst"}) == "worst"
                    ? ModesClearanceSearch::Objective::kWorst
                    : ModesClearanceSearch::Objective::kMean;
  // Each candidate is a DEM calibration of minutes: a handful, not a fine grid.
  constexpr int kMaxCandidates = 20;
  if (r.has("clearances_m")) {
    for (const char* key : {"min_clearance_m", "max_clearance_m", "candidates"})
      if (r.has(key)) r.fail(key, "must not be given with clearances_m (the candidates are listed)");
    s.clearances_m = r.number_array("clearances_m", limits::kClearance, " m", 2);
    if (s.clearances_m.size() > kMaxCandidates)
      r.fail("clearances_m", "has " + std::to_string(s.clearances_m.size()) + " entries: at most " +
                                 std::to_string(kMaxCandidates) + " (each is a DEM calibration)");
    if (std::adjacent_find(s.clearances_m.begin(), s.clearances_m.end(), std::greater_equal<>()) != s.clearances_m.end())
      r.fail("clearances_m", "must be strictly ascending");
  } else {
    const double lo = r.number("min_clearance_m", std::nullopt, limits::kClearance, " m");
    const double hi = r.number("max_clearance_m", std::nullopt, limits::kClearance, " m");
    if (!(hi > lo)) r.fail("max_clearance_m", "must be > min_clearance_m");
    const int n = r.integer("candidates", 5, 2, kMaxCandidates);
    for (int k = 0; k < n; ++k) s.clearances_m.push_back(lo * std::pow(hi / lo, static_cast<double>(k) / (n - 1)));
  }
  if (r.has("wall_layer_thicknesses_m")) {
    const dem_reference::WallLayerOptions& lining = c.dampers.front().layers.front().compartment.layer;
    if (!(lining.thickness_m > 0.0) || (lining.axis >= 0 && lining.axis != c.dampers.front().drive_axis))
      r.fail("wall_layer_thicknesses_m", "needs a wall_layer on the faces across the drive of the damper's layer "
                                         "(/dampers/0/layers/0/wall_layer with axis all or the drive axis)");
    s.wall_layer_thicknesses_m = r.number_array("wall_layer_thicknesses_m", limits::kContainerSize, " m", 1);
    const auto& t = s.wall_layer_thicknesses_m;
    if (std::adjacent_find(t.begin(), t.end(), std::greater_equal<>()) != t.end())
      r.fail("wall_layer_thicknesses_m", "must be strictly ascending");
    if (t.size() * s.clearances_m.size() > kMaxCandidates)
      r.fail("wall_layer_thicknesses_m", "has " + std::to_string(t.size()) + " entries with " +
                                             std::to_string(s.clearances_m.size()) + " clearances: at most " +
                                             std::to_string(kMaxCandidates) + " pairs (each is a DEM calibration)");
  }
  s.calibration.modes = {s.mode};
  r.object("calibration", false, [&](ObjectReader& b) { read_calibration_settings(b, s.calibration); });
  r.object("verify", false, [&](ObjectReader& v) {
    s.verify = read_mode_decays(v, c, {s.mode});
    // The prediction of a decay from X down to fraction·X reads the calibrated strokes only.
    const double lo = s.min_amplitude_m / s.verify->amplitude_fraction;
    for (std::size_t k = 0; k < s.verify->amplitudes_m.size(); ++k)
      if (const double x = s.verify->amplitudes_m[k]; x < lo * (1.0 - 1e-9) || x > s.max_amplitude_m * (1.0 + 1e-9))
        v.fail("amplitudes_m/" + std::to_string(k),
               "= " + base::format_number(x, kMessageDigits) + " m: must lie in [min_amplitude_m/amplitude_fraction, "
               "max_amplitude_m] = [" + base::format_number(lo, kMessageDigits) + ", " +
                   base::format_number(s.max_amplitude_m, kMessageDigits) +
                   "] m (a decay measured down to that fraction stays inside the calibrated strokes)");
  });
  // The candidates are the first damper's one layer, its length along the drive changed.
  if (c.dampers.size() != 1 || c.dampers.front().layers.size() != 1)
    throw CaseError(r.file(), "/dampers", "has " + std::to_string(c.dampers.size()) + " dampers, the first with " +
                                              std::to_string(c.dampers.front().layers.size()) +
                                              " layers: clearance_search takes one damper of one layer");
  return s;
}

ModesTask read_modes(ObjectReader& r, const Case& c) {
  ModesTask t;
  const int available = available_modes(c);
  t.mode_count = r.integer("mode_count", available, 1, available);
  t.backbone_min_amplitude_m = r.number("backbone_min_amplitude_m", std::nullopt, limits::kStroke, " m");
  t.backbone_max_amplitude_m = r.number("backbone_max_amplitude_m", std::nullopt, limits::kStroke, " m");
  if (!(t.backbone_max_amplitude_m > t.backbone_min_amplitude_m))
    r.fail("backbone_max_amplitude_m", "must be > backbone_min_amplitude_m");
  t.backbone_points = r.integer("backbone_points", ModesTask{}.backbone_points, 2, 10000);
  r.object("dem_check", false, [&](ObjectReader& d) {
    t.dem_check = read_mode_decays(d, c, read_mode_list(d, t.mode_count));
  });
  r.object("calibration", false, [&](ObjectReader& b) { t.calibration = read_modes_calibration(b, t); });
  r.object("clearance_search", false, [&](ObjectReader& s) { t.clearance_search = read_clearance_search(s, c, t); });
  return t;
}

/// Spheres in one full slab of a layer's lattice: the product of the transverse counts of
/// an explicit lattice, else the most spheres collected_lattice places in one slab.
int spheres_per_slab(const LayerSpec& layer, int drive_axis) {
  if (layer.packing.lattice_counts) {
    int n = 1;
    for (int axis = 0; axis < 3; ++axis)
      if (axis != drive_axis) n *= (*layer.packing.lattice_counts)[static_cast<std::size_t>(axis)];
    return n;
  }
  // slabs(count) is non-decreasing in count: bisect for the last count of one slab.
  const auto one_slab = [&](int count) {
    try {
      return formulas::collected_lattice(layer.container, count, layer.particle_radius_m, layer.packing).slabs == 1;
    } catch (const std::invalid_argument&) {
      return false;  // does not fit
    }
  };
  int lo = 1, hi = 2;
  while (one_slab(hi) && hi < (1 << 24)) lo = hi, hi *= 2;
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    (one_slab(mid) ? lo : hi) = mid;
  }
  return lo;
}

/// `verify` of task kind filling_ratios (the DEM check of the chosen and baseline designs).
VerifySpec read_verify(ObjectReader& r, const DecayTask& decay) {
  VerifySpec v;
  v.tolerance_relative = r.number("tolerance_relative", VerifySpec{}.tolerance_relative, {0.0, 10.0, true});
  v.duration_s = r.number("duration_s", decay.duration_s, limits::kDuration, " s");
  v.stiffness_softening = r.number("stiffness_softening", VerifySpec{}.stiffness_softening, {1e-6, 1.0});
  v.require_ranking = r.boolean("require_ranking", VerifySpec{}.require_ranking);
  v.softening_check = r.boolean("softening_check", VerifySpec{}.softening_check);
  v.rounds = r.integer("rounds", VerifySpec{}.rounds, 1, 10);
  return v;
}

FillingRatiosTask read_filling_ratios(ObjectReader& r, const Case& c) {
  FillingRatiosTask t;
  t.objective = r.text("objective", std::string("settling_time"), {"settling_time", "integral_square"}) ==
                        "integral_square"
                    ? FillingRatiosTask::Objective::kIntegralSquare
                    : FillingRatiosTask::Objective::kSettlingTime;
  t.mass_budget_kg = r.number("mass_budget_kg", std::nullopt, {0.0, 1e6, true}, " kg");
  t.backend = r.text("backend", std::string("nlopt"), {"nlopt", "ipopt"});
  t.max_evaluations = r.integer("max_evaluations", FillingRatiosTask{}.max_evaluations, 2, 1000000);
  t.global_evaluations = r.integer("global_evaluations", FillingRatiosTask{}.global_evaluations, 1, 1000000);
  if (t.global_evaluations >= t.max_evaluations) r.fail("global_evaluations", "must be < max_evaluations");
  // The candidates are the first damper's layers: boxes with room for two slabs.
  const DamperSpec& damper = c.dampers.front();
  double lightest_slab_kg = 0.0;
  for (std::size_t k = 0; k < damper.layers.size(); ++k) {
    const LayerSpec& layer = damper.layers[k];
    const std::string at = "/dampers/0/layers/" + std::to_string(k);
    if (layer.container.shape != formulas::ContainerShape::kBox)
      throw CaseError(r.file(), at + "/container/shape",
                      "must be box for task kind filling_ratios (a layer is a box of whole slabs)");
    const double length = layer.container.inner_length(damper.drive_axis);
    if (length < 4.0 * layer.particle_radius_m * (1.0 - 1e-9))
      throw CaseError(r.file(), at + "/container/inner_size_m",
                      "= " + base::format_number(length, kMessageDigits) +
                          " m along the drive: task kind filling_ratios needs room for two "
                          "slabs of 2r = " +
                          base::format_number(2.0 * layer.particle_radius_m, kMessageDigits) +
                          " m (one slab and its travel)");
    const int per_slab = spheres_per_slab(layer, damper.drive_axis);
    t.spheres_per_slab.push_back(per_slab);
    t.spheres_per_lane.push_back(layer.bed.spheres_per_lane);
    if ((static_cast<int>(std::floor(length / (2.0 * layer.particle_radius_m) * (1.0 + 1e-9))) - 1) /
            layer.bed.spheres_per_lane < 1)
      throw CaseError(r.file(), at + "/container/inner_size_m",
                      "= " + base::format_number(length, kMessageDigits) + " m along the drive: a slab stacked " +
                          std::to_string(layer.bed.spheres_per_lane) +
                          " high settles into as many rows of 2r on the base; task kind filling_ratios needs room "
                          "for them and one row of travel");
    const double slab_kg = per_slab * layer.bed_mass_kg / layer.particle_count;
    lightest_slab_kg = k == 0 ? slab_kg : std::min(lightest_slab_kg, slab_kg);
  }
  if (t.mass_budget_kg < lightest_slab_kg * (1.0 - 1e-9))
    r.fail("mass_budget_kg", "= " + base::format_number(t.mass_budget_kg, kMessageDigits) +
                                 ": must be >= the lightest whole slab of a layer, " +
                                 base::format_number(lightest_slab_kg, kMessageDigits) + " kg");
  t.decay = read_decay(r, c);
  r.object("verify", false, [&](ObjectReader& v) { t.verify = read_verify(v, t.decay); });
  r.object("calibration", false, [&](ObjectReader& b) {
    CalibrationSpec spec;
    spec.duration_s = b.number("duration_s", t.verify ? t.verify->duration_s : t.decay.duration_s, limits::kDuration, " s");
    spec.stiffness_softening =
        b.number("stiffness_softening", t.verify ? t.verify->stiffness_softening : 1.0, {1e-6, 1.0});
    spec.strokes_per_decade = b.integer("strokes_per_decade", CalibrationSpec{}.strokes_per_decade, 1, 100);
    t.calibration = spec;
  });
  return t;
}

PlacementTask read_placement(ObjectReader& r, const Case& c) {
  PlacementTask t;
  std::vector<std::string> damper_names;
  for (const auto& d : c.dampers) damper_names.push_back(d.name);
  const std::string damper = r.text("damper", c.dampers.front().name, damper_names);
  t.damper_index = static_cast<std::size_t>(std::find(damper_names.begin(), damper_names.end(), damper) - damper_names.begin());
  t.objective = r.text("objective", std::string("weighted_mean"), {"weighted_mean", "worst_mode"}) == "worst_mode"
                    ? optimizer::PlacementObjective::kWorstMode
                    : optimizer::PlacementObjective::kWeightedMean;
  t.backend = r.text("backend", std::string("nlopt"), {"nlopt", "ipopt"});
  const int modes = available_modes(c);
  r.array("targets", [&](ObjectReader& e) {
    optimizer::PlacementTarget target;
    target.mode = e.integer("mode", std::nullopt, 1, modes) - 1;  // counted from 1 in the case
    for (const auto& other : t.targets)
      if (other.mode == target.mode) e.fail("mode", "= " + std::to_string(target.mode + 1) + ": given twice");
    target.weight = e.number("weight", 1.0, {0.0, 1e6});
    target.reference_point = read_point_name(e, "reference_point", c);
    target.reference_amplitude_m = e.number("reference_amplitude_m", std::nullopt, limits::kStroke, " m");
    t.targets.push_back(target);
  });
  if (t.targets.empty()) r.fail("targets", "required: at least one {\"mode\", \"reference_point\", \"reference_amplitude_m\"}");
  if (t.objective == optimizer::PlacementObjective::kWeightedMean) {
    double weights = 0.0;
    for (const auto& target : t.targets) weights += target.weight;
    if (!(weights > 0.0)) r.fail("targets", "the weights sum to 0: at least one must be > 0");
  }
  if (r.has("candidate_points")) {
    t.candidate_points = r.text_array("candidate_points", 1);
    const auto& names = c.structure->point_names;
    for (std::size_t i = 0; i < t.candidate_points.size(); ++i)
      if (std::find(names.begin(), names.end(), t.candidate_points[i]) == names.end())
        r.fail("candidate_points/" + std::to_string(i), "'" + t.candidate_points[i] + "' is no named point of the structure");
  }
  if (c.structure->kind == StructureSpec::Kind::kBeam && t.candidate_points.empty()) {
    const double length = c.structure->beam.length_m();
    const Range along{0.0, length};
    t.min_position_m = r.number("min_position_m", 0.0, along, " m (along the beam)");
    t.max_position_m = r.number("max_position_m", length, along, " m (along the beam)");
    if (!(t.max_position_m > t.min_position_m)) r.fail("max_position_m", "must be > min_position_m");
    t.positions = r.integer("positions", PlacementTask{}.positions, 3, 100000);
  } else if (t.candidate_points.empty()) {
    r.fail("candidate_points", "required for modal data (its shapes are known at the named points only)");
  }
  t.rotation_warning_fraction = r.number("rotation_warning_fraction", PlacementTask{}.rotation_warning_fraction, {0.0, 10.0, true});
  r.object("verify", false, [&](ObjectReader& v) {
    PlacementVerifySpec spec;
    spec.tolerance_relative = v.number("tolerance_relative", spec.tolerance_relative, {0.0, 10.0, true});
    if (t.candidate_points.empty()) {
      spec.other_position_m = v.optional_number("other_position_m", {t.min_position_m, t.max_position_m},
                                                " m (along the beam, inside the search range)");
    } else if (v.has("other_point")) {
      spec.other_point = read_point_name(v, "other_point", c);
      if (std::find(t.candidate_points.begin(), t.candidate_points.end(), spec.other_point) == t.candidate_points.end())
        v.fail("other_point", "'" + spec.other_point + "' is not among candidate_points");
    }
    spec.periods = v.integer("periods", spec.periods, 4, 10000);
    spec.amplitude_fraction = v.number("amplitude_fraction", spec.amplitude_fraction, {0.0, 1.0, true});
    if (spec.amplitude_fraction >= 1.0) v.fail("amplitude_fraction", "must be < 1 (a fraction of the start)");
    spec.require_ranking = v.boolean("require_ranking", spec.require_ranking);
    if (c.dampers.size() != 1)
      throw CaseError(r.file(), "/dampers", "has " + std::to_string(c.dampers.size()) +
                                                " dampers: the verification of a placement takes a case of one damper");
    t.verify = spec;
  });
  return t;
}

/// `verify` of task kind clearance (the DEM stepped sine at the chosen h and its neighbours).
ClearanceVerifySpec read_clearance_verify(ObjectReader& r, const FrfTask& band) {
  ClearanceVerifySpec v;
  if (r.has("clearance_factors")) {
    v.clearance_factors = r.number_array("clearance_factors", {0.1, 10.0}, "", 1);
    if (v.clearance_factors.size() > 4)
      r.fail("clearance_factors", "has " + std::to_string(v.clearance_factors.size()) +
                                      " entries: at most 4 (each is a DEM stepped sine of its own)");
    for (std::size_t i = 0; i < v.clearance_factors.size(); ++i)
      if (std::abs(v.clearance_factors[i] - 1.0) < 1e-9)
        r.fail("clearance_factors/" + std::to_string(i), "= 1: the chosen clearance is checked anyway");
  }
  v.dem_points = r.integer("dem_points", ClearanceVerifySpec{}.dem_points, 2, 1000);
  v.dem_min_frequency_hz = r.number("dem_min_frequency_hz", band.min_frequency_hz, limits::kFrequency, " Hz");
  v.dem_max_frequency_hz = r.number("dem_max_frequency_hz", band.max_frequency_hz, limits::kFrequency, " Hz");
  if (!(v.dem_max_frequency_hz > v.dem_min_frequency_hz)) r.fail("dem_max_frequency_hz", "must be > dem_min_frequency_hz");
  v.tolerance_relative = r.number("tolerance_relative", ClearanceVerifySpec{}.tolerance_relative, {0.0, 10.0, true});
  v.dem_tolerance = r.number("dem_tolerance", ClearanceVerifySpec{}.dem_tolerance, {0.0, 0.99, true});
  v.dem_max_periods = r.integer("dem_max_periods", ClearanceVerifySpec{}.dem_max_periods, 0, 100000);
  v.require_ranking = r.boolean("require_ranking", ClearanceVerifySpec{}.require_ranking);
  return v;
}

ClearanceTask read_clearance(ObjectReader& r, const Case& c) {
  ClearanceTask t;
  if (c.dampers.size() != 1)
    throw CaseError(r.file(), "/dampers", "has " + std::to_string(c.dampers.size()) +
                                              " dampers: task kind clearance sizes one damper on the structure");
  const DamperSpec& damper = c.dampers.front();
  if (damper.layers.size() != 1)
    throw CaseError(r.file(), "/dampers/0/layers",
                    "has " + std::to_string(damper.layers.size()) +
                        " layers: task kind clearance sizes the clearance of a single-layer first damper");
  if (damper.model != formulas::DamperModel::kRolling && damper.model != formulas::DamperModel::kBouncing)
    throw CaseError(r.file(), "/dampers/0/model",
                    "= " + std::string(formulas::to_string(damper.model)) +
                        ": task kind clearance needs rolling or bouncing (their design stroke is a fixed X/h)");
  t.band = read_frf(r, c);
  if (t.band.excitation != FrfTask::Excitation::kBase)
    throw CaseError(r.file(), "/task/excitation/kind", "must be base for task kind clearance (the peak |X/U|)");
  if (t.band.points < 5 || t.band.points > 10000) r.fail("points", "= " + std::to_string(t.band.points) + ": must be in [5, 10000]");
  if (t.band.spacing != surrogate::AxisSpacing::kLinear)
    r.fail("spacing", "must be linear for task kind clearance (the sizing's grid is evenly spaced)");
  t.mode = r.integer("mode", std::nullopt, 1, available_modes(c)) - 1;  // counted from 1 in the case
  t.objective = r.text("objective", std::string("lowest_peak"), {"lowest_peak", "design_stroke_at_resonance"}) ==
                        "design_stroke_at_resonance"
                    ? optimizer::ClearanceObjective::kDesignStrokeAtResonance
                    : optimizer::ClearanceObjective::kLowestPeak;
  t.min_clearance_m = r.optional_number("min_clearance_m", limits::kClearance, " m");
  t.max_clearance_m = r.optional_number("max_clearance_m", limits::kClearance, " m");
  if (t.min_clearance_m && t.max_clearance_m && !(*t.max_clearance_m > *t.min_clearance_m))
    r.fail("max_clearance_m", "must be > min_clearance_m");
  t.backend = r.text("backend", std::string("nlopt"), {"nlopt", "ipopt"});
  r.object("verify", false, [&](ObjectReader& v) { t.verify = read_clearance_verify(v, t.band); });
  return t;
}

void read_task_object(ObjectReader& r, const Case& c, TaskSpec& task) {
  const std::string kind = r.text("kind", std::string("damper_design"),
                                  {"damper_design", "frf", "decay", "modes", "filling_ratios", "placement", "clearance"});
  if (kind == "frf") {
    task.kind = TaskKind::kFrf;
    task.frf = read_frf(r, c);
  } else if (kind == "decay") {
    task.kind = TaskKind::kDecay;
    task.decay = read_decay(r, c);
  } else if (kind == "modes") {
    task.kind = TaskKind::kModes;
    task.modes = read_modes(r, c);
  } else if (kind == "filling_ratios") {
    task.kind = TaskKind::kFillingRatios;
    task.filling_ratios = read_filling_ratios(r, c);
  } else if (kind == "placement") {
    task.kind = TaskKind::kPlacement;
    task.placement = read_placement(r, c);
  } else if (kind == "clearance") {
    task.kind = TaskKind::kClearance;
    task.clearance = read_clearance(r, c);
  }
}

}  // namespace

TaskSpec read_task(ObjectReader& root, const Case& c) {
  TaskSpec task;
  root.object("task", false, [&](ObjectReader& r) { read_task_object(r, c, task); });
  if (!root.has("task")) {
    ObjectReader defaults(root.file(), empty_object(), "/task", root.resolved()["task"]);
    read_task_object(defaults, c, task);
  }
  return task;
}

}  // namespace pdamp::case_file::detail
