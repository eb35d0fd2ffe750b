// Clearance on a structure: the single-mode closed form, the harmonic-balance response at
// one clearance, and the 1-variable sizing problem.
#include "pdamp/optimizer/clearance_on_structure.hpp"
#include "pdamp/base/run_errors.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <memory>
#include <stdexcept>

#include "pdamp/optimizer/solve.hpp"
#include "pdamp/structure/harmonic_balance.hpp"
#include "pdamp/surrogate/loss_model.hpp"
#include "pdamp/base/number_text.hpp"
#include "validation.hpp"

namespace pdamp::optimizer {

const base::Fields<ClearanceEstimate>& ClearanceEstimate::fields() {
  using E = ClearanceEstimate;
  static const auto f =
      base::Fields<E>()
          .field("clearance_m", &E::clearance_m, "m", "h of the single-mode closed form")
          .field("transmissibility", &E::transmissibility, "1", "peak |X/U| of the closed form at that h")
          .field("damper_amplitude_m", &E::damper_amplitude_m, "m", "the design stroke x_opt(h) at resonance")
          .field("resonance_hz", &E::resonance_hz, "Hz", "the resonance with container and apparent bed mass")
          .field("participation", &E::participation, "1", "effective base participation")
          .field("structural_damping", &E::structural_damping, "1", "the structure's damping ratio, mass-scaled")
          .field("added_damping", &E::added_damping, "1", "the damping ratio the bed adds at its design point")
          .field("mass_ratio", &E::mass_ratio, "1", "bed mass in the mode over the mode's mass")
          .field("eta_star_design", &E::eta_star_design, "1", "eta* at the design stroke")
          .field("apparent_mass_fraction", &E::apparent_mass_fraction, "1", "m_app/m_bed at the design stroke")
          .field("stroke_over_clearance", &E::stroke_over_clearance, "1", "x_opt/h of the model");
  return f;
}

const base::Fields<ClearanceResponse>& ClearanceResponse::fields() {
  using R = ClearanceResponse;
  static const auto f =
      base::Fields<R>()
          .field("clearance_m", &R::clearance_m, "m", "h")
          .field("peak_transmissibility", &R::peak_transmissibility, "1",
                 "largest non-unstable or held |X/U| over the band")
          .field("peak_frequency_hz", &R::peak_frequency_hz, "Hz", "where it is")
          .field("damper_amplitude_m", &R::damper_amplitude_m, "m", "the site's amplitude along the drive there")
          .field("onset_m", &R::onset_m, "m", "the onset stroke of collect-and-collide at h")
          .field("design_stroke_m", &R::design_stroke_m, "m", "x_opt(h)")
          .field("held_at_onset", &R::held_at_onset, "", "the peak is a state held at the onset (the jump)");
  return f;
}

namespace {

namespace fm = formulas;
namespace st = structure;

constexpr double kPi = 3.14159265358979323846;

bool is_unit(const Eigen::Vector2d& v) { return v.allFinite() && std::abs(v.norm() - 1.0) <= 1e-9; }

/// x_opt/h of the model (h-independent for rolling and bouncing).
double design_stroke_over_clearance(const ClearanceOnStructureOptions& options) {
  return fm::optimum_stroke(options.model, 1.0, options.model_options).x_opt_m;
}

double onset_over_clearance(const ClearanceOnStructureOptions& options) {
  return fm::optimum_stroke(options.model, 1.0, options.model_options).x_onset_m;
}

void check_against_model(const st::ModalModel& model, const ClearanceOnStructureOptions& options) {
  detail::throw_if_invalid(options.validate(), "clearance-on-structure options");
  std::vector<std::string> problems;
  if (options.mode < 0 || options.mode >= model.mode_count()) {
    problems.push_back("mode = " + std::to_string(options.mode) + ": must be in [0, " +
                       std::to_string(model.mode_count()) + ")");
  }
  if (model.base_participation.cols() != 2) {
    problems.emplace_back("model: has no base participation (base excitation needs it)");
  }
  detail::throw_if_invalid(problems, "clearance-on-structure options");
  (void)model.point(options.site);  // throws naming the site
}

}  // namespace

std::string_view to_string(ClearanceObjective objective) {
  switch (objective) {
    case ClearanceObjective::kDesignStrokeAtResonance: return "design stroke at resonance";
    case ClearanceObjective::kLowestPeak: return "lowest peak";
  }
  return "unknown";
}

std::vector<std::string> ClearanceOnStructureOptions::validate() const {
  std::vector<std::string> problems;
  const auto rule = [&](const char* field, double value, bool holds, const char* text) {
    if (!holds) problems.push_back(std::string(field) + " = " + base::format_number(value, 10) + ": must be " + text);
  };
  if (site.empty()) problems.emplace_back("site: must name a point of the model");
  if (!is_unit(drive_direction)) problems.emplace_back("drive_direction: must be a unit vector");
  if (!is_unit(base_direction)) problems.emplace_back("base_direction: must be a unit vector");
  rule("container_mass_kg", container_mass_kg, std::isfinite(container_mass_kg) && container_mass_kg >= 0.0,
       ">= 0 and finite");
  rule("bed_mass_kg", bed_mass_kg, std::isfinite(bed_mass_kg) && bed_mass_kg > 0.0, "> 0 and finite");
  if (model != fm::DamperModel::kRolling && model != fm::DamperModel::kBouncing) {
    problems.push_back("model = " + std::string(fm::to_string(model)) +
                       ": must be rolling or bouncing (η* a function of X/h only)");
  }
  for (const std::string& line : model_options.validate()) problems.push_back("model_options." + line);
  rule("base_amplitude_m", base_amplitude_m, std::isfinite(base_amplitude_m) && base_amplitude_m > 0.0,
       "> 0 and finite");
  rule("frequency_min_hz", frequency_min_hz, std::isfinite(frequency_min_hz) && frequency_min_hz > 0.0,
       "> 0 and finite");
  rule("frequency_max_hz", frequency_max_hz, std::isfinite(frequency_max_hz) && frequency_max_hz > frequency_min_hz,
       "> frequency_min_hz and finite");
  rule("frequency_points", frequency_points, frequency_points >= 5 && frequency_points <= 10000, "in [5, 10000]");
  rule("scan_points_per_decade", scan_points_per_decade, scan_points_per_decade >= 4, ">= 4");
  rule("stroke_min_over_clearance", stroke_min_over_clearance,
       std::isfinite(stroke_min_over_clearance) && stroke_min_over_clearance > 0.0, "> 0 and finite");
  rule("stroke_max_over_clearance", stroke_max_over_clearance,
       stroke_max_over_clearance > stroke_min_over_clearance && stroke_max_over_clearance <= 10.0,
       "in (stroke_min_over_clearance, 10]");
  if (clearance_min_m) {
    rule("clearance_min_m", *clearance_min_m, std::isfinite(*clearance_min_m) && *clearance_min_m > 0.0,
         "> 0 and finite");
  }
  if (clearance_max_m) {
    rule("clearance_max_m", *clearance_max_m,
         std::isfinite(*clearance_max_m) && *clearance_max_m > clearance_min_m.value_or(0.0),
         "> clearance_min_m and finite");
  }
  return problems;
}

Options clearance_on_structure_solver_options() {
  Options options;
  options.nlopt_local_algorithm = NloptLocalAlgorithm::kCobyla;
  options.global_stage = true;
  options.global_evaluations = 16;
  options.max_evaluations = 60;
  options.relative_tolerance = 1e-3;
  return options;
}

ClearanceEstimate estimate_clearance_on_structure(const st::ModalModel& model,
                                                  const ClearanceOnStructureOptions& options) {
  check_against_model(model, options);
  const auto j = static_cast<Eigen::Index>(options.mode);
  const Eigen::Vector2d phi = model.point(options.site).translation.col(j);
  const double b = phi.dot(options.drive_direction);
  if (!(std::abs(b) > 0.0)) {
    throw std::invalid_argument("clearance-on-structure: site '" + options.site + "' does not move along the drive in mode " +
                                std::to_string(options.mode));
  }
  const double m_j = model.modal_masses_kg(j);
  const double omega_j = 2.0 * kPi * model.natural_frequencies_hz(j);
  ClearanceEstimate e;
  e.stroke_over_clearance = design_stroke_over_clearance(options);
  // The bed at its design point; rolling and bouncing depend on X/h only (h = 1 m here).
  const surrogate::ClosedFormLossModel unit(options.model, 1.0, options.model_options);
  const surrogate::DamperResponse design = unit.evaluate(model.natural_frequencies_hz(j), e.stroke_over_clearance);
  e.eta_star_design = design.eta_star;
  e.apparent_mass_fraction = std::isfinite(design.apparent_mass_fraction) ? design.apparent_mass_fraction : 1.0;
  const double m_app = e.apparent_mass_fraction * options.bed_mass_kg;
  const double mass = m_j + options.container_mass_kg * phi.squaredNorm() + m_app * b * b;
  const Eigen::Vector2d gamma = model.base_participation.row(j).transpose();
  const double load = gamma.dot(options.base_direction) + options.container_mass_kg * phi.dot(options.base_direction) +
                      m_app * b * options.drive_direction.dot(options.base_direction);
  e.resonance_hz = omega_j * std::sqrt(m_j / mass) / (2.0 * kPi);
  e.structural_damping = model.damping_ratios(j) * std::sqrt(m_j / mass);
  e.mass_ratio = options.bed_mass_kg * b * b / mass;
  e.added_damping = 0.5 * e.eta_star_design * e.mass_ratio;
  e.participation = std::abs(b * load) / mass;
  e.transmissibility = e.participation / (2.0 * (e.structural_damping + e.added_damping));
  e.damper_amplitude_m = e.transmissibility * options.base_amplitude_m;
  e.clearance_m = e.damper_amplitude_m / e.stroke_over_clearance;
  return e;
}

ClearanceResponse clearance_response(const st::ModalModel& model, const ClearanceOnStructureOptions& options,
                                     double clearance_m) {
  st::Damper damper;
  damper.name = "damper";
  damper.point = options.site;
  damper.drive_direction = options.drive_direction;
  damper.container_mass_kg = options.container_mass_kg;
  damper.layers.push_back({"bed", options.bed_mass_kg,
                           std::make_shared<surrogate::ClosedFormLossModel>(options.model, clearance_m,
                                                                            options.model_options)});
  st::Excitation excitation;
  excitation.kind = st::Excitation::Kind::kBaseTranslation;
  excitation.direction = options.base_direction;
  excitation.amplitude = options.base_amplitude_m;
  st::HarmonicBalanceOptions hb;
  hb.frequencies_hz.resize(static_cast<std::size_t>(options.frequency_points));
  for (int k = 0; k < options.frequency_points; ++k) {
    hb.frequencies_hz[static_cast<std::size_t>(k)] =
        options.frequency_min_hz +
        (options.frequency_max_hz - options.frequency_min_hz) * k / (options.frequency_points - 1);
  }
  hb.scan_points_per_decade = options.scan_points_per_decade;
  hb.stroke_min_m = options.stroke_min_over_clearance * clearance_m;
  hb.stroke_max_m = options.stroke_max_over_clearance * clearance_m;
  hb.refine_branch_ends = false;  // the peak needs the grid values only
  const st::FrequencyResponse frf = st::harmonic_balance(model, {damper}, excitation, hb);

  ClearanceResponse r;
  r.clearance_m = clearance_m;
  r.onset_m = onset_over_clearance(options) * clearance_m;
  r.design_stroke_m = design_stroke_over_clearance(options) * clearance_m;
  r.peak_transmissibility = -1.0;
  // The largest non-unstable root or held state per frequency: what harmonic_balance's
  // peaks use (a slow sweep on the highest stable branch).
  for (const st::FrequencyPoint& point : frf.points) {
    for (const st::HarmonicRoot& root : point.roots) {
      if (root.stability == st::Stability::kUnstable) continue;
      const double magnitude = std::abs(root.outputs[0]);
      if (magnitude > r.peak_transmissibility) {
        r.peak_transmissibility = magnitude;
        r.peak_frequency_hz = point.frequency_hz;
        r.damper_amplitude_m = root.damper_amplitudes_m[0];
        r.held_at_onset = false;
      }
    }
    for (const st::JumpHeldState& held : point.held_at_jump) {
      const double magnitude = std::abs(held.outputs[0]);
      if (magnitude > r.peak_transmissibility) {
        r.peak_transmissibility = magnitude;
        r.peak_frequency_hz = point.frequency_hz;
        r.damper_amplitude_m = held.damper_amplitude_m;
        r.held_at_onset = true;
      }
    }
  }
  if (r.peak_transmissibility < 0.0) {
    throw base::NumericalError("clearance-on-structure: no stable or held response in the frequency band at h = " +
                               base::format_number(clearance_m, 10) + " m");
  }
  return r;
}

ClearanceOnStructureResult size_clearance_on_structure(const st::ModalModel& model,
                                                       const ClearanceOnStructureOptions& options,
                                                       const Options& solver_options) {
  const auto started = std::chrono::steady_clock::now();
  ClearanceOnStructureResult result;
  result.estimate = estimate_clearance_on_structure(model, options);
  const double lower = options.clearance_min_m.value_or(result.estimate.clearance_m / 3.0);
  const double upper = options.clearance_max_m.value_or(result.estimate.clearance_m * 3.0);
  if (!(upper > lower)) {
    throw std::invalid_argument("invalid clearance-on-structure options:\n  clearance range [" +
                                base::format_number(lower, 10) + ", " + base::format_number(upper, 10) +
                                "] m is empty");
  }
  Problem problem;
  problem.variables.push_back(
      {"clearance_m", "m", lower, upper, std::clamp(result.estimate.clearance_m, lower, upper)});
  const auto shared_model = std::make_shared<const st::ModalModel>(model);
  const auto shared_options = std::make_shared<const ClearanceOnStructureOptions>(options);
  if (options.objective == ClearanceObjective::kDesignStrokeAtResonance) {
    problem.objective = {"design_stroke_mismatch",
                         [shared_model, shared_options](std::span<const double> x) {
                           const ClearanceResponse r = clearance_response(*shared_model, *shared_options, x[0]);
                           const double mismatch = r.damper_amplitude_m / r.design_stroke_m - 1.0;
                           return mismatch * mismatch;
                         },
                         nullptr};
  } else {
    problem.objective = {"peak_transmissibility",
                         [shared_model, shared_options](std::span<const double> x) {
                           return clearance_response(*shared_model, *shared_options, x[0]).peak_transmissibility;
                         },
                         nullptr};
  }
  result.summary = solve(problem, solver_options);
  result.clearance_m = result.summary.x.at(0);
  result.response = clearance_response(model, options, result.clearance_m);
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace pdamp::optimizer
