// Coefficient-of-restitution models, impact CSV, NLopt fits and the Hertz damping calibration.
#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/base/run_errors.hpp"
#include "pdamp/base/checks.hpp"
#include "pdamp/base/csv_text.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/one_dimensional.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string_view>

namespace pdamp::formulas {
namespace {

using std::numbers::pi;

using base::format_number;
using base::printable;
using base::read_input_file;
using base::require_non_negative;
using base::require_positive;
using base::split_csv_line;
using base::trim_blanks;

// "[i]" (written with a stream: GCC 12 gives a false -Wrestrict on "[" + to_string(i)).
std::string bracketed(std::size_t index) {
  std::ostringstream out;
  out << '[' << index << ']';
  return out.str();
}

void require_restitution(const std::string& name, double value) {
  base::require(value > 0.0 && value <= 1.0, name, value, "in (0, 1]");
}

// ---------------------------------------------------------------------------
// Monotone piecewise-cubic Hermite interpolation (Fritsch & Carlson 1980,
// SIAM J. Numer. Anal. 17:238): three-point slopes, zeroed at local extrema,
// then limited to the circle α² + β² <= 9 that guarantees a monotone cubic.
class MonotoneCubic {
 public:
  // x strictly increasing, size >= 2, same size as y (checked by the callers).
  MonotoneCubic(std::vector<double> x, std::vector<double> y)
      : x_(std::move(x)), y_(std::move(y)), slope_(x_.size()) {
    const std::size_t n = x_.size();
    std::vector<double> width(n - 1);
    std::vector<double> secant(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) {
      width[k] = x_[k + 1] - x_[k];
      secant[k] = (y_[k + 1] - y_[k]) / width[k];
    }
    if (n == 2) {
      slope_[0] = slope_[1] = secant[0];
      return;
    }
    // Interior: the second-order three-point derivative (exact for linear and
    // quadratic data), zero where the data turn.
    for (std::size_t k = 1; k + 1 < n; ++k) {
      slope_[k] =
          secant[k - 1] * secant[k] <= 0.0
              ? 0.0
              : (width[k] * secant[k - 1] + width[k - 1] * secant[k]) / (width[k - 1] + width[k]);
    }
    slope_[0] = end_slope(width[0], width[1], secant[0], secant[1]);
    slope_[n - 1] = end_slope(width[n - 2], width[n - 3], secant[n - 2], secant[n - 3]);
    for (std::size_t k = 0; k + 1 < n; ++k) {
      if (secant[k] == 0.0) {
        slope_[k] = slope_[k + 1] = 0.0;
        continue;
      }
      const double alpha = slope_[k] / secant[k];
      const double beta = slope_[k + 1] / secant[k];
      const double radius_sq = alpha * alpha + beta * beta;
      if (radius_sq > 9.0) {
        const double tau = 3.0 / std::sqrt(radius_sq);
        slope_[k] = tau * alpha * secant[k];
        slope_[k + 1] = tau * beta * secant[k];
      }
    }
  }

  // Clamped to the end values outside [x_0, x_{n-1}].
  double operator()(double x) const {
    if (x <= x_.front()) return y_.front();
    if (x >= x_.back()) return y_.back();
    const std::size_t k =
        static_cast<std::size_t>(std::upper_bound(x_.begin(), x_.end(), x) - x_.begin()) - 1;
    const double h = x_[k + 1] - x_[k];
    const double t = (x - x_[k]) / h;
    const double s = 1.0 - t;
    const double value = y_[k] + (y_[k + 1] - y_[k]) * t * t * (3.0 - 2.0 * t) +
                         h * t * s * (slope_[k] * s - slope_[k + 1] * t);
    // The cubic lies between the node values in exact arithmetic; the clamp removes
    // rounding, so that e.g. a flat run at ε = 1 never returns 1 + 1 ulp.
    return std::clamp(value, std::min(y_[k], y_[k + 1]), std::max(y_[k], y_[k + 1]));
  }

  double first_x() const { return x_.front(); }
  double last_x() const { return x_.back(); }
  std::size_t size() const { return x_.size(); }

 private:
  // Non-centred three-point end derivative, kept to the sign of the end secant
  // and to at most 3× it when the data turn (as in Fritsch-Carlson/PCHIP).
  static double end_slope(double h0, double h1, double d0, double d1) {
    const double slope = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (slope * d0 <= 0.0) return 0.0;
    if (d0 * d1 <= 0.0 && std::abs(slope) > 3.0 * std::abs(d0)) return 3.0 * d0;
    return slope;
  }

  std::vector<double> x_;
  std::vector<double> y_;
  std::vector<double> slope_;
};

// ---------------------------------------------------------------------------
// The laws.

class ConstantRestitution final : public RestitutionModel {
 public:
  explicit ConstantRestitution(double restitution) : restitution_(restitution) {}
  double restitution(double impact_speed_m_s) const override {
    require_non_negative("impact_speed_m_s", impact_speed_m_s);
    return restitution_;
  }
  std::string describe() const override { return "constant " + format_number(restitution_, 9); }

