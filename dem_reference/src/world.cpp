// The reference DEM world: particle state (struct of arrays), the staged step
// (neighbours → integrate and contact and wall forces in one sweep → thread halos →
// record), the energy account and the instability checks.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <cmath>
#include <bit>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <omp.h>

#include "broad_phase.hpp"
#include "contact_law.hpp"
#include "initial_state.hpp"
#include "walls.hpp"
#include "world_data.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::Contact;
using detail::ContactHistory;
using detail::ContactKey;
using detail::ContactKinematics;
using detail::ContactResult;
using detail::RowList;
using detail::Slot;
using detail::StepDissipation;
using detail::WallFeature;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;
/// Below this many particles a step runs on one thread whatever `threads` says: the
/// fork/join of a parallel region (~1-2 µs) would cost more than the step itself.
constexpr int kParallelParticles = 1500;
/// Stage times are measured on every 32nd step and scaled (clock reads cost ~20 ns).
constexpr int kTimingStride = 32;
/// NaN and energy-growth checks run every 1024 steps (they need an O(N) energy pass).
constexpr int kHealthStride = 1024;
/// Two particles whose places in the arrays differ by more than this are "far": their
/// data (~130 bytes each in the force loop) are unlikely to share the L1/L2 working
/// set of the sweep.
constexpr int kLocalityWindow = 512;
/// The force loop prefetches the history of the contact this many slots ahead (the
/// pool is read in slot order, but sparsely: only touching pairs have an entry).
constexpr int kPrefetchSlots = 8;
/// ... from this pool size on (smaller pools stay in the L2 cache), bytes.
constexpr std::size_t kPrefetchPoolBytes = 256 * 1024;
/// The integration reads 21 arrays at once, more streams than the hardware prefetcher
/// follows: it prefetches each array's line this many particles ahead (measured at
/// 100,000 spheres: 20% faster steps; 16-64 all do).
constexpr int kIntegratePrefetch = 32;
constexpr int kDoublesPerLine = 8;
/// The sweep integrates at least this many particles at a time ahead of its rows
/// (long runs stream better than one particle per row).
constexpr int kAheadChunk = 64;
/// Rows per block of the sweep (pairs of the block, then its walls).
constexpr int kRowBlock = 64;
/// Work of a particle (integration, row) and of a contact (the contact law) in units of
/// a listed slot's distance test, for splitting the particles between threads
/// (measured at 100,000 spheres: ~20, ~35 and ~5 ns).
constexpr long long kParticleWork = 4;
constexpr long long kContactWork = 7;
/// Every this many steps the split between threads is checked, and planned anew when
/// the busiest thread has more than 1 + kImbalance times the mean work.
constexpr int kBalanceStride = 256;
constexpr double kImbalance = 0.05;

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

/// Contiguous static chunk [begin, end) of n items for thread t of a team of `size`.
std::pair<int, int> chunk(int n, int t, int size) {
  const auto ln = static_cast<long long>(n);
  return {static_cast<int>(ln * t / size), static_cast<int>(ln * (t + 1) / size)};
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

/// Adds a pair's force and torques (ContactResult): F on i and −F on j, R_i·c + m on i and
/// R_j·c − m on j; j's directly, or through the halo when j is beyond the partition.
[[gnu::always_inline]] inline void apply_pair_force(const ForceArrays& to, const ContactResult& r,
                                                    const PairGeometry& g) {
  const std::size_t i = g.i, j = g.j;
  to.fx[i] += r.f[0];
  to.fy[i] += r.f[1];
  to.fz[i] += r.f[2];
  to.tx[i] += g.ri * r.c[0] + r.m[0];
  to.ty[i] += g.ri * r.c[1] + r.m[1];
  to.tz[i] += g.ri * r.c[2] + r.m[2];
  if (j < to.end) {
    to.fx[j] -= r.f[0];
    to.fy[j] -= r.f[1];
    to.fz[j] -= r.f[2];
    to.tx[j] += g.rj * r.c[0] - r.m[0];
    to.ty[j] += g.rj * r.c[1] - r.m[1];
    to.tz[j] += g.rj * r.c[2] - r.m[2];
  } else {
    double* b = to.halo + 6 * (j - to.end);
    b[0] -= r.f[0];
    b[1] -= r.f[1];
    b[2] -= r.f[2];
    b[3] += g.rj * r.c[0] - r.m[0];
    b[4] += g.rj * r.c[1] - r.m[1];
    b[5] += g.rj * r.c[2] - r.m[2];
  }
}

/// Adds a wall contact's force F and torque R_i·c + m on particle i, and its share of the
/// container load: F, and its moment about the container origin r_c × F + m (r_c: the
/// contact point relative to the origin).
[[gnu::always_inline]] inline void apply_wall_force(const ForceArrays& to, LoadSums& load, const ContactResult& r,
                                                    std::size_t i, double ri, const double* rc) {
  to.fx[i] += r.f[0];
  to.fy[i] += r.f[1];
  to.fz[i] += r.f[2];
  to.tx[i] += ri * r.c[0] + r.m[0];
  to.ty[i] += ri * r.c[1] + r.m[1];
  to.tz[i] += ri * r.c[2] + r.m[2];
  load.force[0] += r.f[0];
  load.force[1] += r.f[1];
  load.force[2] += r.f[2];
  load.moment[0] += rc[1] * r.f[2] - rc[2] * r.f[1] + r.m[0];
  load.moment[1] += rc[2] * r.f[0] - rc[0] * r.f[2] + r.m[1];
  load.moment[2] += rc[0] * r.f[1] - rc[1] * r.f[0] + r.m[2];
}

/// Prefetches the history of pair slot s, if it has one in the pool (read in slot order but
/// sparsely: only touching pairs have an entry, so the hardware prefetcher misses them).
[[gnu::always_inline]] inline void prefetch_history(const Slot* slots, int slot_count, const Contact* pool, int s) {
  if (s >= slot_count) return;
  const int contact = slots[s].contact;
  if (contact < 0) return;
  const auto* entry = reinterpret_cast<const char*>(pool + contact);
  __builtin_prefetch(entry, 1);
  __builtin_prefetch(entry + sizeof(Contact) - 1, 1);
}

/// The contacts waiting in w[0..kN) as the lanes of one kernel call: each one's parameters,
/// history and rolling torque, pooled in `rows` or staged in this step in `staged` (found by
/// index: staging may move the staged ones), and where its result goes.
template <int kN, class Waiting>
[[gnu::always_inline]] inline detail::ContactLanes<kN> contact_lanes(RowList& rows, std::vector<StagedContact>& staged,
                                                                     const Waiting* w, ContactResult* out) {
  detail::ContactLanes<kN> c;
  for (int l = 0; l < kN; ++l) {
    Contact* state;
    double* torque;
    if (w[l].contact >= 0) {
      state = &rows.pool.state[static_cast<std::size_t>(w[l].contact)];
      torque = rows.pool.rolling_torque(static_cast<std::size_t>(w[l].contact));
    } else {
      StagedContact& s = staged[static_cast<std::size_t>(w[l].fresh)];
      state = &s.contact;
      torque = s.torque;
    }
    c.params[l] = &state->params;
    c.history[l] = &state->history;
    c.rolling_torque[l] = torque;
    c.out[l] = &out[l];
  }
  return c;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const auto& line : lines) {
    if (!text.empty()) text += '\n';
    text += line;
  }
  return text;
}

void check_options(const WorldOptions& options) {
  const auto errors = options.validate();
  if (!errors.empty()) throw std::invalid_argument(join_lines(errors));
}

/// Smallest radius a group can draw (polydisperse groups spread below nominal).
double smallest_radius(const ParticleGroupOptions& g) { return g.radius_m * (1.0 - g.radius_spread); }

double sphere_mass(double radius_m, double density) { return density * 4.0 / 3.0 * kPi * radius_m * radius_m * radius_m; }

}  // namespace

