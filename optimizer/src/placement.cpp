// Placement of a particle damper along a beam or among named points (docs/optimizer.md, "Placement").
#include "pdamp/optimizer/placement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pdamp/base/number_text.hpp"
#include "pdamp/optimizer/solve.hpp"
#include "pdamp/structure/backbone.hpp"
#include "pdamp/structure/beam.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {

const base::Fields<ModeAtSite>& ModeAtSite::fields() {
  using M = ModeAtSite;
  static const auto f =
      base::Fields<M>()
          .derived("mode", [](const M& m) { return m.mode + 1; }, "", "the mode, from 1")
          .field("natural_frequency_hz", &M::natural_frequency_hz, "Hz", "backbone frequency with the damper")
          .field("drive_shape", &M::drive_shape, "m per unit q", "the mode shape at the site along the drive")
          .field("modal_amplitude", &M::modal_amplitude, "units of q", "the target's modal amplitude")
          .field("damper_amplitude_m", &M::damper_amplitude_m, "m", "the damper's stroke")
          .field("eta_star", &M::eta_star, "1", "the layers' reduced loss factor, bed-mass weighted")
          .field("modal_mass_ratio", &M::modal_mass_ratio, "1", "bed mass in the mode over its modal mass")
          .field("added_damping_ratio", &M::added_damping_ratio, "1", "the damping ratio the beds add")
          .field("rotation_ratio", &M::rotation_ratio, "1",
                 "stroke the container's ends gain or lose from the site's rotation (null: at a node)", base::kNullable)
          .field("rotation_flagged", &M::rotation_flagged, "", "rotation_ratio above the warning fraction")
          .derived("loss_warnings", [](const M& m) { return surrogate::describe_loss_warnings(m.loss_warnings); }, "",
                   "where the loss model was outside its range");
  return f;
}

const base::Fields<PlacementPoint>& PlacementPoint::fields() {
  using P = PlacementPoint;
  static const auto f = base::Fields<P>()
                            .field("site", &P::site, "", "the point")
                            .field("position_m", &P::position_m, "m", "along the beam (null: modal data)",
                                   base::kNullable)
                            .field("objective", &P::objective, "1", "the maximised damping ratio")
                            .field("modes", &P::modes, "", "each target mode at the site");
  return f;
}

namespace {

namespace st = structure;

/// A name for the beam's moving site that none of its points or point masses has.
std::string free_site_name(const st::BeamModel& beam) {
  const auto used = [&](const std::string& name) {
    for (const auto& p : beam.points)
      if (p.name == name) return true;
    for (const auto& p : beam.point_masses)
      if (p.name == name) return true;
    return false;
  };
  std::string name = "placement_site";
  for (int k = 1; used(name); ++k) name = "placement_site_" + std::to_string(k);
  return name;
}

using base::format_number;
using detail::throw_if_invalid;

double objective_of(const std::vector<ModeAtSite>& modes, const PlacementOptions& options) {
  if (options.objective == PlacementObjective::kWorstMode) {
    double worst = std::numeric_limits<double>::infinity();
    for (const auto& m : modes) worst = std::min(worst, m.added_damping_ratio);
    return worst;
  }
  double sum = 0.0, weights = 0.0;
  for (std::size_t k = 0; k < modes.size(); ++k) {
    sum += options.targets[k].weight * modes[k].added_damping_ratio;
    weights += options.targets[k].weight;
  }
  return sum / weights;
}

}  // namespace

std::string_view to_string(PlacementObjective objective) {
  return objective == PlacementObjective::kWorstMode ? "worst_mode" : "weighted_mean";
}

