// Dampers attached to a modal model: layer impedances and the coupled modal arrays.
#include "pdamp/structure/damper_coupling.hpp"
#include "pdamp/base/run_errors.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pdamp::structure {

namespace {

using detail::kTwoPi;
/// A drive direction is a unit vector to this relative tolerance (inputs from JSON carry ~1e-9).
constexpr double kUnitTolerance = 1e-6;

using base::format_number;

/// The named point's shapes, or nullptr (ModalModel::point throws; the coupling collects problems).
const PointModeShape* find_point(const ModalModel& model, const std::string& name) {
  for (const auto& p : model.points)
    if (p.name == name) return &p;
  return nullptr;
}

/// The rules of the modal data the coupling relies on (sizes and signs); ModalModel::validate
/// stays the owner of the full rules and the callers (case_file, CLI) run it.
std::vector<std::string> coupling_model_problems(const ModalModel& model) {
  std::vector<std::string> problems;
  const Eigen::Index modes = model.mode_count();
  if (modes == 0) problems.push_back("modal_model.natural_frequencies_hz: must hold at least one mode");
  if (model.damping_ratios.size() != modes)
    problems.push_back("modal_model.damping_ratios: must have one entry per mode (" + std::to_string(modes) + ")");
  if (model.modal_masses_kg.size() != modes)
    problems.push_back("modal_model.modal_masses_kg: must have one entry per mode (" + std::to_string(modes) + ")");
  for (Eigen::Index j = 0; j < modes; ++j) {
    if (!(model.natural_frequencies_hz[j] > 0.0 && std::isfinite(model.natural_frequencies_hz[j])))
      problems.push_back("modal_model.natural_frequencies_hz[" + std::to_string(j) +
                         "] = " + format_number(model.natural_frequencies_hz[j], 12) + ": must be > 0 and finite");
    if (j < model.damping_ratios.size() && !(model.damping_ratios[j] >= 0.0 && std::isfinite(model.damping_ratios[j])))
      problems.push_back("modal_model.damping_ratios[" + std::to_string(j) +
                         "] = " + format_number(model.damping_ratios[j], 12) + ": must be >= 0 and finite");
    if (j < model.modal_masses_kg.size() && !(model.modal_masses_kg[j] > 0.0 && std::isfinite(model.modal_masses_kg[j])))
      problems.push_back("modal_model.modal_masses_kg[" + std::to_string(j) +
                         "] = " + format_number(model.modal_masses_kg[j], 12) + ": must be > 0 and finite");
  }
  for (const auto& p : model.points)
    if (p.translation.rows() != 2 || p.translation.cols() != modes)
      problems.push_back("modal_model.points[\"" + p.name + "\"].translation: must be 2 x " + std::to_string(modes));
  if (model.base_participation.cols() != 0 &&
      (model.base_participation.rows() != modes || model.base_participation.cols() != 2))
    problems.push_back("modal_model.base_participation: must be " + std::to_string(modes) + " x 2 or empty");
  return problems;
}

}  // namespace

std::vector<std::string> Damper::validate(const ModalModel& model) const {
  std::vector<std::string> problems;
  if (!find_point(model, point)) problems.push_back("point = \"" + point + "\": must name a point of the modal model");
  const double norm = drive_direction.norm();
  if (!(std::abs(norm - 1.0) <= kUnitTolerance))
    problems.push_back("drive_direction = (" + format_number(drive_direction.x(), 12) + ", " +
                       format_number(drive_direction.y(), 12) + "): must be a unit vector");
  if (!(container_mass_kg >= 0.0 && std::isfinite(container_mass_kg)))
    problems.push_back("container_mass_kg = " + format_number(container_mass_kg, 12) + ": must be >= 0 and finite");
  if (!(container_rotary_inertia_kg_m2 >= 0.0 && std::isfinite(container_rotary_inertia_kg_m2)))
    problems.push_back("container_rotary_inertia_kg_m2 = " + format_number(container_rotary_inertia_kg_m2, 12) +
                       ": must be >= 0 and finite");
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const std::string prefix = "layers[" + std::to_string(l) + "].";
    if (!(layers[l].bed_mass_kg > 0.0 && std::isfinite(layers[l].bed_mass_kg)))
      problems.push_back(prefix + "bed_mass_kg = " + format_number(layers[l].bed_mass_kg, 12) +
                         ": must be > 0 and finite");
    if (!layers[l].loss_model) problems.push_back(prefix + "loss_model: must be set");
  }
  return problems;
}

