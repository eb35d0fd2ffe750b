// The reference DEM world: particle state (struct of arrays), the staged step
// (integrate → neighbours → contact forces → wall forces → accumulate → record),
// the energy account and the instability checks.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <omp.h>

#include "broad_phase.hpp"
#include "contact_law.hpp"
#include "initial_state.hpp"
#include "walls.hpp"
#include "world_data.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::ContactHistory;
using detail::ContactKinematics;
using detail::ContactResult;
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

/// Runs body(thread, team_size) on the calling thread alone when team is 1 (no OpenMP
/// region at all: even an `if(false)` region costs a fork/join call and futex traffic,
/// more than a 36-sphere step), else on an OpenMP team. Returns the team size used.
template <class Body>
int run_team(int team, Body&& body) {
  if (team <= 1) {
    body(0, 1);
    return 1;
  }
  int used = 1;
#pragma omp parallel num_threads(team)
  {
    const int size = omp_get_num_threads();
#pragma omp single
    used = size;
    body(omp_get_thread_num(), size);
  }
  return used;
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
  double integrate();
  void rebuild_lists();
  void compute_forces();
  void record(const ContainerState& previous);
  void check_health();

  Vec3 full_velocity(int i) const;
  Vec3 full_angular_velocity(int i) const;
  double elastic_energy() const;
  double kinetic_energy() const;
  double potential_energy() const;
  void mark_unstable(const std::string& message);
  bool parallel() const { return threads > 1 && n > kParallelParticles; }
  void to_body(double px, double py, double pz, double* out) const;

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

  // Particles (struct of arrays).
  int n = 0;
  std::vector<double> x, y, z, vx, vy, vz, wx, wy, wz;  // positions; half-step velocities
  std::vector<double> fx, fy, fz, tx, ty, tz;          // forces and torques at the current positions
  std::vector<double> radius, mass, inv_mass, inv_inertia;
  std::vector<double> lx, ly, lz;  // body-frame positions at the current step
  std::vector<double> rx, ry, rz;  // body-frame positions at the last rebuild
  std::vector<int> material, compartment;
  std::vector<double> clearances;
  double bed_mass = 0.0;

  // Per-thread force buffers (thread 0 writes the main arrays) and sums.
  std::vector<std::vector<double>> buffers;
  std::vector<StepDissipation> thread_dissipation;
  std::vector<LoadSums> thread_load;
  std::vector<double> thread_max;
  int last_team = 1;  // team size of the last force computation

  // Verlet lists and contact history.
  detail::CellGrid grid;
  std::vector<Slot> pairs, wall_slots;
  std::vector<ContactHistory> history, wall_history;
  std::vector<detail::ActiveContact> active;  // scratch of a rebuild
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
                  &inv_mass, &inv_inertia, &lx, &ly, &lz, &rx, &ry, &rz}) {
    v->assign(un, 0.0);
  }
  material = bed.materials;
  compartment = bed.compartments;
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

  buffers.resize(static_cast<std::size_t>(std::max(threads - 1, 0)));
  if (threads > 1 && n > kParallelParticles) {
    for (auto& b : buffers) b.assign(6 * un, 0.0);
  }
  thread_dissipation.resize(static_cast<std::size_t>(threads));
  thread_load.resize(static_cast<std::size_t>(threads));
  thread_max.resize(static_cast<std::size_t>(threads));
  // Typical beds list a few neighbours per sphere; reserving avoids regrowth in the loop.
  pairs.reserve(4 * un);
  history.reserve(4 * un);
  active.reserve(4 * un);
  wall_slots.reserve(un);
  wall_history.reserve(un);

  for (int i = 0; i < n; ++i) {
    double body[3];
    to_body(x[static_cast<std::size_t>(i)], y[static_cast<std::size_t>(i)], z[static_cast<std::size_t>(i)], body);
    lx[static_cast<std::size_t>(i)] = body[0];
    ly[static_cast<std::size_t>(i)] = body[1];
    lz[static_cast<std::size_t>(i)] = body[2];
  }
  for (std::size_t i = 0; i < un; ++i) {
    fx[i] = mass[i] * g[0];
    fy[i] = mass[i] * g[1];
    fz[i] = mass[i] * g[2];
  }
  rebuild_lists();
  compute_forces();
  // Leapfrog start: store v(−dt/2) so that the first kick gives v(0) + F(0)dt/2m.
  for (std::size_t i = 0; i < un; ++i) {
    vx[i] -= 0.5 * dt * fx[i] * inv_mass[i];
    vy[i] -= 0.5 * dt * fy[i] * inv_mass[i];
    vz[i] -= 0.5 * dt * fz[i] * inv_mass[i];
    wx[i] -= 0.5 * dt * tx[i] * inv_inertia[i];
    wy[i] -= 0.5 * dt * ty[i] * inv_inertia[i];
    wz[i] -= 0.5 * dt * tz[i] * inv_inertia[i];
  }
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

