// Measures of a sampled decay (sampled_decay.hpp).
#include "pdamp/structure/sampled_decay.hpp"

#include "pdamp/structure/free_decay.hpp"

#include <algorithm>
#include <numbers>
#include <optional>

namespace pdamp::structure {

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