double rotation_ratio(const PointModeShape& site, Eigen::Index mode, const Eigen::Vector2d& drive_direction,
                      double length_along_drive_m) {
  const double end_motion = std::abs(site.rotation[mode]) * 0.5 * length_along_drive_m;
  if (!(length_along_drive_m > 0.0) || end_motion == 0.0) return 0.0;
  const double translation = std::abs(site.translation.col(mode).dot(drive_direction));
  return translation > 0.0 ? end_motion / translation : std::numeric_limits<double>::infinity();
}

std::vector<std::string> rotation_warnings(const ModalModel& model, const std::vector<Damper>& dampers,
                                           double fraction) {
  std::vector<std::string> warnings;
  for (const Damper& d : dampers) {
    const PointModeShape* site = find_point(model, d.point);
    if (!site) continue;
    for (Eigen::Index j = 0; j < model.mode_count(); ++j) {
      const double ratio = rotation_ratio(*site, j, d.drive_direction, d.length_along_drive_m);
      if (!(ratio > fraction)) continue;
      std::ostringstream out;
      out.precision(3);
      out << "damper " << d.name << " at '" << d.point << "': in mode " << j + 1 << " (" << model.natural_frequencies_hz[j]
          << " Hz) the site rotates, so the container's ends move by ";
      if (std::isfinite(ratio)) {
        out << 100.0 * ratio << "%";
      } else {
        out << "more than 100%";
      }
      out
          << " of its translation along the drive; the closed forms and the fields assume pure translation";
      warnings.push_back(out.str());
    }
  }
  return warnings;
}

std::vector<std::string> CouplingOptions::validate() const {
  if (std::isfinite(apparent_mass_fraction_if_missing)) return {};
  return {"apparent_mass_fraction_if_missing = " + format_number(apparent_mass_fraction_if_missing, 12) +
          ": must be finite"};
}

LayerImpedance layer_impedance(const DamperLayer& layer, double frequency_hz, double stroke_m,
                               const CouplingOptions& options) {
  const surrogate::DamperResponse response = layer.from_above ? layer.loss_model->evaluate_from_above(frequency_hz, stroke_m)
                                                              : layer.loss_model->evaluate(frequency_hz, stroke_m);
  LayerImpedance impedance;
  impedance.loss_warnings = response.warnings;
  impedance.eta_star = response.eta_star;
  double mass_fraction = response.apparent_mass_fraction;
  double d_mass_fraction = response.d_apparent_mass_fraction_d_stroke_1_m;
  if (!std::isfinite(mass_fraction)) {
    mass_fraction = options.apparent_mass_fraction_if_missing;
    d_mass_fraction = 0.0;
    impedance.loss_warnings |= surrogate::kLossApparentMassMissing;
  }
  impedance.apparent_mass_fraction = mass_fraction;
  const double omega = kTwoPi * frequency_hz;
  // Z = m_bed Ω² (−m_app/m_bed + i η*): the real part is the bed's inertia, the imaginary
  // part iΩ c_eq with c_eq = η* m_bed Ω (docs/structure_coupling.md §1).
  const double scale = layer.bed_mass_kg * omega * omega;
  impedance.dynamic_stiffness_n_m = scale * std::complex<double>(-mass_fraction, response.eta_star);
  impedance.d_dynamic_stiffness_d_stroke =
      scale * std::complex<double>(-d_mass_fraction, response.d_eta_star_d_stroke_1_m);
  return impedance;
}

DamperImpedance damper_impedance(const Damper& damper, double frequency_hz, double stroke_m,
                                 const CouplingOptions& options) {
  DamperImpedance sum{{0.0, 0.0}, {0.0, 0.0}, 0};
  for (const auto& layer : damper.layers) {
    const LayerImpedance z = layer_impedance(layer, frequency_hz, stroke_m, options);
    sum.dynamic_stiffness_n_m += z.dynamic_stiffness_n_m;
    sum.d_dynamic_stiffness_d_stroke += z.d_dynamic_stiffness_d_stroke;
    sum.loss_warnings |= z.loss_warnings;
  }
  return sum;
}

