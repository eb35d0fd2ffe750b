// Measures of a sampled decay (sampled_decay.hpp).
#include "pdamp/structure/sampled_decay.hpp"

#include "pdamp/structure/free_decay.hpp"

#include <algorithm>
#include <complex>
#include <numbers>
#include <optional>

namespace pdamp::structure {

const base::Fields<SampledSettling>& SampledSettling::fields() {
  using S = SampledSettling;
  static const auto f =
      base::Fields<S>()
          .field("envelope_time_s", &S::envelope_time_s, "s", "instant of each whole period's largest excursion")
          .field("envelope_m", &S::envelope_m, "m", "each whole period's largest excursion about the offset")
          .field("sample_envelope_m", &S::sample_envelope_m, "m", "the envelope at every sample")
          .field("settling_time_s", &S::settling_time_s, "s", "when the envelope reached the threshold (null: not settled)",
                 base::kNullable)
          .field("frequency_hz", &S::frequency_hz, "Hz", "from the zero crossings up to settling", base::kNullable)
          .field("damping_ratio", &S::damping_ratio, "1", "equivalent damping ratio from the decrement",
                 base::kNullable);
  return f;
}

SampledSettling sampled_settling(const std::vector<double>& t, const Eigen::VectorXd& y, double offset, double period_s,
                                 double initial_m, double threshold_m, double fallback_frequency_hz) {
  SampledSettling out;
  const std::size_t n = t.size();
  std::size_t i = 0;
  for (int k = 0;; ++k) {
    const double end = (k + 1) * period_s;
    if (end > t.back() + 1e-12 * period_s) break;
    double peak = -1.0, at = 0.0;
    for (; i < n && t[i] < end; ++i) {
      const double r = std::abs(y[static_cast<Eigen::Index>(i)] - offset);
      if (r > peak) peak = r, at = t[i];
    }
    if (peak < 0.0) break;
    out.envelope_time_s.push_back(at);
    out.envelope_m.push_back(peak);
  }
  const std::size_t m = out.envelope_m.size();
  std::optional<std::size_t> last_above;
  for (std::size_t k = 0; k < m; ++k)
    if (out.envelope_m[k] >= threshold_m) last_above = k;
  if (m > 0 && !last_above) out.settling_time_s = 0.0;
  if (last_above && *last_above + 1 < m) {
    const std::size_t a = *last_above, b = a + 1;
    const double la = std::log(out.envelope_m[a]), lb = std::log(std::max(out.envelope_m[b], 1e-300));
    const double s = la > lb ? (la - std::log(threshold_m)) / (la - lb) : 0.0;
    out.settling_time_s = out.envelope_time_s[a] + std::clamp(s, 0.0, 1.0) * (out.envelope_time_s[b] - out.envelope_time_s[a]);
  }
  // The envelope at every sample (for the CSV and the plot).
  out.sample_envelope_m.resize(n, NAN);
  std::size_t k = 0;
  for (std::size_t s = 0; s < n && m > 0; ++s) {
    while (k + 1 < m && out.envelope_time_s[k + 1] <= t[s]) ++k;
    if (t[s] <= out.envelope_time_s.front()) out.sample_envelope_m[s] = out.envelope_m.front();
    else if (k + 1 >= m) out.sample_envelope_m[s] = out.envelope_m.back();
    else {
      const double w = (t[s] - out.envelope_time_s[k]) / (out.envelope_time_s[k + 1] - out.envelope_time_s[k]);
      out.sample_envelope_m[s] = std::exp((1.0 - w) * std::log(std::max(out.envelope_m[k], 1e-300)) +
                                          w * std::log(std::max(out.envelope_m[k + 1], 1e-300)));
    }
  }
  // Frequency from the zero crossings of y − y_s (interpolated), up to the settling time.
  const double until = std::isfinite(out.settling_time_s) && out.settling_time_s > 0.0 ? out.settling_time_s : t.back();
  std::vector<double> crossings;
  for (std::size_t s = 1; s < n && t[s] <= until; ++s) {
    const double r0 = y[static_cast<Eigen::Index>(s - 1)] - offset, r1 = y[static_cast<Eigen::Index>(s)] - offset;
    if ((r0 < 0.0) != (r1 < 0.0) && r0 != r1) crossings.push_back(t[s - 1] + (t[s] - t[s - 1]) * r0 / (r0 - r1));
  }
  out.frequency_hz = crossings.size() >= 3
                         ? 0.5 * static_cast<double>(crossings.size() - 1) / (crossings.back() - crossings.front())
                         : fallback_frequency_hz;
  if (std::isfinite(out.settling_time_s) && out.settling_time_s > 0.0)
    out.damping_ratio = equivalent_damping_ratio(initial_m, threshold_m, out.frequency_hz, out.settling_time_s);
  return out;
}

double static_site_offset(const ModalModel& modal, const Eigen::MatrixXd& drive_shapes,
                          const std::vector<double>& bed_masses_kg, const std::vector<double>& drive_gravity_m_s2) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(modal.mode_count());
  for (std::size_t d = 0; d < bed_masses_kg.size(); ++d)
    load += drive_shapes.col(static_cast<Eigen::Index>(d)) * bed_masses_kg[d] * drive_gravity_m_s2[d];
  double y = 0.0;
  for (Eigen::Index j = 0; j < modal.mode_count(); ++j) {
    const double w = 2.0 * std::numbers::pi * modal.natural_frequencies_hz[j];
    y += drive_shapes(j, 0) * load[j] / (modal.modal_masses_kg[j] * w * w);
  }
  return y;
}