 private:
  double restitution_;
};

class LinearRestitution final : public RestitutionModel {
 public:
  LinearRestitution(double intercept, double slope_s_per_m)
      : intercept_(intercept), slope_s_per_m_(slope_s_per_m) {}
  double restitution(double impact_speed_m_s) const override {
    require_non_negative("impact_speed_m_s", impact_speed_m_s);
    return std::clamp(intercept_ - slope_s_per_m_ * impact_speed_m_s, kMinLinearRestitution, 1.0);
  }
  std::string describe() const override {
    return "linear " + format_number(intercept_, 9) + " - " + format_number(slope_s_per_m_, 9) +
           " s/m * v, clamped to [" + format_number(kMinLinearRestitution, 9) + ", 1]";
  }

 private:
  double intercept_;
  double slope_s_per_m_;
};

class TabulatedRestitution final : public RestitutionModel {
 public:
  TabulatedRestitution(std::vector<double> speeds_m_s, std::vector<double> values)
      : curve_(std::move(speeds_m_s), std::move(values)) {}
  double restitution(double impact_speed_m_s) const override {
    require_non_negative("impact_speed_m_s", impact_speed_m_s);
    return curve_(impact_speed_m_s);
  }
  std::string describe() const override {
    return "tabulated (monotone cubic), " + std::to_string(curve_.size()) + " points over v in [" +
           format_number(curve_.first_x(), 9) + ", " + format_number(curve_.last_x(), 9) + "] m/s";
  }

 private:
  MonotoneCubic curve_;
};

// Thornton (1997) ε as a function of r = v_y/v in (0, 1].
double thornton_restitution_ratio(double r) {
  const double r2 = r * r;
  const double root = std::sqrt(1.2 - 0.2 * r2);
  // √(6√3/5): makes ε = 1 at r = 1, since √(1 − 1/6)·(1/3)^{1/4} = √(5/6)·3^{−1/4}.
  const double prefactor = std::sqrt(6.0 * std::numbers::sqrt3 / 5.0);
  return prefactor * std::sqrt(1.0 - r2 / 6.0) * std::sqrt(std::sqrt(r / (r + 2.0 * root)));
}

// d ln ε / d ln r of Thornton's law, for the fit's analytic gradient.
double thornton_log_slope(double r) {
  const double r2 = r * r;
  const double root = std::sqrt(1.2 - 0.2 * r2);
  const double root_derivative = -0.2 * r / root;
  return -(r2 / 6.0) / (1.0 - r2 / 6.0) +
         0.25 * (1.0 - r * (1.0 + 2.0 * root_derivative) / (r + 2.0 * root));
}

class ThorntonRestitution final : public RestitutionModel {
 public:
  ThorntonRestitution(double limiting_pressure_pa, double yield_speed_m_s)
      : limiting_pressure_pa_(limiting_pressure_pa), yield_speed_m_s_(yield_speed_m_s) {}
  double restitution(double impact_speed_m_s) const override {
    require_non_negative("impact_speed_m_s", impact_speed_m_s);
    if (impact_speed_m_s <= yield_speed_m_s_) return 1.0;
    return thornton_restitution_ratio(yield_speed_m_s_ / impact_speed_m_s);
  }
  std::string describe() const override {
    return "Thornton (1997) elastic-perfectly-plastic, p_y = " + format_number(limiting_pressure_pa_, 9) +
           " Pa, v_y = " + format_number(yield_speed_m_s_, 9) + " m/s";
  }