std::vector<std::string> PlacementOptions::validate() const {
  std::vector<std::string> problems;
  if (targets.empty()) problems.push_back("targets: must hold at least one mode");
  double weights = 0.0;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    const auto& t = targets[k];
    const std::string at = "targets[" + std::to_string(k) + "].";
    if (t.mode < 0) problems.push_back(at + "mode = " + std::to_string(t.mode) + ": must be >= 0");
    for (std::size_t i = 0; i < k; ++i)
      if (targets[i].mode == t.mode)
        problems.push_back(at + "mode = " + std::to_string(t.mode) + ": must differ from targets[" + std::to_string(i) +
                           "].mode");
    if (!(t.weight >= 0.0 && std::isfinite(t.weight)))
      problems.push_back(at + "weight = " + format_number(t.weight, 10) + ": must be >= 0 and finite");
    weights += t.weight;
    if (t.reference_point.empty()) problems.push_back(at + "reference_point: must name a point");
    if (!(t.reference_amplitude_m > 0.0 && std::isfinite(t.reference_amplitude_m)))
      problems.push_back(at + "reference_amplitude_m = " + format_number(t.reference_amplitude_m, 10) +
                         ": must be > 0 and finite");
  }
  if (objective == PlacementObjective::kWeightedMean && !targets.empty() && !(weights > 0.0))
    problems.push_back("targets: the weights sum to 0: at least one must be > 0");
  if (damper.layers.empty()) problems.push_back("damper.layers: the placed damper must hold at least one layer");
  if (!(rotation_warning_fraction > 0.0 && rotation_warning_fraction <= 10.0))
    problems.push_back("rotation_warning_fraction = " + format_number(rotation_warning_fraction, 10) +
                       ": must be in (0, 10]");
  if (!(frequency_tolerance > 0.0 && frequency_tolerance <= 1e-3))
    problems.push_back("frequency_tolerance = " + format_number(frequency_tolerance, 10) + ": must be in (0, 1e-3]");
  return problems;
}

std::vector<std::string> BeamPlacement::validate() const {
  std::vector<std::string> problems;
  for (auto& p : beam.validate()) problems.push_back("beam." + p);
  if (mode_count < 1) problems.push_back("mode_count = " + std::to_string(mode_count) + ": must be >= 1");
  for (auto& p : damping.validate()) problems.push_back("damping." + p);
  if (!(carried_mass_kg >= 0.0 && std::isfinite(carried_mass_kg)))
    problems.push_back("carried_mass_kg = " + format_number(carried_mass_kg, 10) + ": must be >= 0 and finite");
  const double length = problems.empty() ? beam.length_m() : 0.0;
  if (!(min_position_m >= 0.0 && min_position_m < max_position_m && max_position_m <= length * (1.0 + 1e-12)))
    problems.push_back("positions [" + format_number(min_position_m, 10) + ", " + format_number(max_position_m, 10) +
                       "] m: must satisfy 0 <= min < max <= the beam's length " + format_number(length, 10) + " m");
  if (scan_positions < 3 || scan_positions > 100000)
    problems.push_back("scan_positions = " + std::to_string(scan_positions) + ": must be in [3, 100000]");
  return problems;
}

