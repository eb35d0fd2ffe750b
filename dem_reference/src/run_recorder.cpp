// The block recorder of a driven run (docs/dem.md "Run machinery").
#include "pdamp/dem_reference/run_recorder.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "vec3_ops.hpp"

namespace pdamp::dem_reference {

namespace {

using detail::dot;


std::int64_t block_count(const BlockRecorderOptions& o) {
  return static_cast<std::int64_t>(o.periods) * o.blocks_per_period;
}

/// Block (0-based) of snapshot s: evenly spaced, the last at the last block. Strictly
/// increasing in s because snapshots <= blocks.
std::int64_t snapshot_block(const BlockRecorderOptions& o, std::int64_t s) {
  return static_cast<std::int64_t>((static_cast<double>(s) + 1.0) * static_cast<double>(block_count(o)) / o.snapshots) - 1;
}

void check(const BlockRecorderOptions& o) {
  std::ostringstream errors;
  if (!(std::isfinite(o.time_step_s) && o.time_step_s > 0.0)) errors << "recorder time_step_s = " << o.time_step_s << ": must be > 0 s\n";
  if (o.steps_per_block < 1) errors << "recorder steps_per_block = " << o.steps_per_block << ": must be >= 1\n";
  if (o.blocks_per_period < 1) errors << "recorder blocks_per_period = " << o.blocks_per_period << ": must be >= 1\n";
  if (o.periods < 1) errors << "recorder periods = " << o.periods << ": must be >= 1\n";
  if (o.start_step < 0) errors << "recorder start_step = " << o.start_step << ": must be >= 0\n";
  if (o.snapshots < 0 || (o.periods >= 1 && o.blocks_per_period >= 1 && o.snapshots > block_count(o))) {
    errors << "recorder snapshots = " << o.snapshots << ": must be in [0, periods x blocks_per_period]\n";
  }
  std::string text = errors.str();
  if (!text.empty()) {
    text.pop_back();
    throw std::invalid_argument(text);
  }
}

}  // namespace

BlockRecorder::BlockRecorder(const BlockRecorderOptions& options) : options_(options), step_(options.start_step) {
  check(options_);
  const auto blocks = static_cast<std::size_t>(block_count(options_));
  for (auto* v : {&series_.time_s, &series_.container_position_m, &series_.container_velocity_m_s, &series_.force_n,
                  &series_.bed_relative_position_m, &series_.bed_momentum_kg_m_s, &series_.kinetic_energy_j,
                  &sample_times_s_}) {
    v->reserve(blocks);
  }
  snapshots_.reserve(static_cast<std::size_t>(options_.snapshots));
}

void BlockRecorder::save(StateWriter& out) const {
  out.i64(step_);
  out.i64(step_in_block_);  // a block in progress (a checkpoint at any step): its sums
  for (double v : {force_sum_, velocity_sum_, position_sum_}) out.f64(v);
  for (const auto* v : {&series_.time_s, &series_.container_position_m, &series_.container_velocity_m_s, &series_.force_n,
                        &series_.bed_relative_position_m, &series_.bed_momentum_kg_m_s, &series_.kinetic_energy_j,
                        &sample_times_s_})
    out.f64s(*v);
  out.i64(next_snapshot_);
  out.i64(static_cast<std::int64_t>(snapshots_.size()));
  for (const auto& s : snapshots_) save_particle_snapshot(out, s);
}

void BlockRecorder::restore(StateReader& in) {
  step_ = in.i64("recorder.step");
  if (step_ < options_.start_step) in.fail("recorder.step", "is before the recorder's start");
  step_in_block_ = in.i64("recorder.step_in_block");
  if (step_in_block_ < 0 || step_in_block_ >= options_.steps_per_block)
    in.fail("recorder.step_in_block", std::to_string(step_in_block_) + ": must be in [0, steps_per_block)");
  force_sum_ = in.finite("recorder.force_sum");
  velocity_sum_ = in.finite("recorder.velocity_sum");
  position_sum_ = in.finite("recorder.position_sum");
  const auto blocks = static_cast<std::size_t>(block_count(options_));
  series_.time_s = in.finite_f64s_up_to("recorder.series", blocks);
  const std::size_t recorded = series_.time_s.size();
  for (auto* v : {&series_.container_position_m, &series_.container_velocity_m_s, &series_.force_n,
                  &series_.bed_relative_position_m, &series_.bed_momentum_kg_m_s, &series_.kinetic_energy_j,
                  &sample_times_s_})
    *v = in.finite_f64s("recorder.series", recorded);
  next_snapshot_ = in.i64("recorder.next_snapshot");
  const std::size_t taken = in.count("recorder.snapshots", static_cast<std::size_t>(options_.snapshots), 8);
  if (next_snapshot_ != static_cast<std::int64_t>(taken)) in.fail("recorder.next_snapshot", "does not match the snapshots taken");
  snapshots_.clear();
  for (std::size_t k = 0; k < taken; ++k) snapshots_.push_back(restore_particle_snapshot(in, "recorder.snapshot"));
}

bool BlockRecorder::record_step(const World& world) {
  const Vec3& axis = options_.drive_axis;
  const ContainerState& container = world.container();
  ++step_;
  force_sum_ += dot(world.load().force_n, axis);
  velocity_sum_ += dot(container.velocity_m_s, axis);
  if (options_.prescribed_motion == nullptr) position_sum_ += dot(container.position_m, axis);
  if (++step_in_block_ < options_.steps_per_block) return false;

  // Block end: the averages over the block's steps, centred at their mean time.
  const double dt = options_.time_step_s;
  const std::int64_t spb = options_.steps_per_block;
  const auto steps = static_cast<double>(spb);
  const double t_mid = (static_cast<double>(step_ - spb) + 0.5 * static_cast<double>(spb + 1)) * dt;
  series_.time_s.push_back(t_mid);
  series_.container_position_m.push_back(options_.prescribed_motion != nullptr
                                             ? dot(options_.prescribed_motion->state(t_mid).position_m, axis)
                                             : position_sum_ / steps);
  series_.container_velocity_m_s.push_back(velocity_sum_ / steps);
  series_.force_n.push_back(force_sum_ / steps);
  // The bed's instantaneous state at the block end.
  const double t_end = static_cast<double>(step_) * dt;
  series_.bed_relative_position_m.push_back(dot(world.bed_centre_of_mass(), axis) - dot(container.position_m, axis));
  sample_times_s_.push_back(t_end);
  series_.bed_momentum_kg_m_s.push_back(dot(world.bed_momentum(), axis));
  series_.kinetic_energy_j.push_back(world.energy().kinetic_j);
  const std::int64_t block = recorded_blocks() - 1;
  if (next_snapshot_ < options_.snapshots && snapshot_block(options_, next_snapshot_) == block) {
    snapshots_.push_back(particle_snapshot(world, t_end));
    ++next_snapshot_;
  }
  step_in_block_ = 0;
  force_sum_ = velocity_sum_ = position_sum_ = 0.0;
  return true;
}

void save_particle_snapshot(StateWriter& out, const ParticleSnapshot& s) {
  out.f64(s.time_s);
  out.i64(static_cast<std::int64_t>(s.radii_m.size()));
  for (const auto* v : {&s.positions_m, &s.velocities_m_s, &s.angular_velocities_rad_s})
    for (const auto& p : *v)
      for (double x : p) out.f64(x);
  out.f64s(s.radii_m);
  out.i32s(s.compartments);
  out.i32s(s.contacts);
}

ParticleSnapshot restore_particle_snapshot(StateReader& in, const std::string& what) {
  ParticleSnapshot s;
  s.time_s = in.finite((what + ".time_s").c_str());
  const std::size_t n = in.count((what + ".particles").c_str(), 100000000, 9 * 8);
  for (auto* v : {&s.positions_m, &s.velocities_m_s, &s.angular_velocities_rad_s}) {
    v->resize(n);
    for (auto& p : *v)
      for (double& x : p) x = in.finite(what.c_str());
  }
  s.radii_m = in.finite_f64s((what + ".radii_m").c_str(), n);
  s.compartments = in.i32s((what + ".compartments").c_str(), n, 0, 1 << 20);
  s.contacts = in.i32s((what + ".contacts").c_str(), n, 0, 1 << 20);
  return s;
}

ParticleSnapshot particle_snapshot(const World& world, double time_s) {
  ParticleSnapshot s;
  s.time_s = time_s;
  const int n = world.particle_count();
  for (int i = 0; i < n; ++i) {
    s.positions_m.push_back(world.position(i));
    s.velocities_m_s.push_back(world.velocity(i));
    s.angular_velocities_rad_s.push_back(world.angular_velocity(i));
    s.radii_m.push_back(world.radius(i));
    s.compartments.push_back(world.compartment(i));
  }
  s.contacts = world.contacts_per_particle();
  return s;
}

}  // namespace pdamp::dem_reference