double World::Impl::integrate() {
  const double h = dt;
  const double g0 = options.gravity_m_s2[0], g1 = options.gravity_m_s2[1], g2 = options.gravity_m_s2[2];
  const int used = run_team(parallel() ? threads : 1, [&](int t, int size) {
    const auto [begin, end] = chunk(n, t, size);
    double max_d2 = 0.0;
    for (int i = begin; i < end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double im = inv_mass[k] * h;
      const double ii = inv_inertia[k] * h;
      vx[k] += fx[k] * im;
      vy[k] += fy[k] * im;
      vz[k] += fz[k] * im;
      wx[k] += tx[k] * ii;
      wy[k] += ty[k] * ii;
      wz[k] += tz[k] * ii;
      x[k] += vx[k] * h;
      y[k] += vy[k] * h;
      z[k] += vz[k] * h;
      double body[3];
      to_body(x[k], y[k], z[k], body);
      lx[k] = body[0];
      ly[k] = body[1];
      lz[k] = body[2];
      const double dx = body[0] - rx[k], dy = body[1] - ry[k], dz = body[2] - rz[k];
      max_d2 = std::max(max_d2, dx * dx + dy * dy + dz * dz);
      fx[k] = mass[k] * g0;
      fy[k] = mass[k] * g1;
      fz[k] = mass[k] * g2;
      tx[k] = ty[k] = tz[k] = 0.0;
    }
    thread_max[static_cast<std::size_t>(t)] = max_d2;
  });
  return *std::max_element(thread_max.begin(), thread_max.begin() + used);
}

void World::Impl::rebuild_lists() {
  ++rebuilds;
  grid.bin(lx.data(), ly.data(), lz.data(), n);
  detail::save_active(pairs, history, active);
  const int list_threads = parallel() ? threads : 1;
  grid.find_pairs(lx.data(), ly.data(), lz.data(), radius.data(), compartment.data(), n, skin, list_threads, pairs);
  const int pair_count = static_cast<int>(pairs.size());
  run_team(list_threads, [&](int t, int size) {
    const auto [begin, end] = chunk(pair_count, t, size);
    for (int s = begin; s < end; ++s) {
      Slot& slot = pairs[static_cast<std::size_t>(s)];
      const auto a = static_cast<std::size_t>(slot.i), b = static_cast<std::size_t>(slot.j);
      slot.params = law.particle_pair(radius[a], mass[a], material[a], radius[b], mass[b], material[b]);
    }
  });
  detail::restore_active(pairs, history, active);

  // Walls within the skin of each particle, in (particle, wall) order.
  detail::save_active(wall_slots, wall_history, active);
  wall_slots.clear();
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto c = static_cast<std::size_t>(compartment[k]);
    const double p[3] = {lx[k], ly[k], lz[k]};
    double nrm[3];
    for (int w = wall_begin[c]; w < wall_end[c]; ++w) {
      const auto& wall = walls[static_cast<std::size_t>(w)];
      if (detail::wall_gap(wall, p, radius[k], nrm) < skin) {
        Slot s;
        s.i = i;
        s.j = w;
        s.params = law.particle_wall(radius[k], mass[k], material[k], wall.material, detail::contact_curvature_radius(wall, p));
        wall_slots.push_back(s);
      }
    }
  }
  detail::restore_active(wall_slots, wall_history, active);
  std::copy(lx.begin(), lx.end(), rx.begin());
  std::copy(ly.begin(), ly.end(), ry.begin());
  std::copy(lz.begin(), lz.end(), rz.begin());
}

