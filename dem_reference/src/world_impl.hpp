// World::Impl, private to the reference DEM world, and what the world's .cpp files share.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <utility>
#include <vector>

#include <omp.h>

#include "pdamp/dem_reference/world.hpp"

#include "broad_phase.hpp"
#include "contact_law.hpp"
#include "walls.hpp"
#include "world_data.hpp"

namespace pdamp::dem_reference::detail {

/// Below this many particles a step runs on one thread whatever `threads` says: the
/// fork/join of a parallel region (~1-2 µs) would cost more than the step itself.
inline constexpr int kParallelParticles = 1500;
/// Stage times are measured on every 32nd step and scaled (clock reads cost ~20 ns).
inline constexpr int kTimingStride = 32;
/// NaN and energy-growth checks run every 1024 steps (they need an O(N) energy pass).
inline constexpr int kHealthStride = 1024;
/// Two particles whose places in the arrays differ by more than this are "far": their
/// data (~130 bytes each in the force loop) are unlikely to share the L1/L2 working
/// set of the sweep.
inline constexpr int kLocalityWindow = 512;
/// The force loop prefetches the history of the contact this many slots ahead (the
/// pool is read in slot order, but sparsely: only touching pairs have an entry).
inline constexpr int kPrefetchSlots = 8;
/// ... from this pool size on (smaller pools stay in the L2 cache), bytes.
inline constexpr std::size_t kPrefetchPoolBytes = 256 * 1024;
/// The integration reads 21 arrays at once, more streams than the hardware prefetcher
/// follows: it prefetches each array's line this many particles ahead (measured at
/// 100,000 spheres: 20% faster steps; 16-64 all do).
inline constexpr int kIntegratePrefetch = 32;
inline constexpr int kDoublesPerLine = 8;
/// The sweep integrates at least this many particles at a time ahead of its rows
/// (long runs stream better than one particle per row).
inline constexpr int kAheadChunk = 64;
/// Rows per block of the sweep (pairs of the block, then its walls).
inline constexpr int kRowBlock = 64;
/// Work of a particle (integration, row) and of a contact (the contact law) in units of
/// a listed slot's distance test, for splitting the particles between threads
/// (measured at 100,000 spheres: ~20, ~35 and ~5 ns).
inline constexpr long long kParticleWork = 4;
inline constexpr long long kContactWork = 7;
/// Every this many steps the split between threads is checked, and planned anew when
/// the busiest thread has more than 1 + kImbalance times the mean work.
inline constexpr int kBalanceStride = 256;
inline constexpr double kImbalance = 0.05;

/// The first exception thrown by a thread of a run_team region. An exception must not
/// leave an OpenMP region (the runtime calls std::terminate), and a thread that leaves
/// its phase early must still reach every barrier (the others would wait forever):
/// threads catch, record here, and carry on to the barriers.
class TeamFailure {
 public:
  /// Call inside a catch block.
  void capture() noexcept {
#pragma omp critical(pdamp_dem_team_failure)
    {
      if (!error_) error_ = std::current_exception();
    }
    failed_.store(true, std::memory_order_release);
  }
  bool failed() const noexcept { return failed_.load(std::memory_order_acquire); }
  void rethrow_if_failed() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::exception_ptr error_;
  std::atomic<bool> failed_{false};
};

/// Runs the phases phase(thread, team_size) one after the other with a barrier between
/// consecutive phases: on the calling thread alone when team is 1 (no OpenMP region at
/// all: even an `if(false)` region costs a fork/join call and futex traffic, more than
/// a 36-sphere step; an exception then simply propagates), else on an OpenMP team. A
/// phase that throws on a team thread is caught (TeamFailure); every thread still
/// passes every barrier, the phases after a failure are skipped, and the first
/// exception is rethrown on the calling thread after the region. The barriers are
/// here, not in the phases, so that no phase can skip one.
template <class... Phases>
void run_team(int team, Phases&&... phases) {
  if (team <= 1) {
    (phases(0, 1), ...);
    return;
  }
  TeamFailure failure;
#pragma omp parallel num_threads(team)
  {
    const int thread = omp_get_thread_num();
    const int size = omp_get_num_threads();
    bool first = true;
    const auto run = [&](auto& phase) {
      if (!first) {
#pragma omp barrier
      }
      first = false;
      if (failure.failed()) return;
      try {
        phase(thread, size);
      } catch (...) {
        failure.capture();
      }
    };
    (run(phases), ...);
  }
  failure.rethrow_if_failed();
}

struct LoadSums {
  double force[3] = {0.0, 0.0, 0.0};
  double moment[3] = {0.0, 0.0, 0.0};
};

/// A touching pair as the distance test leaves it (World::Impl::sweep).
struct PairGeometry {
  double dx, dy, dz;  ///< x_j − x_i, m
  double d2;          ///< |x_j − x_i|², m²
  double sum;         ///< r_i + r_j, m
  double ri, rj;      ///< radii, m
  std::size_t i, j;   ///< particles
};

/// A touching pair waiting for the others of its lanes to be evaluated with.
struct WaitingPair {
  PairGeometry g{};
  int contact = -1;  ///< pool index, or −1: staged at `fresh`
  int fresh = -1;
};

/// A touching wall contact whose kinematics are ready, waiting for the others of its lanes.
struct WaitingWall {
  ContactKinematics k{};
  int contact = -1;  ///< pool index, or −1: staged at `fresh`
  int fresh = -1;
  std::size_t i = 0;
  double ri = 0.0;
  double rc[3] = {0.0, 0.0, 0.0};  ///< contact point relative to the container origin, m
};

/// A contact touched for the first time in this step: it waits here until the
/// partitions have finished and is then appended to the pool.
struct StagedContact {
  int slot = 0;
  ContactKey key;
  Contact contact;
  double torque[3] = {0.0, 0.0, 0.0};
};

/// The work of one thread: a contiguous range of particles and their rows (pairs and
/// walls). The step sweeps the rows in order and integrates the particles just ahead
/// of the rows that need them, so that a particle's data is still in cache when its
/// forces are computed. Forces on particles beyond `end` go to `halo` and are added by
/// their owner after all partitions have finished, in partition order. The particles
/// [begin, head_end) receive such forces from earlier partitions: they are integrated
/// before the sweeps start. Aligned to a cache line: partitions never share one.
struct alignas(64) Partition {
  int begin = 0;     ///< first particle
  int end = 0;       ///< one past the last particle
  int head_end = 0;  ///< [begin, head_end): particles that earlier partitions' rows reach
  int halo_end = 0;  ///< [end, halo_end): particles of later partitions that this one's rows reach
  /// [begin, early_end): integrated before the sweeps start: the head, and on every
  /// partition as many particles as the longest head has (a thread would otherwise wait
  /// at the barrier while another integrates its head: ~2% of a step at 100,000 spheres).
  int early_end = 0;
  std::vector<double> halo;  ///< fx, fy, fz, tx, ty, tz per particle of [end, halo_end)
  std::vector<StagedContact> fresh_pairs, fresh_walls;
  StepDissipation dissipation;
  LoadSums load;
  // Inputs of the displacement bound (World::Impl::displacement_bound), m².
  double max_d2 = 0.0;  ///< largest body-frame displacement² since the last rebuild
  double max_u2 = 0.0;  ///< largest drift² of the coming step, |v_{n+1/2}·dt|²
};

/// Where one partition's sweep adds its forces: the particles' force and torque arrays for
/// the particles before `end`, and the partition's halo for those beyond it (their owner
/// adds them after all partitions, in partition order: World::Impl::reduce_halo).
struct ForceArrays {
  double* fx;
  double* fy;
  double* fz;
  double* tx;
  double* ty;
  double* tz;
  double* halo;     ///< fx, fy, fz, tx, ty, tz per particle from `end` on
  std::size_t end;  ///< one past the partition's last particle
};

/// The container as the wall contacts of a step see it: the orientation R (body → world,
/// used when `rotated`), the origin's position, its half-step translation velocity and its
/// angular velocity.
struct WallFrame {
  Matrix3 orientation;
  bool rotated;
  double position[3];          ///< m
  double velocity[3];          ///< m/s
  double angular_velocity[3];  ///< rad/s
};

/// What the contacts of one partition's sweep need and sum (World::Impl::sweep): where
/// their forces go, the step and the overlap limit (copies: read from the World, they would
/// be read again after every force stored through a double*), the dissipation and the
/// container load.
struct PartitionSweep {
  Partition& part;
  ForceArrays forces;
  double h;              ///< the time step, s
  double overlap_limit;  ///< the instability limit of δ/r_min
  StepDissipation dissipation;
  LoadSums load;
};

}  // namespace pdamp::dem_reference::detail