TimeStepBound time_step_bound(const WorldOptions& options) {
  check_options(options);
  const detail::ContactLaw law(options);
  const double v = options.integration.max_impact_speed_m_s;
  TimeStepBound bound;
  bound.contact_time_s = std::numeric_limits<double>::infinity();
  bound.rayleigh_time_s = std::numeric_limits<double>::infinity();
  const auto consider = [&](double e_star, double r_eff, double m_eff) {
    const formulas::HertzContact contact{e_star, r_eff, m_eff};
    bound.contact_time_s = std::min(bound.contact_time_s, formulas::contact_time(contact, v));
  };
  for (const auto& c : options.compartments) {
    std::vector<int> wall_materials{c.wall_material};
    if (c.layer.thickness_m > 0.0) wall_materials.push_back(c.layer.material);
    for (const auto& p : c.plates) wall_materials.push_back(p.material >= 0 ? p.material : c.wall_material);
    for (const auto& p : c.pins) wall_materials.push_back(p.material >= 0 ? p.material : c.wall_material);
    for (const auto& a : c.particles) {
      const auto& ma = options.materials[static_cast<std::size_t>(a.material)].material;
      const double ra = smallest_radius(a);
      const double mass_a = sphere_mass(ra, ma.density_kg_m3);
      for (const auto& b : c.particles) {
        const auto& mb = options.materials[static_cast<std::size_t>(b.material)].material;
        const double rb = smallest_radius(b);
        const double mass_b = sphere_mass(rb, mb.density_kg_m3);
        consider(law.effective_modulus(a.material, b.material), ra * rb / (ra + rb),
                 mass_a * mass_b / (mass_a + mass_b));
      }
      for (const int wm : wall_materials) consider(law.effective_modulus(a.material, wm), ra, mass_a);
      for (const auto& pin : c.pins) {
        const int wm = pin.material >= 0 ? pin.material : c.wall_material;
        consider(law.effective_modulus(a.material, wm),
                 std::sqrt(ra * ra * pin.radius_m / (ra + pin.radius_m)), mass_a);
      }
      const double g = ma.youngs_modulus_pa / (2.0 * (1.0 + ma.poisson_ratio));
      const double rayleigh =
          kPi * ra * std::sqrt(ma.density_kg_m3 / g) / (0.1631 * ma.poisson_ratio + 0.8766);
      bound.rayleigh_time_s = std::min(bound.rayleigh_time_s, rayleigh);
    }
  }
  bound.max_time_step_s =
      std::min(bound.contact_time_s / options.integration.steps_per_contact,
               options.integration.rayleigh_fraction * bound.rayleigh_time_s);
  return bound;
}


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
  void integrate(int begin, int end, Partition& part);
  template <bool kPrefetch>
  void sweep(Partition& part, bool integrate_ahead);
  // Pieces of a sweep.
  WallFrame wall_frame() const;
  [[gnu::always_inline]] void integrate_to(Partition& part, int& ahead, int upto);
  [[gnu::always_inline]] bool touching_pair(const Slot& slot, int s, Partition& part, WaitingPair& out);
  [[gnu::always_inline]] bool touching_wall(const Slot& slot, int s, const WallFrame& frame, PartitionSweep& sweep,
                                            WaitingWall& out);
  [[gnu::always_inline]] void wall_kinematics(std::size_t i, double ri, const double* n_body, double gap,
                                              const WallFrame& frame, WaitingWall& out) const;
  template <class W>
  [[gnu::noinline]] void contact_forces(const WaitingPair* w, PartitionSweep& sweep);
  template <class W>
  [[gnu::always_inline]] void contact_forces(const WaitingWall* w, PartitionSweep& sweep);
  template <class Waiting>
  [[gnu::always_inline]] void flush(const Waiting* w, int& count, PartitionSweep& sweep);
  void sweep(Partition& part, bool integrate_ahead) {
    // Prefetching pays only when the histories do not stay in cache.
    if (pairs.pool.size() * sizeof(Contact) > kPrefetchPoolBytes) {
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
  bool parallel() const { return threads > 1 && n > kParallelParticles; }
  int team() const { return parallel() ? threads : 1; }
  /// Internal place of particle `id` (the caller's numbering); throws std::out_of_range.
  std::size_t place(int id) const { return static_cast<std::size_t>(index_of.at(static_cast<std::size_t>(id))); }
  void to_body(double px, double py, double pz, double* out) const;
  Contact particle_pair_contact(std::size_t a, std::size_t b) const;
  template <class W>
  [[gnu::always_inline]] detail::KinematicsLanes<W> pair_kinematics(const PairGeometry* const* g) const;
  Contact particle_wall_contact(std::size_t a, int wall) const;

  WorldOptions options;
  detail::ContactLaw law;
  std::vector<WallFeature> walls;
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
  std::vector<Partition> parts;
  double max_d2 = 0.0, max_u2 = 0.0;  // over all partitions, after the last step
  double reach = 0.0;  // largest distance of a point of the grid box from the body origin, m

  // Neighbour rows and contact history.
  detail::CellGrid grid;
  RowList pairs, wall_rows;
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

World::Impl::Impl(const WorldOptions& o, const ContainerState& start) : options(o), law((check_options(o), o)) {
  bound = dem_reference::time_step_bound(options);
  const auto& integ = options.integration;
  if (integ.time_step_s > 0.0) {
    if (integ.time_step_s > bound.max_time_step_s) {
      std::ostringstream msg;
      msg << "integration.time_step_s = " << integ.time_step_s << ": must be <= " << bound.max_time_step_s
          << " s (contact time " << bound.contact_time_s << " s at " << integ.max_impact_speed_m_s
          << " m/s over " << integ.steps_per_contact << " steps, or " << integ.rayleigh_fraction
          << " of the Rayleigh time " << bound.rayleigh_time_s << " s)";
      throw std::invalid_argument(msg.str());
    }
    dt = integ.time_step_s;
  } else {
    dt = bound.max_time_step_s;
  }
  threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  container = start;
  rotated = container.orientation != kIdentity;

  walls = detail::build_walls(options);
  const auto compartments = options.compartments.size();
  wall_begin.assign(compartments, 0);
  wall_end.assign(compartments, 0);
  for (std::size_t c = 0; c < compartments; ++c) {
    int first = -1, last = -1;
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (walls[w].compartment == static_cast<int>(c)) {
        if (first < 0) first = static_cast<int>(w);
        last = static_cast<int>(w) + 1;
      }
    }
    wall_begin[c] = first;
    wall_end[c] = last;
  }

  // Gravity in the body frame decides the lattice's base wall.
  const auto& R = container.orientation;
  const auto& g = options.gravity_m_s2;
  const Vec3 g_body{R[0] * g[0] + R[3] * g[1] + R[6] * g[2], R[1] * g[0] + R[4] * g[1] + R[7] * g[2],
                    R[2] * g[0] + R[5] * g[1] + R[8] * g[2]};
  const auto bed = detail::place_particles(options, walls, g_body);
  clearances = bed.clearances_m;
  n = static_cast<int>(bed.positions_m.size());
  const auto un = static_cast<std::size_t>(n);
  for (auto* v : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz, &radius, &mass,
                  &inv_mass, &inv_inertia, &rx, &ry, &rz, &scratch}) {
    v->assign(un, 0.0);
  }
  material = bed.materials;
  compartment = bed.compartments;
  order.resize(un);
  index_of.resize(un);
  scratch_index.resize(un);
  for (std::size_t i = 0; i < un; ++i) order[i] = index_of[i] = static_cast<int>(i);
  double r_max = 0.0;
  for (std::size_t i = 0; i < un; ++i) {
    const auto& p = bed.positions_m[i];
    x[i] = container.position_m[0] + R[0] * p[0] + R[1] * p[1] + R[2] * p[2];
    y[i] = container.position_m[1] + R[3] * p[0] + R[4] * p[1] + R[5] * p[2];
    z[i] = container.position_m[2] + R[6] * p[0] + R[7] * p[1] + R[8] * p[2];
    radius[i] = bed.radii_m[i];
    const double rho = options.materials[static_cast<std::size_t>(material[i])].material.density_kg_m3;
    mass[i] = sphere_mass(radius[i], rho);
    inv_mass[i] = 1.0 / mass[i];
    inv_inertia[i] = 1.0 / (0.4 * mass[i] * radius[i] * radius[i]);
    bed_mass += mass[i];
    r_max = std::max(r_max, radius[i]);
  }
  skin = integ.skin_fraction * r_max;
  overlap_limit = integ.max_overlap_fraction;
  const double v_max = integ.max_impact_speed_m_s;
  const double g_norm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  energy_scale = 0.5 * bed_mass * v_max * v_max + bed_mass * g_norm * r_max;

  // Grid bounds: the body-frame box around all compartments.
  grid_lo = {1e300, 1e300, 1e300};
  grid_hi = {-1e300, -1e300, -1e300};
  for (const auto& c : options.compartments) {
    for (std::size_t a = 0; a < 3; ++a) {
      double half = 0.0;
      if (c.container.shape == formulas::ContainerShape::kBox) {
        half = 0.5 * c.container.box_inner_size_m[a];
      } else {
        half = static_cast<int>(a) == c.container.cylinder_axis ? 0.5 * c.container.cylinder_inner_length_m
                                                                : c.container.cylinder_inner_radius_m;
      }
      grid_lo[a] = std::min(grid_lo[a], c.offset_m[a] - half);
      grid_hi[a] = std::max(grid_hi[a], c.offset_m[a] + half);
    }
  }
  grid.configure(grid_lo, grid_hi, 2.0 * r_max + skin, n);
  for (std::size_t a = 0; a < 3; ++a) {
    const double far = std::max(std::abs(grid_lo[a]), std::abs(grid_hi[a]));
    reach += far * far;
  }
  reach = std::sqrt(reach);

  parts.resize(parallel() ? static_cast<std::size_t>(threads) : 1);
  for (auto& p : parts) {
    // Contacts that start in one step are few; the reserve avoids regrowth in the loop.
    p.fresh_pairs.reserve(64);
    p.fresh_walls.reserve(16);
  }
  // A bed lists a few neighbours per sphere and touches fewer; reserving avoids
  // regrowth in the loop.
  const bool with_rolling = law.any_rolling_friction();
  pairs.pool.with_rolling = wall_rows.pool.with_rolling = with_rolling;
  pairs.slots.reserve(4 * un);
  pairs.pool.reserve(2 * un);
  wall_rows.slots.reserve(un);
  wall_rows.pool.reserve(un / 2 + 16);

  for (std::size_t i = 0; i < un; ++i) {
    fx[i] = mass[i] * g[0];
    fy[i] = mass[i] * g[1];
    fz[i] = mass[i] * g[2];
  }
  rebuild_lists();
  // The forces at the start: the sweep without integration.
  const int count = static_cast<int>(parts.size());
  run_team(
      team(), [&](int t, int size) { for (int p = t; p < count; p += size) sweep(parts[static_cast<std::size_t>(p)], false); },
      [&](int t, int size) {
        if (t == 0) commit_fresh_contacts();
        for (int p = t; p < count; p += size) reduce_halo(p);
      });
  gather();
  // Leapfrog start: store v(−dt/2) so that the first kick gives v(0) + F(0)dt/2m.
  for (std::size_t i = 0; i < un; ++i) {
    vx[i] -= 0.5 * dt * fx[i] * inv_mass[i];
    vy[i] -= 0.5 * dt * fy[i] * inv_mass[i];
    vz[i] -= 0.5 * dt * fz[i] * inv_mass[i];
    wx[i] -= 0.5 * dt * tx[i] * inv_inertia[i];
    wy[i] -= 0.5 * dt * ty[i] * inv_inertia[i];
    wz[i] -= 0.5 * dt * tz[i] * inv_inertia[i];
  }
  refresh_bound();
  load_previous = load;
  normal_damping = friction = rolling = 0.0;
  initial_energy = kinetic_energy() + potential_energy() + elastic_energy();
}

