// The world's construction: time_step_bound(), the options checked, walls, bed, grid, reserves, the first forces.
#include "pdamp/dem_reference/world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <omp.h>

#include "initial_state.hpp"
#include "world_impl.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::run_team;

constexpr double kPi = 3.14159265358979323846;

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

double restitution_error_bound(double restitution, double steps_per_contact) {
  const double l = std::log(restitution);
  return (0.6 * l * l + 0.1) / steps_per_contact;
}

double smallest_restitution(const WorldOptions& options) {
  double e = 1.0;
  bool model = false;
  const auto consider = [&](const ContactPairOptions& p) {
    const auto& r = p.restitution;
    if (r.model) {
      model = true;
    } else if (!r.table_values.empty()) {
      e = std::min(e, *std::min_element(r.table_values.begin(), r.table_values.end()));
    } else {
      e = std::min(e, r.constant);
    }
  };
  consider(options.default_pair);
  for (const auto& p : options.pairs) consider(p);
  return model ? std::numeric_limits<double>::quiet_NaN() : e;
}

// Why fewer than 50 steps where ε allows: the step count of every run is the cost, and the
// error one impact's restitution takes from the discretisation is (0.6 ln²ε + 0.1)/N at
// the largest impact speed (slower impacts last longer and are resolved better): at
// ε = 0.8, 20 steps give 0.65 %, well inside what a measured ε is known to.
int automatic_steps_per_contact(const WorldOptions& options) {
  const double e = smallest_restitution(options);
  if (!(e > 0.0)) return kMaxAutomaticStepsPerContact;
  const double needed = std::ceil(restitution_error_bound(e, 1.0) / kAutomaticRestitutionError);
  return static_cast<int>(std::clamp(needed, double{limits::kMinStepsPerContact}, double{kMaxAutomaticStepsPerContact}));
}

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
  bound.steps_per_contact = options.integration.steps_per_contact > 0 ? options.integration.steps_per_contact
                                                                      : automatic_steps_per_contact(options);
  bound.max_time_step_s = std::min(bound.contact_time_s / bound.steps_per_contact,
                                   options.integration.rayleigh_fraction * bound.rayleigh_time_s);
  return bound;
}

World::Impl::Impl(const WorldOptions& o, const ContainerState& start) : options(o), law((check_options(o), o)) {
  bound = dem_reference::time_step_bound(options);
  const auto& integ = options.integration;
  if (integ.time_step_s > 0.0) {
    if (integ.time_step_s > bound.max_time_step_s) {
      std::ostringstream msg;
      msg << "integration.time_step_s = " << integ.time_step_s << ": must be <= " << bound.max_time_step_s
          << " s (contact time " << bound.contact_time_s << " s at " << integ.max_impact_speed_m_s
          << " m/s over " << bound.steps_per_contact << " steps, or " << integ.rayleigh_fraction
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

World::World(const WorldOptions& options, const ContainerState& start)
    : impl_(std::make_unique<Impl>(options, start)) {}
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

}  // namespace pdamp::dem_reference
