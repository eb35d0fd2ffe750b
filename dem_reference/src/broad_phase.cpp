// Cell grid and Verlet pair list of the reference DEM.
#include "broad_phase.hpp"

#include <algorithm>
#include <cmath>

namespace pdamp::dem_reference::detail {

void CellGrid::configure(const std::array<double, 3>& lo, const std::array<double, 3>& hi, double cell_m,
                         int particles) {
  const double max_cells = std::max(64.0, 8.0 * particles);
  double cell = cell_m;
  for (;;) {
    double total = 1.0;
    for (std::size_t a = 0; a < 3; ++a) total *= std::max(1.0, std::ceil((hi[a] - lo[a]) / cell));
    if (total <= max_cells) break;
    cell *= 1.25;
  }
  lo_ = lo;
  for (std::size_t a = 0; a < 3; ++a) {
    dims_[a] = static_cast<int>(std::max(1.0, std::ceil((hi[a] - lo[a]) / cell)));
    inv_cell_[a] = 1.0 / cell;
  }
  cell_start_.assign(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2] + 1), 0);
}

int CellGrid::cell_of(double x, double y, double z) const {
  const double p[3] = {x, y, z};
  int c[3];
  for (std::size_t a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - lo_[a]) * inv_cell_[a]);
    // Clamp (also NaN → 0): a particle outside the grid joins the border cell.
    c[a] = f >= 0.0 ? (f < dims_[a] ? static_cast<int>(f) : dims_[a] - 1) : 0;
  }
  return (c[2] * dims_[1] + c[1]) * dims_[0] + c[0];
}

void CellGrid::bin(const double* x, const double* y, const double* z, int n) {
  const auto un = static_cast<std::size_t>(n);
  cell_.resize(un);
  sorted_.resize(un);
  std::fill(cell_start_.begin(), cell_start_.end(), 0);
  for (int i = 0; i < n; ++i) {
    const int c = cell_of(x[i], y[i], z[i]);
    cell_[static_cast<std::size_t>(i)] = c;
    ++cell_start_[static_cast<std::size_t>(c) + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  // Stable fill: within a cell particles stay in index order.
  fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n; ++i) {
    const auto c = static_cast<std::size_t>(cell_[static_cast<std::size_t>(i)]);
    sorted_[static_cast<std::size_t>(fill_[c]++)] = i;
  }
}

void CellGrid::adopt_order() {
  for (std::size_t c = 0; c + 1 < cell_start_.size(); ++c) {
    for (int k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
      cell_[static_cast<std::size_t>(k)] = static_cast<int>(c);
      sorted_[static_cast<std::size_t>(k)] = k;
    }
  }
}

std::size_t CellGrid::memory_bytes() const {
  return sizeof(int) * (cell_start_.capacity() + sorted_.capacity() + cell_.capacity() + fill_.capacity());
}

}  // namespace pdamp::dem_reference::detail