PlacementPoint evaluate_placement(const st::ModalModel& model, const std::string& site, const PlacementOptions& options) {
  throw_if_invalid(options.validate(), "placement options");
  PlacementPoint out;
  out.site = site;
  st::Damper placed = options.damper;
  placed.point = site;
  std::vector<st::Damper> dampers = {placed};
  dampers.insert(dampers.end(), options.fixed_dampers.begin(), options.fixed_dampers.end());
  const st::CoupledModel coupled = st::couple(model, dampers);  // throws for an unknown site
  const st::PointModeShape& shape = model.point(site);
  double bed_mass = 0.0;
  for (const auto& layer : placed.layers) bed_mass += layer.bed_mass_kg;

  for (std::size_t k = 0; k < options.targets.size(); ++k) {
    const PlacementTarget& t = options.targets[k];
    if (t.mode >= model.mode_count())
      throw std::invalid_argument("targets[" + std::to_string(k) + "].mode = " + std::to_string(t.mode) +
                                  ": must be < the model's " + std::to_string(model.mode_count()) + " modes");
    const Eigen::Index j = t.mode;
    const double reference = model.point(t.reference_point).translation.col(j).norm();
    if (!(reference > 0.0))
      throw std::invalid_argument("targets[" + std::to_string(k) + "].reference_point '" + t.reference_point +
                                  "' does not move in mode " + std::to_string(t.mode) +
                                  ": choose a point away from the mode's nodes");
    ModeAtSite m;
    m.mode = t.mode;
    m.modal_amplitude = t.reference_amplitude_m / reference;
    m.drive_shape = coupled.drive_shapes(j, 0);
    m.damper_amplitude_m = std::abs(m.drive_shape) * m.modal_amplitude;
    m.modal_mass_ratio = m.drive_shape * m.drive_shape * bed_mass / model.modal_masses_kg[j];
    const st::BackbonePoint p =
        st::backbone_point(coupled, t.mode, m.modal_amplitude, options.frequency_tolerance);
    m.natural_frequency_hz = p.natural_frequency_hz;
    m.added_damping_ratio = p.added_damping_ratio;
    m.loss_warnings = p.loss_warnings;
    double weighted_eta = 0.0;
    for (std::size_t l = 0; l < placed.layers.size(); ++l) weighted_eta += p.layer_eta_star[l] * placed.layers[l].bed_mass_kg;
    m.eta_star = weighted_eta / bed_mass;
    m.rotation_ratio = st::rotation_ratio(shape, j, placed.drive_direction, placed.length_along_drive_m);
    m.rotation_flagged = m.rotation_ratio > options.rotation_warning_fraction;
    out.modes.push_back(m);
  }
  out.objective = objective_of(out.modes, options);
  return out;
}

namespace {

/// The modal models of a beam placement: computed once when the damper's weight does not
/// load the beam, else once per node the weight can sit at (cached), each with the site's
/// interpolated shape appended.
class BeamSiteModels {
 public:
  explicit BeamSiteModels(const BeamPlacement& placement)
      : placement_(placement),
        moving_weight_(placement.beam.geometric_stiffness && placement.carried_mass_kg > 0.0),
        nodes_m_(st::beam_matrices(placement.beam).node_positions_m) {}

  st::ModalModel at(double position_m, const std::string& site) {
    const st::BeamModel* beam = &placement_.beam;
    st::BeamModel loaded;
    Eigen::Index node = -1;
    if (moving_weight_) {
      (nodes_m_.array() - position_m).abs().minCoeff(&node);
      loaded = placement_.beam;
      loaded.carried_weights.push_back({nodes_m_[node], placement_.carried_mass_kg});
      beam = &loaded;
    }
    if (!cached_ || cached_node_ != node) {
      cached_ = st::beam_modal_model(*beam, placement_.mode_count, placement_.damping).modal;
      cached_node_ = node;
    }
    st::ModalModel model = *cached_;
    model.points.push_back(st::beam_point_shape(*beam, model, site, position_m));
    return model;
  }

 private:
  const BeamPlacement& placement_;
  bool moving_weight_;
  Eigen::VectorXd nodes_m_;
  std::optional<st::ModalModel> cached_;
  Eigen::Index cached_node_ = -1;
};

}  // namespace

st::ModalModel beam_model_with_site(const BeamPlacement& beam, double position_m, const std::string& site) {
  return BeamSiteModels(beam).at(position_m, site);
}

Options placement_solver_options() {
  Options o;
  o.global_stage = false;
  o.nlopt_local_algorithm = NloptLocalAlgorithm::kCobyla;
  o.relative_tolerance = 1e-4;
  o.max_evaluations = 40;
  return o;
}

