// The block recorder of a driven DEM run: the signal series (for plots and the time
// series file) and the particle snapshots, fed after every World::step by any driver.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/world.hpp"

namespace pdamp::dem_reference {

/// Signals over the analysed periods, one sample per block (block averages).
struct TimeSeries {
  std::vector<double> time_s;
  std::vector<double> container_position_m;    ///< along the drive, m
  std::vector<double> container_velocity_m_s;  ///< along the drive, m/s
  std::vector<double> force_n;                 ///< container → particles along the drive, N
  std::vector<double> bed_relative_position_m; ///< bed centre of mass − container, along the drive, m
  std::vector<double> bed_momentum_kg_m_s;     ///< along the drive, kg·m/s
  std::vector<double> kinetic_energy_j;        ///< particles, J
};

/// Particle state at one time (ParaView output).
struct ParticleSnapshot {
  double time_s = 0.0;
  std::vector<Vec3> positions_m;
  std::vector<Vec3> velocities_m_s;
  std::vector<Vec3> angular_velocities_rad_s;
  std::vector<double> radii_m;
  std::vector<int> compartments;
  std::vector<int> contacts;  ///< per particle: its contacts (particles and walls) at time_s
};

/// The particles of `world` now, stamped `time_s` (positions and velocities in the world frame).
ParticleSnapshot particle_snapshot(const World& world, double time_s);
/// A snapshot in a checkpoint (the recorder's and the co-simulation's): its time, particle
/// count, vectors, radii, compartments and contacts. The read refuses non-finite numbers and
/// counts the bytes left cannot hold; `what` prefixes the field names in its errors.
void save_particle_snapshot(StateWriter& out, const ParticleSnapshot& snapshot);
ParticleSnapshot restore_particle_snapshot(StateReader& in, const std::string& what);

/// What a BlockRecorder records: the drive axis, the block clock and the snapshots.
struct BlockRecorderOptions {
  Vec3 drive_axis{1.0, 0.0, 0.0};   ///< unit vector the signals are projected on
  double time_step_s = 0.0;         ///< dt of the world, s; the drive time of step k is k·dt
  std::int64_t steps_per_block = 1; ///< >= 1
  int blocks_per_period = 1;        ///< >= 1
  int periods = 1;                  ///< recorded periods (the series are reserved for them), >= 1
  /// Drive steps taken before the first recorded step (settling not counted).
  std::int64_t start_step = 0;
  /// Particle snapshots, evenly spaced over the recorded blocks (at block ends), in
  /// [0, periods × blocks_per_period].
  int snapshots = 0;
  /// A prescribed motion gives the container position at a block's mid time exactly;
  /// without one (a structure's state, known only at the steps) the block mean of the
  /// positions is recorded, which differs by O((Ω·block)²).
  const ContainerMotion* prescribed_motion = nullptr;
};

/// Records the series of a driven run. Call record_step(world) after every World::step
/// of the recorded periods: it adds the step's container velocity and load (read from
/// the world) to the block averages, and at a block's end samples the bed's
/// instantaneous state (centre of mass, momentum, kinetic energy) and, on schedule, a
/// snapshot. The series are reserved at construction: a step allocates nothing (a
/// snapshot block copies the particles).
class BlockRecorder {
 public:
  /// Throws std::invalid_argument for options out of range.
  explicit BlockRecorder(const BlockRecorderOptions& options);

  /// Adds the world's last step; returns true when it ended a block.
  bool record_step(const World& world);

  const BlockRecorderOptions& options() const { return options_; }
  std::int64_t recorded_blocks() const { return static_cast<std::int64_t>(series_.time_s.size()); }
  const TimeSeries& series() const { return series_; }
  /// Drive times of the block ends, where the bed's instantaneous samples are taken, s.
  const std::vector<double>& sample_times_s() const { return sample_times_s_; }
  /// Checkpoints at any step (checkpoint.hpp): the step, the block in progress, the series
  /// and the snapshots so far. restore throws std::invalid_argument for a state of another
  /// recorder (more blocks or snapshots than its options hold, non-finite values).
  void save(StateWriter& out) const;
  void restore(StateReader& in);
  /// Moves the series and the snapshots out (the recorder is spent afterwards).
  TimeSeries take_series() { return std::move(series_); }
  std::vector<ParticleSnapshot> take_snapshots() { return std::move(snapshots_); }

 private:
  BlockRecorderOptions options_;
  std::int64_t step_ = 0;           ///< drive step index of the last recorded step
  std::int64_t step_in_block_ = 0;
  double force_sum_ = 0.0;          ///< Σ over the block, N
  double velocity_sum_ = 0.0;       ///< Σ over the block, m/s
  double position_sum_ = 0.0;       ///< Σ over the block, m (without a prescribed motion)
  std::int64_t next_snapshot_ = 0;  ///< index of the next snapshot to take
  TimeSeries series_;
  std::vector<double> sample_times_s_;
  std::vector<ParticleSnapshot> snapshots_;
};

}  // namespace pdamp::dem_reference