 private:
  double limiting_pressure_pa_;
  double yield_speed_m_s_;
};

// ln v_y = ln C + (5/2) ln p_y with C from yield_speed(); written in logs so that
// the fit's wide p_y range cannot overflow.
double log_yield_speed_constant(double effective_modulus_pa, double effective_radius_m,
                                double effective_mass_kg) {
  return 0.5 * (5.0 * std::log(pi) + 3.0 * std::log(effective_radius_m) - std::log(30.0) -
                4.0 * std::log(effective_modulus_pa) - std::log(effective_mass_kg));
}

// ---------------------------------------------------------------------------
// Impact CSV.

// ---------------------------------------------------------------------------
// NLopt plumbing: exceptions never cross NLopt's C boundary. The callback stores
// the exception and asks NLopt to stop; it is re-thrown after optimize().

struct NloptCallback {
  std::function<double(const std::vector<double>&, std::vector<double>&)> function;
  std::exception_ptr error;
};

double nlopt_trampoline(const std::vector<double>& x, std::vector<double>& gradient, void* data) {
  auto* callback = static_cast<NloptCallback*>(data);
  try {
    return callback->function(x, gradient);
  } catch (...) {
    callback->error = std::current_exception();
    throw nlopt::forced_stop();  // the C++ wrapper turns this into nlopt_force_stop
  }
}

// Runs the optimiser; x holds the best point found on return.
void run_optimizer(nlopt::opt& optimizer, std::vector<double>& x,
                   std::initializer_list<const NloptCallback*> callbacks) {
  double best = 0.0;
  auto rethrow_callback_error = [&] {
    for (const NloptCallback* callback : callbacks) {
      if (callback->error) std::rethrow_exception(callback->error);
    }
  };
  try {
    optimizer.optimize(x, best);
  } catch (const nlopt::roundoff_limited&) {
    // Converged as far as floating point allows: x is the best point, keep it.
  } catch (const nlopt::forced_stop&) {
    rethrow_callback_error();
    throw base::NumericalError("restitution fit: NLopt stopped without a reason");
  } catch (const std::exception& error) {
    rethrow_callback_error();
    throw base::NumericalError(std::string("restitution fit: NLopt failed: ") + error.what());
  }
}

void validate_impact_data(const ImpactData& data) {
  if (data.speed_m_s.size() != data.restitution.size()) {
    throw std::invalid_argument("impact data: speed_m_s has " +
                                std::to_string(data.speed_m_s.size()) + " values, restitution " +
                                std::to_string(data.restitution.size()) + ": must be equal");
  }
  if (data.speed_m_s.empty()) throw std::invalid_argument("impact data: no points: need >= 1");
  for (std::size_t i = 0; i < data.speed_m_s.size(); ++i) {
    const double speed = data.speed_m_s[i];
    require_non_negative("impact data: speed_m_s[" + std::to_string(i) + "]", speed);
    require_restitution("impact data: restitution[" + std::to_string(i) + "]", data.restitution[i]);
  }
}

double root_mean_square_residual(const ImpactData& data, const RestitutionModel& model) {
  double sum = 0.0;
  for (std::size_t i = 0; i < data.speed_m_s.size(); ++i) {
    const double residual = model.restitution(data.speed_m_s[i]) - data.restitution[i];
    sum += residual * residual;
  }
  return std::sqrt(sum / static_cast<double>(data.speed_m_s.size()));
}

// Stopping rules shared by the fits: the problems are tiny and smooth, so ask
// for full convergence; maxeval only guards against a pathological data set.
void set_fit_tolerances(nlopt::opt& optimizer) {
  optimizer.set_xtol_rel(1e-12);
  optimizer.set_ftol_abs(1e-18);
  optimizer.set_maxeval(2000);
}

std::vector<double> fit_constant(const ImpactData& data) {
  const double n = static_cast<double>(data.speed_m_s.size());
  NloptCallback objective{[&](const std::vector<double>& x, std::vector<double>& gradient) {
                            double sum = 0.0;
                            double sum_residual = 0.0;
                            for (double value : data.restitution) {
                              const double residual = x[0] - value;
                              sum += residual * residual;
                              sum_residual += residual;
                            }
                            if (!gradient.empty()) gradient[0] = 2.0 * sum_residual / n;
                            return sum / n;
                          },
                          nullptr};
  nlopt::opt optimizer(nlopt::LD_SLSQP, 1);
  optimizer.set_lower_bounds({kMinLinearRestitution});
  optimizer.set_upper_bounds({1.0});
  optimizer.set_min_objective(nlopt_trampoline, &objective);
  set_fit_tolerances(optimizer);
  std::vector<double> x{0.5};
  run_optimizer(optimizer, x, {&objective});
  return x;
}

std::vector<double> fit_linear(const ImpactData& data) {
  const double n = static_cast<double>(data.speed_m_s.size());
  const auto [min_speed, max_speed] =
      std::minmax_element(data.speed_m_s.begin(), data.speed_m_s.end());
  if (!(*max_speed > *min_speed)) {
    throw std::invalid_argument("impact data: all " + std::to_string(data.speed_m_s.size()) + " speeds equal " +
                                format_number(*min_speed, 9) + " m/s: the linear law needs >= 2 distinct speeds");
  }
  const double top_speed = *max_speed;
  NloptCallback objective{[&](const std::vector<double>& x, std::vector<double>& gradient) {
                            double sum = 0.0;
                            double sum_residual = 0.0;
                            double sum_residual_speed = 0.0;
                            for (std::size_t i = 0; i < data.speed_m_s.size(); ++i) {
                              const double residual =
                                  x[0] - x[1] * data.speed_m_s[i] - data.restitution[i];
                              sum += residual * residual;
                              sum_residual += residual;
                              sum_residual_speed += residual * data.speed_m_s[i];
                            }
                            if (!gradient.empty()) {
                              gradient[0] = 2.0 * sum_residual / n;
                              gradient[1] = -2.0 * sum_residual_speed / n;
                            }
                            return sum / n;
                          },
                          nullptr};
  // The line is monotone, so it stays in [floor, 1] on [0, v_max] if it does at
  // both ends: ε₀ is bounded, the end at v_max is constrained.
  NloptCallback above_floor{[&](const std::vector<double>& x, std::vector<double>& gradient) {
                              if (!gradient.empty()) gradient = {-1.0, top_speed};
                              return kMinLinearRestitution - (x[0] - x[1] * top_speed);
                            },
                            nullptr};
  NloptCallback below_one{[&](const std::vector<double>& x, std::vector<double>& gradient) {
                            if (!gradient.empty()) gradient = {1.0, -top_speed};
                            return x[0] - x[1] * top_speed - 1.0;
                          },
                          nullptr};
  nlopt::opt optimizer(nlopt::LD_SLSQP, 2);
  optimizer.set_lower_bounds({kMinLinearRestitution, -HUGE_VAL});
  optimizer.set_upper_bounds({1.0, HUGE_VAL});
  optimizer.set_min_objective(nlopt_trampoline, &objective);
  optimizer.add_inequality_constraint(nlopt_trampoline, &above_floor, 1e-14);
  optimizer.add_inequality_constraint(nlopt_trampoline, &below_one, 1e-14);
  set_fit_tolerances(optimizer);
  std::vector<double> x{0.5, 0.0};  // feasible start: a flat line
  run_optimizer(optimizer, x, {&objective, &above_floor, &below_one});
  return x;
}

std::vector<double> fit_thornton(const ImpactData& data, double effective_modulus_pa,
                                 double effective_radius_m, double effective_mass_kg) {
  require_positive("effective_modulus_pa", effective_modulus_pa);
  require_positive("effective_radius_m", effective_radius_m);
  require_positive("effective_mass_kg", effective_mass_kg);
  double min_positive_speed = HUGE_VAL;
  double max_speed = 0.0;
  for (double speed : data.speed_m_s) {
    if (speed > 0.0) min_positive_speed = std::min(min_positive_speed, speed);
    max_speed = std::max(max_speed, speed);
  }
  if (max_speed == 0.0) {
    throw std::invalid_argument(
        "impact data: all speeds are 0: Thornton's law needs a positive speed");
  }
  const double n = static_cast<double>(data.speed_m_s.size());
  const double log_constant =
      log_yield_speed_constant(effective_modulus_pa, effective_radius_m, effective_mass_kg);
  // The unknown is ln p_y (p_y spans decades; ε depends on it through
  // v_y ∝ p_y^{5/2}). Above v_y = v_max every point is elastic and the objective
  // is flat; below v_y = 1e-6·v_min the law is far outside any metal's range.
  const double lower = (std::log(1e-6 * min_positive_speed) - log_constant) / 2.5;
  const double upper = (std::log(max_speed) - log_constant) / 2.5;
  NloptCallback objective{[&](const std::vector<double>& x, std::vector<double>& gradient) {
                            const double yield_speed_m_s = std::exp(log_constant + 2.5 * x[0]);
                            double sum = 0.0;
                            double derivative = 0.0;
                            for (std::size_t i = 0; i < data.speed_m_s.size(); ++i) {
                              const double speed = data.speed_m_s[i];
                              double model = 1.0;
                              double model_derivative = 0.0;  // dε/d ln p_y
                              if (speed > yield_speed_m_s) {
                                const double r = yield_speed_m_s / speed;
                                model = thornton_restitution_ratio(r);
                                model_derivative = 2.5 * model * thornton_log_slope(r);
                              }
                              const double residual = model - data.restitution[i];
                              sum += residual * residual;
                              derivative += 2.0 * residual * model_derivative;
                            }
                            if (!gradient.empty()) gradient[0] = derivative / n;
                            return sum / n;
                          },
                          nullptr};
  // ε(p_y) is not convex over decades of p_y and is flat above v_y = v_max: a
  // coarse scan picks the basin, SLSQP polishes it.
  constexpr int kScanPoints = 97;
  std::vector<double> x{upper};
  std::vector<double> unused_gradient;
  double best = HUGE_VAL;
  for (int i = 0; i < kScanPoints; ++i) {
    const double candidate = lower + (upper - lower) * i / (kScanPoints - 1);
    const double value = objective.function({candidate}, unused_gradient);
    if (value < best) {
      best = value;
      x[0] = candidate;
    }
  }
  nlopt::opt optimizer(nlopt::LD_SLSQP, 1);
  optimizer.set_lower_bounds({lower});
  optimizer.set_upper_bounds({upper});
  optimizer.set_min_objective(nlopt_trampoline, &objective);
  set_fit_tolerances(optimizer);
  run_optimizer(optimizer, x, {&objective});
  return {std::exp(x[0])};
}

// ---------------------------------------------------------------------------
// The dimensionless damped Hertz impact x'' = −x^{3/2} − γ x^{1/4} x'.

struct ImpactState {
  double x = 0.0;  // overlap δ/δ₀
  double v = 0.0;  // overlap rate, in units of the impact speed
};

// x^{3/2} and x^{1/4} are extended oddly/evenly to x < 0 (x·|x|^{1/2}, |x|^{1/4}):
// only trial stages of the step that crosses the end of contact can see x < 0.
double impact_acceleration(double x, double v, double damping) {
  const double quarter = std::sqrt(std::sqrt(std::abs(x)));
  return -x * quarter * quarter - damping * quarter * v;
}

// Total force over x^{1/4}: x^{5/4} + γ x'. It is > 0 during the contact, and its
// first zero with x' < 0 is the end of a contact without tension.
double end_of_contact_function(const ImpactState& state, double damping) {
  return state.x * std::sqrt(std::sqrt(std::abs(state.x))) + damping * state.v;
}

struct DopriStep {
  ImpactState state;
  double end_acceleration = 0.0;  // FSAL: the first stage of the next step
  double error_x = 0.0;
  double error_v = 0.0;
};

// One Dormand–Prince 5(4) step (Dormand & Prince 1980; Hairer, Nørsett & Wanner,
// Solving ODEs I, Table II.5.2); the state is advanced with the 5th-order weights.
DopriStep dopri_step(const ImpactState& y, double acceleration, double h, double damping) {
  constexpr double a21 = 1.0 / 5.0;
  constexpr double a31 = 3.0 / 40.0, a32 = 9.0 / 40.0;
  constexpr double a41 = 44.0 / 45.0, a42 = -56.0 / 15.0, a43 = 32.0 / 9.0;
  constexpr double a51 = 19372.0 / 6561.0, a52 = -25360.0 / 2187.0, a53 = 64448.0 / 6561.0,
                   a54 = -212.0 / 729.0;
  constexpr double a61 = 9017.0 / 3168.0, a62 = -355.0 / 33.0, a63 = 46732.0 / 5247.0,
                   a64 = 49.0 / 176.0, a65 = -5103.0 / 18656.0;
  constexpr double b1 = 35.0 / 384.0, b3 = 500.0 / 1113.0, b4 = 125.0 / 192.0,
                   b5 = -2187.0 / 6784.0, b6 = 11.0 / 84.0;
  constexpr double e1 = 71.0 / 57600.0, e3 = -71.0 / 16695.0, e4 = 71.0 / 1920.0,
                   e5 = -17253.0 / 339200.0, e6 = 22.0 / 525.0, e7 = -1.0 / 40.0;
  // Stage i: position derivative = velocity vi, velocity derivative = acceleration ai.
  const double v1 = y.v, a1 = acceleration;
  double x = y.x + h * a21 * v1, v = y.v + h * a21 * a1;
  const double v2 = v, a2 = impact_acceleration(x, v, damping);
  x = y.x + h * (a31 * v1 + a32 * v2);
  v = y.v + h * (a31 * a1 + a32 * a2);
  const double v3 = v, a3 = impact_acceleration(x, v, damping);
  x = y.x + h * (a41 * v1 + a42 * v2 + a43 * v3);
  v = y.v + h * (a41 * a1 + a42 * a2 + a43 * a3);
  const double v4 = v, a4 = impact_acceleration(x, v, damping);
  x = y.x + h * (a51 * v1 + a52 * v2 + a53 * v3 + a54 * v4);
  v = y.v + h * (a51 * a1 + a52 * a2 + a53 * a3 + a54 * a4);
  const double v5 = v, a5 = impact_acceleration(x, v, damping);
  x = y.x + h * (a61 * v1 + a62 * v2 + a63 * v3 + a64 * v4 + a65 * v5);
  v = y.v + h * (a61 * a1 + a62 * a2 + a63 * a3 + a64 * a4 + a65 * a5);
  const double v6 = v, a6 = impact_acceleration(x, v, damping);
  DopriStep step;
  step.state.x = y.x + h * (b1 * v1 + b3 * v3 + b4 * v4 + b5 * v5 + b6 * v6);
  step.state.v = y.v + h * (b1 * a1 + b3 * a3 + b4 * a4 + b5 * a5 + b6 * a6);
  step.end_acceleration = impact_acceleration(step.state.x, step.state.v, damping);
  const double v7 = step.state.v, a7 = step.end_acceleration;
  step.error_x = h * (e1 * v1 + e3 * v3 + e4 * v4 + e5 * v5 + e6 * v6 + e7 * v7);
  step.error_v = h * (e1 * a1 + e3 * a3 + e4 * a4 + e5 * a5 + e6 * a6 + e7 * a7);
  return step;
}

// Integrates one impact with local error tolerance `tolerance` (absolute and
// relative) and returns ε = −x'(t_end) at the first zero of the total force.
double integrate_restitution(double damping, double tolerance) {
  // γ = 0 is elastic Hertz: energy is conserved and the contact ends at x = 0 with
  // x' = −1 exactly.
  if (damping == 0.0) return 1.0;
  // x^{1/4} is not smooth at x = 0, which would spoil any Runge-Kutta step from
  // t = 0. Start at t₀ > 0 from the series (x'' = −γt^{1/4} − (1 − 8γ²/9)t^{3/2} + …)
  //   x = t − (16/45)γ t^{9/4} − (4/35)(1 − 8γ²/9) t^{7/2},
  //   x' = 1 − (4/5)γ t^{5/4} − (2/5)(1 − 8γ²/9) t^{5/2},
  // whose first neglected terms are O((γ + γ³) t^{15/4}); t₀ keeps them below
  // tolerance/10.
  // The Hertz-only terms neglected are O(t⁵): the cap t₀ <= 1e-3 keeps them at 1e-16.
  const double start = std::min(
      1e-3, std::pow(0.1 * tolerance / (damping + damping * damping * damping), 4.0 / 15.0));
  const double gamma_sq_term = 1.0 - 8.0 * damping * damping / 9.0;
  ImpactState state;
  state.x = start - 16.0 / 45.0 * damping * std::pow(start, 2.25) -
            4.0 / 35.0 * gamma_sq_term * std::pow(start, 3.5);
  state.v =
      1.0 - 0.8 * damping * std::pow(start, 1.25) - 0.4 * gamma_sq_term * std::pow(start, 2.5);
  double acceleration = impact_acceleration(state.x, state.v, damping);
  double h = start;
  constexpr int kMaxSteps = 1'000'000;
  for (int i = 0; i < kMaxSteps; ++i) {
    const DopriStep step = dopri_step(state, acceleration, h, damping);
    const double error =
        std::max(std::abs(step.error_x) / (tolerance * (1.0 + std::abs(step.state.x))),
                 std::abs(step.error_v) / (tolerance * (1.0 + std::abs(step.state.v))));
    // Standard step-size control (HNW I, §II.4), growth limited to ×5, cut to ×0.2.
    const double factor = std::clamp(0.9 * std::pow(std::max(error, 1e-30), -0.2), 0.2, 5.0);
    if (error > 1.0) {
      h *= factor;
      continue;
    }
    if (end_of_contact_function(step.state, damping) > 0.0) {
      state = step.state;
      acceleration = step.end_acceleration;
      h *= factor;
      continue;
    }
    // The end lies inside this step: locate it by the Illinois method on the step
    // length, re-stepping from the accepted state (full 5th-order accuracy). At the
    // end the acceleration is zero (the total force vanishes), so ε = −x' is
    // insensitive to the end time to first order: a loose time tolerance suffices.
    double lo = 0.0, hi = h;
    double f_lo = end_of_contact_function(state, damping);
    double f_hi = end_of_contact_function(step.state, damping);
    ImpactState end = step.state;
    int side = 0;
    for (int iteration = 0; iteration < 100 && hi - lo > 1e-12 * h; ++iteration) {
      const double trial = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
      const ImpactState at = dopri_step(state, acceleration, trial, damping).state;
      const double f = end_of_contact_function(at, damping);
      if (f > 0.0) {
        lo = trial;
        f_lo = f;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      } else {
        hi = trial;
        f_hi = f;
        end = at;
        if (side == 1) f_lo *= 0.5;
        side = 1;
        if (f == 0.0) break;
      }
    }
    return -end.v;
  }
  throw base::NumericalError("realised_restitution: no end of contact after " + std::to_string(kMaxSteps) +
                             " steps at damping " + format_number(damping, 9));
}

// Tolerances of the two uses: the accurate public solve (|ε error| ~1e-11) and the
// table's nodes (|ε error| ~1e-9, well inside the table's 1e-5 budget, 4x cheaper).
constexpr double kAccurateTolerance = 1e-12;
constexpr double kTableTolerance = 1e-9;

}  // namespace

// ---------------------------------------------------------------------------

std::unique_ptr<RestitutionModel> make_constant_restitution(double restitution) {
  require_restitution("restitution", restitution);
  return std::make_unique<ConstantRestitution>(restitution);
}

std::unique_ptr<RestitutionModel> make_linear_restitution(double intercept, double slope_s_per_m) {
  require_restitution("intercept", intercept);
  base::require(std::isfinite(slope_s_per_m), "slope_s_per_m", slope_s_per_m, "finite");
  return std::make_unique<LinearRestitution>(intercept, slope_s_per_m);
}

std::unique_ptr<RestitutionModel> make_tabulated_restitution(std::span<const double> speeds_m_s,
                                                             std::span<const double> values) {
  if (speeds_m_s.size() != values.size()) {
    throw std::invalid_argument("restitution table: " + std::to_string(speeds_m_s.size()) +
                                " speeds and " + std::to_string(values.size()) +
                                " values: must have equal lengths");
  }
  if (speeds_m_s.size() < 2) {
    throw std::invalid_argument("restitution table: " + std::to_string(speeds_m_s.size()) +
                                " points: must have >= 2");
  }
  for (std::size_t i = 0; i < speeds_m_s.size(); ++i) {
    const std::string index = bracketed(i);
    require_non_negative("restitution table: speeds_m_s" + index, speeds_m_s[i]);
    if (i > 0 && !(speeds_m_s[i] > speeds_m_s[i - 1])) {
      throw std::invalid_argument("restitution table: speeds_m_s" + index + " = " + format_number(speeds_m_s[i], 9) +
                                  ": must be > speeds_m_s[" + std::to_string(i - 1) +
                                  "] = " + format_number(speeds_m_s[i - 1], 9) + " (strictly increasing)");
    }
    require_restitution("restitution table: values" + index, values[i]);
  }
  return std::make_unique<TabulatedRestitution>(
      std::vector<double>(speeds_m_s.begin(), speeds_m_s.end()),
      std::vector<double>(values.begin(), values.end()));
}

double yield_speed(double limiting_pressure_pa, double effective_modulus_pa,
                   double effective_radius_m, double effective_mass_kg) {
  require_positive("limiting_pressure_pa", limiting_pressure_pa);
  require_positive("effective_modulus_pa", effective_modulus_pa);
  require_positive("effective_radius_m", effective_radius_m);
  require_positive("effective_mass_kg", effective_mass_kg);
  // Hertz: p₀ = 2E*a/(πR*), a² = R*δ, so p₀ = p_y at δ_y = R*(πp_y/(2E*))²; the
  // elastic energy there, (8/15)E*√R*δ_y^{5/2}, equals ½m*v_y². (p_y/E*)⁴ is formed
  // first so that nothing overflows.
  const double ratio = limiting_pressure_pa / effective_modulus_pa;
  const double ratio_sq = ratio * ratio;
  return std::sqrt(std::pow(pi, 5) / 30.0 * ratio_sq * ratio_sq * limiting_pressure_pa *
                   effective_radius_m * effective_radius_m * effective_radius_m /
                   effective_mass_kg);
}

std::unique_ptr<RestitutionModel> make_thornton_restitution(double limiting_pressure_pa,
                                                            double effective_modulus_pa,
                                                            double effective_radius_m,
                                                            double effective_mass_kg) {
  return std::make_unique<ThorntonRestitution>(
      limiting_pressure_pa, yield_speed(limiting_pressure_pa, effective_modulus_pa,
                                        effective_radius_m, effective_mass_kg));
}

std::unique_ptr<RestitutionModel> make_thornton_restitution_from_yield_stress(
    double yield_stress_pa, double effective_modulus_pa, double effective_radius_m,
    double effective_mass_kg) {
  require_positive("yield_stress_pa", yield_stress_pa);
  return make_thornton_restitution(kLimitingPressurePerYieldStress * yield_stress_pa,
                                   effective_modulus_pa, effective_radius_m, effective_mass_kg);
}

ImpactData read_impact_csv(const std::string& path) {
  // read_input_file refuses a directory, a FIFO (at once, it never blocks), a device or a
  // huge file with "<path>: <reason>"; the prefix keeps this reader's message form.
  std::string contents;
  try {
    contents = read_input_file(path);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("impact CSV ") + e.what());
  }
  // Every message goes through printable(): a binary file's NUL or control bytes in a
  // quoted cell would otherwise cut or break the one-line message.
  const std::string file_label = "impact CSV " + printable(path);
  std::istringstream file(contents);
  constexpr std::string_view kSpeedColumn = "impact_speed_m_s";
  constexpr std::string_view kRestitutionColumn = "restitution";
  ImpactData data;
  std::size_t speed_column = 0, restitution_column = 0, needed_fields = 0;
  bool have_header = false;
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const std::string_view content = trim_blanks(line);
    if (content.empty() || content.front() == '#') continue;
    const std::string where = file_label + ":" + std::to_string(line_number) + ": ";
    const std::vector<std::string_view> fields = split_csv_line(content);
    if (!have_header) {
      auto find_column = [&](std::string_view name) {
        const auto found = std::find(fields.begin(), fields.end(), name);
        if (found == fields.end()) {
          throw std::invalid_argument(where + "header '" + printable(std::string(content)) +
                                      "' has no column '" + std::string(name) + "'");
        }
        return static_cast<std::size_t>(found - fields.begin());
      };
      speed_column = find_column(kSpeedColumn);
      restitution_column = find_column(kRestitutionColumn);
      needed_fields = std::max(speed_column, restitution_column) + 1;
      have_header = true;
      continue;
    }
    if (fields.size() < needed_fields) {
      throw std::invalid_argument(where + std::to_string(fields.size()) +
                                  " columns: the header needs >= " + std::to_string(needed_fields));
    }
    auto parse = [&](std::size_t column, std::string_view name) {
      const std::string_view text = fields[column];
      double value = 0.0;
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
      if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
        throw std::invalid_argument(where + std::string(name) + " = '" + printable(std::string(text)) +
                                    "': not a number");
      }
      if (!std::isfinite(value)) {
        throw std::invalid_argument(where + std::string(name) + " = " + printable(std::string(text)) +
                                    ": must be finite");
      }
      return value;
    };
    const double speed = parse(speed_column, kSpeedColumn);
    const double restitution = parse(restitution_column, kRestitutionColumn);
    if (speed < 0.0) {
      throw std::invalid_argument(where + "impact_speed_m_s = " + format_number(speed, 9) + ": must be >= 0");
    }
    if (!(restitution > 0.0 && restitution <= 1.0)) {
      throw std::invalid_argument(where + "restitution = " + format_number(restitution, 9) + ": must be in (0, 1]");
    }
    data.speed_m_s.push_back(speed);
    data.restitution.push_back(restitution);
  }
  if (!have_header) throw std::invalid_argument(file_label + ": no header line");
  if (data.speed_m_s.empty()) throw std::invalid_argument(file_label + ": no data rows");
  return data;
}

