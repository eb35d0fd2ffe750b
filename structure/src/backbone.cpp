// Single-mode averaged backbones: natural frequency and added damping ratio over the
// damper amplitude.
#include "pdamp/structure/backbone.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"

#include "single_mode.hpp"

#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pdamp::structure {

namespace {
using detail::kTwoPi;

using base::format_number;
}  // namespace

std::vector<std::string> BackboneOptions::validate() const {
  std::vector<std::string> problems;
  if (mode < 0) problems.push_back("mode = " + std::to_string(mode) + ": must be >= 0");
  if (damper_amplitudes_m.empty()) problems.push_back("damper_amplitudes_m: must hold at least one amplitude");
  for (std::size_t k = 0; k < damper_amplitudes_m.size(); ++k)
    if (!(damper_amplitudes_m[k] > 0.0 && std::isfinite(damper_amplitudes_m[k])))
      problems.push_back("damper_amplitudes_m[" + std::to_string(k) +
                         "] = " + format_number(damper_amplitudes_m[k], 12) + ": must be > 0 and finite");
  if (!(frequency_tolerance > 0.0 && frequency_tolerance <= 1e-3))
    problems.push_back("frequency_tolerance = " + format_number(frequency_tolerance, 12) + ": must be in (0, 1e-3]");
  if (max_iterations < 1) problems.push_back("max_iterations = " + std::to_string(max_iterations) + ": must be >= 1");
  for (auto& p : coupling.validate()) problems.push_back("coupling." + p);
  return problems;
}

namespace detail {

SingleMode single_mode(const CoupledModel& coupled, int mode, double modal_amplitude, double frequency_tolerance,
                       int max_iterations, double* layer_eta_star) {
  const Eigen::Index j = mode;
  const double omega_j = coupled.angular_frequencies_rad_s[j];
  const double modal_mass = coupled.modal_masses_kg[j];
  const double stiffness = modal_mass * omega_j * omega_j;
  const double container_mass = coupled.mass_with_containers_kg(j, j);  // m_j + Σ m_c |φ_j(d)|²
  const double structural_damping = 2.0 * coupled.damping_ratios[j] * omega_j * modal_mass;
  SingleMode result;
  double omega = omega_j;
  double mass = container_mass, bed_damping = 0.0;  // bed_damping: Σ b² η* m_bed (times Ω gives c)
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const double frequency_hz = omega / kTwoPi;
    mass = container_mass;
    bed_damping = 0.0;
    result.loss_warnings = 0;
    std::size_t slot = 0;
    for (std::size_t d = 0; d < coupled.dampers.size(); ++d) {
      const double b = coupled.drive_shapes(j, static_cast<Eigen::Index>(d));
      const double stroke_m = std::abs(b) * modal_amplitude;
      for (const auto& layer : coupled.dampers[d].layers) {
        double eta = 0.0;
        if (stroke_m > 0.0) {  // a damper at a node of the mode takes no part
          const LayerImpedance z = layer_impedance(layer, frequency_hz, stroke_m, coupled.options);
          mass += b * b * layer.bed_mass_kg * z.apparent_mass_fraction;
          bed_damping += b * b * layer.bed_mass_kg * z.eta_star;
          result.loss_warnings |= z.loss_warnings;
          eta = z.eta_star;
        }
        if (layer_eta_star) layer_eta_star[slot] = eta;
        ++slot;
      }
    }
    if (!(mass > 0.0))
      throw std::invalid_argument("backbone: the effective modal mass of mode " + std::to_string(mode) + " is " +
                                  format_number(mass, 12) + " kg at modal amplitude " +
                                  format_number(modal_amplitude, 12) +
                                  " (negative apparent mass of the beds exceeds the structure's)");
    const double next = std::sqrt(stiffness / mass);
    const bool done = std::abs(next - omega) <= frequency_tolerance * omega;
    omega = next;
    if (done) {
      result.converged = true;
      break;
    }
  }
  result.natural_angular_frequency_rad_s = omega;
  result.added_damping_ratio = bed_damping / (2.0 * mass);
  result.structural_damping_ratio = structural_damping / (2.0 * mass * omega);
  result.effective_modal_mass_kg = mass;
  return result;
}

}  // namespace detail

