// The checkpoints of a co-simulation run in segments and the joining of its segments'
// results (cosimulation_state.hpp).
#include "pdamp/structure/cosimulation_state.hpp"

#include <algorithm>
#include <string>

#include "cosimulation_plan.hpp"
#include "pdamp/dem_reference/damper_simulation.hpp"

namespace pdamp::structure {

namespace dem = pdamp::dem_reference;
using detail::energy_terms;
using detail::ledger_error;

namespace {

constexpr std::size_t kMaxModes = 100000;
constexpr std::size_t kMaxDampers = 1000;
constexpr std::size_t kMaxSamples = 100000000;
constexpr std::size_t kMaxWarningBytes = 1 << 16;

void write_matrix(dem::StateWriter& out, const Eigen::MatrixXd& m) {
  out.i64(m.rows());
  out.i64(m.cols());
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) out.f64(m(i, j));
}

Eigen::MatrixXd read_matrix(dem::StateReader& in, const char* field, std::size_t rows, std::size_t cols) {
  const std::size_t r = in.count(field, kMaxSamples, 0), c = in.count(field, kMaxModes, 0);
  if (r != rows || c != cols)
    in.fail(field, std::to_string(r) + " x " + std::to_string(c) + ": must be " + std::to_string(rows) + " x " +
                       std::to_string(cols));
  if (c > 0 && r > in.remaining() / (8 * c)) in.fail(field, "holds more values than the bytes left");
  Eigen::MatrixXd m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) m(i, j) = in.finite(field);
  return m;
}

void write_vector(dem::StateWriter& out, const Eigen::VectorXd& v) {
  out.f64s(std::vector<double>(v.data(), v.data() + v.size()));
}

Eigen::VectorXd read_vector(dem::StateReader& in, const char* field, std::size_t size) {
  const std::vector<double> v = in.finite_f64s(field, size);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

}  // namespace

void save_cosimulation_state(const CosimulationState& state, dem::StateWriter& out) {
  out.tag("cosimulation state");
  out.i64(static_cast<std::int64_t>(state.worlds.size()));
  for (const dem::World& world : state.worlds) {
    const auto& integ = world.options().integration;
    out.f64(integ.time_step_s);
    out.i32(integ.steps_per_contact);
    for (double v : {integ.rayleigh_fraction, integ.max_impact_speed_m_s, integ.skin_fraction, integ.max_overlap_fraction})
      out.f64(v);
    world.save_state(out);
  }
  write_vector(out, state.modal_displacements);
  write_vector(out, state.modal_velocities);
  out.f64(state.time_s);
  out.i64(state.steps);
  out.f64(state.time_step_s);
  const auto& e = state.excitation;
  out.i32(static_cast<std::int32_t>(e.kind));
  out.f64(e.direction.x());
  out.f64(e.direction.y());
  out.f64(e.amplitude);
  out.f64(e.frequency_hz);
  out.text(e.point);
  out.f64(state.excitation_phase_rad);
  CosimulationEnergy e_since = state.energy_since_start;
  for (double* v : energy_terms(e_since)) out.f64(*v);
  out.f64(state.start_structure_kinetic_j);
  out.f64(state.start_structure_potential_j);
  for (const auto& a : state.start_world_energy)
    for (double v : {a.container_work_j, a.normal_damping_j, a.friction_j, a.rolling_j, a.kinetic_j, a.potential_j,
                     a.elastic_j})
      out.f64(v);
  out.tag("end of cosimulation state");
}

