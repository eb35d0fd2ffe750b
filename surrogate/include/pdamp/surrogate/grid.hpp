// Axes and the two-dimensional grid of an effective field (values live elsewhere).
//
// A grid has two axes: either (frequency_hz × amplitude_m) or the normalised pair
// (intensity Γ × stroke_over_clearance X/h). Each axis holds explicit node values,
// strictly increasing and > 0, and a spacing that also fixes the coordinate in which
// the field is interpolated: linear axes in x, log axes in ln x. Storage order is
// row-major with axis 0 slowest: node (i0, i1) is entry i0·n1 + i1.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pdamp::surrogate {

/// The physical quantity an axis carries, with its JSON name and unit.
enum class AxisQuantity {
  kFrequencyHz,          ///< drive frequency f, "frequency_hz", Hz
  kAmplitudeM,           ///< container stroke X (displacement amplitude), "amplitude_m", m
  kIntensity,            ///< Γ = X(2πf)²/g, "intensity", dimensionless ("1")
  kStrokeOverClearance,  ///< X/h, "stroke_over_clearance", dimensionless ("1")
};
std::string_view to_string(AxisQuantity quantity);
/// SI unit text as written in field files: "Hz", "m" or "1".
std::string_view unit_of(AxisQuantity quantity);
std::optional<AxisQuantity> axis_quantity_from_string(std::string_view name);

/// Node spacing, and the coordinate the field is interpolated in along the axis.
enum class AxisSpacing {
  kLinear,  ///< interpolation linear in x
  kLog,     ///< interpolation linear in ln x (a field that is a power law in x is reproduced better)
};
std::string_view to_string(AxisSpacing spacing);
std::optional<AxisSpacing> axis_spacing_from_string(std::string_view name);

/// A user-set axis range: count nodes from min to max (both included).
struct AxisRange {
  double min = 0.0;                            ///< first node, in the axis unit, > 0 and finite
  double max = 0.0;                            ///< last node, >= min (== min only with count 1)
  int count = 2;                               ///< number of nodes, [1, 100000]
  AxisSpacing spacing = AxisSpacing::kLinear;  ///< equal steps in x (linear) or in ln x (log)
  /// One line per violated rule, each prefixed with `prefix` ("field.frequency_hz.count = 0: ...").
  std::vector<std::string> validate(const std::string& prefix) const;
};

/// One axis: quantity, spacing and the node values.
struct Axis {
  AxisQuantity quantity = AxisQuantity::kFrequencyHz;
  AxisSpacing spacing = AxisSpacing::kLinear;
  std::vector<double> values;  ///< nodes, strictly increasing, > 0, finite, at least one

  /// Nodes of `range` (equal steps in x or ln x; the end nodes are exactly min and max).
  /// Throws std::invalid_argument listing every violated rule of the range.
  static Axis from_range(AxisQuantity quantity, const AxisRange& range);
  std::size_t size() const { return values.size(); }
  /// One line per violated rule, prefixed with `prefix` ("axis 0.values[3] = 2: must be > values[2] = 2").
  std::vector<std::string> validate(const std::string& prefix) const;
  bool operator==(const Axis&) const = default;
};

/// Most nodes a grid may have (1000 x 1000). A finer field is never needed for
/// interpolation, its file would approach the 256 MiB input-file limit, and its DEM
/// sweep (minutes per point) would run for years: a 2000 x 2000 request is a typo.
inline constexpr std::size_t kMaxGridNodes = 1'000'000;

/// Which pair of quantities a grid spans.
enum class GridAxes {
  kFrequencyAmplitude,            ///< axis 0 frequency_hz, axis 1 amplitude_m
  kIntensityStrokeOverClearance,  ///< axis 0 intensity Γ, axis 1 stroke_over_clearance X/h
};
std::string_view to_string(GridAxes axes);

/// The nodes of an effective field: two axes, row-major storage with axis 0 slowest.
struct Grid {
  Axis axis0;  ///< frequency_hz or intensity (slow index i0)
  Axis axis1;  ///< amplitude_m or stroke_over_clearance (fast index i1)

  /// Grid of the given kind from two ranges (throws std::invalid_argument on bad ranges
  /// or more than kMaxGridNodes nodes in all).
  static Grid from_ranges(GridAxes axes, const AxisRange& range0, const AxisRange& range1);
  /// The pair of quantities; throws std::invalid_argument if the pair is not one of GridAxes.
  GridAxes axes() const;
  std::size_t size() const { return axis0.size() * axis1.size(); }
  /// Storage index of node (i0, i1): i0·n1 + i1.
  std::size_t index(std::size_t i0, std::size_t i1) const { return i0 * axis1.size() + i1; }
  /// Axis values of storage entry k: {axis0.values[k / n1], axis1.values[k % n1]}.
  double coordinate0(std::size_t k) const { return axis0.values[k / axis1.size()]; }
  double coordinate1(std::size_t k) const { return axis1.values[k % axis1.size()]; }
  /// Both axes' rules, the pairing rule and size() <= kMaxGridNodes; empty if valid.
  std::vector<std::string> validate() const;
  bool operator==(const Grid&) const = default;
};

/// Drive frequency (Hz) and stroke (m) of storage entry k; for a (Γ, X/h) grid through
/// X = (X/h)·h and f = √(Γg/X)/(2π) with the clearance h (clearance_m > 0, finite).
struct DrivePoint {
  double frequency_hz = 0.0;
  double amplitude_m = 0.0;
};
DrivePoint drive_point(const Grid& grid, std::size_t k, double clearance_m);

}  // namespace pdamp::surrogate