void World::Impl::compute_forces() {
  const int team = parallel() ? threads : 1;
  const double h = dt;
  const double limit = overlap_limit;
  const auto& R = container.orientation;
  const bool rot = rotated;
  const double cw[3] = {container.angular_velocity_rad_s[0], container.angular_velocity_rad_s[1],
                        container.angular_velocity_rad_s[2]};
  const double cp[3] = {container.position_m[0], container.position_m[1], container.position_m[2]};
  const double cv[3] = {container_velocity[0], container_velocity[1], container_velocity[2]};
  const auto un = static_cast<std::size_t>(n);
  const int pair_count = static_cast<int>(pairs.size());
  const int wall_count = static_cast<int>(wall_slots.size());
  const int used = run_team(team, [&](int t, int size) {
    double* Fx = fx.data();
    double* Fy = fy.data();
    double* Fz = fz.data();
    double* Tx = tx.data();
    double* Ty = ty.data();
    double* Tz = tz.data();
    if (t > 0) {
      double* b = buffers[static_cast<std::size_t>(t - 1)].data();
      Fx = b;
      Fy = b + un;
      Fz = b + 2 * un;
      Tx = b + 3 * un;
      Ty = b + 4 * un;
      Tz = b + 5 * un;
    }
    StepDissipation diss;
    LoadSums sums;
    ContactKinematics k;
    ContactResult out;
    const auto [pair_begin, pair_end] = chunk(pair_count, t, size);
    for (int s = pair_begin; s < pair_end; ++s) {
      const Slot& slot = pairs[static_cast<std::size_t>(s)];
      ContactHistory& hist = history[static_cast<std::size_t>(s)];
      const auto i = static_cast<std::size_t>(slot.i), j = static_cast<std::size_t>(slot.j);
      const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
      const double ri = radius[i], rj = radius[j];
      const double d2 = dx * dx + dy * dy + dz * dz;
      const double sum = ri + rj;
      if (d2 >= sum * sum) {
        if (hist.gamma >= 0.0) hist = ContactHistory{};
        continue;
      }
      const double dist = std::sqrt(d2);
      const double inv = 1.0 / dist;
      k.n[0] = dx * inv;
      k.n[1] = dy * inv;
      k.n[2] = dz * inv;
      k.delta = sum - dist;
      const double rmin = ri < rj ? ri : rj;
      if (k.delta > limit * rmin) diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, k.delta / rmin);
      // Contact-point velocity of i relative to j: v_i − v_j + (r_i ω_i + r_j ω_j) × n.
      const double ax = ri * wx[i] + rj * wx[j], ay = ri * wy[i] + rj * wy[j], az = ri * wz[i] + rj * wz[j];
      k.v[0] = vx[i] - vx[j] + ay * k.n[2] - az * k.n[1];
      k.v[1] = vy[i] - vy[j] + az * k.n[0] - ax * k.n[2];
      k.v[2] = vz[i] - vz[j] + ax * k.n[1] - ay * k.n[0];
      k.w[0] = wx[i] - wx[j];
      k.w[1] = wy[i] - wy[j];
      k.w[2] = wz[i] - wz[j];
      detail::contact_force(slot.params, hist, k, h, law, out, diss);
      Fx[i] += out.f[0];
      Fy[i] += out.f[1];
      Fz[i] += out.f[2];
      Fx[j] -= out.f[0];
      Fy[j] -= out.f[1];
      Fz[j] -= out.f[2];
      Tx[i] += ri * out.c[0] + out.m[0];
      Ty[i] += ri * out.c[1] + out.m[1];
      Tz[i] += ri * out.c[2] + out.m[2];
      Tx[j] += rj * out.c[0] - out.m[0];
      Ty[j] += rj * out.c[1] - out.m[1];
      Tz[j] += rj * out.c[2] - out.m[2];
    }
    const auto [wall_begin_s, wall_end_s] = chunk(wall_count, t, size);
    for (int s = wall_begin_s; s < wall_end_s; ++s) {
      const Slot& slot = wall_slots[static_cast<std::size_t>(s)];
      ContactHistory& hist = wall_history[static_cast<std::size_t>(s)];
      const auto i = static_cast<std::size_t>(slot.i);
      const double ri = radius[i];
      const double p[3] = {lx[i], ly[i], lz[i]};
      double nb[3];
      const double gap = detail::wall_gap(walls[static_cast<std::size_t>(slot.j)], p, ri, nb);
      if (gap >= 0.0) {
        if (hist.gamma >= 0.0) hist = ContactHistory{};
        continue;
      }
      if (rot) {
        k.n[0] = R[0] * nb[0] + R[1] * nb[1] + R[2] * nb[2];
        k.n[1] = R[3] * nb[0] + R[4] * nb[1] + R[5] * nb[2];
        k.n[2] = R[6] * nb[0] + R[7] * nb[1] + R[8] * nb[2];
      } else {
        k.n[0] = nb[0];
        k.n[1] = nb[1];
        k.n[2] = nb[2];
      }
      k.delta = -gap;
      if (k.delta > limit * ri) diss.max_overlap_ratio = std::max(diss.max_overlap_ratio, k.delta / ri);
      // Contact point and the wall's velocity there (translation + rotation).
      const double arm[3] = {ri * k.n[0], ri * k.n[1], ri * k.n[2]};
      const double rc[3] = {x[i] + arm[0] - cp[0], y[i] + arm[1] - cp[1], z[i] + arm[2] - cp[2]};
      const double vw[3] = {cv[0] + cw[1] * rc[2] - cw[2] * rc[1], cv[1] + cw[2] * rc[0] - cw[0] * rc[2],
                            cv[2] + cw[0] * rc[1] - cw[1] * rc[0]};
      k.v[0] = vx[i] + wy[i] * arm[2] - wz[i] * arm[1] - vw[0];
      k.v[1] = vy[i] + wz[i] * arm[0] - wx[i] * arm[2] - vw[1];
      k.v[2] = vz[i] + wx[i] * arm[1] - wy[i] * arm[0] - vw[2];
      k.w[0] = wx[i] - cw[0];
      k.w[1] = wy[i] - cw[1];
      k.w[2] = wz[i] - cw[2];
      detail::contact_force(slot.params, hist, k, h, law, out, diss);
      Fx[i] += out.f[0];
      Fy[i] += out.f[1];
      Fz[i] += out.f[2];
      Tx[i] += ri * out.c[0] + out.m[0];
      Ty[i] += ri * out.c[1] + out.m[1];
      Tz[i] += ri * out.c[2] + out.m[2];
      sums.force[0] += out.f[0];
      sums.force[1] += out.f[1];
      sums.force[2] += out.f[2];
      sums.moment[0] += rc[1] * out.f[2] - rc[2] * out.f[1] + out.m[0];
      sums.moment[1] += rc[2] * out.f[0] - rc[0] * out.f[2] + out.m[1];
      sums.moment[2] += rc[0] * out.f[1] - rc[1] * out.f[0] + out.m[2];
    }
    thread_dissipation[static_cast<std::size_t>(t)] = diss;
    thread_load[static_cast<std::size_t>(t)] = sums;
  });
  last_team = used;
  if (used > 1) {
    // Ordered reduction of the thread buffers: identical results run to run.
    const int extra = used - 1;
    run_team(used, [&](int t, int size) {
      const auto [begin, end] = chunk(n, t, size);
      for (int i = begin; i < end; ++i) {
        const auto k = static_cast<std::size_t>(i);
        for (int b = 0; b < extra; ++b) {
        double* buf = buffers[static_cast<std::size_t>(b)].data();
        fx[k] += buf[k];
        fy[k] += buf[un + k];
        fz[k] += buf[2 * un + k];
        tx[k] += buf[3 * un + k];
        ty[k] += buf[4 * un + k];
        tz[k] += buf[5 * un + k];
        buf[k] = buf[un + k] = buf[2 * un + k] = buf[3 * un + k] = buf[4 * un + k] = buf[5 * un + k] = 0.0;
        }
      }
    });
  }
  load = ContainerLoad{};
  for (int t = 0; t < used; ++t) {
    const auto& s = thread_load[static_cast<std::size_t>(t)];
    for (std::size_t a = 0; a < 3; ++a) {
      load.force_n[a] += s.force[a];
      load.moment_nm[a] += s.moment[a];
    }
  }
}

