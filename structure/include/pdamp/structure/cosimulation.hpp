// A co-simulation: a ModalModel integrated in time with one reference-DEM World per damper,
// the bed in the loop (docs/theory.md §7.8, docs/cosimulation.md). The run as an object:
// built (fresh, continuing a state, or from a checkpoint), advanced step by step in segments
// of any length, saved, and read out (docs/cosimulation.md §8); cosimulate() runs it through.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdamp/base/run_hooks.hpp"
#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/structure/cosimulation_damper.hpp"
#include "pdamp/structure/cosimulation_options.hpp"
#include "pdamp/structure/cosimulation_result.hpp"
#include "pdamp/structure/cosimulation_state.hpp"
#include "pdamp/structure/modal_model.hpp"

namespace pdamp::structure {

/// One co-simulation run: what cosimulate() does, with the run's length in the caller's
/// hands. The constructor validates the inputs, plans the step, builds the worlds and settles
/// the beds (a fresh run) or takes them over (a continuation); advance() then runs the
/// coupled steps in segments of any length. A run advanced in segments gives the bits of one
/// advanced at once (the segments share every sum and the drive's clock), and result() is at
/// any point what cosimulate() of that length returns. Each step is the stages of
/// CosimulationStageTimes in order. The model and dampers are copied where needed: the
/// arguments need not outlive the run. Not copyable; movable.
class Cosimulation {
 public:
  /// A fresh run, as cosimulate(model, dampers, run, hooks): throws std::invalid_argument
  /// for invalid inputs (every violation, one per line) and for a step the structure cannot
  /// take. `hooks` (which must outlive the run) get progress reports while the beds settle
  /// and from advance(), and are asked whether to stop: while the beds settle a stop throws
  /// base::Interrupted (no consistent state to keep yet).
  Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers, const CosimulationRun& run,
               base::RunHooks& hooks = base::silent_hooks());
  /// `run` continuing `state` (CosimulationState::started(); else a fresh run, as
  /// cosimulate(…, state, …)). Throws as cosimulate() before taking the state: on a throw
  /// `state` is left as it was.
  Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers, const CosimulationRun& run,
               CosimulationState&& state, base::RunHooks& hooks = base::silent_hooks());
  /// The free decay `run` (the same as its fresh start) from the checkpoint that save()
  /// wrote: the run goes on at the saved step, and its result and state are those of the run
  /// never stopped, to the bit. Throws std::invalid_argument for a checkpoint that does not
  /// fit (another case, another step, damaged bytes: the field named) and for a harmonic run
  /// (its measures' running sums are not in the checkpoint).
  static Cosimulation restore(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const DecayRun& run, dem_reference::StateReader& in,
                              base::RunHooks& hooks = base::silent_hooks());

  Cosimulation(Cosimulation&&) noexcept;
  Cosimulation& operator=(Cosimulation&&) noexcept;
  ~Cosimulation();

  /// Runs min(steps, total_steps() − steps_done()) further coupled steps (fewer when a World
  /// stops: result().outcome says why) and returns how many it ran. steps <= 0 runs none.
  /// The hooks are asked every kStopPollSteps steps whether to stop (a step of a
  /// million-sphere bed is tens of milliseconds, so a stop request is met within about a
  /// second): a stop ends it early at a step boundary, where save() may follow and a
  /// restored run continues it to the bit; stop_signal() then says which.
  std::int64_t advance(std::int64_t steps);
  static constexpr std::int64_t kStopPollSteps = 16;
  /// The signal of the stop request that ended advance() early, 0 when none did.
  int stop_signal() const;
  /// The run is at its end, or a World stopped.
  bool finished() const;
  /// Coupled steps of this run so far (a restored run counts its steps before the checkpoint).
  std::int64_t steps_done() const;
  /// The run's planned steps. Harmonic with settle_until_stable: moves earlier once the
  /// response has settled (the analysed periods then follow at once).
  std::int64_t total_steps() const;
  /// The common step dt of the worlds and the modes, s.
  double time_step_s() const;

  /// The run so far, as cosimulate() of this length returns it (steady state: the analysed
  /// periods completed; a continuation's stage times and wall time are this run's).
  CosimulationResult result() const&;
  /// The same with the histories moved out rather than copied (a run sampled at every step
  /// holds large ones); afterwards only take_state() may follow.
  CosimulationResult result() &&;
  /// The state at steps_done(), to continue with a new run (a new frequency of a stepped
  /// sine) or to save.
  const CosimulationState& state() const;
  /// Hands the state (worlds and all) over to the caller; advance() and result() then throw
  /// std::logic_error.
  CosimulationState take_state() &&;
  /// A checkpoint of a free decay: save_cosimulation_state, then save_cosimulation_result of
  /// the run so far (the layout of pdamp's decay checkpoints), for restore(). Throws
  /// std::logic_error for a harmonic run (restore() could not continue its measures).
  void save(dem_reference::StateWriter& out) const;

 private:
  struct Impl;
  explicit Cosimulation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// Runs the co-simulation. The modal equations
///   M q̈ + C q̇ + K q = f_exc(t) − Σ_d (b_d F_d + r_d M_d),   M = diag(m_j) + Σ m_c Φ_dᵀΦ_d,
/// (F_d, M_d: what container d applies to its bed along n and about the rotation axis; b_d,
/// r_d the site's drive and rotation shapes) are advanced with the worlds' step dt by
/// velocity Verlet with the damping term trapezoidal (implicit, exact solve): the structure
/// and the beds form one leapfrog, second order, with no lag in the coupling.
/// Throws std::invalid_argument for invalid inputs (every violation, one per line) and for a
/// step the structure cannot take (ω_max·dt > 0.2). It is a Cosimulation advanced to its
/// end: use that class to run the steps in segments.
/// A stop request (the hooks) throws base::Interrupted: the run keeps nothing.
CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationRun& run, base::RunHooks& hooks = base::silent_hooks());

/// The same run, continuing `state` when it has started, and leaving the run's end in it.
/// - Fresh (state.started() false): as above (worlds built, beds settled); then the state
///   holds the worlds, q, q̇, t, dt, the excitation and the drive's end phase.
/// - Continuation: no new worlds, no settling; q(0), q̇(0) are the state's (the run's
///   initial_modal_* must be empty); dt is the state's (its time_step_s must be 0 or
///   equal); the excitation must have the state's kind, direction, amplitude and point
///   (harmonic: the frequency may change; a free decay continues a free decay only); a
///   harmonic drive starts at the state's end phase, so the base displacement and the force
///   are continuous at the junction (with φ = π/2 the base velocity too, docs/cosimulation.md
///   §6); history times continue from state.time_s. Two runs continued at one frequency are
///   bit-identical to one run of the combined length (tests/structure/test_cosimulation.cpp).
///   A new frequency whose automatic step is > 10% below the carried dt warns (plan the
///   sweep's dt at its most demanding frequency: cosimulation_time_step()).
/// Throws std::invalid_argument as above, and for a state that does not fit (one line each).
CosimulationResult cosimulate(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationRun& run, CosimulationState& state,
                              base::RunHooks& hooks = base::silent_hooks());

/// The common step a fresh cosimulate() would take for these inputs, s, and its whole steps
/// per period (harmonic, else 0), without building worlds (a stepped sine takes the smallest
/// over its frequencies as the time_step_s of its first run). Throws as cosimulate().
struct CosimulationTimeStep {
  double time_step_s = 0.0;
  std::int64_t steps_per_period = 0;
  std::vector<std::string> warnings;
};
CosimulationTimeStep cosimulation_time_step(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                                            const CosimulationRun& run);

}  // namespace pdamp::structure
