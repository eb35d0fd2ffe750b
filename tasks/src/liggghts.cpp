// pdamp dem's run as a LIGGGHTS deck, and its output read back (liggghts.hpp, docs/liggghts.md).
#include "pdamp/tasks/liggghts.hpp"

#include <charconv>
#include <cmath>
#include <iomanip>
#include <limits>
#include <locale>
#include <numbers>
#include <sstream>

#include "pdamp/case_file/ranges.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/surrogate/effective_field.hpp"
#include "pdamp/formulas/cor_models.hpp"
#include "pdamp/base/input_error.hpp"
#include "pdamp/base/input_file.hpp"
#include "pdamp/base/number_text.hpp"
#include "pdamp/base/strict_object.hpp"
#include "task_support.hpp"

namespace pdamp::tasks {

namespace fm = formulas;
namespace dr = dem_reference;
using base::format_number;
using base::InputError;
using nlohmann::json;

namespace {

constexpr const char* kRecordFormat = "pdamp_liggghts_export";
constexpr int kRecordFormatVersion = 1;
constexpr const char* kAxisNames[3] = {"x", "y", "z"};

/// Numbers in the deck: 17 significant digits, which LIGGGHTS reads back to the last bit.
constexpr int kDeckDigits = 17;

/// FNV-1a over the deck's files: the export's identity, written into the title line of
/// every output file, so that an import never reads the output of an earlier deck.
std::string deck_id(const std::vector<std::pair<std::string, std::string>>& files) {
  std::uint64_t hash = 1469598103934665603ull;
  for (const auto& [name, content] : files)
    for (const std::string* text : {&name, &content})
      for (const unsigned char byte : *text) {
        hash ^= byte;
        hash *= 1099511628211ull;
      }
  std::ostringstream out;
  out << std::hex << std::setw(16) << std::setfill('0') << hash;
  return out.str();
}

/// The case key of a layer's DEM geometry: /dem/<key> in format 1, in the layer in format 2.
std::string layer_key(const case_file::Case& c, const std::string& key) {
  return c.format_version == 1 ? "/dem/" + key : "/dampers/0/layers/0/" + key;
}

/// `run N` as LIGGGHTS takes it: N in pieces of at most 2^31 − 1 steps (its run command's
/// bound); consecutive runs continue the same simulation (timestep, fixes, files).
template <class Line>
void run_lines(const Line& line, std::int64_t steps) {
  constexpr std::int64_t kMaxRunSteps = 2147483647;
  while (steps > 0) {
    const std::int64_t piece = std::min(steps, kMaxRunSteps);
    line("run " + std::to_string(piece));
    steps -= piece;
  }
}

const dr::ContactPairOptions& pair_of(const dr::WorldOptions& world, int a, int b) {
  for (const auto& p : world.pairs)
    if ((p.material_a == a && p.material_b == b) || (p.material_a == b && p.material_b == a)) return p;
  return world.default_pair;
}

/// Refuses what the deck cannot run as pdamp does, naming the case key.
void check_exportable(const case_file::Case& c, const dr::DamperSimulationOptions& o) {
  const auto& compartment = o.world.compartments.front();
  const std::string no = "has no counterpart in the LIGGGHTS export (docs/liggghts.md, \"What is exported\"): ";
  if (!compartment.plates.empty() || !compartment.pins.empty())
    throw InputError(c.path, layer_key(c, "inner_structures"), no + "run this case with pdamp dem");
  if (compartment.layer.thickness_m > 0.0)
    throw InputError(c.path, layer_key(c, "wall_layer"),
                     no + "LIGGGHTS has no bonded-layer contact law; run this case with pdamp dem");
  if (o.approach_amplitude_m > 0.0)
    throw InputError(c.path, "/dem/approach", no + "the deck drives the bed from rest; remove the approach or use pdamp dem");
  const auto table = [](const dr::ContactPairOptions& p) { return p.restitution.model || !p.restitution.table_values.empty(); };
  if (table(o.world.default_pair))
    throw InputError(c.path, "/dem/contact/restitution",
                     no + "LIGGGHTS takes one restitution per material pair; give a constant");
  for (std::size_t k = 0; k < o.world.pairs.size(); ++k)
    if (table(o.world.pairs[k]))
      throw InputError(c.path, "/dem/pairs/" + std::to_string(k) + "/restitution",
                       no + "LIGGGHTS takes one restitution per material pair; give a constant");
}

/// ASCII STL of the container's inner walls, centred at `centre` (world frame at rest).
/// A cylinder's mantle is a prism of `segments` flat facets tangent to the mantle at their
/// middles (corners at R/cos(π/n)): no facet comes nearer the axis than the true mantle,
/// so a lattice sphere that touches the mantle in pdamp's start overlaps no facet (with
/// the corners on the mantle it would overlap one by up to R(1 − cos(π/n)), at full
/// stiffness a force that scatters the bed in the first step); at the corners a sphere
/// reaches at most R(1/cos(π/n) − 1) beyond the true mantle.
std::string container_stl(const fm::Container& container, const dr::Vec3& centre, int segments) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(17);
  out << "solid pdamp_container\n";
  const auto facet = [&](const dr::Vec3& a, const dr::Vec3& b, const dr::Vec3& d) {
    out << " facet normal 0 0 0\n  outer loop\n";
    for (const dr::Vec3* p : {&a, &b, &d})
      out << "   vertex " << (*p)[0] + centre[0] << ' ' << (*p)[1] + centre[1] << ' ' << (*p)[2] + centre[2] << "\n";
    out << "  endloop\n endfacet\n";
  };
  if (container.shape == fm::ContainerShape::kBox) {
    const dr::Vec3 h{container.box_inner_size_m[0] / 2, container.box_inner_size_m[1] / 2, container.box_inner_size_m[2] / 2};
    // Each face as two triangles: for axis k and side s the corners in the plane x_k = s·h_k.
    for (int k = 0; k < 3; ++k)
      for (const double s : {-1.0, 1.0}) {
        const int u = (k + 1) % 3, v = (k + 2) % 3;
        dr::Vec3 q[4];
        const double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
        for (int i = 0; i < 4; ++i) {
          q[i][k] = s * h[k];
          q[i][u] = su[i] * h[u];
          q[i][v] = sv[i] * h[v];
        }
        facet(q[0], q[1], q[2]);
        facet(q[0], q[2], q[3]);
      }
  } else {
    const int k = container.cylinder_axis, u = (k + 1) % 3, v = (k + 2) % 3;
    const double radius = container.cylinder_inner_radius_m / std::cos(std::numbers::pi / segments);
    const double half = container.cylinder_inner_length_m / 2;
    const auto rim = [&](int i, double side) {
      dr::Vec3 p{0.0, 0.0, 0.0};
      const double angle = 2.0 * std::numbers::pi * i / segments;
      p[k] = side * half;
      p[u] = radius * std::cos(angle);
      p[v] = radius * std::sin(angle);
      return p;
    };
    for (int i = 0; i < segments; ++i) {
      const auto a0 = rim(i, -1), a1 = rim(i + 1, -1), b0 = rim(i, 1), b1 = rim(i + 1, 1);
      facet(a0, a1, b1);  // mantle
      facet(a0, b1, b0);
      dr::Vec3 c0{0.0, 0.0, 0.0}, c1{0.0, 0.0, 0.0};
      c0[k] = -half;
      c1[k] = half;
      facet(c0, a1, a0);  // end caps as fans
      facet(c1, b0, b1);
    }
  }
  out << "endsolid pdamp_container\n";
  return out.str();
}

/// Facets of a cylinder's mantle: the corners' excess R(1/cos(π/n) − 1) at most 1% of the
/// smallest radius, so that the facets lie within 1% of a sphere of the true mantle.
int mantle_segments(double cylinder_radius_m, double smallest_particle_radius_m) {
  const double n = std::numbers::pi / std::acos(1.0 / (1.0 + 0.01 * smallest_particle_radius_m / cylinder_radius_m));
  return static_cast<int>(std::clamp(std::ceil(n), 32.0, 4096.0));
}

std::string readme_text(const json& r, bool cylinder) {
  std::ostringstream out;
  out << "LIGGGHTS deck of pdamp dem's run of case '" << base::printable(r["case"].get<std::string>()) << "'\n"
      << "written by pdamp " << r["pdamp_version"].get<std::string>() << " (export "
      << r["export_id"].get<std::string>() << "); docs/liggghts.md of pdamp explains every command.\n\n"
      << "The run: " << r["particles"].get<int>() << " spheres (" << format_number(r["bed_mass_kg"].get<double>(), 4)
      << " kg) settle for " << r["settling_steps"].get<long long>() << " steps with the container at rest, then the\n"
      << "container moves as x = X sin(2 pi f t) along " << r["drive_axis"].get<std::string>()
      << ", X = " << format_number(r["amplitude_m"].get<double>())
      << " m, f = " << format_number(r["frequency_hz"].get<double>()) << " Hz, for "
      << r["transient_periods"].get<int>() << " transient and " << r["analysed_periods"].get<int>()
      << " analysed periods\nat a time step of " << format_number(r["time_step_s"].get<double>()) << " s ("
      << r["steps_per_period"].get<long long>() << " steps a period). It writes " << kLiggghtsForceFile
      << " (the force of the bed on the\ncontainer walls, mean over each of " << r["samples_per_period"].get<int>()
      << " samples a period) and " << kLiggghtsEnergyFile << " (kinetic energy and centre of\nmass at each sample).\n\n"
      << "Files: " << kLiggghtsInputFile << " (the input), particles.data (the spheres at pdamp's initial positions,\n"
      << "radii and densities), container.stl (the inner walls" << (cylinder ? "; the mantle as flat facets" : "")
      << "), " << kLiggghtsExportRecord << "\n(what was exported; "
      << "pdamp import liggghts reads it).\n\n"
      << "Run it in this folder:\n"
      << "  liggghts -in " << kLiggghtsInputFile << "                      (one process)\n"
      << "  mpirun -np 4 liggghts -in " << kLiggghtsInputFile
      << "         (4 processes: the box is split into 4 parts)\n"
      << "On a cluster (Slurm), e.g. 2 nodes of 32 cores:\n"
      << "  #SBATCH --nodes=2\n  #SBATCH --ntasks-per-node=32\n  srun liggghts -in " << kLiggghtsInputFile
      << "       (or mpirun -np 64 liggghts -in " << kLiggghtsInputFile << ")\n"
      << "Domain decomposition is for large beds, where each process owns many spheres; a bed of\n"
      << "a few dozen spheres gains nothing from a second process.\n\n"
      << "Then read the result into pdamp's measures (eta*, its standard error, apparent mass):\n"
      << "  pdamp import liggghts THIS_FOLDER [-o OUT] [--json]\n";
  return out.str();
}

}  // namespace

