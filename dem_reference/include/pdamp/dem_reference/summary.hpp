// Outcome, counters and per-stage times of a DEM run.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace pdamp::dem_reference {

enum class Outcome {
  kCompleted,  ///< ran to the end
  kUnstable,   ///< numerical instability detected (overlap, NaN, energy growth): see message
  kFailed,     ///< any other run-time failure: see message
};
/// "completed", "unstable", "failed".
std::string_view to_string(Outcome outcome);

/// Wall-clock seconds spent in each stage of World::step (sampled every 32nd step
/// and scaled, so that timing costs nothing measurable).
struct StageTimes {
  double integrate_s = 0.0;       ///< kick + drift of the particles
  double neighbour_s = 0.0;       ///< displacement check and Verlet-list rebuilds
  /// particle–particle and particle–wall contacts, reduction of the thread buffers
  double contact_forces_s = 0.0;
  double record_s = 0.0;          ///< container load, energy account, stability checks
  double total() const;
};

struct Summary {
  Outcome outcome = Outcome::kCompleted;
  /// Empty when completed; else what happened and advice (e.g. reduce the time step).
  std::string message;
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  std::int64_t neighbour_rebuilds = 0;
  int particles = 0;
  double time_step_s = 0.0;
  double simulated_time_s = 0.0;
  double wall_time_s = 0.0;
  StageTimes stage_times;

  /// One line: outcome, steps, particle-steps/s, wall time.
  std::string brief_report() const;
  /// Several lines: the brief report, the stage times and the message.
  std::string full_report() const;
};

}  // namespace pdamp::dem_reference
