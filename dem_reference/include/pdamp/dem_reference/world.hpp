// The reference DEM world: spheres in a moving container, one explicit step at a time.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/container_motion.hpp"
#include "pdamp/dem_reference/summary.hpp"
#include "pdamp/dem_reference/world_options.hpp"

namespace pdamp::dem_reference {

/// Version of the DEM physics (contact laws, integration, measures). Bumped whenever
/// results change for the same input; the effective fields hash it.
/// 2: the ISO 3290 ball-lot tolerance by default, the drive-bin measure accumulated
/// every step, the impact speed from the free-fall height.
/// 3: wall layers with the bonded-layer contact law (worlds without layers give the
/// same results as in version 2).
/// 4: the tangential and rolling springs projected into the new contact plane without
/// the rescale to their old magnitude (docs/dem.md "Tangential").
/// 5: the automatic step takes the fewest steps per contact in [20, 50] that keep one
/// impact's restitution error within 1 % (automatic_steps_per_contact; was 50 always).
inline constexpr int kPhysicsModelVersion = 5;

/// The largest relative error of the restitution one impact realises at N steps per
/// contact time, for the target ε: (0.6 ln²ε + 0.1)/N (the realised ε is low by at most
/// this, high by at most 0.15/N; measured for N >= 40, ε >= 0.05 in test_measures; at
/// 20-39 steps small ε exceed it by up to 0.1 percentage point).
double restitution_error_bound(double restitution, double steps_per_contact);

/// The automatic steps per contact (docs/dem.md "Integration and time step"): the fewest
/// N in [limits::kMinStepsPerContact, kMaxAutomaticStepsPerContact] with
/// restitution_error_bound(ε_min, N) <= kAutomaticRestitutionError, ε_min the smallest
/// restitution of the pairs (constants and table values); the upper end when a pair
/// takes ε from a restitution model (its smallest value is not known beforehand) or
/// when ε_min is below 0.44 (the bound at 50 steps is then above 1 %: ε = 0.3 gives 2.9 %).
inline constexpr double kAutomaticRestitutionError = 0.01;
inline constexpr int kMaxAutomaticStepsPerContact = 50;
int automatic_steps_per_contact(const WorldOptions& options);

/// The smallest restitution the pairs of these options can give (constants and table
/// nodes); NaN when a pair takes ε from a restitution model.
double smallest_restitution(const WorldOptions& options);

/// The automatic time-step bound (docs/dem.md "Integration and time step").
struct TimeStepBound {
  double contact_time_s = 0.0;   ///< shortest Hertz contact time at max_impact_speed_m_s over all pairs
  double rayleigh_time_s = 0.0;  ///< T_R = πr√(ρ/G)/(0.1631ν + 0.8766) of the smallest sphere
  /// N: integration.steps_per_contact when given, else automatic_steps_per_contact
  int steps_per_contact = 0;
  double max_time_step_s = 0.0;  ///< min(t_c/N, rayleigh_fraction·T_R)
};
/// Bound for these options; throws std::invalid_argument if the options are invalid.
TimeStepBound time_step_bound(const WorldOptions& options);

/// Cumulative energy account since construction (J) and the current energies.
struct EnergyAccount {
  double container_work_j = 0.0;   ///< work done by the container on the particles
  double normal_damping_j = 0.0;   ///< dissipated by the normal damping
  /// dissipated tangentially: Coulomb slip and the Mindlin loading/unloading hysteresis
  double friction_j = 0.0;
  double rolling_j = 0.0;          ///< dissipated by rolling resistance
  double kinetic_j = 0.0;          ///< current translational + rotational kinetic energy
  double potential_j = 0.0;        ///< current gravitational energy −Σ m g·x
  double elastic_j = 0.0;          ///< current energy stored in contacts (Hertz, tangential, rolling springs)
  double dissipated_j() const { return normal_damping_j + friction_j + rolling_j; }
};

/// Who touches what at the current step.
struct ContactCensus {
  int touching_walls = 0;  ///< particles touching a container wall, inner structure or layer
  /// particles touching a wall whose normal (sphere → wall) is within 45° of `down`
  int touching_base = 0;
  int airborne = 0;        ///< particles touching nothing
};

/// Status of a world: instability or a failure stops meaningful stepping.
struct WorldStatus {
  /// kCompleted while healthy, kUnstable once an instability is detected, kFailed once
  /// a step threw (e.g. a user restitution model): step() catches it on every thread.
  Outcome outcome = Outcome::kCompleted;
  std::string message;                    ///< reason and advice when not kCompleted
};

/// A world of spheres in one or more compartments of a rigid damper body.
///
/// Each step is the leapfrog form of velocity Verlet: kick the half-step velocities
/// with the last forces, drift, move the container to the state given for the new
/// time, then find contacts and compute forces (Hertz + calibrated damping, Mindlin
/// tangential spring with Coulomb cap, rolling resistance). See docs/dem.md.
class World {
 public:
  /// Builds particles and walls and places the bed (initial container state `start`).
  /// Throws std::invalid_argument: invalid options (all violations, one per line),
  /// a user time step above the automatic bound, particles that do not fit.
  explicit World(const WorldOptions& options, const ContainerState& start = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  /// Advances one time step; `container` is the container's state at time_s() + dt.
  /// Returns what the container applies to the particles at the new time. Does not
  /// allocate (except when a Verlet-list rebuild outgrows the reserved capacity).
  /// Never throws: an exception inside the step (any thread) sets status() to kFailed
  /// with its message. After an instability or a failure (status().outcome !=
  /// kCompleted) it does nothing.
  const ContainerLoad& step(const ContainerState& container);
  /// step(motion.state(time_s() + dt)).
  const ContainerLoad& step(const ContainerMotion& motion);

  /// Sets particle i's position (m), velocity (m/s) and angular velocity (rad/s), world
  /// frame, at the current time: for test set-ups and co-simulation starts. The particle
  /// should be free of contacts; the Verlet lists are rebuilt at the next step.
  /// Throws std::out_of_range for an index outside [0, particle_count()).
  void set_particle_state(int i, const Vec3& position_m, const Vec3& velocity_m_s,
                          const Vec3& angular_velocity_rad_s);

  /// Adds the same velocity (m/s, world frame) to every particle: a Galilean boost that
  /// leaves contacts unchanged (run_harmonic starts the bed moving with the container).
  void add_velocity(const Vec3& velocity_m_s);

  /// The options the world was built with (integration.time_step_s as given, 0 = automatic).
  const WorldOptions& options() const;
  double time_step_s() const;
  double time_s() const;
  std::int64_t step_count() const;
  const TimeStepBound& time_step_bound() const;
  const WorldStatus& status() const;
  const ContainerLoad& load() const;
  const ContainerState& container() const;

  int particle_count() const;
  int compartment_count() const;
  Vec3 position(int i) const;          ///< m, world frame
  Vec3 velocity(int i) const;          ///< m/s, at the current time (full step)
  Vec3 angular_velocity(int i) const;  ///< rad/s, at the current time (full step)
  double radius(int i) const;          ///< m
  double mass(int i) const;            ///< kg
  int compartment(int i) const;
  double bed_mass_kg() const;          ///< all particles
  /// Clearance h of the compartment's collected bed along its collect axis (the free
  /// travel of the settled bed, docs/theory.md §9, "Clearance of a real bed",
  /// formulas::LatticeBed::settled_clearance_m), m; NaN if a lattice cannot be built.
  double clearance_m(int compartment) const;
  /// Σ m v: total momentum of the particles at the current time, kg·m/s.
  Vec3 bed_momentum() const;
  /// Centre of mass of the particles, m, world frame.
  Vec3 bed_centre_of_mass() const;

  /// Energy account (cumulative terms since construction, current energies now).
  EnergyAccount energy() const;
  /// Contact census; `down` is any non-zero direction (e.g. gravity), else touching_base = 0.
  ContactCensus contact_census(const Vec3& down) const;
  /// Particle pairs currently in contact.
  int contact_count() const;
  /// Per particle (the caller's numbering): the contacts it has now, with other particles
  /// and with walls, plates, pins and layers.
  std::vector<int> contacts_per_particle() const;

  std::int64_t neighbour_rebuilds() const;
  const StageTimes& stage_times() const;
  /// Bytes held by the world's arrays (particles, contact lists and history, cells).
  std::size_t memory_bytes() const;
  /// FNV-1a hash of positions, velocities and angular velocities (determinism tests).
  std::uint64_t state_hash() const;

  /// Writes the world's whole mutable state (checkpoint.hpp, docs/dem.md "Checkpoints"):
  /// particles (positions, half-step velocities, forces and torques, positions at the last
  /// list rebuild, internal numbering), neighbour rows and contact histories, the work
  /// partitions, the container, the energy account and the counters (not the stage times:
  /// a resumed run times its own steps). What the options determine (radii, masses,
  /// materials, walls, time step) is not written.
  void save_state(StateWriter& out) const;
  /// Continues from what save_state wrote on a World built from the same options: the
  /// steps that follow are bit for bit those the saved world would have taken (same
  /// thread count: the partitions are part of the state). std::invalid_argument naming the
  /// field when the state is of another world (particle, compartment, wall or partition
  /// count, time step, rolling resistance) or inconsistent (a numbering that is no
  /// permutation, a list entry pointing outside, a non-finite value); the world is then
  /// unchanged.
  void restore_state(StateReader& in);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pdamp::dem_reference