namespace pdamp::dem_reference {

// The world's files (dem_reference/src/):
//   world_setup.cpp      time_step_bound() and the construction (the first forces, the leapfrog start)
//   world_step.cpp       World::step and its stages (advance), the integration, and the force sweep
//                        with every contact piece it inlines (one translation unit: see there)
//   neighbour_lists.cpp  the rebuild decision (displacement_bound), the list rebuild, the renumbering
//   partitions.cpp       the work split between threads, and a step's merges in partition order
//   energy_ledger.cpp    a step's record, the energies, the instability checks, World::energy()
//   world_accessors.cpp  the public accessors, the particles set by hand, the census, the memory
//   world_state.cpp      state_hash(), save_state() and restore_state()
struct World::Impl {
  explicit Impl(const WorldOptions& o, const ContainerState& start);

  // Stages of a step.
  void advance(bool timed, const ContainerState& previous);
  double displacement_bound(const ContainerState& previous) const;
  void rebuild_lists();
  bool renumbering_pays();
  void renumber_particles();
  void plan_partitions();
  bool imbalanced() const;
  void integrate(int begin, int end, detail::Partition& part);
  template <bool kPrefetch>
  void sweep(detail::Partition& part, bool integrate_ahead);
  // Pieces of a sweep.
  detail::WallFrame wall_frame() const;
  [[gnu::always_inline]] void integrate_to(detail::Partition& part, int& ahead, int upto);
  [[gnu::always_inline]] bool touching_pair(const detail::Slot& slot, int s, detail::Partition& part,
                                            detail::WaitingPair& out);
  [[gnu::always_inline]] bool touching_wall(const detail::Slot& slot, int s, const detail::WallFrame& frame,
                                            detail::PartitionSweep& sweep, detail::WaitingWall& out);
  [[gnu::always_inline]] void wall_kinematics(std::size_t i, double ri, const double* n_body, double gap,
                                              const detail::WallFrame& frame, detail::WaitingWall& out) const;
  template <class W>
  [[gnu::noinline]] void contact_forces(const detail::WaitingPair* w, detail::PartitionSweep& sweep);
  template <class W>
  [[gnu::always_inline]] void contact_forces(const detail::WaitingWall* w, detail::PartitionSweep& sweep);
  template <class Waiting>
  [[gnu::always_inline]] void flush(const Waiting* w, int& count, detail::PartitionSweep& sweep);
  void sweep(detail::Partition& part, bool integrate_ahead) {
    // Prefetching pays only when the histories do not stay in cache.
    if (pairs.pool.size() * sizeof(detail::Contact) > detail::kPrefetchPoolBytes) {
      sweep<true>(part, integrate_ahead);
    } else {
      sweep<false>(part, integrate_ahead);
    }
  }
  void commit_fresh_contacts();
  void reduce_halo(int owner);
  void gather();
  void record(const ContainerState& previous);
  void check_health();