double liggghts_damping_coefficient(double restitution) {
  const double log_e = std::log(restitution);
  const double beta = log_e / std::sqrt(log_e * log_e + std::numbers::pi * std::numbers::pi);
  return std::sqrt(5.0) * std::abs(beta);
}

LiggghtsDeck export_liggghts(const case_file::Case& c, const DemRunOptions& options, const std::string& pdamp_version) {
  DemRunOptions o = options;
  o.snapshots = 0;  // the deck writes no snapshots: none counted against memory
  const DemRunPlan plan = plan_dem(c, o);
  const auto& sim = plan.options;
  check_exportable(c, sim);
  const auto& estimate = plan.estimate;
  const auto& world_options = sim.world;
  const auto& compartment = world_options.compartments.front();

  // pdamp's own initial bed: the World places the spheres exactly as pdamp dem's run does
  // (lattice, ball-lot radii, seed), before it settles them. The placement does not depend
  // on the step, so the World is built at its automatic one: it refuses a user step above
  // its own bound, which pdamp dem accepts with a warning (estimate.warnings, passed on).
  dr::WorldOptions placement_options = world_options;
  placement_options.integration.time_step_s = 0.0;
  const dr::World world(placement_options);
  const int n = world.particle_count();
  const double x = plan.amplitude_m, f = plan.frequency_hz, omega = 2.0 * std::numbers::pi * f;
  const dr::Vec3 d = sim.drive_axis;
  int axis = 0;
  for (int k = 0; k < 3; ++k)
    if (std::abs(d[k]) > 0.5) axis = k;
  const std::int64_t steps_per_sample = estimate.steps_per_period / sim.samples_per_period;
  const std::int64_t drive_steps = estimate.transient_steps + estimate.analysed_steps;
  // Every sphere of the (one) group shares its material; several groups would each need theirs.
  if (compartment.particles.size() != 1)
    throw InputError(c.path, layer_key(c, "particles"), "the export takes one particle group");

  LiggghtsDeck deck;
  deck.warnings = estimate.warnings;

  // Materials: LIGGGHTS atom type 1 is the spheres' material, type 2 the walls' when it is
  // another (LIGGGHTS refuses types that do not start from 1, so materials the deck does not
  // use get no type); Young's moduli already multiplied by /dem/stiffness_softening, as
  // pdamp's DEM takes them.
  std::vector<int> used = {compartment.particles.front().material};
  if (compartment.wall_material != used.front()) used.push_back(compartment.wall_material);
  const int types = static_cast<int>(used.size());
  const int particle_type = 1;
  const int wall_type = types;
  double max_radius = 0.0, min_radius = std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    max_radius = std::max(max_radius, world.radius(i));
    min_radius = std::min(min_radius, world.radius(i));
  }

  // particles.data: the box holds the container at both ends of its stroke with a margin.
  const fm::Container& container = compartment.container;
  dr::Vec3 low{}, high{};
  for (int k = 0; k < 3; ++k) {
    const double half = container.inner_length(k) / 2.0;
    const double margin = std::max(0.05 * half, 4.0 * max_radius) + (k == axis ? x : 0.0);
    low[k] = compartment.offset_m[k] - half - margin;
    high[k] = compartment.offset_m[k] + half + margin;
  }
  std::ostringstream data;
  data.imbue(std::locale::classic());
  data << std::setprecision(17);
  data << "pdamp: the spheres of case '" << base::printable(c.name) << "' at pdamp's initial positions\n\n"
       << n << " atoms\n" << types << " atom types\n\n";
  for (int k = 0; k < 3; ++k)
    data << low[k] << ' ' << high[k] << ' ' << kAxisNames[k] << "lo " << kAxisNames[k] << "hi\n";
  data << "\nAtoms\n\n";
  // Granular atom style: id type diameter density x y z.
  for (int i = 0; i < n; ++i) {
    const auto p = world.position(i);
    const double r = world.radius(i);
    const double density = world.mass(i) / (4.0 / 3.0 * std::numbers::pi * r * r * r);
    data << i + 1 << ' ' << particle_type << ' ' << 2.0 * r << ' '
         << density << ' ' << p[0] << ' ' << p[1] << ' ' << p[2] << "\n";
  }

  const bool cylinder = container.shape == fm::ContainerShape::kCylinder;
  const std::string stl = container_stl(
      container, compartment.offset_m,
      cylinder ? mantle_segments(container.cylinder_inner_radius_m, min_radius) : 0);

  bool rolling = false;
  // The contact of deck types a and b (0-based) is that of the materials they stand for.
  const auto pair_of_types = [&](int a, int b) -> const dr::ContactPairOptions& {
    return pair_of(world_options, used[static_cast<std::size_t>(a)], used[static_cast<std::size_t>(b)]);
  };
  const auto material_of_type = [&](int a) -> const auto& { return world_options.materials[used[static_cast<std::size_t>(a)]]; };
  for (int a = 0; a < types; ++a)
    for (int b = 0; b < types; ++b) rolling = rolling || pair_of_types(a, b).rolling_friction > 0.0;
  const auto per_type = [&](auto value) {
    std::string s;
    for (int a = 0; a < types; ++a) s += " " + format_number(value(material_of_type(a).material), kDeckDigits);
    return s;
  };
  const auto per_pair = [&](auto value) {
    std::string s(" ");
    s += std::to_string(types);
    for (int a = 0; a < types; ++a)
      for (int b = 0; b < types; ++b) {
        s += ' ';
        s += format_number(value(pair_of_types(a, b)), kDeckDigits);
      }
    return s;
  };
  // The contact model, the same for particle pairs and walls: Hertz with the β damping
  // law, Mindlin's history spring, no tangential damping (pdamp's tangential spring has
  // none), no attraction at the end of a contact (pdamp's normal force is max(0, ...)),
  // and cdt rolling friction (the constant torque μ_r R* F_n, the cap of pdamp's spring).
  const std::string model = std::string("model hertz tangential history") + (rolling ? " rolling_friction cdt" : "");
  const std::string settings = "tangential_damping off limitForce on";

  const dr::Vec3 g = world_options.gravity_m_s2;
  const double g_norm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  std::ostringstream in;
  in.imbue(std::locale::classic());
  const auto line = [&](const std::string& text) { in << text << "\n"; };
  line("# LIGGGHTS-PUBLIC 3.8 deck of pdamp dem's run of case '" + base::printable(c.name) + "'");
  line("# written by pdamp " + pdamp_version + "; README.txt says how to run it, docs/liggghts.md of pdamp");
  line("# maps every pdamp parameter to the commands below.");
  line("# Drive: x_c(t) = X sin(2 pi f t) along " + std::string(kAxisNames[axis]) + ", X = " +
       format_number(x, kDeckDigits) + " m, f = " + format_number(f, kDeckDigits) + " Hz, t = 0 at the drive's start.");
  line("atom_style granular");
  line("atom_modify map array");
  line("boundary f f f");
  line("newton off");
  line("communicate single vel yes");
  line("units si");
  line("# pdamp's moduli are physical (LIGGGHTS otherwise refuses E > 1e9 Pa in SI units).");
  line("hard_particles yes");
  line("read_data particles.data");
  line("");
  line("# Neighbour skin as pdamp's: skin_fraction x the largest radius.");
  line("neighbor " + format_number(world_options.integration.skin_fraction * max_radius, kDeckDigits) + " bin");
  line("neigh_modify delay 0");
  line("");
  std::string names;
  for (int a = 0; a < types; ++a) names += (a ? ", " : "") + std::to_string(a + 1) + " " + material_of_type(a).name;
  line("# Atom types = the materials in use (" + base::printable(names) + "): the spheres are type 1, the walls type " +
       std::to_string(wall_type) + ".");
  line("# Young's moduli include /dem/stiffness_softening = " + format_number(c.dem.stiffness_softening, kDeckDigits) +
       " as in pdamp's DEM.");
  line("fix pdamp_m1 all property/global youngsModulus peratomtype" +
       per_type([](const fm::Material& m) { return m.youngs_modulus_pa; }));
  line("fix pdamp_m2 all property/global poissonsRatio peratomtype" +
       per_type([](const fm::Material& m) { return m.poisson_ratio; }));
  line("fix pdamp_m3 all property/global coefficientRestitution peratomtypepair" +
       per_pair([](const dr::ContactPairOptions& p) { return p.restitution.constant; }));
  line("fix pdamp_m4 all property/global coefficientFriction peratomtypepair" +
       per_pair([](const dr::ContactPairOptions& p) { return p.friction; }));
  if (rolling)
    line("fix pdamp_m5 all property/global coefficientRollingFriction peratomtypepair" +
         per_pair([](const dr::ContactPairOptions& p) { return p.rolling_friction; }));
  line("pair_style gran " + model + " " + settings);
  line("pair_coeff * *");
  line("");
  line("# pdamp's time step for this run: " + format_number(estimate.steps_per_period, kDeckDigits) +
       " steps a period, " + std::to_string(steps_per_sample) + " a sample.");
  line("timestep " + format_number(estimate.time_step_s, kDeckDigits));
  if (g_norm > 0.0)
    line("fix pdamp_gravity all gravity " + format_number(g_norm, kDeckDigits) + " vector " +
         format_number(g[0] / g_norm, kDeckDigits) + " " + format_number(g[1] / g_norm, kDeckDigits) + " " +
         format_number(g[2] / g_norm, kDeckDigits));
  line("fix pdamp_container all mesh/surface/stress file container.stl type " + std::to_string(wall_type));
  line("fix pdamp_walls all wall/gran " + model + " mesh n_meshes 1 meshes pdamp_container " + settings);
  line("fix pdamp_integrate all nve/sphere");
  line("compute pdamp_ke all ke");
  line("compute pdamp_rke all erotate/sphere");
  line("compute pdamp_com all com");
  line("thermo_style custom step atoms c_pdamp_ke c_pdamp_rke f_pdamp_container[1] f_pdamp_container[2] f_pdamp_container[3]");
  line("thermo " + std::to_string(std::max<std::int64_t>(1, estimate.steps_per_period / 10)));
  line("thermo_modify lost error norm no");
  line("");
  if (estimate.settling_steps > 0) {
    line("# 1. Settling with the container at rest, as pdamp's run (" +
         format_number(estimate.settling_steps * estimate.time_step_s, kDeckDigits) + " s).");
    run_lines(line, estimate.settling_steps);
    line("");
  }
  line("# 2. The drive. Step numbers restart at 0, so that sample k ends at step k x " + std::to_string(steps_per_sample) +
       ".");
  line("reset_timestep 0");
  line("# The bed starts with the container's velocity X*Omega along the drive, as in pdamp's run.");
  {
    std::string v;
    for (int k = 0; k < 3; ++k)
      v += " " + format_number(k == axis ? x * omega * (d[k] > 0 ? 1 : -1) : 0.0, kDeckDigits);
    line("velocity all set" + v + " sum yes units box");
  }
  line("# wiggle moves the mesh by A sin(2 pi t/T), t from this fix's creation: pdamp's sine.");
  {
    std::string a;
    for (int k = 0; k < 3; ++k) a += " " + format_number(k == axis ? x * (d[k] > 0 ? 1 : -1) : 0.0, kDeckDigits);
    line("fix pdamp_drive all move/mesh mesh pdamp_container wiggle amplitude" + a + " period " +
         format_number(1.0 / f, kDeckDigits));
  }
  const std::string title = "title1 \"# pdamp export EXPORT_ID\"";
  line("# Force of the bed on the walls (N, x y z), mean over each sample of " + std::to_string(steps_per_sample) + " steps.");
  line("fix pdamp_force all ave/time 1 " + std::to_string(steps_per_sample) + " " + std::to_string(steps_per_sample) +
       " f_pdamp_container[1] f_pdamp_container[2] f_pdamp_container[3] file " + kLiggghtsForceFile + " " + title);
  line("# Kinetic energy (translational, rotational, J) and centre of mass (m) at each sample's end.");
  line("fix pdamp_energy all ave/time " + std::to_string(steps_per_sample) + " 1 " + std::to_string(steps_per_sample) +
       " c_pdamp_ke c_pdamp_rke c_pdamp_com[1] c_pdamp_com[2] c_pdamp_com[3] file " + kLiggghtsEnergyFile + " " + title);
  line("# One run (in pieces of at most 2^31 - 1 steps, LIGGGHTS' limit): the mesh's phase runs on from the");
  line("# fix's creation through transient and analysis.");
  run_lines(line, drive_steps);

  // The identity covers the deck's physics (input with a placeholder id, spheres, walls).
  std::string input = in.str();
  const std::string placeholder = "EXPORT_ID";
  const std::string id = deck_id({{kLiggghtsInputFile, input}, {"particles.data", data.str()}, {"container.stl", stl}});
  for (std::size_t at; (at = input.find(placeholder)) != std::string::npos;) input.replace(at, placeholder.size(), id);

  const auto& damper = c.dampers.front();
  const auto closed = fm::reduced_loss_factor(damper.model, world.clearance_m(0), x, f,
                                              case_file::layer_model_options(damper, damper.layers.front()));
  json contacts = json::array();
  for (int a = 0; a < types; ++a)
    for (int b = a; b < types; ++b) {
      const auto& p = pair_of_types(a, b);
      const double e = p.restitution.constant;
      contacts.push_back({{"material_a", material_of_type(a).name},
                          {"material_b", material_of_type(b).name},
                          {"restitution", e},
                          {"liggghts_realised_restitution", e >= 1.0 ? 1.0 : fm::realised_restitution(liggghts_damping_coefficient(e))},
                          {"friction", p.friction},
                          {"rolling_friction", p.rolling_friction}});
    }
  json& r = deck.record;
  r = {{"format", kRecordFormat},
       {"format_version", kRecordFormatVersion},
       {"export_id", id},
       {"pdamp_version", pdamp_version},
       {"case", c.name},
       {"frequency_hz", f},
       {"amplitude_m", x},
       {"velocity_amplitude_m_s", x * omega},
       {"intensity", x * omega * omega / fm::kStandardGravity},
       {"transient_periods", sim.transient_periods},
       {"analysed_periods", sim.analysed_periods},
       {"time_step_s", estimate.time_step_s},
       {"steps_per_period", estimate.steps_per_period},
       {"samples_per_period", sim.samples_per_period},
       {"steps_per_sample", steps_per_sample},
       {"sample_interval_s", static_cast<double>(steps_per_sample) * estimate.time_step_s},
       {"settling_steps", estimate.settling_steps},
       {"particles", n},
       {"bed_mass_kg", world.bed_mass_kg()},
       {"clearance_m", world.clearance_m(0)},
       {"drive_axis", kAxisNames[axis]},
       {"drive_direction", {d[0], d[1], d[2]}},
       {"gravity_m_s2", {g[0], g[1], g[2]}},
       {"stiffness_softening", c.dem.stiffness_softening},
       {"contacts", contacts},
       {"closed_form",
        {{"eta_star", closed.eta_star}, {"model_used", fm::to_string(closed.model_used)}, {"regime", fm::to_string(closed.regime)}}}};
  deck.files = {{kLiggghtsInputFile, input},
                {"particles.data", data.str()},
                {"container.stl", stl},
                {"README.txt", readme_text(r, cylinder)},
                {kLiggghtsExportRecord, r.dump(2) + "\n"}};
  return deck;
}