void World::Impl::to_body(double px, double py, double pz, double* out) const {
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

Contact World::Impl::particle_pair_contact(std::size_t a, std::size_t b) const {
  Contact c;
  c.params = law.particle_pair(radius[a], mass[a], material[a], radius[b], mass[b], material[b]);
  return c;
}

// The curvature is that of the wall part nearest to where the particle was when the
// contact was listed (the last rebuild): a sphere sliding over a pin's rim keeps it.
Contact World::Impl::particle_wall_contact(std::size_t a, int wall) const {
  const auto& w = walls[static_cast<std::size_t>(wall)];
  const double listed_at[3] = {rx[a], ry[a], rz[a]};
  Contact c;
  c.params = law.particle_wall(radius[a], mass[a], material[a], w.material,
                               detail::contact_curvature_radius(w, listed_at), w.layer_thickness_m);
  return c;
}

// Normal, overlap and relative motion of W::kWidth touching pairs (lane l: g[l]):
// contact-point velocity of i relative to j, v_i − v_j + (r_i ω_i + r_j ω_j) × n, and
// ω_i − ω_j. One IEEE operation order for every width (see detail::contact_force_lanes).
template <class W>
inline detail::KinematicsLanes<W> World::Impl::pair_kinematics(const PairGeometry* const* g) const {
  const auto at = [&](const std::vector<double>& a, bool of_i) {
    return W::gather([&](int l) { return a[of_i ? g[l]->i : g[l]->j]; });
  };
  const W dist = sqrt(W::gather([&](int l) { return g[l]->d2; }));
  const W inv = W::splat(1.0) / dist;
  detail::KinematicsLanes<W> k;
  k.n[0] = W::gather([&](int l) { return g[l]->dx; }) * inv;
  k.n[1] = W::gather([&](int l) { return g[l]->dy; }) * inv;
  k.n[2] = W::gather([&](int l) { return g[l]->dz; }) * inv;
  k.delta = W::gather([&](int l) { return g[l]->sum; }) - dist;
  const W ri = W::gather([&](int l) { return g[l]->ri; }), rj = W::gather([&](int l) { return g[l]->rj; });
  const W wi[3] = {at(wx, true), at(wy, true), at(wz, true)};
  const W wj[3] = {at(wx, false), at(wy, false), at(wz, false)};
  const W ax = ri * wi[0] + rj * wj[0], ay = ri * wi[1] + rj * wj[1], az = ri * wi[2] + rj * wj[2];
  k.v[0] = at(vx, true) - at(vx, false) + ay * k.n[2] - az * k.n[1];
  k.v[1] = at(vy, true) - at(vy, false) + az * k.n[0] - ax * k.n[2];
  k.v[2] = at(vz, true) - at(vz, false) + ax * k.n[1] - ay * k.n[0];
  for (int c = 0; c < 3; ++c) k.w[c] = wi[c] - wj[c];
  return k;
}

// A step in one OpenMP region: the rebuild check (before: a rebuild has parallel loops
// of its own), then per partition integrate the head (up to early_end), barrier, sweep
// (integrating just ahead of the rows), barrier, fresh contacts and halo forces. On the
// steps that sample the stage times the partitions are integrated whole before the
// sweep (the same arithmetic: the results do not depend on it).
void World::Impl::advance(bool timed, const ContainerState& previous) {
  const auto t0 = timed ? Clock::now() : Clock::time_point{};
  if (rebuild_due || displacement_bound(previous) > 0.5 * skin) {
    rebuild_due = false;
    rebuild_lists();
  } else if (parts.size() > 1 && steps % kBalanceStride == 0 && imbalanced()) {
    plan_partitions();
  }
  const auto t1 = timed ? Clock::now() : Clock::time_point{};
  auto t2 = t1;
  const int count = static_cast<int>(parts.size());
  run_team(
      team(),
      [&](int t, int size) {
        for (int p = t; p < count; p += size) {
          Partition& part = parts[static_cast<std::size_t>(p)];
          part.max_d2 = part.max_u2 = 0.0;
          integrate(part.begin, timed ? part.end : part.early_end, part);
        }
      },
      [&](int t, int size) {
        if (timed && t == 0) t2 = Clock::now();
        for (int p = t; p < count; p += size) sweep(parts[static_cast<std::size_t>(p)], !timed);
      },
      [&](int t, int size) {
        if (t == 0) commit_fresh_contacts();
        for (int p = t; p < count; p += size) reduce_halo(p);
      });
  gather();
  if (timed) {
    const auto t3 = Clock::now();
    const auto span = [](Clock::time_point a, Clock::time_point b) {
      return kTimingStride * std::chrono::duration<double>(b - a).count();
    };
    stage_times.neighbour_s += span(t0, t1);
    stage_times.integrate_s += span(t1, t2);
    stage_times.contact_forces_s += span(t2, t3);
  }
}

// Upper bound of the body-frame displacement since the last rebuild that the coming
// step can reach (the lists stay valid while it is below skin/2). With l = Rᵀ(x − c):
//   |l_{n+1} − r| <= |l_n − r| + |x_{n+1} − x_n| + |c_{n+1} − c_n| + ‖R_{n+1} − R_n‖_F |l_n|,
// where x_{n+1} − x_n = v_{n+1/2}·dt is known once the forces of step n are, and |l_n|
// is at most the reach of the grid box (a particle outside the container has first
// overlapped a wall by more than the instability limit). Taking each term's maximum
// over the particles keeps it an upper bound. Deciding before the step (rather than
// after integrating, as an exact check would) is what lets the sweep integrate just
// ahead of the force rows. The drift term is a few nm per step against a skin/2 of
// 0.1 r: rebuilds come at most a step earlier than with the exact check. (Without a
// renumbering, when the lists are rebuilt does not change any result: a listed pair
// that does not touch adds nothing, and the rows keep their order.)
double World::Impl::displacement_bound(const ContainerState& previous) const {
  double dc2 = 0.0, dr2 = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    const double d = container.position_m[a] - previous.position_m[a];
    dc2 += d * d;
  }
  for (std::size_t a = 0; a < 9; ++a) {
    const double d = container.orientation[a] - previous.orientation[a];
    dr2 += d * d;
  }
  return std::sqrt(max_d2) + std::sqrt(max_u2) + std::sqrt(dc2) + std::sqrt(dr2) * reach;
}

namespace {

/// The particle arrays integrate_rows reads and writes (raw: the rows of one call never
/// alias, which lets the compiler put neighbouring particles in the lanes of a register).
struct IntegrationArrays {
  double* __restrict x;
  double* __restrict y;
  double* __restrict z;
  double* __restrict vx;
  double* __restrict vy;
  double* __restrict vz;
  double* __restrict wx;
  double* __restrict wy;
  double* __restrict wz;
  double* __restrict fx;
  double* __restrict fy;
  double* __restrict fz;
  double* __restrict tx;
  double* __restrict ty;
  double* __restrict tz;
  const double* __restrict inv_mass;
  const double* __restrict inv_inertia;
  const double* __restrict mass;
  const double* __restrict rx;
  const double* __restrict ry;
  const double* __restrict rz;
};

/// One step of rows [begin, end) (at most kDoublesPerLine, one cache line): the kick with the
/// forces and torques of the current positions, the drift, the squared displacement since the
/// last rebuild (in the container's body frame as to_body gives it: R^T (x − c), R the
/// container's orientation when kRotated, else x − c) into d2_max, and the forces reset to
/// gravity for the next sweep. Each particle takes the
/// operations of the scalar update in the same order whatever the lanes, so the bits do not
/// depend on how the compiler vectorises the loop; the largest displacement is a max, which
/// does not depend on the order either.
template <bool kRotated>
void integrate_rows(const IntegrationArrays a, int begin, int end, double h, const double* g, const double* c,
                    const double* R, double& d2_max) {
  // The rows' squared displacements, their max taken after the loop: a max reduction inside
  // it would keep the loop scalar (without -ffinite-math-only the compiler may not reorder it).
  double u2_of[kDoublesPerLine];
  for (int k = begin; k < end; ++k) {
    const double im = a.inv_mass[k] * h;
    const double ii = a.inv_inertia[k] * h;
    a.vx[k] += a.fx[k] * im;
    a.vy[k] += a.fy[k] * im;
    a.vz[k] += a.fz[k] * im;
    a.wx[k] += a.tx[k] * ii;
    a.wy[k] += a.ty[k] * ii;
    a.wz[k] += a.tz[k] * ii;
    a.x[k] += a.vx[k] * h;
    a.y[k] += a.vy[k] * h;
    a.z[k] += a.vz[k] * h;
    const double d0 = a.x[k] - c[0], d1 = a.y[k] - c[1], d2 = a.z[k] - c[2];
    double b0 = d0, b1 = d1, b2 = d2;
    if constexpr (kRotated) {
      b0 = R[0] * d0 + R[3] * d1 + R[6] * d2;
      b1 = R[1] * d0 + R[4] * d1 + R[7] * d2;
      b2 = R[2] * d0 + R[5] * d1 + R[8] * d2;
    }
    const double ux = b0 - a.rx[k], uy = b1 - a.ry[k], uz = b2 - a.rz[k];
    u2_of[k - begin] = ux * ux + uy * uy + uz * uz;
    a.fx[k] = a.mass[k] * g[0];
    a.fy[k] = a.mass[k] * g[1];
    a.fz[k] = a.mass[k] * g[2];
    a.tx[k] = 0.0;
    a.ty[k] = 0.0;
    a.tz[k] = 0.0;
  }
  for (int r = 0; r < end - begin; ++r) d2_max = std::max(d2_max, u2_of[r]);
}

}  // namespace

void World::Impl::integrate(int begin, int end, Partition& part) {
  const IntegrationArrays arrays{x.data(),  y.data(),  z.data(),  vx.data(),       vy.data(),          vz.data(),
                                 wx.data(), wy.data(), wz.data(), fx.data(),       fy.data(),          fz.data(),
                                 tx.data(), ty.data(), tz.data(), inv_mass.data(), inv_inertia.data(), mass.data(),
                                 rx.data(), ry.data(), rz.data()};
  const double* const g = options.gravity_m_s2.data();
  const double* const c = container.position_m.data();
  const double* const R = container.orientation.data();
  double d2_max = part.max_d2;
  // Cache line by cache line, the lines kIntegratePrefetch particles ahead requested first
  // (a large bed streams its arrays through the step).
  for (int line = begin; line < end;) {
    const int line_end = std::min(end, (line / kDoublesPerLine + 1) * kDoublesPerLine);
    if (line % kDoublesPerLine == 0 && line + kIntegratePrefetch < n) {
      const auto ahead = static_cast<std::size_t>(line + kIntegratePrefetch);
      for (const auto* v : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz}) {
        __builtin_prefetch(v->data() + ahead, 1);
      }
      for (const auto* v : {&inv_mass, &inv_inertia, &mass, &rx, &ry, &rz}) __builtin_prefetch(v->data() + ahead, 0);
    }
    if (rotated) {
      integrate_rows<true>(arrays, line, line_end, dt, g, c, R, d2_max);
    } else {
      integrate_rows<false>(arrays, line, line_end, dt, g, c, R, d2_max);
    }
    line = line_end;
  }
  part.max_d2 = d2_max;
}

// The bound's inputs from scratch (after the start, or a velocity change by hand).
void World::Impl::refresh_bound() {
  max_d2 = max_u2 = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    double body[3];
    to_body(x[k], y[k], z[k], body);
    const double dx = body[0] - rx[k], dy = body[1] - ry[k], dz = body[2] - rz[k];
    max_d2 = std::max(max_d2, dx * dx + dy * dy + dz * dz);
    max_u2 = std::max(max_u2, drift2(k));
  }
}

