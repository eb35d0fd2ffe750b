// The end of a co-simulation run, to be continued by the next or saved (docs/cosimulation.md
// §6, §6b): the worlds, the modal state, the clock and the energy account since the first
// start; the checkpoints of a run in segments.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/dem_reference/world.hpp"
#include "pdamp/structure/cosimulation_damper.hpp"
#include "pdamp/structure/cosimulation_options.hpp"
#include "pdamp/structure/cosimulation_result.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// The end of a co-simulation run, to be continued by the next (a stepped sine: each
/// frequency starts from the previous one's final state, bed included). Filled by
/// cosimulate(…, state, …); pass it back unchanged. It owns the worlds: the particles, their
/// contacts (tangential springs, rolling history), the container pose and the time step.
struct CosimulationState {
  std::vector<dem_reference::World> worlds;  ///< one per damper, at the end of the last run
  Eigen::VectorXd modal_displacements;       ///< q at the end (relative for base motion)
  Eigen::VectorXd modal_velocities;          ///< q̇ at the end
  double time_s = 0.0;                       ///< coupled time since the first run's start, s
  std::int64_t steps = 0;                    ///< coupled steps since the first run's start
  double time_step_s = 0.0;                  ///< the worlds' step, s (fixed for all continuations)
  /// The excitation of the last run (after a sweep: its frequency the sweep's end frequency).
  CosimulationExcitation excitation;
  /// Harmonic: the drive's phase ψ at the end, rad, in [0, 2π). Runs at one frequency end on
  /// whole periods, so this is their start phase; the next run starts its sine there.
  double excitation_phase_rad = 0.0;
  /// The energy account since the first run's start (docs/cosimulation.md §4): what one run
  /// of the combined length reports, to the bit. Its running sums (work, structural damping)
  /// continue from run to run; its changes are taken from the first start's references below.
  /// A run split into segments (checkpoints) reports this as its whole.
  CosimulationEnergy energy_since_start;
  double start_structure_kinetic_j = 0.0;    ///< T' at the first start, J
  double start_structure_potential_j = 0.0;  ///< ½qᵀKq at the first start, J
  std::vector<dem_reference::EnergyAccount> start_world_energy;  ///< each world's account at the first start
  /// true once a run has filled the state (worlds built, beds settled).
  bool started() const { return !worlds.empty(); }
};

/// Checkpoints of a co-simulation run in segments (docs/cosimulation.md §6b).
/// save_cosimulation_state writes a started state: each world's integration settings and
/// whole state (World::save_state), q, q̇, the time, steps, step and the excitation with its
/// phase. restore_cosimulation_state builds the worlds from `dampers` (their World options
/// with the saved integration settings) and restores them, so that continuing the restored
/// state is bit for bit continuing the saved one. std::invalid_argument naming the field when
/// the state does not fit the model and dampers (mode or damper count, another bed) or is
/// damaged.
void save_cosimulation_state(const CosimulationState& state, dem_reference::StateWriter& out);
CosimulationState restore_cosimulation_state(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                             dem_reference::StateReader& in);

/// A free decay's result so far, for a checkpoint: the histories, the counters, the
/// frequencies with the containers and the warnings (the energy account is the state's) (harmonic results are not
/// written: only a free decay is run in segments). restore_cosimulation_result refuses a
/// result of another shape (modes, dampers) naming the field.
void save_cosimulation_result(const CosimulationResult& result, dem_reference::StateWriter& out);
CosimulationResult restore_cosimulation_result(dem_reference::StateReader& in, Eigen::Index modes, std::size_t dampers);

/// Appends the result of a continuation to the result of the runs before it (a free decay
/// run in segments, each continuing the state the last one left): the histories without the
/// continuation's first sample (the last one's final sample again), the counters summed, the
/// continuation's outcome, final states and warnings not yet listed, the stage times summed,
/// and the energy account of `state` since the first start (CosimulationState::
/// energy_since_start: a sum of the runs' own accounts would differ from one run's in the
/// last bits). Segments of whole
/// sample intervals (options.sample_interval_s fixed) give the histories one run records.
void append_continuation(CosimulationResult& total, const CosimulationResult& next, const CosimulationState& state);

}  // namespace pdamp::structure
