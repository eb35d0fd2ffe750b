#pragma once
// The resonance of a response known at sampled frequencies: the harmonic balance's grid
// or a stepped sine's points. Shared by find_peaks (harmonic_balance.cpp) and the DEM
// stepped sine, so the three couplings' peaks are measured the same way.
#include <cstddef>
#include <limits>
#include <vector>

namespace pdamp::structure {

/// Share of the peak magnitude that bounds the resonance band of SampledPeak. Where a
/// damper holds its stroke near the design value (amplitude-limited, the plateau of an
/// optimally tuned particle damper) the top is flat: a 1% change of magnitude moves the
/// argmax by several per cent of frequency, while the band's edges, on the steep flanks,
/// move by a fraction of that. 0.9 keeps the band on the resonance (the half-power band
/// of a mode with ζ = 0.2 extends ±20%; the 0.9 band ±10%) and above the noise of a DEM
/// point (its spread is a few per cent).
inline constexpr double kResonanceBandFraction = 0.9;

/// Frequencies where a sampled curve c(f) falls below `level` on the two sides of the
/// samples [first, last] (linear interpolation between samples); NaN where it does not
/// within the samples (or meets a NaN sample first).
struct LevelCrossings {
  double low_hz = std::numeric_limits<double>::quiet_NaN();
  double high_hz = std::numeric_limits<double>::quiet_NaN();
};
LevelCrossings level_crossings(const std::vector<double>& f, const std::vector<double>& c, std::size_t first,
                               std::size_t last, double level);

/// The band where a sampled curve reaches `level`: from the first sample at or above it
/// (from the low end) to the last (from the high end), each edge interpolated linearly
/// with its outer neighbour; NaN where the end sample itself is at or above the level (or
/// no sample is). A dip inside the band, or a DEM point's scatter near the top, does not
/// cut it short, as the crossing nearest the peak would. Needs level in (c[k]/√2, c[k]].
/// The scan covers the samples of the peak at index k down to where the curve first falls
/// below 1/√2 of c[k] on each side (its half-power flanks), so a neighbouring mode's peak
/// does not join the band.
LevelCrossings outer_level_crossings(const std::vector<double>& f, const std::vector<double>& c, std::size_t k,
                                     double level);

/// Abscissa of the vertex of the parabola through three points (non-uniform spacing); x1
/// when the three are collinear.
double parabola_vertex(double x0, double y0, double x1, double y1, double x2, double y2);

/// The largest sample of a curve and its resonance measures.
struct SampledPeak {
  std::size_t index = 0;       ///< the largest sample
  double frequency_hz = 0.0;   ///< vertex of the parabola through it and its neighbours (the sample at an end)
  double magnitude = 0.0;      ///< the largest sample's magnitude
  /// The band where the curve reaches kResonanceBandFraction × magnitude
  /// (outer_level_crossings; NaN edge: the curve does not fall that low within the
  /// samples) and its centre.
  LevelCrossings band;
  double band_centre_hz = std::numeric_limits<double>::quiet_NaN();
  /// The lowest and highest frequency of the samples that cannot be told from the largest
  /// within two standard errors (m_i + 2 se_i ≥ m_max − 2 se_max): the argmax is only
  /// known to lie among them. Without standard errors, the peak sample's frequency.
  double indistinguishable_low_hz = 0.0, indistinguishable_high_hz = 0.0;
  /// Where the sampled curve's own maximum lies: from the sample below the lowest
  /// indistinguishable sample to the sample above the highest (the end sample at an end).
  /// A curve with one maximum peaks between the neighbours of its largest sample, so a
  /// maximum between two samples is located to within a spacing, not to a sample:
  /// [indistinguishable_low_hz, indistinguishable_high_hz] alone can shrink to one
  /// sample's frequency and refuse a peak a fraction of a spacing beside it.
  double maximum_low_hz = 0.0, maximum_high_hz = 0.0;
  /// Half-power damping ratio (f₂ − f₁)/(2 frequency_hz), f₁, f₂ where the curve first falls
  /// below magnitude/√2 on either side of the largest sample (level_crossings), as the
  /// harmonic balance's ResponsePeak; NaN where a side does not fall that low in the samples.
  double damping_ratio = std::numeric_limits<double>::quiet_NaN();
};

/// Throws std::invalid_argument unless f is strictly increasing, c finite and of f's size
/// (at least one sample), and standard_errors empty or of f's size and ≥ 0.
SampledPeak sampled_peak(const std::vector<double>& f, const std::vector<double>& c,
                         const std::vector<double>& standard_errors = {});

}  // namespace pdamp::structure