void World::Impl::rebuild_lists() {
  ++rebuilds;
  const auto un = static_cast<std::size_t>(n);
  for (std::size_t k = 0; k < un; ++k) {
    double body[3];
    to_body(x[k], y[k], z[k], body);
    rx[k] = body[0];
    ry[k] = body[1];
    rz[k] = body[2];
  }
  grid.bin(rx.data(), ry.data(), rz.data(), n);
  // Only touching contacts carry history over; the pools shrink to them first.
  pairs.pool.drop_ended();
  wall_rows.pool.drop_ended();
  const int list_threads = team();
  grid.find_pairs(rx.data(), ry.data(), rz.data(), radius.data(), compartment.data(), n, skin, list_threads,
                  pairs.offsets, pairs.slots);
  if (renumbering_pays()) {
    renumber_particles();
    grid.find_pairs(rx.data(), ry.data(), rz.data(), radius.data(), compartment.data(), n, skin, list_threads,
                    pairs.offsets, pairs.slots);
  }
  run_team(list_threads, [&](int t, int size) {
    const auto [begin, end] = chunk(n, t, size);
    for (int i = begin; i < end; ++i) {
      const auto a = static_cast<std::size_t>(i);
      for (int s = pairs.offsets[a]; s < pairs.offsets[a + 1]; ++s) {
        Slot& slot = pairs.slots[static_cast<std::size_t>(s)];
        slot.i = i;
        const auto b = static_cast<std::size_t>(slot.j);
        const double dx = rx[b] - rx[a], dy = ry[b] - ry[a], dz = rz[b] - rz[a];
        const double sum = radius[a] + radius[b];
        slot.contact = dx * dx + dy * dy + dz * dz < sum * sum ? detail::kFreshContact : -1;
      }
    }
  });
  detail::attach_contacts(pairs, [&](int a, int b) {
    return particle_pair_contact(static_cast<std::size_t>(a), static_cast<std::size_t>(b)).params;
  });

  // Walls within the skin of each particle, in (particle, wall) order.
  detail::resize_with_margin(wall_rows.offsets, un + 1);
  wall_rows.slots.clear();
  wall_rows.offsets[0] = 0;
  for (std::size_t k = 0; k < un; ++k) {
    const auto c = static_cast<std::size_t>(compartment[k]);
    const double p[3] = {rx[k], ry[k], rz[k]};
    double nrm[3];
    for (int w = wall_begin[c]; w < wall_end[c]; ++w) {
      const double gap = detail::wall_gap(walls[static_cast<std::size_t>(w)], p, radius[k], nrm);
      if (gap < skin) {
        if (wall_rows.slots.size() == wall_rows.slots.capacity()) {
          wall_rows.slots.reserve(wall_rows.slots.size() + wall_rows.slots.size() / 8 + 16);
        }
        wall_rows.slots.push_back(Slot{static_cast<int>(k), w, gap < 0.0 ? detail::kFreshContact : -1});
      }
    }
    wall_rows.offsets[k + 1] = static_cast<int>(wall_rows.slots.size());
  }
  detail::attach_contacts(wall_rows, [&](int a, int w) {
    return particle_wall_contact(static_cast<std::size_t>(a), w).params;
  });
  plan_partitions();
}

// Whether renumbering the particles in cell order (CellGrid::order) would bring the
// neighbours of the new pair list markedly closer in memory: it counts the listed pairs
// farther apart than kLocalityWindow places now and in cell order. Renumbering costs a
// pass over all arrays and changes the order of the force sums; it is done when the
// bed has mixed (a fluidised bed loses any order within a few periods), not when the
// order is already good (a collected lattice is in lattice order, which serves the
// sweep better than the cell order: cells are wider than the lattice spacing, so a
// cell row mixes two lattice rows). Deterministic: integer counts of the same lists.
bool World::Impl::renumbering_pays() {
  const auto un = static_cast<std::size_t>(n);
  if (pairs.offsets.size() != un + 1 || pairs.slots.empty()) return false;
  const auto& cell_order = grid.order();
  auto& rank = scratch_index;
  for (std::size_t k = 0; k < un; ++k) rank[static_cast<std::size_t>(cell_order[k])] = static_cast<int>(k);
  long long far_now = 0, far_cells = 0;
  for (std::size_t i = 0; i < un; ++i) {
    for (int s = pairs.offsets[i]; s < pairs.offsets[i + 1]; ++s) {
      const auto j = static_cast<std::size_t>(pairs.slots[static_cast<std::size_t>(s)].j);
      far_now += j - i > static_cast<std::size_t>(kLocalityWindow) ? 1 : 0;
      far_cells += std::abs(rank[j] - rank[i]) > kLocalityWindow ? 1 : 0;
    }
  }
  const auto listed = static_cast<long long>(pairs.slots.size());
  return 2 * far_now > 3 * far_cells + listed / 10;
}

// Renumbers the particles in the grid's cell order. Each array is gathered into the
// scratch array, which then takes its place (a swap of buffers, no copy back). Needs
// the ranks left in scratch_index by renumbering_pays().
void World::Impl::renumber_particles() {
  const auto& perm = grid.order();  // perm[k]: old place of the particle at new place k
  const auto& rank = scratch_index;  // rank[old place] = new place
  const auto un = static_cast<std::size_t>(n);
  // A pair keeps i < j: if the new numbers swap the two, the stored spring force and
  // rolling torque (which act on i) change sign; everything else is symmetric.
  auto& pool = pairs.pool;
  for (std::size_t e = 0; e < pool.size(); ++e) {
    auto& key = pool.keys[e];
    int i = rank[static_cast<std::size_t>(key.i)];
    int j = rank[static_cast<std::size_t>(key.j)];
    if (i > j) {
      std::swap(i, j);
      double* ft = pool.state[e].history.ft;
      double* mr = pool.rolling_torque(e);
      for (std::size_t a = 0; a < 3; ++a) {
        ft[a] = -ft[a];
        if (mr) mr[a] = -mr[a];
      }
    }
    key = ContactKey{i, j};
  }
  for (auto& key : wall_rows.pool.keys) key.i = rank[static_cast<std::size_t>(key.i)];
  for (auto* v : {&x, &y, &z, &vx, &vy, &vz, &wx, &wy, &wz, &fx, &fy, &fz, &tx, &ty, &tz, &radius, &mass, &inv_mass,
                  &inv_inertia, &rx, &ry, &rz}) {
    for (std::size_t k = 0; k < un; ++k) scratch[k] = (*v)[static_cast<std::size_t>(perm[k])];
    v->swap(scratch);
  }
  for (auto* v : {&material, &compartment, &order}) {
    for (std::size_t k = 0; k < un; ++k) scratch_index[k] = (*v)[static_cast<std::size_t>(perm[k])];
    v->swap(scratch_index);
  }
  for (std::size_t k = 0; k < un; ++k) index_of[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
  grid.adopt_order();
}

// Splits the particles into contiguous ranges of about equal work (kParticleWork per
// particle, 1 per listed slot, kContactWork per slot with a pool entry, i.e. a recent
// contact) and finds each range's reach: the particles beyond its end that its rows
// name.
void World::Impl::plan_partitions() {
  const int count = static_cast<int>(parts.size());
  const auto weight = [&](std::size_t i) {
    long long w = kParticleWork;
    for (const RowList* rows : {&pairs, &wall_rows}) {
      for (int s = rows->offsets[i]; s < rows->offsets[i + 1]; ++s) {
        w += rows->slots[static_cast<std::size_t>(s)].contact >= 0 ? kContactWork : 1;
      }
    }
    return w;
  };
  long long total = 0;
  if (count > 1) {
    for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) total += weight(i);
  }
  long long sum = 0;
  int i = 0;
  int reached = 0;  // largest halo_end of the partitions so far
  for (int p = 0; p < count; ++p) {
    Partition& part = parts[static_cast<std::size_t>(p)];
    part.begin = i;
    if (p == count - 1) {
      i = n;
    } else {
      const long long goal = total * (p + 1) / count;
      while (i < n && sum < goal) sum += weight(static_cast<std::size_t>(i++));
    }
    part.end = i;
    part.head_end = std::clamp(reached, part.begin, part.end);
    int reach = part.end;
    for (int k = part.begin; k < part.end; ++k) {
      const int row_end = pairs.offsets[static_cast<std::size_t>(k) + 1];
      if (row_end > pairs.offsets[static_cast<std::size_t>(k)]) {
        reach = std::max(reach, pairs.slots[static_cast<std::size_t>(row_end) - 1].j + 1);
      }
    }
    part.halo_end = reach;
    part.halo.assign(6 * static_cast<std::size_t>(reach - part.end), 0.0);
    reached = std::max(reached, reach);
  }
  int longest_head = 0;
  for (const auto& part : parts) longest_head = std::max(longest_head, part.head_end - part.begin);
  for (auto& part : parts) part.early_end = std::min(part.end, part.begin + longest_head);
}