// ---------------------------------------------------------------- import

namespace {

/// Whether `path` exists; InputError naming it when the file system cannot tell (a loop of
/// symbolic links, a folder without permission) rather than a raw filesystem_error.
bool exists_or_refuse(const std::filesystem::path& path) {
  std::error_code error;
  const bool found = std::filesystem::exists(path, error);
  if (error) throw InputError(path.string(), "", "cannot be read: " + error.message());
  return found;
}

/// The rows of one LIGGGHTS output file: its title line must name this export; every
/// other line not starting with '#' holds `columns` finite numbers, the first the step. A
/// file of more than `max_rows` rows is refused at the first row too many (the export's run
/// writes a known number: a huge file costs no more than its text).
std::vector<std::vector<double>> read_output_file(const std::filesystem::path& path, const std::string& export_id,
                                                  std::size_t columns, std::size_t max_rows) {
  const std::string file = path.string();
  if (!exists_or_refuse(path))
    throw InputError(file, "", "missing: run LIGGGHTS on the deck in this folder first (README.txt)");
  const std::string text = base::read_input_file(file);
  std::vector<std::vector<double>> rows;
  std::istringstream lines(text);
  std::string line;
  std::size_t number = 0;
  bool titled = false;
  while (std::getline(lines, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = "line " + std::to_string(number) + ": ";
    if (number == 1) {
      if (line != "# pdamp export " + export_id)
        throw InputError(file, "",
                         where + "'" + base::printable(line.substr(0, 80)) + "' is not the title of export " +
                             export_id + " (an earlier deck's output, or not LIGGGHTS's): run LIGGGHTS on this deck again");
      titled = true;
      continue;
    }
    if (line.empty() || line[0] == '#') continue;
    if (rows.size() == max_rows)
      throw InputError(file, "",
                       where + "holds more than the " + std::to_string(max_rows) + " samples of this export's run");
    std::vector<double> row;
    const char* at = line.data();
    const char* end = line.data() + line.size();
    while (at < end) {
      while (at < end && (*at == ' ' || *at == '\t')) ++at;
      if (at == end) break;
      const char* token_end = at;
      while (token_end < end && *token_end != ' ' && *token_end != '\t') ++token_end;
      double value = 0.0;
      const auto [parsed, error] = std::from_chars(at, token_end, value);
      if (error != std::errc() || parsed != token_end || !std::isfinite(value))
        throw InputError(file, "",
                         where + "'" + base::printable(std::string(at, token_end).substr(0, 40)) +
                             "' is not a finite number");
      row.push_back(value);
      at = token_end;
    }
    if (row.size() != columns)
      throw InputError(file, "",
                       where + "holds " + std::to_string(row.size()) + " numbers, expected " + std::to_string(columns) +
                           " (the step and " + std::to_string(columns - 1) + " values)");
    rows.push_back(std::move(row));
  }
  if (!titled) throw InputError(file, "", "is empty: the LIGGGHTS run did not start (see its log)");
  return rows;
}

}  // namespace

LiggghtsImport import_liggghts(const std::filesystem::path& dir) {
  const std::filesystem::path record_path = dir / kLiggghtsExportRecord;
  const std::string record_file = record_path.string();
  std::error_code error;
  if (!exists_or_refuse(dir) || !std::filesystem::is_directory(dir, error))
    throw InputError(dir.string(), "", "is not a folder (the folder pdamp export liggghts wrote)");
  if (!exists_or_refuse(record_path))
    throw InputError(record_file, "", "missing: the folder holds no deck of pdamp export liggghts");
  const json document = base::parse_json_document(base::read_input_file(record_file), record_file);
  base::StrictObject r(document, "", record_file);
  r.expect_string("format", kRecordFormat);
  if (r.integer("format_version", 1, 1000) != kRecordFormatVersion)
    r.fail("format_version", "must be " + std::to_string(kRecordFormatVersion) + " (an export of another pdamp version)");
  LiggghtsImport out;
  out.record = document;
  const std::string id = r.string("export_id");
  out.case_name = r.string("case");
  // The case's own ranges (docs/bad_inputs.md): a record edited to 1e300 m or 1e-320 kg is
  // refused here rather than turned into a NaN or a silent 0 further on.
  const auto ranged = [&](std::string_view key, const case_file::Range& range, std::string_view unit) {
    const double value = r.number(key, false, unit);
    if (!range.contains(value)) r.fail(key, "= " + format_number(value, 10) + ": " + range.text() + " " + std::string(unit));
    return value;
  };
  out.frequency_hz = ranged("frequency_hz", case_file::limits::kFrequency, "Hz");
  out.amplitude_m = ranged("amplitude_m", case_file::limits::kStroke, "m");
  out.bed_mass_kg = ranged("bed_mass_kg", {1e-9, 1e6}, "kg");
  out.time_step_s = ranged("time_step_s", {dr::limits::kMinTimeStep_s, dr::limits::kMaxTimeStep_s}, "s");
  const int transient = static_cast<int>(r.integer("transient_periods", 0, dr::limits::kMaxPeriods));
  out.analysed_periods = static_cast<int>(r.integer("analysed_periods", 1, dr::limits::kMaxPeriods));
  out.samples_per_period = static_cast<int>(r.integer("samples_per_period", 3, dr::limits::kMaxSamplesPerPeriod));
  const std::int64_t per_sample = r.integer("steps_per_sample", 1, std::int64_t{1} << 40);
  out.steps_per_period = r.integer("steps_per_period", 3, std::int64_t{1} << 50);
  if (out.steps_per_period != per_sample * out.samples_per_period)
    r.fail("steps_per_period", "must be samples_per_period x steps_per_sample");
  // The drive-bin measure needs whole steps per period: T/dt a whole number (1e-9 relative).
  if (std::abs(out.time_step_s * static_cast<double>(out.steps_per_period) * out.frequency_hz - 1.0) > 1e-9)
    r.fail("time_step_s", "times steps_per_period must be the period 1/frequency_hz");
  const std::string axis_name = r.string("drive_axis");
  int axis = -1;
  for (int k = 0; k < 3; ++k)
    if (axis_name == kAxisNames[k]) axis = k;
  if (axis < 0) r.fail("drive_axis", "must be x, y or z");
  const json& direction = r.required("drive_direction");
  const json& gravity = r.required("gravity_m_s2");
  dr::Vec3 d{}, g{};
  for (auto [value, into, key] : {std::tuple{&direction, &d, "drive_direction"}, std::tuple{&gravity, &g, "gravity_m_s2"}}) {
    if (!value->is_array() || value->size() != 3) r.fail(key, "must be 3 numbers");
    for (int k = 0; k < 3; ++k) (*into)[k] = r.number_value((*value)[k], r.pointer(key) + "/" + std::to_string(k), false);
  }
  for (int k = 0; k < 3; ++k)
    if (!case_file::limits::kGravity.contains(g[k]))
      r.fail("gravity_m_s2", "= " + format_number(g[k], 10) + " in component " + std::to_string(k) + ": " +
                                 case_file::limits::kGravity.text() + " m/s^2");
  // The export writes the unit vector of its drive axis; another is an edited record whose
  // force would be measured along the wrong axis or scaled.
  for (int k = 0; k < 3; ++k)
    if (d[k] != (k == axis ? 1.0 : 0.0))
      r.fail("drive_direction", "must be the unit vector of drive_axis " + axis_name);
  // Informative keys are not used, but a wrong type is still a wrong record.
  for (const char* text : {"pdamp_version"})
    if (const auto* v = r.optional(text); v && !v->is_string()) r.fail(text, std::string("must be a string, got ") + v->type_name());
  for (const char* number : {"velocity_amplitude_m_s", "intensity", "sample_interval_s", "settling_steps", "particles",
                             "clearance_m", "stiffness_softening"})
    if (const auto* v = r.optional(number); v && !v->is_number())
      r.fail(number, std::string("must be a number, got ") + v->type_name());
  for (const char* informative : {"contacts", "closed_form"}) (void)r.optional(informative);
  r.finish();

  const double omega = 2.0 * std::numbers::pi * out.frequency_hz;
  const double dt = out.time_step_s, x = out.amplitude_m;
  const std::int64_t samples = out.samples_per_period;
  const std::int64_t first = transient * samples + 1, last = (transient + out.analysed_periods) * samples;

  // Force: sample m ends at step m·B and is the mean over steps m·B − B + 1 ... m·B.
  const auto force_path = dir / kLiggghtsForceFile;
  const auto force_rows = read_output_file(force_path, id, 4, static_cast<std::size_t>(last));
  if (static_cast<std::int64_t>(force_rows.size()) < last)
    throw InputError(force_path.string(), "",
                     "holds " + std::to_string(force_rows.size()) + " samples of the " + std::to_string(last) +
                         " the run writes: the LIGGGHTS run has not finished (see its log)");
  dr::DriveBinMeasure bin(samples, out.frequency_hz, out.bed_mass_kg);
  for (std::int64_t m = 1; m <= last; ++m) {
    const auto& row = force_rows[static_cast<std::size_t>(m - 1)];
    if (row[0] != static_cast<double>(m * per_sample))
      throw InputError(force_path.string(), "",
                       "sample " + std::to_string(m) + " is at step " + format_number(row[0], 12) + ", expected " +
                           std::to_string(m * per_sample) + " (a step every " + std::to_string(per_sample) +
                           " from the drive's start)");
    // A bed of at most 1e6 kg (the case's mass range) at 1e5 m/s² pushes with 1e11 N: a force
    // beyond 1e12 N is no bed's, and would overflow the measure's sums.
    for (int k = 1; k <= 3; ++k)
      if (std::abs(row[static_cast<std::size_t>(k)]) > 1e12)
        throw InputError(force_path.string(), "",
                         "its forces give sample " + std::to_string(m) + " a force of " +
                             format_number(row[static_cast<std::size_t>(k)], 6) + " N, beyond any bed's (1e12 N)");
    if (m < first) continue;
    // The force of the container on the bed is minus the force of the bed on the walls.
    const double force = -(row[1] * d[0] + row[2] * d[1] + row[3] * d[2]);
    // The container's velocity is known: V = XΩ cos(Ωt), taken at the sample's mid time
    // (the force is the sample's mean; a common shift of both does not change η*).
    const double mid = (static_cast<double>(m * per_sample) - 0.5 * static_cast<double>(per_sample - 1)) * dt;
    bin.add(m - first, force, x * omega * std::cos(omega * mid));
    // The velocity-Verlet force of step s is the impulse over [t_s − dt/2, t_s + dt/2]: the
    // sample's steps act over the container's travel from ((m−1)B + ½)dt to (mB + ½)dt,
    // centred on the sample's mid time.
    const double t_end = (static_cast<double>(m * per_sample) + 0.5) * dt;
    const double t_start = (static_cast<double>((m - 1) * per_sample) + 0.5) * dt;
    out.container_work_j += force * x * (std::sin(omega * t_end) - std::sin(omega * t_start));
  }
  // Forces of 1e300 N pass the row check but overflow the sums: the file's fault, named.
  try {
    out.measures = bin.result();
  } catch (const std::exception& e) {
    throw InputError(force_path.string(), "", std::string("its forces give no measure: ") + e.what());
  }
  if (!std::isfinite(out.measures.eta_star) || !std::isfinite(out.measures.e_diss_j) ||
      !std::isfinite(out.measures.apparent_mass_kg) || !std::isfinite(out.container_work_j))
    throw InputError(force_path.string(), "", "its forces give a non-finite eta*, E_diss, apparent mass or work "
                                              "(forces far beyond any bed's): not the output of this run");
  // The fields' ranges (η* in [−1, 100], m_app/m_bed within ±10): beyond them no bed.
  if (const std::string problem =
          surrogate::field_value_problem(out.measures.eta_star, out.measures.apparent_mass_kg / out.bed_mass_kg);
      !problem.empty())
    throw InputError(force_path.string(), "", "its forces give " + problem + ": not the output of this run");

  // Energy at the analysis' two ends (instantaneous values at sample ends).
  const auto energy_path = dir / kLiggghtsEnergyFile;
  // One row at each sample's end, the drive's start (step 0) included.
  const auto energy_rows = read_output_file(energy_path, id, 6, static_cast<std::size_t>(last) + 1);
  const auto at_step = [&](std::int64_t step) -> const std::vector<double>& {
    for (const auto& row : energy_rows)
      if (row[0] == static_cast<double>(step)) return row;
    throw InputError(energy_path.string(), "",
                     "has no line for step " + std::to_string(step) + " (the analysis' " +
                         (step == (first - 1) * per_sample ? "start" : "end") + "): the LIGGGHTS run has not finished");
  };
  const auto& start = at_step((first - 1) * per_sample);
  const auto& end = at_step(last * per_sample);
  out.delta_kinetic_j = (end[1] + end[2]) - (start[1] + start[2]);
  out.delta_potential_j = 0.0;
  for (int k = 0; k < 3; ++k) out.delta_potential_j -= out.bed_mass_kg * g[k] * (end[3 + k] - start[3 + k]);
  if (!std::isfinite(out.delta_kinetic_j) || !std::isfinite(out.delta_potential_j) ||
      !std::isfinite(out.container_work_j - out.delta_kinetic_j - out.delta_potential_j))
    throw InputError(energy_path.string(), "", "its energies give a non-finite energy balance (values near 1e308): "
                                               "not the output of this run");

  // The drive bin weighs a sample as a force held over it (sinc(π/M)); a sample's mean of
  // a harmonic force is that force times sinc(π/M) already, so η* is low by 1 − sinc²(π/M).
  const double a = std::numbers::pi / static_cast<double>(samples);
  const double bias = 1.0 - std::pow(std::sin(a) / a, 2);
  if (bias > 1e-3)
    out.warnings.push_back(
        "with " + std::to_string(samples) + " samples a period the sampled force's mean lowers eta* by " +
        format_number(100.0 * bias, 2) + "%: export with more /dem/samples_per_period (1000 gives 3e-6)");
  return out;
}

json to_json(const LiggghtsImport& r) {
  const auto& m = r.measures;
  const double v = r.amplitude_m * 2.0 * std::numbers::pi * r.frequency_hz;
  const double dissipated = r.container_work_j - r.delta_kinetic_j - r.delta_potential_j;
  json out = {{"case", r.case_name},
              {"source", "liggghts"},
              {"eta_star", m.eta_star},
              {"eta_star_stderr", m.eta_star_stderr},
              {"eta_star_per_period", m.eta_star_per_period},
              {"e_diss_j", m.e_diss_j},
              {"energy_per_cycle_j", m.energy_per_cycle_j},
              {"apparent_mass_kg", m.apparent_mass_kg},
              {"apparent_mass_fraction", m.apparent_mass_kg / r.bed_mass_kg},
              {"bed_mass_kg", r.bed_mass_kg},
              {"amplitude_m", r.amplitude_m},
              {"frequency_hz", r.frequency_hz},
              {"velocity_amplitude_m_s", v},
              {"intensity", v * 2.0 * std::numbers::pi * r.frequency_hz / fm::kStandardGravity},
              {"time_step_s", r.time_step_s},
              {"steps_per_period", r.steps_per_period},
              {"energy",
               {{"container_work_j", r.container_work_j},
                {"delta_kinetic_j", r.delta_kinetic_j},
                {"delta_potential_j", r.delta_potential_j},
                {"dissipated_j", dissipated}}},
              {"liggghts",
               {{"export_id", r.record.value("export_id", "")},
                {"samples_per_period", r.samples_per_period},
                {"analysed_periods", r.analysed_periods}}}};
  if (r.record.contains("clearance_m")) out["clearance_m"] = r.record["clearance_m"];
  if (r.record.contains("closed_form")) out["closed_form"] = r.record["closed_form"];
  if (r.record.contains("particles"))
    out["run"] = {{"outcome", "completed"},
                  {"particles", r.record["particles"]},
                  {"steps", r.record.value("settling_steps", 0LL) +
                                r.steps_per_period * (r.record.value("transient_periods", 0) + r.analysed_periods)}};
  return out;
}

}  // namespace pdamp::tasks