CosimulationState restore_cosimulation_state(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                             dem::StateReader& in) {
  CosimulationState state;
  in.expect_tag("cosimulation state");
  const std::size_t worlds = in.count("worlds", kMaxDampers, 8);
  if (worlds != dampers.size())
    in.fail("worlds", std::to_string(worlds) + " in the state for " + std::to_string(dampers.size()) +
                          " damper(s): a state of another case");
  for (std::size_t d = 0; d < worlds; ++d) {
    dem::WorldOptions options = dampers[d].world;
    auto& integ = options.integration;
    integ.time_step_s = in.finite("integration.time_step_s");
    integ.steps_per_contact = in.i32("integration.steps_per_contact");
    for (double* v : {&integ.rayleigh_fraction, &integ.max_impact_speed_m_s, &integ.skin_fraction,
                      &integ.max_overlap_fraction})
      *v = in.finite("integration");
    try {
      state.worlds.emplace_back(options);
    } catch (const std::invalid_argument& e) {
      in.fail("damper " + dampers[d].name, std::string("its world cannot be built with the saved settings: ") + e.what());
    }
    state.worlds.back().restore_state(in);
  }
  const auto modes = static_cast<std::size_t>(model.mode_count());
  state.modal_displacements = read_vector(in, "modal_displacements", modes);
  state.modal_velocities = read_vector(in, "modal_velocities", modes);
  state.time_s = in.finite("time_s");
  state.steps = in.i64("steps");
  state.time_step_s = in.finite("time_step_s");
  if (state.steps < 0 || !(state.time_step_s > 0.0)) in.fail("steps", "a negative count or a step that is not > 0");
  for (const auto& w : state.worlds)
    if (w.time_step_s() != state.time_step_s) in.fail("time_step_s", "differs from the worlds' step");
  auto& e = state.excitation;
  e.kind = static_cast<CosimulationExcitationKind>(in.i32_in("excitation.kind", 0, 2));
  const double ex = in.finite("excitation.direction"), ey = in.finite("excitation.direction");
  e.direction = {ex, ey};
  e.amplitude = in.finite("excitation.amplitude");
  e.frequency_hz = in.finite("excitation.frequency_hz");
  e.point = in.text("excitation.point", 4096);
  state.excitation_phase_rad = in.finite("excitation_phase_rad");
  for (double* v : energy_terms(state.energy_since_start)) *v = in.finite("energy_since_start");
  state.energy_since_start.relative_error = ledger_error(state.energy_since_start);
  state.start_structure_kinetic_j = in.finite("start_structure_kinetic_j");
  state.start_structure_potential_j = in.finite("start_structure_potential_j");
  state.start_world_energy.resize(worlds);
  for (auto& a : state.start_world_energy)
    for (double* v : {&a.container_work_j, &a.normal_damping_j, &a.friction_j, &a.rolling_j, &a.kinetic_j, &a.potential_j,
                      &a.elastic_j})
      *v = in.finite("start_world_energy");
  in.expect_tag("end of cosimulation state");
  return state;
}

void save_cosimulation_result(const CosimulationResult& r, dem::StateWriter& out) {
  // "2": with the beds' snapshots (an older checkpoint is refused at this tag).
  out.tag("cosimulation result 2");
  out.i32(static_cast<std::int32_t>(r.outcome));
  out.text(r.message);
  out.f64(r.time_step_s);
  for (std::int64_t v : {r.steps, r.steps_per_period, r.settling_steps}) out.i64(v);
  out.f64(r.simulated_time_s);
  out.f64(r.start_time_s);
  out.u8(r.continued ? 1 : 0);
  out.f64(r.wall_time_s);
  write_vector(out, r.frequencies_with_containers_hz);
  write_vector(out, r.final_modal_displacements);
  write_vector(out, r.final_modal_velocities);
  const auto& h = r.history;
  out.f64s(h.time_s);
  for (const auto* m : {&h.modal_displacements, &h.site_displacement_m, &h.site_rotation_rad, &h.container_load_n,
                        &h.container_moment_nm})
    write_matrix(out, *m);
  out.f64s(h.pending_load_sum_n);
  out.f64s(h.pending_moment_sum_nm);
  out.i64(h.pending_steps);
  out.i64(static_cast<std::int64_t>(r.warnings.size()));
  for (const auto& w : r.warnings) out.text(w);
  out.i64(static_cast<std::int64_t>(r.bed_snapshots.size()));
  for (const auto& beds : r.bed_snapshots)
    for (const auto& bed : beds) {
      dem::save_particle_snapshot(out, bed.particles);
      for (double x : bed.container_position_m) out.f64(x);
    }
  out.tag("end of cosimulation result");
}