// Forces of the rows of one partition, in blocks of rows: the pairs of the block, then
// its walls (flat loops over many slots: rows are short, and a loop per row would pay
// a mispredicted exit per particle). A particle's walls thus follow all its pair forces
// (from its own row and from earlier rows naming it), so its sums run in the same
// order as with all walls after all pairs. Touching contacts are evaluated
// SweepLanes::kWidth at a time (contact_force_lanes; the rest of a block with fewer
// lanes) and their forces added one after the other, in slot order.
// With integrate_ahead, the particles a slot needs are integrated just before it (a
// particle's data then come from memory once per step).
template <bool kPrefetch>
void World::Impl::sweep(Partition& part, bool integrate_ahead) {
  using Lanes = detail::simd::SweepLanes;
  constexpr int kLanes = Lanes::kWidth;
  const WallFrame frame = wall_frame();
  PartitionSweep sweep{part,
                       ForceArrays{fx.data(), fy.data(), fz.data(), tx.data(), ty.data(), tz.data(), part.halo.data(),
                                   static_cast<std::size_t>(part.end)},
                       dt,
                       overlap_limit,
                       {},
                       {}};
  int ahead = integrate_ahead ? part.early_end : part.end;  // the particles before it are integrated
  double u2_max = part.max_u2;
  const Slot* const pair_slots = pairs.slots.data();
  const int pair_slot_count = static_cast<int>(pairs.slots.size());
  const Contact* const pair_state = pairs.pool.state.data();
  const Slot* const wall_slots = wall_rows.slots.data();
  WaitingPair waiting_pairs[kLanes];
  WaitingWall waiting_walls[kLanes];
  int pair_count = 0, wall_count = 0;
  for (int block = part.begin; block < part.end; block += kRowBlock) {
    const int block_end = std::min(part.end, block + kRowBlock);
    if (block_end > ahead) integrate_to(part, ahead, block_end);
    // The block's pairs; touching ones wait until SweepLanes::kWidth of them are evaluated
    // together (pair_kinematics and contact_force_lanes).
    const int pair_last = pairs.offsets[static_cast<std::size_t>(block_end)];
    for (int s = pairs.offsets[static_cast<std::size_t>(block)]; s < pair_last; ++s) {
      if (kPrefetch) prefetch_history(pair_slots, pair_slot_count, pair_state, s + kPrefetchSlots);
      const Slot& slot = pair_slots[s];
      if (slot.j >= ahead && ahead < part.end) integrate_to(part, ahead, slot.j + 1);
      if (!touching_pair(slot, s, part, waiting_pairs[pair_count])) continue;
      if (++pair_count == kLanes) {
        contact_forces<Lanes>(waiting_pairs, sweep);
        pair_count = 0;
      }
    }
    flush(waiting_pairs, pair_count, sweep);
    // Then its walls, in the same lanes.
    const int wall_last = wall_rows.offsets[static_cast<std::size_t>(block_end)];
    for (int s = wall_rows.offsets[static_cast<std::size_t>(block)]; s < wall_last; ++s) {
      if (!touching_wall(wall_slots[s], s, frame, sweep, waiting_walls[wall_count])) continue;
      if (++wall_count == kLanes) {
        contact_forces<Lanes>(waiting_walls, sweep);
        wall_count = 0;
      }
    }
    flush(waiting_walls, wall_count, sweep);
    // The block's forces are complete (but for what earlier partitions add: reduce_halo).
    for (int row = std::max(block, part.head_end); row < block_end; ++row) {
      u2_max = std::max(u2_max, drift2(static_cast<std::size_t>(row)));
    }
  }
  part.max_u2 = u2_max;
  part.dissipation = sweep.dissipation;
  part.load = sweep.load;
}

WallFrame World::Impl::wall_frame() const {
  WallFrame f;
  f.orientation = container.orientation;
  f.rotated = rotated;
  for (std::size_t a = 0; a < 3; ++a) {
    f.position[a] = container.position_m[a];
    f.velocity[a] = container_velocity[a];
    f.angular_velocity[a] = container.angular_velocity_rad_s[a];
  }
  return f;
}

// Integrates the partition's particles up to `upto` (exclusive), at least kAheadChunk at a
// time (long runs stream better than one particle per row).
inline void World::Impl::integrate_to(Partition& part, int& ahead, int upto) {
  const int to = std::min(part.end, std::max(upto, ahead + kAheadChunk));
  integrate(ahead, to, part);
  ahead = to;
}

// The distance test of pair slot s (both particles integrated): false when the two do not
// touch (a contact that has just ended loses its history); else the pair's geometry and
// where its history is: in the pool, or staged now in the partition for a first touch.
inline bool World::Impl::touching_pair(const Slot& slot, int s, Partition& part, WaitingPair& out) {
  const auto i = static_cast<std::size_t>(slot.i), j = static_cast<std::size_t>(slot.j);
  const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
  const double ri = radius[i], rj = radius[j];
  const double d2 = dx * dx + dy * dy + dz * dz;
  const double sum = ri + rj;
  if (d2 >= sum * sum) {
    if (slot.contact >= 0 && pairs.pool.state[static_cast<std::size_t>(slot.contact)].history.gamma >= 0.0) {
      pairs.pool.reset(static_cast<std::size_t>(slot.contact));
    }
    return false;
  }
  int fresh = -1;
  if (slot.contact < 0) {
    StagedContact& staged = part.fresh_pairs.emplace_back();
    staged.slot = s;
    staged.key = ContactKey{slot.i, slot.j};
    staged.contact = particle_pair_contact(i, j);
    fresh = static_cast<int>(part.fresh_pairs.size()) - 1;
  }
  out = WaitingPair{PairGeometry{dx, dy, dz, d2, sum, ri, rj, i, j}, slot.contact, fresh};
  return true;
}

// The gap of wall slot s: false when the particle does not touch the wall (a contact that
// has just ended loses its history); else its kinematics, an overlap beyond the instability
// limit recorded, and where its history is (pooled, or staged now for a first touch).
inline bool World::Impl::touching_wall(const Slot& slot, int s, const WallFrame& frame, PartitionSweep& sweep,
                                       WaitingWall& out) {
  const auto i = static_cast<std::size_t>(slot.i);
  const double ri = radius[i];
  double p[3];
  to_body(x[i], y[i], z[i], p);
  double n_body[3];
  const double gap = detail::wall_gap(walls[static_cast<std::size_t>(slot.j)], p, ri, n_body);
  if (gap >= 0.0) {
    if (slot.contact >= 0 && wall_rows.pool.state[static_cast<std::size_t>(slot.contact)].history.gamma >= 0.0) {
      wall_rows.pool.reset(static_cast<std::size_t>(slot.contact));
    }
    return false;
  }
  wall_kinematics(i, ri, n_body, gap, frame, out);
  StepDissipation& diss = sweep.dissipation;
  if (out.k.delta > sweep.overlap_limit * ri) diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, out.k.delta / ri);
  out.fresh = -1;
  if (slot.contact < 0) {
    StagedContact& staged = sweep.part.fresh_walls.emplace_back();
    staged.slot = s;
    staged.key = ContactKey{slot.i, slot.j};
    staged.contact = particle_wall_contact(i, slot.j);
    out.fresh = static_cast<int>(sweep.part.fresh_walls.size()) - 1;
  }
  out.contact = slot.contact;
  return true;
}

// A touching wall's contact in the world frame: the normal n = R·n_body (into the wall), the
// overlap δ = −gap, the contact point r_c = x_i + r_i n − c relative to the container origin
// c, and the velocity of the particle's surface there relative to the wall's,
// v_i + ω_i × r_i n − (v_c + ω_c × r_c), with ω_i − ω_c.
inline void World::Impl::wall_kinematics(std::size_t i, double ri, const double* n_body, double gap,
                                         const WallFrame& frame, WaitingWall& out) const {
  ContactKinematics& k = out.k;
  if (frame.rotated) {
    const auto& R = frame.orientation;
    k.n[0] = R[0] * n_body[0] + R[1] * n_body[1] + R[2] * n_body[2];
    k.n[1] = R[3] * n_body[0] + R[4] * n_body[1] + R[5] * n_body[2];
    k.n[2] = R[6] * n_body[0] + R[7] * n_body[1] + R[8] * n_body[2];
  } else {
    k.n[0] = n_body[0];
    k.n[1] = n_body[1];
    k.n[2] = n_body[2];
  }
  k.delta = -gap;
  const double* cp = frame.position;
  const double* cv = frame.velocity;
  const double* cw = frame.angular_velocity;
  const double arm[3] = {ri * k.n[0], ri * k.n[1], ri * k.n[2]};
  double* rc = out.rc;
  rc[0] = x[i] + arm[0] - cp[0];
  rc[1] = y[i] + arm[1] - cp[1];
  rc[2] = z[i] + arm[2] - cp[2];
  const double vw[3] = {cv[0] + cw[1] * rc[2] - cw[2] * rc[1], cv[1] + cw[2] * rc[0] - cw[0] * rc[2],
                        cv[2] + cw[0] * rc[1] - cw[1] * rc[0]};
  k.v[0] = vx[i] + wy[i] * arm[2] - wz[i] * arm[1] - vw[0];
  k.v[1] = vy[i] + wz[i] * arm[0] - wx[i] * arm[2] - vw[1];
  k.v[2] = vz[i] + wx[i] * arm[1] - wy[i] * arm[0] - vw[2];
  k.w[0] = wx[i] - cw[0];
  k.w[1] = wy[i] - cw[1];
  k.w[2] = wz[i] - cw[2];
  out.i = i;
  out.ri = ri;
}

// W::kWidth waiting pairs in the lanes of a W: their kinematics (pair_kinematics), an overlap
// beyond the instability limit recorded (δ/r_min of the pair), the contact law, and their
// forces added one after the other, in slot order. Out of line: inlined into the row loop,
// its many live lanes cost the loop its registers (measured at 10,000 spheres: 7% more
// instructions in the sweep).
template <class W>
void World::Impl::contact_forces(const WaitingPair* w, PartitionSweep& sweep) {
  constexpr int kN = W::kWidth;
  const PairGeometry* g[kN];
  for (int l = 0; l < kN; ++l) g[l] = &w[l].g;
  const detail::KinematicsLanes<W> kin = pair_kinematics<W>(g);
  StepDissipation& diss = sweep.dissipation;
  for (int l = 0; l < kN; ++l) {
    const double delta = lane(kin.delta, l);
    const double rmin = w[l].g.ri < w[l].g.rj ? w[l].g.ri : w[l].g.rj;
    if (delta > sweep.overlap_limit * rmin) diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, delta / rmin);
  }
  ContactResult out[kN];
  detail::contact_force_lanes<W>(contact_lanes<kN>(pairs, sweep.part.fresh_pairs, w, out), kin, sweep.h, law, diss);
  for (int l = 0; l < kN; ++l) apply_pair_force(sweep.forces, out[l], w[l].g);
}

// W::kWidth waiting wall contacts in the lanes of a W: the contact law, then their forces and
// their share of the container load, one after the other, in slot order.
template <class W>
inline void World::Impl::contact_forces(const WaitingWall* w, PartitionSweep& sweep) {
  constexpr int kN = W::kWidth;
  const ContactKinematics* kin[kN];
  for (int l = 0; l < kN; ++l) kin[l] = &w[l].k;
  ContactResult out[kN];
  detail::contact_force_lanes<W>(contact_lanes<kN>(wall_rows, sweep.part.fresh_walls, w, out),
                                 detail::load_kinematics<W>(kin), sweep.h, law, sweep.dissipation);
  for (int l = 0; l < kN; ++l) apply_wall_force(sweep.forces, sweep.load, out[l], w[l].i, w[l].ri, w[l].rc);
}

// The count < SweepLanes::kWidth contacts left waiting at the end of a block: two lanes at a
// time, then one.
template <class Waiting>
inline void World::Impl::flush(const Waiting* w, int& count, PartitionSweep& sweep) {
  int done = 0;
  if constexpr (detail::simd::SweepLanes::kWidth > 2) {
    for (; count - done >= 2; done += 2) contact_forces<detail::simd::Lanes2>(w + done, sweep);
  }
  for (; done < count; ++done) contact_forces<detail::simd::Lanes1>(w + done, sweep);
  count = 0;
}

