// Broad phase of the reference DEM: a uniform cell grid in the body frame, the cell
// order used to renumber particles, and the Verlet list of particle pairs closer than
// r_i + r_j + skin as compressed rows.
#pragma once

#include <algorithm>
#include <array>
#include <exception>
#include <vector>

namespace pdamp::dem_reference::detail {

/// Uniform grid over the body-frame bounding box of the compartments; particles
/// outside it (only after an instability) are clamped into the border cells, which
/// keeps every pair within one cell of each other.
class CellGrid {
 public:
  /// cell_m: smallest cell edge (>= 2 r_max + skin); the edge grows if the grid
  /// would exceed max(64, 8·particles) cells.
  void configure(const std::array<double, 3>& lo, const std::array<double, 3>& hi, double cell_m,
                 int particles);
  /// Counting sort of the particles into cells (cells in x-fastest row-major order;
  /// within a cell by index).
  void bin(const double* x, const double* y, const double* z, int n);
  /// The particles in cell order after bin(): order()[k] is the particle at place k.
  const std::vector<int>& order() const { return sorted_; }
  /// The caller has renumbered the particles so that particle k is the old order()[k]:
  /// updates the binning to match without recomputing cells.
  void adopt_order();
  /// Pairs i < j of equal `group` with |x_i − x_j| < r_i + r_j + skin as compressed rows:
  /// the partners of i are out[offsets[i] .. offsets[i+1]), ascending in j
  /// (deterministic for any thread count). Writes the `j` member of each entry; `out` and
  /// `offsets` keep their capacity between calls and grow by 1/8 when outgrown. Uses the
  /// binning of bin().
  template <class Entry>
  void find_pairs(const double* x, const double* y, const double* z, const double* radius,
                  const int* group, int n, double skin_m, int threads, std::vector<int>& offsets,
                  std::vector<Entry>& out);
  std::size_t memory_bytes() const;

 private:
  int cell_of(double x, double y, double z) const;
  template <class Visit>
  void for_each_candidate(int i, Visit&& visit) const;

  std::array<double, 3> lo_{};
  std::array<double, 3> inv_cell_{};
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<int> cell_start_;  // size cells + 1
  std::vector<int> sorted_;      // particle indices by cell
  std::vector<int> cell_;        // cell of each particle
  std::vector<int> fill_;        // next free place per cell (scratch of bin)
};

/// Below this many particles the list is built serially (thread start-up costs more).
inline constexpr int kParallelListParticles = 4096;

/// Grows `v` to `size` elements; when the capacity is outgrown it reserves 1/8 more
/// than needed instead of the standard library's doubling (the lists are the largest
/// arrays of the world and the memory per particle is a target).
template <class T>
void resize_with_margin(std::vector<T>& v, std::size_t size) {
  if (size > v.capacity()) v.reserve(size + size / 8);
  v.resize(size);
}

template <class Visit>
void CellGrid::for_each_candidate(int i, Visit&& visit) const {
  const int c = cell_[static_cast<std::size_t>(i)];
  const int cx = c % dims_[0];
  const int cy = (c / dims_[0]) % dims_[1];
  const int cz = c / (dims_[0] * dims_[1]);
  for (int z = std::max(cz - 1, 0); z <= std::min(cz + 1, dims_[2] - 1); ++z) {
    for (int y = std::max(cy - 1, 0); y <= std::min(cy + 1, dims_[1] - 1); ++y) {
      for (int x = std::max(cx - 1, 0); x <= std::min(cx + 1, dims_[0] - 1); ++x) {
        const auto cell = static_cast<std::size_t>((z * dims_[1] + y) * dims_[0] + x);
        for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
          const int j = sorted_[static_cast<std::size_t>(k)];
          if (j > i) visit(j);
        }
      }
    }
  }
}

template <class Entry>
void CellGrid::find_pairs(const double* x, const double* y, const double* z, const double* radius,
                          const int* group, int n, double skin_m, int threads, std::vector<int>& offsets,
                          std::vector<Entry>& out) {
  const auto un = static_cast<std::size_t>(n);
  resize_with_margin(offsets, un + 1);
  const auto near = [&](int i, int j) {
    if (group[i] != group[j]) return false;
    const double dx = x[i] - x[j];
    const double dy = y[i] - y[j];
    const double dz = z[i] - z[j];
    const double cut = radius[i] + radius[j] + skin_m;
    return dx * dx + dy * dy + dz * dz < cut * cut;
  };
  const bool parallel = threads > 1 && n > kParallelListParticles;
  int* row = offsets.data();
  // Nothing in the two loops allocates or throws (the sort is in place); should that
  // change, an exception must not leave the OpenMP region (std::terminate): each
  // iteration catches, and the first exception is rethrown after the loop.
  std::exception_ptr error;
  const auto capture = [&error]() noexcept {
#pragma omp critical(pdamp_dem_find_pairs)
    {
      if (!error) error = std::current_exception();
    }
  };
#pragma omp parallel for schedule(static) num_threads(threads) if (parallel)
  for (int i = 0; i < n; ++i) {
    try {
      int count = 0;
      for_each_candidate(i, [&](int j) { count += near(i, j) ? 1 : 0; });
      row[i + 1] = count;
    } catch (...) {
      capture();
    }
  }
  if (error) std::rethrow_exception(error);
  row[0] = 0;
  for (std::size_t i = 0; i < un; ++i) offsets[i + 1] += offsets[i];
  resize_with_margin(out, static_cast<std::size_t>(offsets[un]));
#pragma omp parallel for schedule(static) num_threads(threads) if (parallel)
  for (int i = 0; i < n; ++i) {
    try {
      const auto begin = static_cast<std::size_t>(row[i]);
      auto k = begin;
      for_each_candidate(i, [&](int j) {
        if (near(i, j)) out[k++].j = j;
      });
      std::sort(out.begin() + static_cast<std::ptrdiff_t>(begin), out.begin() + static_cast<std::ptrdiff_t>(k),
                [](const Entry& a, const Entry& b) { return a.j < b.j; });
    } catch (...) {
      capture();
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace pdamp::dem_reference::detail
