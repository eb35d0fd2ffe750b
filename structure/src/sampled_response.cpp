#include "pdamp/structure/sampled_response.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace pdamp::structure {

LevelCrossings level_crossings(const std::vector<double>& f, const std::vector<double>& c, std::size_t first,
                               std::size_t last, double level) {
  LevelCrossings out;
  for (std::size_t i = first; i > 0; --i) {
    if (!std::isfinite(c[i - 1])) break;
    if (c[i - 1] < level) {
      out.low_hz = f[i - 1] + (level - c[i - 1]) / (c[i] - c[i - 1]) * (f[i] - f[i - 1]);
      break;
    }
  }
  for (std::size_t i = last; i + 1 < c.size(); ++i) {
    if (!std::isfinite(c[i + 1])) break;
    if (c[i + 1] < level) {
      out.high_hz = f[i] + (c[i] - level) / (c[i] - c[i + 1]) * (f[i + 1] - f[i]);
      break;
    }
  }
  return out;
}

LevelCrossings outer_level_crossings(const std::vector<double>& f, const std::vector<double>& c, std::size_t k,
                                     double level) {
  LevelCrossings out;
  const double half_power = c[k] / std::sqrt(2.0);
  std::size_t first = k, last = k;
  while (first > 0 && std::isfinite(c[first - 1]) && c[first - 1] >= half_power) --first;
  while (last + 1 < c.size() && std::isfinite(c[last + 1]) && c[last + 1] >= half_power) ++last;
  if (first > 0) --first;  // the flank's sample below half power (or a NaN) bounds the scan
  if (last + 1 < c.size()) ++last;
  // level <= c[k]: both scans stop at k at the latest; NaN samples count as below.
  std::size_t lo = first;
  while (!(c[lo] >= level)) ++lo;
  std::size_t hi = last;
  while (!(c[hi] >= level)) --hi;
  if (lo > first && std::isfinite(c[lo - 1]))
    out.low_hz = f[lo - 1] + (level - c[lo - 1]) / (c[lo] - c[lo - 1]) * (f[lo] - f[lo - 1]);
  if (hi < last && std::isfinite(c[hi + 1]))
    out.high_hz = f[hi] + (c[hi] - level) / (c[hi] - c[hi + 1]) * (f[hi + 1] - f[hi]);
  return out;
}

double parabola_vertex(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double num = (x1 - x0) * (x1 - x0) * (y1 - y2) - (x1 - x2) * (x1 - x2) * (y1 - y0);
  const double den = (x1 - x0) * (y1 - y2) - (x1 - x2) * (y1 - y0);
  return den != 0.0 ? x1 - 0.5 * num / den : x1;
}

SampledPeak sampled_peak(const std::vector<double>& f, const std::vector<double>& c,
                         const std::vector<double>& standard_errors) {
  const std::size_t n = f.size();
  if (n == 0 || c.size() != n) throw std::invalid_argument("sampled_peak: needs as many magnitudes as frequencies, at least one");
  if (!standard_errors.empty() && standard_errors.size() != n)
    throw std::invalid_argument("sampled_peak: standard_errors must be empty or one per frequency");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(f[i]) || !std::isfinite(c[i]) || (i > 0 && !(f[i] > f[i - 1])))
      throw std::invalid_argument("sampled_peak: sample " + std::to_string(i) +
                                  ": frequencies must increase strictly and every value be finite");
    if (!standard_errors.empty() && !(standard_errors[i] >= 0.0))
      throw std::invalid_argument("sampled_peak: standard error " + std::to_string(i) + " must be >= 0");
  }
  SampledPeak peak;
  for (std::size_t i = 1; i < n; ++i)
    if (c[i] > c[peak.index]) peak.index = i;
  const std::size_t k = peak.index;
  peak.magnitude = c[k];
  peak.frequency_hz = f[k];
  if (k > 0 && k + 1 < n) {
    // The vertex stays between the neighbours: a flat top cannot throw it outside them.
    const double vertex = parabola_vertex(f[k - 1], c[k - 1], f[k], c[k], f[k + 1], c[k + 1]);
    peak.frequency_hz = std::clamp(vertex, f[k - 1], f[k + 1]);
  }
  peak.band = outer_level_crossings(f, c, k, kResonanceBandFraction * c[k]);
  peak.band_centre_hz = 0.5 * (peak.band.low_hz + peak.band.high_hz);
  const LevelCrossings half_power = level_crossings(f, c, k, k, c[k] / std::sqrt(2.0));
  peak.damping_ratio = (half_power.high_hz - half_power.low_hz) / (2.0 * peak.frequency_hz);
  std::size_t low = k, high = k;  // the first and last sample indistinguishable from the largest
  if (!standard_errors.empty()) {
    const double floor = c[k] - 2.0 * standard_errors[k];
    for (std::size_t i = 0; i < n; ++i)
      if (c[i] + 2.0 * standard_errors[i] >= floor) {
        low = std::min(low, i);
        high = std::max(high, i);
      }
  }
  peak.indistinguishable_low_hz = f[low];
  peak.indistinguishable_high_hz = f[high];
  peak.maximum_low_hz = f[low > 0 ? low - 1 : 0];
  peak.maximum_high_hz = f[high + 1 < n ? high + 1 : n - 1];
  return peak;
}

}  // namespace pdamp::structure