// Whether the work of the last step (in the units of plan_partitions, with the contacts
// actually computed) differs between the partitions by more than kImbalance. The
// partitions are planned at a rebuild; a bed that settles or compresses afterwards
// (a collected bed under gravity: contacts form at the bottom first) moves the work.
// Deterministic: counts, not clocks.
bool World::Impl::imbalanced() const {
  long long most = 0, total = 0;
  for (const auto& part : parts) {
    const long long slots = (pairs.offsets[static_cast<std::size_t>(part.end)] -
                             pairs.offsets[static_cast<std::size_t>(part.begin)]) +
                            (wall_rows.offsets[static_cast<std::size_t>(part.end)] -
                             wall_rows.offsets[static_cast<std::size_t>(part.begin)]);
    const long long work = kParticleWork * (part.end - part.begin) + slots +
                           (kContactWork - 1) * part.dissipation.contacts;
    most = std::max(most, work);
    total += work;
  }
  return static_cast<double>(most) * static_cast<double>(parts.size()) > (1.0 + kImbalance) * static_cast<double>(total);
}

// Appends the contacts first touched in this step to the pools, in partition order
// (the place in the pool does not change any result).
void World::Impl::commit_fresh_contacts() {
  const auto commit = [](std::vector<StagedContact>& staged, RowList& rows) {
    for (const auto& s : staged) {
      rows.slots[static_cast<std::size_t>(s.slot)].contact = rows.pool.add(s.key, s.contact, s.torque);
    }
    staged.clear();
  };
  for (auto& part : parts) {
    commit(part.fresh_pairs, pairs);
    commit(part.fresh_walls, wall_rows);
  }
}

// Adds to the particles of partition `owner` the halo forces of the partitions before
// it, in partition order, and clears those halo entries.
void World::Impl::reduce_halo(int owner) {
  Partition& mine = parts[static_cast<std::size_t>(owner)];
  for (int p = 0; p < owner; ++p) {
    Partition& from = parts[static_cast<std::size_t>(p)];
    const int first = std::max(from.end, mine.begin);
    const int last = std::min(from.halo_end, mine.end);
    for (int i = first; i < last; ++i) {
      const auto k = static_cast<std::size_t>(i);
      double* b = from.halo.data() + 6 * static_cast<std::size_t>(i - from.end);
      fx[k] += b[0];
      fy[k] += b[1];
      fz[k] += b[2];
      tx[k] += b[3];
      ty[k] += b[4];
      tz[k] += b[5];
      b[0] = b[1] = b[2] = b[3] = b[4] = b[5] = 0.0;
    }
  }
  for (int i = mine.begin; i < mine.head_end; ++i) mine.max_u2 = std::max(mine.max_u2, drift2(static_cast<std::size_t>(i)));
}

// Sums over the partitions, in partition order: the container load and the bound's inputs.
void World::Impl::gather() {
  load = ContainerLoad{};
  max_d2 = max_u2 = 0.0;
  for (const auto& part : parts) {
    for (std::size_t a = 0; a < 3; ++a) {
      load.force_n[a] += part.load.force[a];
      load.moment_nm[a] += part.load.moment[a];
    }
    max_d2 = std::max(max_d2, part.max_d2);
    max_u2 = std::max(max_u2, part.max_u2);
  }
}

void World::Impl::record(const ContainerState& previous) {
  double max_ratio = 0.0;
  for (const auto& part : parts) {
    const auto& d = part.dissipation;
    normal_damping += d.normal_damping;
    friction += d.friction;
    rolling += d.rolling;
    max_ratio = std::max(max_ratio, d.max_overlap_ratio);
  }
  // Trapezoidal work of the container load over the step's displacement and rotation.
  double work = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    work += 0.5 * (load_previous.force_n[a] + load.force_n[a]) * (container.position_m[a] - previous.position_m[a]);
    work += 0.5 * (load_previous.moment_nm[a] + load.moment_nm[a]) * container.angular_velocity_rad_s[a] * dt;
  }
  container_work += work;
  load_previous = load;
  if (max_ratio > overlap_limit) {
    std::ostringstream msg;
    msg << "overlap reached " << max_ratio << " of a radius (limit " << overlap_limit << ") at t = " << time
        << " s: the time step " << dt
        << " s does not resolve the contacts; lower integration.time_step_s or raise "
           "integration.max_impact_speed_m_s / integration.steps_per_contact";
    mark_unstable(msg.str());
  }
}

void World::Impl::check_health() {
  const double kinetic = kinetic_energy();
  if (!std::isfinite(kinetic)) {
    std::ostringstream msg;
    msg << "non-finite particle velocities at t = " << time << " s (step " << steps
        << "): lower integration.time_step_s or check the material moduli";
    mark_unstable(msg.str());
    return;
  }
  const double energy = kinetic + potential_energy() + elastic_energy();
  const double dissipated = normal_damping + friction + rolling;
  const double created = energy - (initial_energy + container_work - dissipated);
  const double threshold = std::max(0.5 * energy_scale, 0.05 * (std::abs(container_work) + dissipated));
  if (created > threshold) {
    std::ostringstream msg;
    msg << "energy growth: " << created << " J appeared that no work supplied (threshold " << threshold
        << " J) at t = " << time << " s: lower integration.time_step_s";
    mark_unstable(msg.str());
  }
}

void World::Impl::mark_failed(const std::string& what) {
  std::ostringstream msg;
  msg << "step " << steps + 1 << " (t = " << time + dt << " s) failed: " << what;
  status.outcome = Outcome::kFailed;
  status.message = msg.str();
}

void World::Impl::mark_unstable(const std::string& message) {
  if (status.outcome == Outcome::kUnstable) return;
  status.outcome = Outcome::kUnstable;
  status.message = message;
}

Vec3 World::Impl::full_velocity(std::size_t k) const {
  const double s = 0.5 * dt * inv_mass[k];
  return {vx[k] + s * fx[k], vy[k] + s * fy[k], vz[k] + s * fz[k]};
}

Vec3 World::Impl::full_angular_velocity(std::size_t k) const {
  const double s = 0.5 * dt * inv_inertia[k];
  return {wx[k] + s * tx[k], wy[k] + s * ty[k], wz[k] + s * tz[k]};
}

double World::Impl::kinetic_energy() const {
  double e = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    const Vec3 v = full_velocity(k);
    const Vec3 w = full_angular_velocity(k);
    e += 0.5 * mass[k] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
         0.5 / inv_inertia[k] * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  return e;
}

double World::Impl::potential_energy() const {
  const auto& g = options.gravity_m_s2;
  double e = 0.0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    e -= mass[k] * (g[0] * x[k] + g[1] * y[k] + g[2] * z[k]);
  }
  return e;
}

double World::Impl::elastic_energy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    for (int s = pairs.offsets[i]; s < pairs.offsets[i + 1]; ++s) {
      const Slot& slot = pairs.slots[static_cast<std::size_t>(s)];
      if (slot.contact < 0) continue;
      const auto c = static_cast<std::size_t>(slot.contact);
      const auto j = static_cast<std::size_t>(slot.j);
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const double delta = radius[i] + radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
      const auto& params = pairs.pool.state[c].params;
      e += detail::stored_energy(params, law, pairs.pool.state[c].history,
                                 pairs.pool.rolling_torque(c), delta);
    }
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
    for (int s = wall_rows.offsets[i]; s < wall_rows.offsets[i + 1]; ++s) {
      const Slot& slot = wall_rows.slots[static_cast<std::size_t>(s)];
      if (slot.contact < 0) continue;
      const auto c = static_cast<std::size_t>(slot.contact);
      double p[3];
      to_body(x[i], y[i], z[i], p);
      double nb[3];
      const double gap = detail::wall_gap(walls[static_cast<std::size_t>(slot.j)], p, radius[i], nb);
      const auto& params = wall_rows.pool.state[c].params;
      e += detail::stored_energy(params, law, wall_rows.pool.state[c].history,
                                 wall_rows.pool.rolling_torque(c), -gap);
    }
  }
  return e;
}

World::World(const WorldOptions& options, const ContainerState& start)
    : impl_(std::make_unique<Impl>(options, start)) {}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

const ContainerLoad& World::step(const ContainerState& next) {
  Impl& w = *impl_;
  if (w.status.outcome != Outcome::kCompleted) return w.load;
  const bool timed = w.steps % kTimingStride == 0;
  const ContainerState previous = w.container;
  w.container = next;
  w.rotated = next.orientation != kIdentity;
  for (std::size_t a = 0; a < 3; ++a) {
    w.container_velocity[a] = (next.position_m[a] - previous.position_m[a]) / w.dt;
  }
  // A failure inside the step (a restitution law that throws, memory for a list that
  // outgrew its reserve) leaves the particles half advanced: the world stops, as on an
  // instability, and says why; the caller's loop sees status() and ends the run.
  try {
    w.advance(timed, previous);
  } catch (const std::exception& e) {
    w.mark_failed(e.what());
    return w.load;
  } catch (...) {
    w.mark_failed("unknown exception");
    return w.load;
  }
  const auto t3 = timed ? Clock::now() : Clock::time_point{};
  w.time += w.dt;
  ++w.steps;
  w.record(previous);
  if (w.steps % kHealthStride == 0) w.check_health();
  if (timed) w.stage_times.record_s += kTimingStride * std::chrono::duration<double>(Clock::now() - t3).count();
  return w.load;
}

const ContainerLoad& World::step(const ContainerMotion& motion) {
  return step(motion.state(impl_->time + impl_->dt));
}