CosimulationResult restore_cosimulation_result(dem::StateReader& in, Eigen::Index modes, std::size_t dampers) {
  CosimulationResult r;
  in.expect_tag("cosimulation result 2");
  r.outcome = static_cast<dem::Outcome>(in.i32_in("outcome", 0, 2));
  r.message = in.text("message", kMaxWarningBytes);
  r.time_step_s = in.finite("time_step_s");
  for (std::int64_t* v : {&r.steps, &r.steps_per_period, &r.settling_steps}) {
    *v = in.i64("steps");
    if (*v < 0) in.fail("steps", "must not be negative");
  }
  r.simulated_time_s = in.finite("simulated_time_s");
  r.start_time_s = in.finite("start_time_s");
  r.continued = in.boolean("continued");
  r.wall_time_s = in.finite("wall_time_s");
  const auto n = static_cast<std::size_t>(modes);
  r.frequencies_with_containers_hz = read_vector(in, "frequencies_with_containers_hz", n);
  r.final_modal_displacements = read_vector(in, "final_modal_displacements", n);
  r.final_modal_velocities = read_vector(in, "final_modal_velocities", n);
  auto& h = r.history;
  h.time_s = in.finite_f64s_up_to("history.time_s", kMaxSamples);
  const std::size_t samples = h.time_s.size();
  h.modal_displacements = read_matrix(in, "history.modal_displacements", samples, n);
  h.site_displacement_m = read_matrix(in, "history.site_displacement_m", samples, dampers);
  h.site_rotation_rad = read_matrix(in, "history.site_rotation_rad", samples, dampers);
  h.container_load_n = read_matrix(in, "history.container_load_n", samples, dampers);
  h.container_moment_nm = read_matrix(in, "history.container_moment_nm", samples, dampers);
  h.pending_load_sum_n = in.finite_f64s_up_to("history.pending_load_sum_n", dampers);
  h.pending_moment_sum_nm = in.finite_f64s_up_to("history.pending_moment_sum_nm", dampers);
  h.pending_steps = in.i64("history.pending_steps");
  if (h.pending_steps < 0) in.fail("history.pending_steps", "must not be negative");
  const std::size_t warnings = in.count("warnings", 10000, 8);
  for (std::size_t k = 0; k < warnings; ++k) r.warnings.push_back(in.text("warnings", kMaxWarningBytes));
  const std::size_t snapshots = in.count("bed_snapshots", static_cast<std::size_t>(dem::limits::kMaxSnapshots), 8);
  for (std::size_t k = 0; k < snapshots; ++k) {
    std::vector<BedSnapshot> beds(dampers);
    for (auto& bed : beds) {
      bed.particles = dem::restore_particle_snapshot(in, "bed_snapshot");
      for (double& x : bed.container_position_m) x = in.finite("bed_snapshot.container_position_m");
    }
    r.bed_snapshots.push_back(std::move(beds));
  }
  in.expect_tag("end of cosimulation result");
  return r;
}

void append_continuation(CosimulationResult& total, const CosimulationResult& next, const CosimulationState& state) {
  auto& h = total.history;
  const auto& g = next.history;
  const Eigen::Index have = static_cast<Eigen::Index>(h.time_s.size());
  const Eigen::Index add = std::max<Eigen::Index>(0, static_cast<Eigen::Index>(g.time_s.size()) - 1);
  h.time_s.insert(h.time_s.end(), g.time_s.begin() + std::min<std::size_t>(1, g.time_s.size()), g.time_s.end());
  for (auto [to, from] : {std::pair{&h.modal_displacements, &g.modal_displacements},
                          std::pair{&h.site_displacement_m, &g.site_displacement_m},
                          std::pair{&h.site_rotation_rad, &g.site_rotation_rad},
                          std::pair{&h.container_load_n, &g.container_load_n},
                          std::pair{&h.container_moment_nm, &g.container_moment_nm}}) {
    to->conservativeResize(have + add, from->cols());
    if (add > 0) to->bottomRows(add) = from->bottomRows(add);
  }
  h.pending_load_sum_n = g.pending_load_sum_n;
  h.pending_moment_sum_nm = g.pending_moment_sum_nm;
  h.pending_steps = g.pending_steps;
  total.energy = state.energy_since_start;
  total.steps += next.steps;
  total.simulated_time_s += next.simulated_time_s;
  total.wall_time_s += next.wall_time_s;
  auto& times = total.stage_times;
  const auto& more = next.stage_times;
  times.settling_s += more.settling_s;
  times.modal_kick_drift_s += more.modal_kick_drift_s;
  times.bed_steps_s += more.bed_steps_s;
  times.closing_kick_s += more.closing_kick_s;
  times.ledger_s += more.ledger_s;
  times.measures_s += more.measures_s;
  total.outcome = next.outcome;
  total.message = next.message;
  total.final_modal_displacements = next.final_modal_displacements;
  total.final_modal_velocities = next.final_modal_velocities;
  total.world_status = next.world_status;
  total.final_container_states = next.final_container_states;
  for (const auto& w : next.warnings)
    if (std::find(total.warnings.begin(), total.warnings.end(), w) == total.warnings.end()) total.warnings.push_back(w);
}

}  // namespace pdamp::structure