  double drift2(std::size_t k) const {
    const double s = inv_mass[k] * dt;
    const double ux = (vx[k] + fx[k] * s) * dt, uy = (vy[k] + fy[k] * s) * dt, uz = (vz[k] + fz[k] * s) * dt;
    return ux * ux + uy * uy + uz * uz;
  }
  void refresh_bound();
  Vec3 full_velocity(std::size_t k) const;
  Vec3 full_angular_velocity(std::size_t k) const;
  double elastic_energy() const;
  double kinetic_energy() const;
  double potential_energy() const;
  void mark_unstable(const std::string& message);
  void mark_failed(const std::string& what);
  bool parallel() const { return threads > 1 && n > detail::kParallelParticles; }
  int team() const { return parallel() ? threads : 1; }
  /// Internal place of particle `id` (the caller's numbering); throws std::out_of_range.
  std::size_t place(int id) const { return static_cast<std::size_t>(index_of.at(static_cast<std::size_t>(id))); }
  void to_body(double px, double py, double pz, double* out) const;
  detail::Contact particle_pair_contact(std::size_t a, std::size_t b) const;
  template <class W>
  [[gnu::always_inline]] detail::KinematicsLanes<W> pair_kinematics(const detail::PairGeometry* const* g) const;
  detail::Contact particle_wall_contact(std::size_t a, int wall) const;