void World::set_particle_state(int i, const Vec3& position_m, const Vec3& velocity_m_s,
                               const Vec3& angular_velocity_rad_s) {
  Impl& w = *impl_;
  const auto k = w.place(i);
  // The energy set here is supplied, not created: keep the growth check honest (only
  // this particle's kinetic and potential energy change).
  const auto own_energy = [&]() {
    const Vec3 v = w.full_velocity(k);
    const Vec3 om = w.full_angular_velocity(k);
    const auto& g = w.options.gravity_m_s2;
    return 0.5 * w.mass[k] * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) +
           0.5 / w.inv_inertia[k] * (om[0] * om[0] + om[1] * om[1] + om[2] * om[2]) -
           w.mass[k] * (g[0] * w.x[k] + g[1] * w.y[k] + g[2] * w.z[k]);
  };
  const double before = own_energy();
  w.x[k] = position_m[0];
  w.y[k] = position_m[1];
  w.z[k] = position_m[2];
  // Half-step velocities such that the full-step velocity is the one given.
  const double s = 0.5 * w.dt * w.inv_mass[k];
  const double r = 0.5 * w.dt * w.inv_inertia[k];
  w.vx[k] = velocity_m_s[0] - s * w.fx[k];
  w.vy[k] = velocity_m_s[1] - s * w.fy[k];
  w.vz[k] = velocity_m_s[2] - s * w.fz[k];
  w.wx[k] = angular_velocity_rad_s[0] - r * w.tx[k];
  w.wy[k] = angular_velocity_rad_s[1] - r * w.ty[k];
  w.wz[k] = angular_velocity_rad_s[2] - r * w.tz[k];
  w.initial_energy += own_energy() - before;
  w.rebuild_due = true;
}

void World::add_velocity(const Vec3& velocity_m_s) {
  Impl& w = *impl_;
  const double before = w.kinetic_energy();
  for (std::size_t k = 0; k < static_cast<std::size_t>(w.n); ++k) {
    w.vx[k] += velocity_m_s[0];
    w.vy[k] += velocity_m_s[1];
    w.vz[k] += velocity_m_s[2];
  }
  w.initial_energy += w.kinetic_energy() - before;
  w.refresh_bound();
}

const WorldOptions& World::options() const { return impl_->options; }
double World::time_step_s() const { return impl_->dt; }
double World::time_s() const { return impl_->time; }
std::int64_t World::step_count() const { return impl_->steps; }
const TimeStepBound& World::time_step_bound() const { return impl_->bound; }
const WorldStatus& World::status() const { return impl_->status; }
const ContainerLoad& World::load() const { return impl_->load; }
const ContainerState& World::container() const { return impl_->container; }
int World::particle_count() const { return impl_->n; }
int World::compartment_count() const { return static_cast<int>(impl_->options.compartments.size()); }

Vec3 World::position(int i) const {
  const auto k = impl_->place(i);
  return {impl_->x[k], impl_->y[k], impl_->z[k]};
}
Vec3 World::velocity(int i) const { return impl_->full_velocity(impl_->place(i)); }
Vec3 World::angular_velocity(int i) const { return impl_->full_angular_velocity(impl_->place(i)); }
double World::radius(int i) const { return impl_->radius[impl_->place(i)]; }
double World::mass(int i) const { return impl_->mass[impl_->place(i)]; }
int World::compartment(int i) const { return impl_->compartment[impl_->place(i)]; }
double World::bed_mass_kg() const { return impl_->bed_mass; }
double World::clearance_m(int c) const { return impl_->clearances.at(static_cast<std::size_t>(c)); }

Vec3 World::bed_momentum() const {
  Vec3 p{0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < static_cast<std::size_t>(impl_->n); ++k) {
    const Vec3 v = impl_->full_velocity(k);
    const double m = impl_->mass[k];
    for (std::size_t a = 0; a < 3; ++a) p[a] += m * v[a];
  }
  return p;
}

Vec3 World::bed_centre_of_mass() const {
  Vec3 c{0.0, 0.0, 0.0};
  const Impl& w = *impl_;
  for (std::size_t k = 0; k < static_cast<std::size_t>(w.n); ++k) {
    c[0] += w.mass[k] * w.x[k];
    c[1] += w.mass[k] * w.y[k];
    c[2] += w.mass[k] * w.z[k];
  }
  for (auto& v : c) v /= w.bed_mass;
  return c;
}

EnergyAccount World::energy() const {
  const Impl& w = *impl_;
  EnergyAccount e;
  e.container_work_j = w.container_work;
  e.normal_damping_j = w.normal_damping;
  e.friction_j = w.friction;
  e.rolling_j = w.rolling;
  e.kinetic_j = w.kinetic_energy();
  e.potential_j = w.potential_energy();
  e.elastic_j = w.elastic_energy();
  return e;
}

ContactCensus World::contact_census(const Vec3& down) const {
  const Impl& w = *impl_;
  auto& flags = w.census_flags;
  flags.assign(static_cast<std::size_t>(w.n), 0);
  const auto& pair_pool = w.pairs.pool;
  for (std::size_t e = 0; e < pair_pool.size(); ++e) {
    if (pair_pool.state[e].history.gamma < 0.0) continue;
    flags[static_cast<std::size_t>(pair_pool.keys[e].i)] |= 1;
    flags[static_cast<std::size_t>(pair_pool.keys[e].j)] |= 1;
  }
  const double norm = std::sqrt(down[0] * down[0] + down[1] * down[1] + down[2] * down[2]);
  const auto& R = w.container.orientation;
  const auto& wall_pool = w.wall_rows.pool;
  for (std::size_t e = 0; e < wall_pool.size(); ++e) {
    if (wall_pool.state[e].history.gamma < 0.0) continue;
    const auto i = static_cast<std::size_t>(wall_pool.keys[e].i);
    flags[i] |= 2;
    if (norm > 0.0) {
      double p[3];
      w.to_body(w.x[i], w.y[i], w.z[i], p);
      double nb[3];
      detail::wall_gap(w.walls[static_cast<std::size_t>(wall_pool.keys[e].j)], p, w.radius[i], nb);
      double along = 0.0;
      for (std::size_t a = 0; a < 3; ++a) along += (R[3 * a] * nb[0] + R[3 * a + 1] * nb[1] + R[3 * a + 2] * nb[2]) * down[a];
      if (along > 0.70710678 * norm) flags[i] |= 4;
    }
  }
  ContactCensus census;
  for (const unsigned char f : flags) {
    census.touching_walls += (f & 2) ? 1 : 0;
    census.touching_base += (f & 4) ? 1 : 0;
    census.airborne += f == 0 ? 1 : 0;
  }
  return census;
}

std::vector<int> World::contacts_per_particle() const {
  const Impl& w = *impl_;
  std::vector<int> count(static_cast<std::size_t>(w.n), 0);
  const auto& pairs = w.pairs.pool;
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    if (pairs.state[e].history.gamma < 0.0) continue;  // listed, not touching
    ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(pairs.keys[e].i)])];
    ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(pairs.keys[e].j)])];
  }
  const auto& walls = w.wall_rows.pool;
  for (std::size_t e = 0; e < walls.size(); ++e)
    if (walls.state[e].history.gamma >= 0.0) ++count[static_cast<std::size_t>(w.order[static_cast<std::size_t>(walls.keys[e].i)])];
  return count;
}

int World::contact_count() const {
  int count = 0;
  for (const auto& c : impl_->pairs.pool.state) count += c.history.gamma >= 0.0 ? 1 : 0;
  return count;
}

std::int64_t World::neighbour_rebuilds() const { return impl_->rebuilds; }
const StageTimes& World::stage_times() const { return impl_->stage_times; }

std::size_t World::memory_bytes() const {
  const Impl& w = *impl_;
  std::size_t bytes = 0;
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx,
                        &w.ty, &w.tz, &w.radius, &w.mass, &w.inv_mass, &w.inv_inertia, &w.rx, &w.ry, &w.rz,
                        &w.scratch}) {
    bytes += v->capacity() * sizeof(double);
  }
  for (const auto* v : {&w.material, &w.compartment, &w.order, &w.index_of, &w.scratch_index}) {
    bytes += v->capacity() * sizeof(int);
  }
  for (const auto& p : w.parts) {
    bytes += sizeof(Partition) + p.halo.capacity() * sizeof(double) +
             (p.fresh_pairs.capacity() + p.fresh_walls.capacity()) * sizeof(StagedContact);
  }
  bytes += w.pairs.memory_bytes() + w.wall_rows.memory_bytes();
  bytes += w.grid.memory_bytes() + w.walls.capacity() * sizeof(WallFeature);
  return bytes;
}

std::uint64_t World::state_hash() const {
  const Impl& w = *impl_;
  std::uint64_t hash = 14695981039346656037ULL;
  // In the caller's particle order: the hash does not see the internal numbering.
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz}) {
    for (const int k : w.index_of) {
      const auto* bytes = reinterpret_cast<const unsigned char*>(v->data() + k);
      for (std::size_t b = 0; b < sizeof(double); ++b) {
        hash ^= bytes[b];
        hash *= 1099511628211ULL;
      }
    }
  }
  return hash;
}

}  // namespace pdamp::dem_reference

// ------------------------------------------------------------------ checkpoints