BackbonePoint backbone_point(const CoupledModel& coupled, int mode, double modal_amplitude,
                             double frequency_tolerance, int max_iterations) {
  std::size_t layers = 0;
  for (const auto& d : coupled.dampers) layers += d.layers.size();
  BackbonePoint point;
  point.layer_eta_star.resize(layers);
  const detail::SingleMode m = detail::single_mode(coupled, mode, modal_amplitude, frequency_tolerance,
                                                   max_iterations, point.layer_eta_star.data());
  point.modal_amplitude = modal_amplitude;
  point.natural_frequency_hz = m.natural_angular_frequency_rad_s / kTwoPi;
  const double zeta = m.added_damping_ratio + m.structural_damping_ratio;
  point.damped_frequency_hz = zeta < 1.0 ? point.natural_frequency_hz * std::sqrt(1.0 - zeta * zeta) : 0.0;
  point.added_damping_ratio = m.added_damping_ratio;
  point.structural_damping_ratio = m.structural_damping_ratio;
  point.effective_modal_mass_kg = m.effective_modal_mass_kg;
  point.loss_warnings = m.loss_warnings;
  point.converged = m.converged;
  for (std::size_t d = 0; d < coupled.dampers.size(); ++d) {
    const double stroke_m = std::abs(coupled.drive_shapes(mode, static_cast<Eigen::Index>(d))) * modal_amplitude;
    for (std::size_t l = 0; l < coupled.dampers[d].layers.size(); ++l) point.layer_damper_amplitude_m.push_back(stroke_m);
  }
  return point;
}

Backbone backbone(const ModalModel& model, const std::vector<Damper>& dampers, const BackboneOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::string> problems = options.validate();
  if (options.mode >= model.mode_count())
    problems.push_back("mode = " + std::to_string(options.mode) + ": must be < " + std::to_string(model.mode_count()));
  if (options.reference_damper >= dampers.size())
    problems.push_back("reference_damper = " + std::to_string(options.reference_damper) + ": must be < " +
                       std::to_string(dampers.size()));
  if (!problems.empty()) {
    std::string message = "backbone: invalid input";
    for (const auto& p : problems) message += "\n  " + p;
    throw std::invalid_argument(message);
  }
  const CoupledModel coupled = couple(model, dampers, options.coupling);
  const Eigen::Index j = options.mode;
  const double b_reference = std::abs(coupled.drive_shapes(j, static_cast<Eigen::Index>(options.reference_damper)));
  if (!(b_reference > 0.0))
    throw std::invalid_argument("backbone: damper " + std::to_string(options.reference_damper) +
                                " does not move along its drive in mode " + std::to_string(options.mode));
  Backbone result;
  result.mode = options.mode;
  double bed_modal_mass = 0.0;
  for (std::size_t d = 0; d < dampers.size(); ++d) {
    const double b = coupled.drive_shapes(j, static_cast<Eigen::Index>(d));
    for (const auto& layer : dampers[d].layers) bed_modal_mass += b * b * layer.bed_mass_kg;
  }
  result.modal_mass_ratio = bed_modal_mass / coupled.modal_masses_kg[j];
  result.points.reserve(options.damper_amplitudes_m.size());
  std::uint32_t warnings = 0;
  bool all_converged = true;
  for (double x : options.damper_amplitudes_m) {
    BackbonePoint point = backbone_point(coupled, options.mode, x / b_reference, options.frequency_tolerance,
                                         options.max_iterations);
    point.damper_amplitude_m = x;
    warnings |= point.loss_warnings;
    all_converged = all_converged && point.converged;
    result.points.push_back(std::move(point));
  }
  result.warnings = surrogate::describe_loss_warnings(warnings);
  if (!all_converged)
    result.warnings.push_back("the frequency fixed point did not converge at some amplitudes (converged = false)");
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

}  // namespace pdamp::structure