namespace {

/// Flags the chosen site's rotation and the targets whose stroke sits at a node.
void add_site_warnings(const PlacementPoint& best, const PlacementOptions& options, std::vector<std::string>& warnings) {
  for (const auto& m : best.modes) {
    if (m.rotation_flagged) {
      std::ostringstream out;
      out.precision(3);
      out << "at the chosen site (" << best.site;
      if (std::isfinite(best.position_m)) out << ", x = " << best.position_m << " m";
      out << ") mode " << m.mode + 1 << " (" << m.natural_frequency_hz << " Hz) rotates the container: its ends move by ";
      if (std::isfinite(m.rotation_ratio)) {
        out << 100.0 * m.rotation_ratio << "%";
      } else {
        out << "more than 100%";
      }
      out << " of its stroke (limit " << 100.0 * options.rotation_warning_fraction
          << "%); the closed forms and fields assume pure translation";
      warnings.push_back(out.str());
    }
    if (m.damper_amplitude_m == 0.0)
      warnings.push_back("at the chosen site (" + best.site + ") mode " + std::to_string(m.mode + 1) +
                         " does not move the damper along its drive: it gets no damping there");
  }
}

}  // namespace

PlacementResult optimize_placement_on_beam(const BeamPlacement& beam, const PlacementOptions& options,
                                           const Options& solver, std::optional<double> current_position_m) {
  const auto started = std::chrono::steady_clock::now();
  throw_if_invalid(options.validate(), "placement options");
  throw_if_invalid(beam.validate(), "beam placement");
  throw_if_invalid(solver.validate(), "solver options");
  PlacementResult result;
  const std::string site = free_site_name(beam.beam);
  BeamSiteModels models(beam);
  const auto at = [&](double x) {
    ++result.evaluations;
    PlacementPoint p = evaluate_placement(models.at(x, site), site, options);
    p.position_m = x;
    return p;
  };
  const int n = beam.scan_positions;
  const double step = (beam.max_position_m - beam.min_position_m) / (n - 1);
  std::size_t best = 0;
  for (int i = 0; i < n; ++i) {
    const double x = i + 1 == n ? beam.max_position_m : beam.min_position_m + i * step;
    result.scan.push_back(at(x));
    if (result.scan.back().objective > result.scan[best].objective) best = result.scan.size() - 1;
  }
  result.best = result.scan[best];

  // Refine between the best scanned position's neighbours. The variable is the position
  // mapped onto u in [1, 2], so that the solver's relative tolerance on u is a fraction of
  // that interval (a position near x = 0 would make a relative tolerance on x meaningless).
  const double lo = result.scan[best == 0 ? 0 : best - 1].position_m;
  const double hi = result.scan[std::min<std::size_t>(best + 1, result.scan.size() - 1)].position_m;
  const auto position_of = [lo, hi](double u) { return lo + (u - 1.0) * (hi - lo); };
  // The objective is scaled by the best scanned value, O(1) at the start: damping ratios of
  // 1e-5 would meet Ipopt's optimality tolerance before it takes a step.
  const double scale = result.best.objective > 0.0 ? result.best.objective : 1.0;
  Problem problem;
  problem.variables.push_back({"position_in_bracket", "", 1.0, 2.0, 1.0 + (result.best.position_m - lo) / (hi - lo)});
  problem.objective = {"minus_scaled_placement_objective",
                       [&](std::span<const double> u) { return -at(position_of(u[0])).objective / scale; }, nullptr};
  result.summary = solve(problem, solver);
  result.refined = true;
  if (-result.summary.objective * scale > result.best.objective) result.best = at(position_of(result.summary.x.at(0)));
  if (current_position_m) result.current = at(*current_position_m);
  add_site_warnings(result.best, options, result.warnings);
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

PlacementResult optimize_placement_at_points(const st::ModalModel& model, const std::vector<std::string>& candidates,
                                             const PlacementOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  throw_if_invalid(options.validate(), "placement options");
  if (candidates.empty()) throw std::invalid_argument("invalid placement: no candidate points");
  PlacementResult result;
  for (const auto& name : candidates) {
    result.scan.push_back(evaluate_placement(model, name, options));
    ++result.evaluations;
    if (result.scan.size() == 1 || result.scan.back().objective > result.best.objective) result.best = result.scan.back();
  }
  if (!options.damper.point.empty()) {
    result.current = evaluate_placement(model, options.damper.point, options);
    ++result.evaluations;
  }
  add_site_warnings(result.best, options, result.warnings);
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace pdamp::optimizer