namespace pdamp::dem_reference {

namespace {

void write_rows(StateWriter& out, const RowList& rows, bool with_rolling) {
  out.i32s(rows.offsets);
  out.i64(static_cast<std::int64_t>(rows.slots.size()));
  for (const Slot& s : rows.slots) {
    out.i32(s.i);
    out.i32(s.j);
    out.i32(s.contact);
  }
  out.i64(static_cast<std::int64_t>(rows.pool.size()));
  for (std::size_t e = 0; e < rows.pool.size(); ++e) {
    out.i32(rows.pool.keys[e].i);
    out.i32(rows.pool.keys[e].j);
    const ContactHistory& h = rows.pool.state[e].history;
    for (double v : {h.ft[0], h.ft[1], h.ft[2], h.inv_kt_prev, h.gamma, h.fd_prev, h.fn_prev}) out.f64(v);
    if (with_rolling)
      for (double v : rows.pool.rolling[e]) out.f64(v);
  }
}

/// Reads rows written by write_rows. `partner_ok(i, j)` says whether row i may list
/// partner j (a later particle, or a wall of i's compartment); `params(i, j)` gives the
/// contact parameters, which depend on the options only and are not stored.
template <class PartnerOk, class Params>
void read_rows(StateReader& in, RowList& rows, int n, bool with_rolling, PartnerOk&& partner_ok, Params&& params) {
  const auto un = static_cast<std::size_t>(n);
  rows.offsets = in.i32s("rows.offsets", un + 1, 0, std::numeric_limits<int>::max());
  const std::size_t slots = in.count("rows.slots", static_cast<std::size_t>(std::numeric_limits<int>::max()), 12);
  if (rows.offsets[0] != 0 || static_cast<std::size_t>(rows.offsets[un]) != slots)
    in.fail("rows.offsets", "must run from 0 to the slot count " + std::to_string(slots));
  for (std::size_t i = 0; i < un; ++i)
    if (rows.offsets[i + 1] < rows.offsets[i]) in.fail("rows.offsets", "must not decrease");
  rows.slots.resize(slots);
  for (auto& s : rows.slots) {
    s.i = in.i32("rows.slot.i");
    s.j = in.i32("rows.slot.j");
    s.contact = in.i32("rows.slot.contact");
  }
  const std::size_t entry_bytes = 8 + 7 * 8 + (with_rolling ? 24 : 0);
  const std::size_t pool = in.count("rows.pool", slots, entry_bytes);
  rows.pool.resize(pool);
  for (std::size_t e = 0; e < pool; ++e) {
    ContactKey& key = rows.pool.keys[e];
    key.i = in.i32_in("rows.pool.key.i", 0, n - 1);
    key.j = in.i32("rows.pool.key.j");
    if (!partner_ok(key.i, key.j)) in.fail("rows.pool.key.j", "= " + std::to_string(key.j) + ": no partner of particle " + std::to_string(key.i));
    ContactHistory& h = rows.pool.state[e].history;
    for (double* v : {&h.ft[0], &h.ft[1], &h.ft[2], &h.inv_kt_prev, &h.gamma, &h.fd_prev, &h.fn_prev})
      *v = in.finite("rows.pool.history");
    if (with_rolling)
      for (double& v : rows.pool.rolling[e]) v = in.finite("rows.pool.rolling_torque");
    rows.pool.state[e].params = params(key.i, key.j);
  }
  std::vector<unsigned char> used(pool, 0);
  for (std::size_t i = 0; i < un; ++i) {
    for (int k = rows.offsets[i]; k < rows.offsets[i + 1]; ++k) {
      const Slot& s = rows.slots[static_cast<std::size_t>(k)];
      if (s.i != static_cast<int>(i) || !partner_ok(s.i, s.j)) {
        std::ostringstream msg;  // a stream: GCC 12 flags "(" + std::string with a false -Wrestrict
        msg << "(" << s.i << ", " << s.j << ") in row " << i << ": not a pair this world can list";
        in.fail("rows.slot", msg.str());
      }
      if (s.contact < -1 || s.contact >= static_cast<int>(pool)) in.fail("rows.slot.contact", "points outside the pool");
      if (s.contact >= 0) {
        const auto c = static_cast<std::size_t>(s.contact);
        if (used[c]++ != 0 || rows.pool.keys[c].i != s.i || rows.pool.keys[c].j != s.j)
          in.fail("rows.slot.contact", "does not belong to its pair (or is shared)");
      }
    }
  }
  rows.target.clear();
}

}  // namespace

void World::save_state(StateWriter& out) const {
  const Impl& w = *impl_;
  const bool with_rolling = w.pairs.pool.with_rolling;
  out.tag("world");
  out.i32(w.n);
  out.i32(static_cast<std::int32_t>(w.options.compartments.size()));
  out.i32(static_cast<std::int32_t>(w.walls.size()));
  out.i32(static_cast<std::int32_t>(w.parts.size()));
  out.u8(with_rolling ? 1 : 0);
  out.f64(w.dt);
  out.i32(static_cast<std::int32_t>(w.status.outcome));
  out.text(w.status.message);
  out.f64(w.time);
  out.i64(w.steps);
  out.i64(w.rebuilds);
  out.u8(w.rebuild_due ? 1 : 0);
  const ContainerState& c = w.container;
  for (const auto* v : {&c.position_m, &c.velocity_m_s, &c.angular_velocity_rad_s})
    for (double x : *v) out.f64(x);
  for (double x : c.orientation) out.f64(x);
  out.u8(w.rotated ? 1 : 0);
  for (double x : w.container_velocity) out.f64(x);
  for (const auto* l : {&w.load, &w.load_previous})
    for (const auto* v : {&l->force_n, &l->moment_nm})
      for (double x : *v) out.f64(x);
  for (double x : {w.container_work, w.normal_damping, w.friction, w.rolling, w.initial_energy, w.max_d2, w.max_u2})
    out.f64(x);
  out.tag("particles");
  out.i32s(w.order);
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx, &w.ty,
                        &w.tz, &w.rx, &w.ry, &w.rz})
    out.f64s(*v);
  out.tag("pairs");
  write_rows(out, w.pairs, with_rolling);
  out.tag("walls");
  write_rows(out, w.wall_rows, with_rolling);
  out.tag("partitions");
  for (const Partition& p : w.parts) {
    for (int v : {p.begin, p.end, p.head_end, p.halo_end, p.early_end}) out.i32(v);
    for (double v : {p.max_d2, p.max_u2, p.dissipation.normal_damping, p.dissipation.friction, p.dissipation.rolling,
                     p.dissipation.max_overlap_ratio})
      out.f64(v);
    out.i32(p.dissipation.contacts);
    for (const double* v : {p.load.force, p.load.moment})
      for (int a = 0; a < 3; ++a) out.f64(v[a]);
  }
  out.tag("end of world");
}

void World::restore_state(StateReader& in) {
  const Impl& now = *impl_;
  auto staged = std::make_unique<Impl>(now);
  Impl& w = *staged;
  const bool with_rolling = w.pairs.pool.with_rolling;
  const auto same = [&](const char* field, long long saved, long long here) {
    if (saved != here)
      in.fail(field, "= " + std::to_string(saved) + " in the state, " + std::to_string(here) +
                         " in this world: a state of another world (other case, options or thread count)");
  };
  in.expect_tag("world");
  same("particles", in.i32("particles"), w.n);
  same("compartments", in.i32("compartments"), static_cast<long long>(w.options.compartments.size()));
  same("walls", in.i32("walls"), static_cast<long long>(w.walls.size()));
  same("partitions", in.i32("partitions"), static_cast<long long>(w.parts.size()));
  same("rolling resistance", in.boolean("rolling resistance") ? 1 : 0, with_rolling ? 1 : 0);
  const double dt = in.f64("time_step_s");
  if (std::bit_cast<std::uint64_t>(dt) != std::bit_cast<std::uint64_t>(w.dt)) {
    std::ostringstream msg;
    msg.precision(17);
    msg << "= " << dt << " s in the state, " << w.dt << " s in this world: a state of another world";
    in.fail("time_step_s", msg.str());
  }
  w.status.outcome = static_cast<Outcome>(in.i32_in("status.outcome", 0, 2));
  w.status.message = in.text("status.message", 1 << 16);
  w.time = in.finite("time_s");
  w.steps = in.i64("steps");
  w.rebuilds = in.i64("rebuilds");
  if (w.steps < 0 || w.rebuilds < 0) in.fail("steps", "must not be negative");
  w.rebuild_due = in.boolean("rebuild_due");
  ContainerState& c = w.container;
  for (auto* v : {&c.position_m, &c.velocity_m_s, &c.angular_velocity_rad_s})
    for (double& x : *v) x = in.finite("container");
  for (double& x : c.orientation) x = in.finite("container.orientation");
  w.rotated = in.boolean("container.rotated");
  for (double& x : w.container_velocity) x = in.finite("container.velocity");
  for (auto* l : {&w.load, &w.load_previous})
    for (auto* v : {&l->force_n, &l->moment_nm})
      for (double& x : *v) x = in.finite("load");
  for (double* x : {&w.container_work, &w.normal_damping, &w.friction, &w.rolling, &w.initial_energy, &w.max_d2, &w.max_u2})
    *x = in.finite("energy account");

  in.expect_tag("particles");
  const auto un = static_cast<std::size_t>(w.n);
  w.order = in.i32s("order", un, 0, w.n - 1);
  std::vector<unsigned char> seen(un, 0);
  for (int id : w.order)
    if (seen[static_cast<std::size_t>(id)]++ != 0) in.fail("order", "is no permutation of the particles");
  for (std::size_t k = 0; k < un; ++k) w.index_of[static_cast<std::size_t>(w.order[k])] = static_cast<int>(k);
  // What the options fix, at the state's places: particle id order[k] sits at place k.
  for (std::size_t k = 0; k < un; ++k) {
    const std::size_t from = now.place(w.order[k]);
    w.radius[k] = now.radius[from];
    w.mass[k] = now.mass[from];
    w.inv_mass[k] = now.inv_mass[from];
    w.inv_inertia[k] = now.inv_inertia[from];
    w.material[k] = now.material[from];
    w.compartment[k] = now.compartment[from];
  }
  for (auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx, &w.ty, &w.tz,
                  &w.rx, &w.ry, &w.rz})
    *v = in.finite_f64s("particles", un);

  in.expect_tag("pairs");
  read_rows(
      in, w.pairs, w.n, with_rolling,
      [&](int i, int j) {
        return j > i && j < w.n && w.compartment[static_cast<std::size_t>(i)] == w.compartment[static_cast<std::size_t>(j)];
      },
      [&](int a, int b) { return w.particle_pair_contact(static_cast<std::size_t>(a), static_cast<std::size_t>(b)).params; });
  in.expect_tag("walls");
  read_rows(
      in, w.wall_rows, w.n, with_rolling,
      [&](int i, int j) {
        const auto c = static_cast<std::size_t>(w.compartment[static_cast<std::size_t>(i)]);
        return j >= w.wall_begin[c] && j < w.wall_end[c];
      },
      [&](int a, int wall) { return w.particle_wall_contact(static_cast<std::size_t>(a), wall).params; });

  in.expect_tag("partitions");
  int next = 0;
  for (Partition& p : w.parts) {
    p.begin = in.i32_in("partition.begin", next, next);
    p.end = in.i32_in("partition.end", p.begin, w.n);
    p.head_end = in.i32_in("partition.head_end", p.begin, p.end);
    p.halo_end = in.i32_in("partition.halo_end", p.end, w.n);
    p.early_end = in.i32_in("partition.early_end", p.begin, p.end);
    next = p.end;
    for (double* v : {&p.max_d2, &p.max_u2, &p.dissipation.normal_damping, &p.dissipation.friction,
                      &p.dissipation.rolling, &p.dissipation.max_overlap_ratio})
      *v = in.finite("partition");
    p.dissipation.contacts = in.i32_in("partition.contacts", 0, std::numeric_limits<int>::max());
    for (double* v : {p.load.force, p.load.moment})
      for (int a = 0; a < 3; ++a) v[a] = in.finite("partition.load");
    p.halo.assign(6 * static_cast<std::size_t>(p.halo_end - p.end), 0.0);
    p.fresh_pairs.clear();
    p.fresh_walls.clear();
  }
  if (next != w.n) in.fail("partitions", "must cover every particle");
  in.expect_tag("end of world");
  impl_ = std::move(staged);
}

}  // namespace pdamp::dem_reference