std::vector<double> damper_discontinuities_m(const Damper& damper, double frequency_hz) {
  std::vector<double> strokes;
  for (const auto& layer : damper.layers) {
    const auto jumps = layer.loss_model->discontinuities_stroke_m(frequency_hz);
    strokes.insert(strokes.end(), jumps.begin(), jumps.end());
  }
  std::sort(strokes.begin(), strokes.end());
  strokes.erase(std::unique(strokes.begin(), strokes.end()), strokes.end());
  return strokes;
}

surrogate::StrokeRange damper_stroke_range_m(const Damper& damper, double frequency_hz) {
  surrogate::StrokeRange range{0.0, 0.0};
  for (std::size_t l = 0; l < damper.layers.size(); ++l) {
    const auto r = damper.layers[l].loss_model->stroke_range_m(frequency_hz);
    range.min_m = l == 0 ? r.min_m : std::min(range.min_m, r.min_m);
    range.max_m = l == 0 ? r.max_m : std::max(range.max_m, r.max_m);
  }
  return range;
}

CoupledModel couple(const ModalModel& model, const std::vector<Damper>& dampers, const CouplingOptions& options) {
  std::vector<std::string> problems = coupling_model_problems(model);
  for (auto& p : options.validate()) problems.push_back("coupling." + p);
  for (std::size_t d = 0; d < dampers.size(); ++d)
    for (auto& p : dampers[d].validate(model)) problems.push_back("dampers[" + std::to_string(d) + "]." + p);
  if (!problems.empty()) {
    std::string message = "couple: invalid input";
    for (const auto& p : problems) message += "\n  " + p;
    throw std::invalid_argument(message);
  }
  const Eigen::Index modes = model.mode_count();
  CoupledModel coupled;
  coupled.angular_frequencies_rad_s = kTwoPi * model.natural_frequencies_hz;
  coupled.damping_ratios = model.damping_ratios;
  coupled.modal_masses_kg = model.modal_masses_kg;
  coupled.mass_with_containers_kg = coupled.modal_masses_kg.asDiagonal();
  coupled.drive_shapes.resize(modes, static_cast<Eigen::Index>(dampers.size()));
  coupled.base_participation = model.base_participation;
  coupled.container_participation = Eigen::MatrixXd::Zero(modes, 2);
  for (std::size_t d = 0; d < dampers.size(); ++d) {
    const PointModeShape& site = *find_point(model, dampers[d].point);
    const Eigen::MatrixXd& shape = site.translation;  // 2 x modes
    const double container = dampers[d].container_mass_kg;
    coupled.mass_with_containers_kg += container * shape.transpose() * shape;
    if (dampers[d].container_rotary_inertia_kg_m2 > 0.0)  // kinetic energy ½J θ̇², θ = θ_d q
      coupled.mass_with_containers_kg += dampers[d].container_rotary_inertia_kg_m2 * site.rotation.transpose() * site.rotation;
    coupled.container_participation += container * shape.transpose();
    coupled.drive_shapes.col(static_cast<Eigen::Index>(d)) = shape.transpose() * dampers[d].drive_direction;
  }
  coupled.dampers = dampers;
  coupled.options = options;
  return coupled;
}

Eigen::VectorXd natural_frequencies_with_containers_hz(const CoupledModel& coupled) {
  const Eigen::VectorXd k = coupled.modal_masses_kg.cwiseProduct(coupled.angular_frequencies_rad_s.cwiseAbs2());
  const Eigen::MatrixXd stiffness = k.asDiagonal();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> solver(stiffness, coupled.mass_with_containers_kg,
                                                                         Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) {
    throw base::NumericalError("natural_frequencies_with_containers_hz: the eigenproblem with the containers failed");
  }
  return solver.eigenvalues().cwiseMax(0.0).cwiseSqrt() / kTwoPi;
}

void linear_dynamic_stiffness(const CoupledModel& coupled, double angular_frequency_rad_s, Eigen::MatrixXcd& out) {
  const double omega = angular_frequency_rad_s;
  out = (-omega * omega) * coupled.mass_with_containers_kg.cast<std::complex<double>>();
  for (Eigen::Index j = 0; j < out.rows(); ++j) {
    const double m = coupled.modal_masses_kg[j], w = coupled.angular_frequencies_rad_s[j];
    out(j, j) += m * std::complex<double>(w * w, 2.0 * coupled.damping_ratios[j] * w * omega);
  }
}

}  // namespace pdamp::structure
