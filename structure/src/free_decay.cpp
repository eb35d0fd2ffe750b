// Free decay by slowly varying amplitude: RK4 on the modal envelopes and the energies.
#include "pdamp/structure/free_decay.hpp"
#include "numbers.hpp"
#include "pdamp/base/number_text.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pdamp/structure/backbone.hpp"
#include "single_mode.hpp"

namespace pdamp::structure {

namespace {

using detail::kTwoPi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Settling instant located by bisection of the last step: 2⁻⁶⁰ of one step.
constexpr int kSettlingBisections = 60;
/// Closest approach in ln a to a jump before a step crosses it (~40 graded steps from 0.05).
constexpr double kJumpApproach = 1e-12;

using base::format_number;

const PointModeShape& point_of(const ModalModel& model, const std::string& name) {
  for (const auto& p : model.points)
    if (p.name == name) return p;
  throw std::invalid_argument("free_decay: threshold_point = \"" + name + "\": must name a point of the modal model");
}

/// A mode whose amplitude fell below this fraction of its initial value (ln a down by 20.7)
/// is treated as decayed: it stops limiting the step (the fast higher modes would otherwise
/// set dt for the whole decay) and no longer dissipates.
constexpr double kDecayedFraction = 1e-9;

/// State: y = [ln a_j (modes) | E_layer (layers) | E_structural]. Rates from the single-mode
/// oscillator of backbone.hpp. No allocation per step.
class EnvelopeSystem {
 public:
  EnvelopeSystem(const CoupledModel& coupled, const Eigen::VectorXd& initial) : coupled_(coupled) {
    for (const auto& d : coupled.dampers) layers_ += d.layers.size();
    modes_ = coupled.angular_frequencies_rad_s.size();
    rates_.resize(modes_);
    layer_power_.resize(static_cast<Eigen::Index>(layers_));
    layer_eta_.resize(layers_);
    floor_ = (initial.array() * kDecayedFraction).log().matrix();
    k1_.resize(size());
    k2_.resize(size());
    k3_.resize(size());
    k4_.resize(size());
    stage_.resize(size());
  }
  Eigen::Index size() const { return modes_ + static_cast<Eigen::Index>(layers_) + 1; }

  /// dy/dt; fills rates_ (ζΩ per mode, 1/s) and layer_power_ (W) as a side product.
  void derivative(const Eigen::VectorXd& y, Eigen::VectorXd& dy) {
    layer_power_.setZero();
    double structural_power = 0.0;
    for (Eigen::Index j = 0; j < modes_; ++j) {
      if (!(y[j] > floor_[j])) {  // at rest or decayed
        rates_[j] = 0.0;
        dy[j] = 0.0;
        continue;
      }
      const double a = std::exp(y[j]);
      const detail::SingleMode m = detail::single_mode(coupled_, static_cast<int>(j), a, 1e-12, 100, layer_eta_.data());
      const double omega = m.natural_angular_frequency_rad_s;
      rates_[j] = (m.added_damping_ratio + m.structural_damping_ratio) * omega;
      dy[j] = -rates_[j];
      // Cycle-averaged powers E_cycle/T: layer ½ η* m_bed Ω³ X², structure ½ c_j Ω² a².
      std::size_t l = 0;
      for (std::size_t d = 0; d < coupled_.dampers.size(); ++d) {
        const double x = std::abs(coupled_.drive_shapes(j, static_cast<Eigen::Index>(d))) * a;
        for (const auto& layer : coupled_.dampers[d].layers) {
          layer_power_[static_cast<Eigen::Index>(l)] +=
              0.5 * layer_eta_[l] * layer.bed_mass_kg * omega * omega * omega * x * x;
          ++l;
        }
      }
      const double c = 2.0 * coupled_.damping_ratios[j] * coupled_.angular_frequencies_rad_s[j] *
                       coupled_.modal_masses_kg[j];
      structural_power += 0.5 * c * omega * omega * a * a;
    }
    dy.segment(modes_, static_cast<Eigen::Index>(layers_)) = layer_power_;
    dy[size() - 1] = structural_power;
  }

