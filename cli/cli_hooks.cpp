// The command line's RunHooks (cli_hooks.hpp).
#include "cli_hooks.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>

#include "pdamp/report/external_program.hpp"
#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::cli {

CliHooks::CliHooks(double checkpoint_interval_s, bool accept_long_runs)
    : checkpoint_interval_s_(checkpoint_interval_s),
      accept_long_runs_(accept_long_runs),
      tty_(::isatty(STDERR_FILENO) == 1) {}

CliHooks::~CliHooks() {
  if (line_open_) std::cerr << "\n";
}

void CliHooks::progress(const tasks::Progress& p) {
  std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  const bool last = p.done >= p.total;
  auto [it, first] = last_line_.try_emplace(p.label, now);
  if (!tty_ && !first && !last && now - it->second < std::chrono::seconds(10)) return;
  it->second = now;
  double eta_s = p.eta_s;
  const auto [start, inserted] = first_report_.try_emplace(p.label, now, p.done);
  if (!std::isfinite(eta_s) && !inserted) {
    const double wall = std::chrono::duration<double>(now - start->second.first).count();
    const double progressed = p.done - start->second.second;
    if (wall > 0.0 && progressed > 0.0) eta_s = (p.total - p.done) * wall / progressed;
  }
  const std::string eta = std::isfinite(eta_s) ? std::to_string(static_cast<long long>(eta_s)) + " s" : "?";
  char line[300];
  if (p.counts_points) {
    std::snprintf(line, sizeof line, "%s: %.0f/%.0f %s, ETA %s", p.label.c_str(), p.done, p.total, p.stage.c_str(),
                  eta.c_str());
  } else if (!std::isfinite(p.steps_per_s)) {  // before the first step: no rate yet
    std::snprintf(line, sizeof line, "%s: %-9s t = %8.3f / %.3f s, ETA %s", p.label.c_str(), p.stage.c_str(), p.done,
                  p.total, eta.c_str());
  } else {
    std::snprintf(line, sizeof line, "%s: %-9s t = %8.3f / %.3f s  %7.2f k steps/s  ETA %s", p.label.c_str(),
                  p.stage.c_str(), p.done, p.total, p.steps_per_s * 1e-3, eta.c_str());
  }
  // One write per line, so that runs on two threads do not split each other's lines.
  std::cerr << (tty_ ? "\r" + std::string(line) + "   " : std::string(line) + "\n") << std::flush;
  line_open_ = tty_;
}

void CliHooks::note(const std::string& line) {
  std::lock_guard lock(mutex_);
  std::cerr << (line_open_ ? "\n" : "") + strict_json::printable(line) + "\n" << std::flush;
  line_open_ = false;
}

bool CliHooks::checkpoint_due(double seconds_since_checkpoint) {
  return report::pending_interrupt() != 0 || seconds_since_checkpoint >= checkpoint_interval_s_;
}

int CliHooks::stop_requested() { return report::pending_interrupt(); }

}  // namespace pdamp::cli