double half_integral_square(const std::vector<double>& t, const std::vector<double>& e) {
  double sum = 0.0;
  for (std::size_t i = 1; i < t.size() && i < e.size(); ++i)
    sum += 0.25 * (t[i] - t[i - 1]) * (e[i] * e[i] + e[i - 1] * e[i - 1]);
  return sum;
}

}  // namespace pdamp::structure

namespace pdamp::structure {

namespace {

/// ∫_{t0}^{t1} g(t) e^{(λ − iΩ)(t − t0)} dt for g sampled at t (linear between samples, the
/// ends t0 and t1 inside the samples `first − 1 .. last`), by the trapezoid.
std::complex<double> weighted_integral(const std::vector<double>& t, const Eigen::VectorXd& g, double offset,
                                       std::size_t first, std::size_t last, double t0, double t1, double omega,
                                       double lambda) {
  const auto at = [&](std::size_t s) { return g(static_cast<Eigen::Index>(s)) - offset; };
  const auto kernel = [&](double time) { return std::exp(std::complex<double>(lambda, -omega) * (time - t0)); };
  const auto between = [&](std::size_t s, double time) {  // g at `time` in [t[s − 1], t[s]]
    return at(s - 1) + (at(s) - at(s - 1)) * (time - t[s - 1]) / (t[s] - t[s - 1]);
  };
  // Pieces: [t0, t_first], the samples up to t_{last−1}, [t_{last−1}, t1].
  std::vector<std::pair<double, double>> points = {{t0, between(first, t0)}};
  for (std::size_t s = first; s < last; ++s) points.emplace_back(t[s], at(s));
  points.emplace_back(t1, between(last, t1));
  std::complex<double> sum;
  for (std::size_t k = 1; k < points.size(); ++k) {
    const auto& [ta, ga] = points[k - 1];
    const auto& [tb, gb] = points[k];
    sum += 0.5 * (tb - ta) * (ga * kernel(ta) + gb * kernel(tb));
  }
  return sum;
}

}  // namespace

std::vector<surrogate::DecayPeriodResponse> bed_response_per_period(const std::vector<double>& t,
                                                                   const Eigen::VectorXd& y, double offset,
                                                                   const Eigen::VectorXd& force_on_bed_n,
                                                                   double bed_mass_kg) {
  // Upward zero crossings of y − offset: the sample just after each, and the interpolated instant.
  std::vector<std::pair<std::size_t, double>> up;
  for (std::size_t s = 1; s < t.size(); ++s) {
    const double r0 = y(static_cast<Eigen::Index>(s - 1)) - offset, r1 = y(static_cast<Eigen::Index>(s)) - offset;
    if (r0 < 0.0 && r1 >= 0.0 && t[s] > t[s - 1]) up.emplace_back(s, t[s - 1] + (t[s] - t[s - 1]) * r0 / (r0 - r1));
  }
  if (up.size() < 2) return {};
  const std::size_t periods = up.size() - 1;
  // Each force sample is the mean over the interval that ends at it (CosimulationHistory):
  // it belongs half an interval earlier, a phase lag ΩΔt/2 that would turn the inertial force
  // into damping, η* too high by (m_app/m_bed)·sin(ΩΔt/2) (0.015 at 60 samples a period:
  // the whole η* of a rolling bed's tail). The mean of the two intervals either side of a
  // sample is centred on it (a triangle of width 2Δt: its gain at Ω is 1 − (ΩΔt)²/12).
  Eigen::VectorXd force_at_samples = force_on_bed_n;
  for (Eigen::Index k = 0; k + 1 < force_on_bed_n.size(); ++k)
    force_at_samples(k) = 0.5 * (force_on_bed_n(k) + force_on_bed_n(k + 1));
  // The motion decays within a period, y ≈ Im(X e^{st}), s = −λ + iΩ. Taken as a pure sine,
  // an inertial bed F = m_a ÿ + c ẏ would seem to give energy back (its kinetic energy falls
  // with the envelope): η* low by 2(λ/Ω)·m_a/m_bed, as large as the tail's η* itself at the
  // structure's own damping. So the envelope is taken out: each period's harmonics are taken
  // of the signals times e^{λ(t − t0)}, λ from the neighbouring periods' strokes (first pass
  // λ = 0), and the bed's impedance F̂/(sX̂) = m_a s + c gives m_a = Im/Ω and c = Re + m_a λ:
  // exact for a linear bed, η* = c/(m_bed Ω), m_app/m_bed = m_a/m_bed (docs/theory.md §1).
  std::vector<double> lambda(periods, 0.0), stroke(periods), middle(periods);
  std::vector<surrogate::DecayPeriodResponse> out(periods);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t k = 0; k < periods; ++k) {
      const auto [first, t0] = up[k];
      const auto [last, t1] = up[k + 1];
      const double period = t1 - t0, omega = 2.0 * std::numbers::pi / period;
      const std::complex<double> x_hat =
          2.0 / period * weighted_integral(t, y, offset, first, last, t0, t1, omega, lambda[k]);
      const std::complex<double> f_hat =
          2.0 / period * weighted_integral(t, force_at_samples, 0.0, first, last, t0, t1, omega, lambda[k]);
      const std::complex<double> s(-lambda[k], omega);
      const std::complex<double> impedance = f_hat / (s * x_hat);  // m_a s + c
      const double mass = impedance.imag() / omega, damping = impedance.real() + mass * lambda[k];
      middle[k] = 0.5 * (t0 + t1);
      stroke[k] = std::abs(x_hat) * std::exp(-0.5 * lambda[k] * period);  // at the period's middle
      out[k] = {middle[k], 1.0 / period, stroke[k], damping / (bed_mass_kg * omega), mass / bed_mass_kg};
    }
    for (std::size_t k = 0; k < periods && periods > 1; ++k) {
      const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, periods - 1);
      const double rate = std::log(stroke[a] / stroke[b]) / (middle[b] - middle[a]);
      lambda[k] = std::isfinite(rate) ? rate : 0.0;
    }
  }
  std::erase_if(out, [](const surrogate::DecayPeriodResponse& r) {
    return !(std::isfinite(r.stroke_m) && r.stroke_m > 0.0 && std::isfinite(r.eta_star) &&
             std::isfinite(r.apparent_mass_fraction));
  });
  return out;
}

}  // namespace pdamp::structure
