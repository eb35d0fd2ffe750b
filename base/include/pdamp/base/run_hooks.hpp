// What a long run reports and asks while it works: progress, when to save a checkpoint,
// whether to stop. Every long library run (a DEM run, a sweep, a DEM-in-the-loop decay or
// stepped sine, a verification) takes one RunHooks; the command line implements it
// (progress lines on stderr, its checkpoint interval, the signals), tests and benchmarks
// take the silent defaults.
#pragma once

#include <cmath>
#include <string>
#include <utility>

namespace pdamp::base {

/// Where a long run stands.
struct Progress {
  std::string label;           ///< the run: "pdamp dem", "pdamp frf (dem) up 3/9 1.8 Hz", ...
  std::string stage;           ///< "setup", "settle", "transient", "analysis", "decay", "sweep", "points"
  double done = 0.0;           ///< simulated time reached, s; points done when counts_points
  double total = 0.0;          ///< simulated time at the end, s; points in all when counts_points
  bool counts_points = false;  ///< a sweep: done and total count points, not seconds
  double steps_per_s = NAN;    ///< integration steps per wall-clock second (NaN: none yet)
  double eta_s = NAN;          ///< wall-clock seconds to the end (NaN: not known yet)
  /// Share of the whole run done, in [0, 1], where done/total measure one part of it (a
  /// stepped sine's point): the ETA of a run that gives none comes from it (NaN: done/total).
  double fraction_done = NAN;
};

/// The hooks of a run. Runs that go in parallel (two DEM decays, a sweep's points) share one
/// object and call it from several threads: implementations must be thread-safe.
class RunHooks {
 public:
  virtual ~RunHooks() = default;
  /// A progress report, about twice a second while a run steps and once per finished point.
  virtual void progress(const Progress&) {}
  /// A line for the user that is not a result: the cost estimate of a run before it starts,
  /// "resuming from ...", a checkpoint of an earlier run being replaced.
  virtual void note(const std::string&) {}
  /// Whether a run that last saved a checkpoint `seconds_since_checkpoint` wall-clock seconds
  /// ago (or started that long ago) should save one at its next consistent point.
  virtual bool checkpoint_due(double /*seconds_since_checkpoint*/) { return false; }
  /// Nonzero (the signal number) when the runs should stop at their next consistent point,
  /// save their checkpoint and throw base::Interrupted; 0 to go on.
  virtual int stop_requested() { return 0; }
  /// Whether a run estimated to take longer than kMaxDemWallTime_s (a week) may start.
  virtual bool long_runs_accepted() { return false; }
};

/// Hooks that pass everything on to `inner`: a subclass changes what it needs (the label
/// of the progress reports, the share of a longer run they stand for).
class ForwardingHooks : public RunHooks {
 public:
  explicit ForwardingHooks(RunHooks& inner) : inner_(inner) {}
  void progress(const Progress& p) override { inner_.progress(p); }
  void note(const std::string& line) override { inner_.note(line); }
  bool checkpoint_due(double seconds_since_checkpoint) override { return inner_.checkpoint_due(seconds_since_checkpoint); }
  int stop_requested() override { return inner_.stop_requested(); }
  bool long_runs_accepted() override { return inner_.long_runs_accepted(); }

 protected:
  RunHooks& inner_;
};

/// The progress reports under `label`: a library reports its run's stage and numbers, its
/// caller names the run ("pdamp dem", "pdamp frf (dem) up"). A report that has a label of
/// its own (a part of the run) keeps it after the caller's.
class LabelledHooks : public ForwardingHooks {
 public:
  LabelledHooks(RunHooks& inner, std::string label) : ForwardingHooks(inner), label_(std::move(label)) {}
  void progress(const Progress& p) override {
    Progress labelled = p;
    labelled.label = p.label.empty() ? label_ : label_ + " " + p.label;
    inner_.progress(labelled);
  }

 private:
  std::string label_;
};

/// The hooks that report nothing, save no checkpoint and never stop.
inline RunHooks& silent_hooks() {
  static RunHooks hooks;
  return hooks;
}

}  // namespace pdamp::base