RestitutionFit fit_restitution(const ImpactData& data, RestitutionLaw law,
                               double effective_modulus_pa, double effective_radius_m,
                               double effective_mass_kg) {
  validate_impact_data(data);
  RestitutionFit fit;
  fit.law = law;
  fit.points = static_cast<int>(data.speed_m_s.size());
  switch (law) {
    case RestitutionLaw::kConstant:
      fit.coefficients = fit_constant(data);
      fit.model = make_constant_restitution(fit.coefficients[0]);
      break;
    case RestitutionLaw::kLinear:
      fit.coefficients = fit_linear(data);
      fit.model = make_linear_restitution(fit.coefficients[0], fit.coefficients[1]);
      break;
    case RestitutionLaw::kThornton:
      fit.coefficients =
          fit_thornton(data, effective_modulus_pa, effective_radius_m, effective_mass_kg);
      fit.model = make_thornton_restitution(fit.coefficients[0], effective_modulus_pa,
                                            effective_radius_m, effective_mass_kg);
      break;
    default:
      throw std::invalid_argument("law = " + std::to_string(static_cast<int>(law)) +
                                  ": not a RestitutionLaw");
  }
  fit.rms_residual = root_mean_square_residual(data, *fit.model);
  return fit;
}

double realised_restitution(double damping_coefficient) {
  base::require_in("damping_coefficient", damping_coefficient, 0.0, kMaxDampingCoefficient);
  return integrate_restitution(damping_coefficient, kAccurateTolerance);
}

