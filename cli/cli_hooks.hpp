// The command line's RunHooks: progress lines on stderr, notes, the checkpoint interval
// of --checkpoint-interval, and the signals that ask a run to stop.
#pragma once

#include <chrono>
#include <map>
#include <mutex>
#include <string>

#include "pdamp/base/run_hooks.hpp"

namespace pdamp::cli {

class CliHooks : public base::RunHooks {
 public:
  /// `checkpoint_interval_s`: wall-clock seconds between checkpoints (0: at every chance);
  /// `accept_long_runs`: --accept-long-run (a DEM run estimated beyond a week may start).
  /// `terminal`: progress rewrites one line in place (default: stderr is a terminal).
  explicit CliHooks(double checkpoint_interval_s = 60.0, bool accept_long_runs = false,
                    bool terminal = stderr_is_terminal());
  static bool stderr_is_terminal();
  ~CliHooks() override;
  /// One progress line: rewritten in place on a terminal (at most four times a second),
  /// else a new line at most every 5 s over all runs (a run's first and last reports
  /// always). A run that gives no ETA gets one from its mean rate since its first report.
  void progress(const base::Progress& p) override;
  void note(const std::string& line) override;
  bool checkpoint_due(double seconds_since_checkpoint) override;
  /// The signal (SIGINT, SIGTERM, SIGHUP) that arrived while a run defers signals, or 0.
  int stop_requested() override;
  bool long_runs_accepted() override { return accept_long_runs_; }

 private:
  std::mutex mutex_;
  double checkpoint_interval_s_;
  bool accept_long_runs_;
  bool tty_;
  bool line_open_ = false;  // a terminal line being rewritten
  std::chrono::steady_clock::time_point last_line_{};
  /// Per run: the wall time and progress of its first report, for an ETA where the run gives none.
  std::map<std::string, std::pair<std::chrono::steady_clock::time_point, double>> first_report_;
};

}  // namespace pdamp::cli
