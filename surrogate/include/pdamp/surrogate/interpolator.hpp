// Bilinear interpolation of one value per node over a Grid, with derivatives and an
// explicit out-of-range policy (the grid itself knows nothing of interpolation).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdamp/surrogate/grid.hpp"

namespace pdamp::surrogate {

/// What a lookup outside the grid does.
enum class OutOfRangePolicy {
  kClamp,  ///< (default) take the value at the nearest edge, derivative 0 along that axis, and flag it
  kError,  ///< throw std::invalid_argument naming the axis, the value and the range
};
std::string_view to_string(OutOfRangePolicy policy);
/// "clamp" or "error"; std::nullopt otherwise.
std::optional<OutOfRangePolicy> out_of_range_policy_from_string(std::string_view name);

/// Bilinear interpolation over a Grid in the axes' interpolation coordinates: t = x on a
/// linear axis, t = ln x on a log axis. Inside a cell
///   v = (1−w0)(1−w1)v00 + w0(1−w1)v10 + (1−w0)w1 v01 + w0 w1 v11,  w = (t − t_i)/(t_{i+1} − t_i),
/// which reproduces any a + b·t0 + c·t1 + d·t0·t1 exactly. Along an axis with a single node
/// the value is constant. A NaN node value (a missing point) makes every lookup in the
/// cells around it NaN; callers decide whether that is an error (FieldLookup: it is).
///
/// Lookup cost: no allocation; the cell is found by direct indexing on axes whose nodes
/// are equally spaced in t (to 1e-10 of the span) and by binary search otherwise.
class BilinearInterpolator {
 public:
  struct Result {
    double value = 0.0;
    double d_dx0 = 0.0;     ///< ∂v/∂x0 in value per axis-0 unit (chain rule through ln x on log axes); 0 if clamped
    double d_dx1 = 0.0;     ///< ∂v/∂x1 in value per axis-1 unit; 0 if clamped
    bool clamped0 = false;  ///< x0 was outside axis 0 (kClamp only)
    bool clamped1 = false;  ///< x1 was outside axis 1 (kClamp only)
  };

  /// `values` holds one number per node in grid storage order (NaN = missing). Throws
  /// std::invalid_argument if the grid does not validate or the sizes differ.
  BilinearInterpolator(const Grid& grid, std::vector<double> values,
                       OutOfRangePolicy policy = OutOfRangePolicy::kClamp);

  /// Value and derivatives at (x0, x1) in the axes' units. Inside a cell the derivatives
  /// are those of the bilinear patch (on a cell edge, of the cell above). Points within
  /// 1e-9 of an axis span outside it count as inside. NaN coordinates throw
  /// std::invalid_argument; so do points outside with kError.
  Result evaluate(double x0, double x1) const;
  /// Storage index of the node nearest to (x0, x1) in interpolation coordinates, after
  /// clamping (the policy is not applied; NaN coordinates throw std::invalid_argument).
  std::size_t nearest_node(double x0, double x1) const;

  const Grid& grid() const { return grid_; }
  OutOfRangePolicy policy() const { return policy_; }

 private:
  /// Hot per-axis data: node coordinates t and reciprocal cell widths.
  struct AxisLookup {
    std::vector<double> t;          ///< node coordinates (x or ln x)
    std::vector<double> inv_width;  ///< 1/(t[i+1] − t[i]) per cell; {0} for a single node
    double t_min = 0.0, t_max = 0.0;
    double t_low = 0.0, t_high = 0.0;  ///< accepted range: [t_min, t_max] widened by the tolerance
    double inv_step = 0.0;             ///< (n−1)/(t_max − t_min) on equally spaced axes
    std::size_t last_cell = 0;         ///< n − 2 (0 for a single node)
    std::size_t next = 1;              ///< index step to the cell's upper node (0 for a single node)
    bool uniform = false;
    bool log = false;
    AxisQuantity quantity = AxisQuantity::kFrequencyHz;
  };
  struct Located {
    std::size_t cell;
    double w;      ///< position in the cell, [0, 1]
    double dw_dx;  ///< ∂w/∂x (0 when clamped)
    bool clamped;
  };
  static AxisLookup make_axis(const Axis& axis);
  /// Cell holding t, for t in [t_min, t_max].
  static std::size_t cell_of(const AxisLookup& axis, double t);
  Located locate(const AxisLookup& axis, double x) const;
  /// Cold path of locate(): NaN, or outside under kError (throws), or the clamped t.
  double outside(const AxisLookup& axis, double x, double t) const;

  Grid grid_;
  std::vector<double> values_;
  OutOfRangePolicy policy_;
  AxisLookup axis0_;
  AxisLookup axis1_;
};

}  // namespace pdamp::surrogate