double damping_for_restitution(double restitution) {
  base::require_in("restitution", restitution, kMinCalibratedRestitution, 1.0);
  if (restitution == 1.0) return 0.0;
  // Solve ln ε(γ) = ln ε_target in u = ln(1 + γ): ln ε is nearly linear in u
  // (slope −π/√5 at γ = 0, tending to −2 as ε ≈ 1.25/γ² for large γ), so the
  // bracketed Illinois iteration converges in a few solves.
  const double target = std::log(restitution);
  auto residual = [&](double u) {
    return std::log(integrate_restitution(std::expm1(u), kAccurateTolerance)) - target;
  };
  const double max_u = std::log1p(kMaxDampingCoefficient);
  double lo = 0.0, f_lo = -target;
  double hi = std::min(-target / 1.3, max_u), f_hi = residual(hi);
  while (f_hi > 0.0) {
    if (hi == max_u) {
      throw base::NumericalError("damping_for_restitution: restitution " + format_number(restitution, 9) +
                                 " not reached at damping " + format_number(kMaxDampingCoefficient, 9));
    }
    lo = hi;
    f_lo = f_hi;
    hi = std::min(2.0 * hi, max_u);
    f_hi = residual(hi);
  }
  // |Δ ln ε| < 1e-10 gives |Δε| < 1e-10: inside the 1e-9 promise with the
  // integrator's own ~1e-11 error.
  const double u = base::illinois_root(residual, lo, f_lo, hi, f_hi, 1e-10, 1e-15, 200);
  return std::expm1(u);
}