void World::Impl::record(const ContainerState& previous) {
  double max_ratio = 0.0;
  for (int t = 0; t < last_team; ++t) {
    const auto& d = thread_dissipation[static_cast<std::size_t>(t)];
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

void World::Impl::mark_unstable(const std::string& message) {
  if (status.outcome == Outcome::kUnstable) return;
  status.outcome = Outcome::kUnstable;
  status.message = message;
}

Vec3 World::Impl::full_velocity(int i) const {
  const auto k = static_cast<std::size_t>(i);
  const double s = 0.5 * dt * inv_mass[k];
  return {vx[k] + s * fx[k], vy[k] + s * fy[k], vz[k] + s * fz[k]};
}

Vec3 World::Impl::full_angular_velocity(int i) const {
  const auto k = static_cast<std::size_t>(i);
  const double s = 0.5 * dt * inv_inertia[k];
  return {wx[k] + s * tx[k], wy[k] + s * ty[k], wz[k] + s * tz[k]};
}

double World::Impl::kinetic_energy() const {
  double e = 0.0;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Vec3 v = full_velocity(i);
    const Vec3 w = full_angular_velocity(i);
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
  for (std::size_t s = 0; s < pairs.size(); ++s) {
    const auto i = static_cast<std::size_t>(pairs[s].i), j = static_cast<std::size_t>(pairs[s].j);
    const double dx = x[j] - x[i], dy = y[j] - y[i], dz = z[j] - z[i];
    const double delta = radius[i] + radius[j] - std::sqrt(dx * dx + dy * dy + dz * dz);
    e += detail::stored_energy(pairs[s].params, law.type(pairs[s].params.pair_type), history[s], delta);
  }
  for (std::size_t s = 0; s < wall_slots.size(); ++s) {
    const auto i = static_cast<std::size_t>(wall_slots[s].i);
    const double p[3] = {lx[i], ly[i], lz[i]};
    double nb[3];
    const double gap = detail::wall_gap(walls[static_cast<std::size_t>(wall_slots[s].j)], p, radius[i], nb);
    e += detail::stored_energy(wall_slots[s].params, law.type(wall_slots[s].params.pair_type), wall_history[s],
                               -gap);
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
  const auto t0 = timed ? Clock::now() : Clock::time_point{};
  const ContainerState previous = w.container;
  w.container = next;
  w.rotated = next.orientation != kIdentity;
  for (std::size_t a = 0; a < 3; ++a) {
    w.container_velocity[a] = (next.position_m[a] - previous.position_m[a]) / w.dt;
  }
  const double max_d2 = w.integrate();
  const auto t1 = timed ? Clock::now() : Clock::time_point{};
  if (w.rebuild_due || max_d2 > 0.25 * w.skin * w.skin) {
    w.rebuild_due = false;
    w.rebuild_lists();
  }
  const auto t2 = timed ? Clock::now() : Clock::time_point{};
  w.compute_forces();
  const auto t3 = timed ? Clock::now() : Clock::time_point{};
  w.time += w.dt;
  ++w.steps;
  w.record(previous);
  if (w.steps % kHealthStride == 0) w.check_health();
  if (timed) {
    const auto t4 = Clock::now();
    const auto span = [](Clock::time_point a, Clock::time_point b) {
      return kTimingStride * std::chrono::duration<double>(b - a).count();
    };
    w.stage_times.integrate_s += span(t0, t1);
    w.stage_times.neighbour_s += span(t1, t2);
    w.stage_times.contact_forces_s += span(t2, t3);
    w.stage_times.record_s += span(t3, t4);
  }
  return w.load;
}

const ContainerLoad& World::step(const ContainerMotion& motion) {
  return step(motion.state(impl_->time + impl_->dt));
}

void World::set_particle_state(int i, const Vec3& position_m, const Vec3& velocity_m_s,
                               const Vec3& angular_velocity_rad_s) {
  Impl& w = *impl_;
  const auto k = static_cast<std::size_t>(i);
  (void)w.x.at(k);
  const double before = w.kinetic_energy() + w.potential_energy();
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
  double body[3];
  w.to_body(w.x[k], w.y[k], w.z[k], body);
  w.lx[k] = body[0];
  w.ly[k] = body[1];
  w.lz[k] = body[2];
  // The energy set here is supplied, not created: keep the growth check honest.
  w.initial_energy += w.kinetic_energy() + w.potential_energy() - before;
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
}

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
  const auto k = static_cast<std::size_t>(i);
  return {impl_->x.at(k), impl_->y[k], impl_->z[k]};
}
Vec3 World::velocity(int i) const {
  (void)impl_->x.at(static_cast<std::size_t>(i));
  return impl_->full_velocity(i);
}
Vec3 World::angular_velocity(int i) const {
  (void)impl_->x.at(static_cast<std::size_t>(i));
  return impl_->full_angular_velocity(i);
}
double World::radius(int i) const { return impl_->radius.at(static_cast<std::size_t>(i)); }
double World::mass(int i) const { return impl_->mass.at(static_cast<std::size_t>(i)); }
int World::compartment(int i) const { return impl_->compartment.at(static_cast<std::size_t>(i)); }
double World::bed_mass_kg() const { return impl_->bed_mass; }
double World::clearance_m(int c) const { return impl_->clearances.at(static_cast<std::size_t>(c)); }

Vec3 World::bed_momentum() const {
  Vec3 p{0.0, 0.0, 0.0};
  for (int i = 0; i < impl_->n; ++i) {
    const Vec3 v = impl_->full_velocity(i);
    const double m = impl_->mass[static_cast<std::size_t>(i)];
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
  for (std::size_t s = 0; s < w.pairs.size(); ++s) {
    if (w.history[s].gamma < 0.0) continue;
    flags[static_cast<std::size_t>(w.pairs[s].i)] |= 1;
    flags[static_cast<std::size_t>(w.pairs[s].j)] |= 1;
  }
  const double norm = std::sqrt(down[0] * down[0] + down[1] * down[1] + down[2] * down[2]);
  const auto& R = w.container.orientation;
  for (std::size_t s = 0; s < w.wall_slots.size(); ++s) {
    if (w.wall_history[s].gamma < 0.0) continue;
    const auto i = static_cast<std::size_t>(w.wall_slots[s].i);
    flags[i] |= 2;
    if (norm > 0.0) {
      const double p[3] = {w.lx[i], w.ly[i], w.lz[i]};
      double nb[3];
      detail::wall_gap(w.walls[static_cast<std::size_t>(w.wall_slots[s].j)], p, w.radius[i], nb);
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

int World::contact_count() const {
  int count = 0;
  for (const auto& h : impl_->history) count += h.gamma >= 0.0 ? 1 : 0;
  return count;
}

std::int64_t World::neighbour_rebuilds() const { return impl_->rebuilds; }
const StageTimes& World::stage_times() const { return impl_->stage_times; }

std::size_t World::memory_bytes() const {
  const Impl& w = *impl_;
  std::size_t bytes = 0;
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz, &w.fx, &w.fy, &w.fz, &w.tx,
                        &w.ty, &w.tz, &w.radius, &w.mass, &w.inv_mass, &w.inv_inertia, &w.lx, &w.ly, &w.lz, &w.rx,
                        &w.ry, &w.rz}) {
    bytes += v->capacity() * sizeof(double);
  }
  bytes += (w.material.capacity() + w.compartment.capacity()) * sizeof(int);
  for (const auto& b : w.buffers) bytes += b.capacity() * sizeof(double);
  bytes += (w.pairs.capacity() + w.wall_slots.capacity()) * sizeof(Slot);
  bytes += (w.history.capacity() + w.wall_history.capacity()) * sizeof(ContactHistory);
  bytes += w.active.capacity() * sizeof(detail::ActiveContact);
  bytes += w.grid.memory_bytes() + w.walls.capacity() * sizeof(WallFeature);
  return bytes;
}

std::uint64_t World::state_hash() const {
  const Impl& w = *impl_;
  std::uint64_t hash = 14695981039346656037ULL;
  for (const auto* v : {&w.x, &w.y, &w.z, &w.vx, &w.vy, &w.vz, &w.wx, &w.wy, &w.wz}) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(v->data());
    for (std::size_t b = 0; b < v->size() * sizeof(double); ++b) {
      hash ^= bytes[b];
      hash *= 1099511628211ULL;
    }
  }
  return hash;
}

}  // namespace pdamp::dem_reference