  WorldOptions options;
  detail::ContactLaw law;
  std::vector<detail::WallFeature> walls;
  std::vector<int> wall_begin;  // per compartment, first wall index (walls sorted by compartment)
  std::vector<int> wall_end;
  TimeStepBound bound;
  double dt = 0.0;
  double skin = 0.0;
  double overlap_limit = 0.0;
  double energy_scale = 0.0;
  int threads = 1;

  // Particles (struct of arrays) at internal places. The places follow the cell order
  // when renumbering pays (renumbering_pays); order[k] is the caller's number of the
  // particle at place k and index_of its inverse.
  int n = 0;
  std::vector<double> x, y, z, vx, vy, vz, wx, wy, wz;  // positions; half-step velocities
  std::vector<double> fx, fy, fz, tx, ty, tz;          // forces and torques at the current positions
  std::vector<double> radius, mass, inv_mass, inv_inertia;
  std::vector<double> rx, ry, rz;  // body-frame positions at the last rebuild
  std::vector<int> material, compartment;
  std::vector<int> order, index_of;
  std::vector<double> scratch;     // one array of a renumbering
  std::vector<int> scratch_index;  // ranks in cell order, then one int array of a renumbering
  std::vector<double> clearances;
  double bed_mass = 0.0;

  // Work split: one partition per thread of a parallel world, else one.
  std::vector<detail::Partition> parts;
  double max_d2 = 0.0, max_u2 = 0.0;  // over all partitions, after the last step
  double reach = 0.0;  // largest distance of a point of the grid box from the body origin, m

  // Neighbour rows and contact history.
  detail::CellGrid grid;
  detail::RowList pairs, wall_rows;
  mutable std::vector<unsigned char> census_flags;  // scratch of contact_census()
  std::array<double, 3> grid_lo{}, grid_hi{};

  // Container.
  ContainerState container;
  bool rotated = false;
  double container_velocity[3] = {0.0, 0.0, 0.0};  // half-step translation velocity
  ContainerLoad load, load_previous;

  // Energy account and counters.
  double container_work = 0.0, normal_damping = 0.0, friction = 0.0, rolling = 0.0;
  double initial_energy = 0.0;
  double time = 0.0;
  std::int64_t steps = 0;
  std::int64_t rebuilds = 0;
  bool rebuild_due = false;
  WorldStatus status;
  StageTimes stage_times;
};

// Used by the step, the rebuild, the energies and the census: here, to be inlined in each.
inline void World::Impl::to_body(double px, double py, double pz, double* out) const {
  const double d[3] = {px - container.position_m[0], py - container.position_m[1], pz - container.position_m[2]};
  if (!rotated) {
    out[0] = d[0];
    out[1] = d[1];
    out[2] = d[2];
    return;
  }
  const auto& R = container.orientation;
  out[0] = R[0] * d[0] + R[3] * d[1] + R[6] * d[2];
  out[1] = R[1] * d[0] + R[4] * d[1] + R[7] * d[2];
  out[2] = R[2] * d[0] + R[5] * d[1] + R[8] * d[2];
}

inline Vec3 World::Impl::full_velocity(std::size_t k) const {
  const double s = 0.5 * dt * inv_mass[k];
  return {vx[k] + s * fx[k], vy[k] + s * fy[k], vz[k] + s * fz[k]};
}

inline Vec3 World::Impl::full_angular_velocity(std::size_t k) const {
  const double s = 0.5 * dt * inv_inertia[k];
  return {wx[k] + s * tx[k], wy[k] + s * ty[k], wz[k] + s * tz[k]};
}

}  // namespace pdamp::dem_reference
