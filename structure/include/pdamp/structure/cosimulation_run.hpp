// A co-simulation run as an object: built (fresh, continuing a state, or from a checkpoint),
// advanced step by step in segments of any length, saved, and read out (docs/cosimulation.md §8).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "pdamp/dem_reference/checkpoint.hpp"
#include "pdamp/structure/cosimulation.hpp"
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
  /// A fresh run, as cosimulate(model, dampers, options, progress): throws
  /// std::invalid_argument for invalid inputs (every violation, one per line) and for a step
  /// the structure cannot take. The progress callback is called while the beds settle and
  /// then from advance().
  Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
               const CosimulationOptions& options, CosimulationProgressCallback progress = {});
  /// The run of `options` continuing `state` (CosimulationState::started(); else a fresh
  /// run, as cosimulate(…, state, …)). Throws as cosimulate() before taking the state: on a
  /// throw `state` is left as it was.
  Cosimulation(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
               const CosimulationOptions& options, CosimulationState&& state,
               CosimulationProgressCallback progress = {});
  /// The free decay of `options` (the same options as its fresh start) from the checkpoint
  /// that save() wrote: the run goes on at the saved step, and its result and state are those
  /// of the run never stopped, to the bit. Throws std::invalid_argument for a checkpoint that
  /// does not fit (another case, another step, damaged bytes: the field named) and for a
  /// harmonic run (its measures' running sums are not in the checkpoint).
  static Cosimulation restore(const ModalModel& model, const std::vector<CosimulationDamper>& dampers,
                              const CosimulationOptions& options, dem_reference::StateReader& in,
                              CosimulationProgressCallback progress = {});

  Cosimulation(Cosimulation&&) noexcept;
  Cosimulation& operator=(Cosimulation&&) noexcept;
  ~Cosimulation();

  /// Runs min(steps, total_steps() − steps_done()) further coupled steps (fewer when a World
  /// stops: result().outcome says why) and returns how many it ran. steps <= 0 runs none.
  std::int64_t advance(std::int64_t steps);
  /// The same, ending early once `stop` returns true: it is asked every kStopPollSteps
  /// steps (a relaxed flag read costs nothing; a step of a million-sphere bed is tens of
  /// milliseconds, so a stop request is met within about a second), and the run then
  /// stands at a step boundary where save() may follow and a restored run continues it to
  /// the bit.
  std::int64_t advance(std::int64_t steps, const std::function<bool()>& stop);
  static constexpr std::int64_t kStopPollSteps = 16;
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

}  // namespace pdamp::structure