  void rk4_step(const Eigen::VectorXd& y, double dt, Eigen::VectorXd& out) {
    derivative(y, k1_);
    stage_ = y + 0.5 * dt * k1_;
    derivative(stage_, k2_);
    stage_ = y + 0.5 * dt * k2_;
    derivative(stage_, k3_);
    stage_ = y + dt * k3_;
    derivative(stage_, k4_);
    out = y + dt / 6.0 * (k1_ + 2.0 * k2_ + 2.0 * k3_ + k4_);
  }

  const Eigen::VectorXd& rates() const { return rates_; }
  const Eigen::VectorXd& layer_power() const { return layer_power_; }

 private:
  const CoupledModel& coupled_;
  Eigen::Index modes_ = 0;
  std::size_t layers_ = 0;
  Eigen::VectorXd floor_;  ///< ln of the decayed amplitude per mode
  std::vector<double> layer_eta_;
  Eigen::VectorXd rates_, layer_power_, k1_, k2_, k3_, k4_, stage_;
};

/// A bed released above its onset comes down from collect-and-collide and keeps that history
/// below the onset (docs/theory.md §3.4); one released below it starts as from rest. The
/// release stroke is the damper's envelope bound Σ_j |b_dj| a_j(0); the onset is taken at the
/// natural frequency of the mode that moves the damper most.
void mark_beds_from_above(CoupledModel& coupled, const ModalModel& model, const Eigen::VectorXd& initial) {
  for (std::size_t d = 0; d < coupled.dampers.size(); ++d) {
    const Eigen::VectorXd share = coupled.drive_shapes.col(static_cast<Eigen::Index>(d)).cwiseAbs().cwiseProduct(initial);
    Eigen::Index largest = 0;
    share.maxCoeff(&largest);
    const double release_m = share.sum();
    const double frequency_hz = model.natural_frequencies_hz[largest];
    for (auto& layer : coupled.dampers[d].layers) {
      const auto jumps = layer.loss_model->discontinuities_stroke_m(frequency_hz);
      layer.from_above = !jumps.empty() && release_m >= jumps.front();
    }
  }
}

}  // namespace

std::vector<std::string> FreeDecayOptions::validate(Eigen::Index modes) const {
  std::vector<std::string> problems;
  if (initial_modal_amplitudes.size() != modes)
    problems.push_back("initial_modal_amplitudes: must have one entry per mode (" + std::to_string(modes) + ")");
  else if (!(initial_modal_amplitudes.array() >= 0.0).all() || !initial_modal_amplitudes.allFinite() ||
           !(initial_modal_amplitudes.maxCoeff() > 0.0))
    problems.push_back("initial_modal_amplitudes: must be >= 0 and finite, not all 0");
  if (!(duration_s > 0.0 && std::isfinite(duration_s)))
    problems.push_back("duration_s = " + format_number(duration_s, 12) + ": must be > 0 and finite");
  for (std::size_t k = 0; k < sample_times_s.size(); ++k)
    if (!(sample_times_s[k] >= 0.0 && sample_times_s[k] <= duration_s) ||
        (k > 0 && !(sample_times_s[k] >= sample_times_s[k - 1])))
      problems.push_back("sample_times_s[" + std::to_string(k) + "] = " + format_number(sample_times_s[k], 12) +
                         ": must be ascending in [0, duration_s]");
  if (!(std::abs(threshold_direction.norm() - 1.0) <= 1e-6))
    problems.push_back("threshold_direction: must be a unit vector");
  if (!(threshold_m >= 0.0 && std::isfinite(threshold_m)))
    problems.push_back("threshold_m = " + format_number(threshold_m, 12) + ": must be >= 0 and finite");
  if (!(threshold_fraction > 0.0 && threshold_fraction < 1.0))
    problems.push_back("threshold_fraction = " + format_number(threshold_fraction, 12) + ": must be in (0, 1)");
  if (!(step_log_change > 0.0 && step_log_change <= 0.2))
    problems.push_back("step_log_change = " + format_number(step_log_change, 12) + ": must be in (0, 0.2]");
  if (!(max_step_s >= 0.0 && std::isfinite(max_step_s)))
    problems.push_back("max_step_s = " + format_number(max_step_s, 12) + ": must be >= 0 and finite");
  if (!(second_mode_warning_fraction > 0.0 && second_mode_warning_fraction < 1.0))
    problems.push_back("second_mode_warning_fraction = " + format_number(second_mode_warning_fraction, 12) +
                       ": must be in (0, 1)");
  for (auto& p : coupling.validate()) problems.push_back("coupling." + p);
  return problems;
}

std::string FreeDecay::brief_report() const {
  std::ostringstream out;
  out << "free decay: " << (outcome == Outcome::kSettled ? "settled" : "not settled");
  if (outcome == Outcome::kSettled)
    out << " at t = " << settling_time_s << " s (threshold " << threshold_used_m << " m), zeta_eq = "
        << equivalent_damping_ratio;
  out << ", " << steps << " RK4 steps, " << solve_time_s << " s";
  return out.str();
}

FreeDecay free_decay(const ModalModel& model, const std::vector<Damper>& dampers, const FreeDecayOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  std::vector<std::string> problems = options.validate(model.mode_count());
  if (options.threshold_point.empty() && dampers.empty())
    problems.push_back("threshold_point: must be set when there is no damper");
  if (!problems.empty()) {
    std::string message = "free_decay: invalid input";
    for (const auto& p : problems) message += "\n  " + p;
    throw std::invalid_argument(message);
  }
  CoupledModel coupled = couple(model, dampers, options.coupling);
  const Eigen::Index modes = model.mode_count();
  mark_beds_from_above(coupled, model, options.initial_modal_amplitudes);
  // Weights of the settling measure: |e·φ_j(p)|.
  Eigen::VectorXd weights(modes);
  if (options.threshold_point.empty()) {
    weights = coupled.drive_shapes.col(0).cwiseAbs();
  } else {
    weights = (options.threshold_direction.transpose() * point_of(model, options.threshold_point).translation)
                  .transpose()
                  .cwiseAbs();
  }
  FreeDecay result;
  for (const auto& d : dampers)
    for (const auto& l : d.layers) result.layer_names.push_back(d.name + "/" + l.name);
  const Eigen::VectorXd& a0 = options.initial_modal_amplitudes;
  const double measure0 = weights.dot(a0);
  if (!(measure0 > 0.0))
    throw std::invalid_argument("free_decay: the settling measure is 0 at t = 0 (no mode moves the threshold point)");
  result.threshold_used_m = options.threshold_m > 0.0 ? options.threshold_m : options.threshold_fraction * measure0;
  Eigen::Index dominant = 0;
  (weights.cwiseProduct(a0)).maxCoeff(&dominant);
  result.dominant_mode = static_cast<int>(dominant);

  EnvelopeSystem envelopes(coupled, a0);
  const Eigen::Index layers = static_cast<Eigen::Index>(result.layer_names.size());
  Eigen::VectorXd y = Eigen::VectorXd::Zero(envelopes.size()), next(envelopes.size()), dy(envelopes.size());
  for (Eigen::Index j = 0; j < modes; ++j) y[j] = std::log(a0[j]);  // −inf for a mode at rest: stays at rest
  const double max_step = options.max_step_s > 0.0 ? options.max_step_s : options.duration_s / 20.0;

  auto amplitudes = [&](const Eigen::VectorXd& state) { return Eigen::VectorXd(state.head(modes).array().exp()); };
  auto measure = [&](const Eigen::VectorXd& state) { return weights.dot(amplitudes(state)); };
  bool warned_second_mode = false;
  auto record = [&](double t, const Eigen::VectorXd& state) {
    DecaySample s;
    s.time_s = t;
    s.modal_amplitudes = amplitudes(state);
    s.threshold_measure_m = weights.dot(s.modal_amplitudes);
    for (Eigen::Index d = 0; d < coupled.drive_shapes.cols(); ++d)
      s.damper_amplitudes_m.push_back(coupled.drive_shapes.col(d).cwiseAbs().dot(s.modal_amplitudes));
    for (Eigen::Index j = 0; j < modes; ++j)
      s.mechanical_energy_j += 0.5 * coupled.modal_masses_kg[j] * coupled.angular_frequencies_rad_s[j] *
                               coupled.angular_frequencies_rad_s[j] * s.modal_amplitudes[j] * s.modal_amplitudes[j];
    s.layer_dissipated_energy_j.assign(state.data() + modes, state.data() + modes + layers);
    s.structural_dissipated_energy_j = state[envelopes.size() - 1];
    envelopes.derivative(state, dy);
    s.layer_power_w.assign(envelopes.layer_power().data(), envelopes.layer_power().data() + layers);
    result.samples.push_back(std::move(s));
  };
  auto check_second_mode = [&](double t, const Eigen::VectorXd& a) {
    if (warned_second_mode || modes < 2) return;
    for (Eigen::Index d = 0; d < coupled.drive_shapes.cols(); ++d) {
      const Eigen::VectorXd share = coupled.drive_shapes.col(d).cwiseAbs().cwiseProduct(a);
      Eigen::Index largest = 0;
      const double total = share.sum(), top = share.maxCoeff(&largest);
      const double second = total - top;
      if (total > 0.0 && second > options.second_mode_warning_fraction * total) {
        result.warnings.push_back("at t = " + format_number(t, 12) + " s modes other than mode " +
                                  std::to_string(largest) + " carry " + format_number(100.0 * second / total, 12) +
                                  "% of damper " + dampers[static_cast<std::size_t>(d)].name +
                                  "'s amplitude: single-mode averaging misjudges eta* there");
        warned_second_mode = true;
        return;
      }
    }
  };

  // ln a_j at which some layer's damper amplitude |b_dj| a_j meets a jump of its loss model
  // (taken at the mode's natural frequency without beds: the closed forms' onsets do not
  // depend on f for a fixed block, auto's only through Γ).
  std::vector<std::vector<double>> jump_log_amplitudes(static_cast<std::size_t>(modes));
  for (Eigen::Index j = 0; j < modes; ++j)
    for (std::size_t d = 0; d < dampers.size(); ++d) {
      const double b = std::abs(coupled.drive_shapes(j, static_cast<Eigen::Index>(d)));
      if (!(b > 0.0)) continue;
      for (double jump : damper_discontinuities_m(dampers[d], model.natural_frequencies_hz[j]))
        jump_log_amplitudes[static_cast<std::size_t>(j)].push_back(std::log(jump / b));
    }

  std::size_t next_sample = 0;
  double t = 0.0;
  bool settled = measure(y) < result.threshold_used_m;
  result.settling_time_s = settled ? 0.0 : kNaN;
  while (next_sample < options.sample_times_s.size() && options.sample_times_s[next_sample] <= 0.0) record(0.0, y), ++next_sample;
  check_second_mode(0.0, amplitudes(y));
  while (t < options.duration_s) {
    envelopes.derivative(y, dy);
    const double fastest = envelopes.rates().maxCoeff();
    double dt = fastest > 0.0 ? std::min(max_step, options.step_log_change / fastest) : max_step;
    // Approaching a jump the steps shrink geometrically (at most half the remaining distance
    // in ln a): the orbit's η* has a square-root singularity at the onset (a saddle-node,
    // docs/collect_and_collide.md §3), which would cut RK4 to first order on a uniform step.
    for (Eigen::Index j = 0; j < modes; ++j) {
      if (!(envelopes.rates()[j] > 0.0)) continue;
      for (double jump : jump_log_amplitudes[static_cast<std::size_t>(j)])
        if (y[j] > jump) dt = std::min(dt, std::max(0.5 * (y[j] - jump), 2.0 * kJumpApproach) / envelopes.rates()[j]);
    }
    double target = options.duration_s;
    if (next_sample < options.sample_times_s.size()) target = std::min(target, options.sample_times_s[next_sample]);
    bool lands = t + dt >= target;
    if (lands) dt = target - t;
    envelopes.rk4_step(y, dt, next);
    // A loss-model jump inside the step: shorten the step to end just past the first one, so
    // no RK4 stage averages the two sides (the step after it starts on the lower side).
    double first_crossing = dt;
    for (Eigen::Index j = 0; j < modes; ++j)
      for (double jump : jump_log_amplitudes[static_cast<std::size_t>(j)]) {
        // Land kJumpApproach below the jump in ln a: the next step's first stage must see
        // the lower side (a model classifies X = X_jump itself as the upper state).
        const double below = jump - kJumpApproach;
        if (!(y[j] > below && next[j] <= below)) continue;
        double lo = 0.0, hi = dt;
        Eigen::VectorXd trial(envelopes.size());
        for (int k = 0; k < kSettlingBisections; ++k) {
          const double mid = 0.5 * (lo + hi);
          envelopes.rk4_step(y, mid, trial);
          (trial[j] <= below ? hi : lo) = mid;
        }
        first_crossing = std::min(first_crossing, hi);
      }
    if (first_crossing < dt) {
      dt = first_crossing;
      lands = false;
      envelopes.rk4_step(y, dt, next);
    }
    ++result.steps;
    if (!settled && measure(next) < result.threshold_used_m) {
      // Bisect the step for the crossing (the measure decreases monotonically).
      double lo = 0.0, hi = dt;
      Eigen::VectorXd trial(envelopes.size());
      for (int k = 0; k < kSettlingBisections; ++k) {
        const double mid = 0.5 * (lo + hi);
        envelopes.rk4_step(y, mid, trial);
        (measure(trial) < result.threshold_used_m ? hi : lo) = mid;
      }
      result.settling_time_s = t + hi;
      settled = true;
    }
    y = next;
    t = lands ? target : t + dt;
    check_second_mode(t, amplitudes(y));
    while (next_sample < options.sample_times_s.size() && options.sample_times_s[next_sample] <= t) {
      record(options.sample_times_s[next_sample], y);
      ++next_sample;
    }
  }
  result.outcome = settled ? FreeDecay::Outcome::kSettled : FreeDecay::Outcome::kNotSettled;
  if (settled && result.settling_time_s > 0.0) {
    const BackbonePoint p = backbone_point(coupled, result.dominant_mode, a0[dominant]);  // f_d at the start
    result.equivalent_damping_ratio =
        equivalent_damping_ratio(measure0, result.threshold_used_m, p.damped_frequency_hz, result.settling_time_s);
  } else {
    result.equivalent_damping_ratio = kNaN;
  }
  result.solve_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

double equivalent_damping_ratio(double initial, double threshold, double frequency_hz, double settling_time_s) {
  const double decrement = std::log(initial / threshold) / (frequency_hz * settling_time_s);
  return decrement / std::sqrt(kTwoPi * kTwoPi + decrement * decrement);
}

std::vector<double> uniform_sample_times(double duration_s, int count) {
  std::vector<double> t(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) t[static_cast<std::size_t>(i)] = static_cast<double>(i) / (count - 1) * duration_s;
  t.back() = duration_s;
  return t;
}

}  // namespace pdamp::structure