DampingTable::DampingTable() : damping_(kPoints) {
  // Forward solves on nodes uniform in u = ln(1 + γ), where ln ε(γ) is nearly
  // linear, up to γ = 12 (ε ≈ 0.008 < kMinRestitution); then the inverse γ(ln ε)
  // by monotone cubic interpolation, evaluated on the uniform ε grid. Inverting at
  // each of the 2001 grid points would cost ~100x more solves.
  constexpr int kNodes = 161;
  constexpr double kMaxDamping = 12.0;
  const double max_u = std::log1p(kMaxDamping);
  std::vector<double> log_restitution(kNodes);
  std::vector<double> damping(kNodes);
  for (int j = 0; j < kNodes; ++j) {
    // Stored in increasing ln ε (decreasing γ), as the interpolant needs.
    const double gamma = std::expm1(max_u * (kNodes - 1 - j) / (kNodes - 1));
    damping[j] = gamma;
    log_restitution[j] = std::log(integrate_restitution(gamma, kTableTolerance));
  }
  if (!(log_restitution.front() < std::log(kMinRestitution))) {
    throw base::NumericalError("DampingTable: realised restitution at damping " + format_number(kMaxDamping, 9) +
                               " is " + format_number(std::exp(log_restitution.front()), 9) +
                               ", not below the table's lower end");
  }
  const MonotoneCubic inverse(std::move(log_restitution), std::move(damping));
  for (int i = 0; i < kPoints; ++i) {
    damping_[i] = inverse(std::log(kMinRestitution + i / kInverseStep));
  }
  // The last grid value may round to 1 − 1e-16; ε = 1 is exactly elastic.
  damping_.back() = 0.0;
}

void DampingTable::throw_out_of_range(double restitution) {
  throw std::invalid_argument("DampingTable: " +
                              base::violation("restitution", restitution,
                                              "in [" + format_number(kMinRestitution, base::kCheckDigits) + ", 1]"));
}

}  // namespace pdamp::formulas
