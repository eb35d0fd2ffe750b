// The command line's RunHooks (cli_hooks.hpp).
#include "cli_hooks.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "pdamp/report/external_program.hpp"
#include "pdamp/base/input_file.hpp"

namespace pdamp::cli {

namespace {

/// A wall time as people read an ETA: "42 s", "3 min 20 s", "2 h 05 min".
std::string duration_text(double seconds) {
  const auto s = static_cast<long long>(std::llround(std::min(seconds, 1e9)));
  char text[40];
  if (s < 60) std::snprintf(text, sizeof text, "%lld s", s);
  else if (s < 3600) std::snprintf(text, sizeof text, "%lld min %02lld s", s / 60, s % 60);
  else std::snprintf(text, sizeof text, "%lld h %02lld min", s / 3600, s / 60 % 60);
  return text;
}

}  // namespace

CliHooks::CliHooks(double checkpoint_interval_s, bool accept_long_runs, bool terminal)
    : checkpoint_interval_s_(checkpoint_interval_s), accept_long_runs_(accept_long_runs), tty_(terminal) {}

bool CliHooks::stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

CliHooks::~CliHooks() {
  if (line_open_) std::cerr << "\n";
}

void CliHooks::progress(const base::Progress& p) {
  using namespace std::chrono_literals;
  std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  const bool last = p.done >= p.total;
  // The share done, and for the ETA the wall time and share of the run's first report.
  const double fraction = std::isfinite(p.fraction_done) ? p.fraction_done : p.total > 0.0 ? p.done / p.total : 0.0;
  const auto [start, first] = first_report_.try_emplace(p.label, now, fraction);
  if (!first && !last && now - last_line_ < (tty_ ? 250ms : 5s)) return;
  last_line_ = now;
  double eta_s = p.eta_s;
  if (!std::isfinite(eta_s) && !first) {
    const double wall = std::chrono::duration<double>(now - start->second.first).count();
    const double progressed = fraction - start->second.second;
    if (wall > 0.0 && progressed > 0.0) eta_s = (1.0 - fraction) * wall / progressed;
  }
  // One write per line, so that runs on two threads do not split each other's lines; on a
  // terminal the line is rewritten in place and cleared to its end.
  std::ostringstream line;
  line << (tty_ ? "\r" : "") << p.label << ": ";
  if (p.counts_points) {
    line << std::llround(p.done) << "/" << std::llround(p.total) << " " << p.stage;
  } else {
    char times[120];
    std::snprintf(times, sizeof times, "%-9s t = %8.3f / %.3f s", p.stage.c_str(), p.done, p.total);
    line << times;
    if (std::isfinite(p.steps_per_s)) {  // none before the first step
      std::snprintf(times, sizeof times, "  %7.2f k steps/s", p.steps_per_s * 1e-3);
      line << times;
    }
  }
  line << ", ETA " << (std::isfinite(eta_s) ? duration_text(eta_s) : "?");
  line << (tty_ ? "\x1b[K" : "\n");
  std::cerr << line.str() << std::flush;
  line_open_ = tty_;
}

void CliHooks::note(const std::string& line) {
  std::lock_guard lock(mutex_);
  std::ostringstream text;  // one write, so that another thread's line is not split
  text << (line_open_ ? "\n" : "") << base::printable(line) << "\n";
  std::cerr << text.str() << std::flush;
  line_open_ = false;
}

bool CliHooks::checkpoint_due(double seconds_since_checkpoint) {
  return report::pending_interrupt() != 0 || seconds_since_checkpoint >= checkpoint_interval_s_;
}

int CliHooks::stop_requested() { return report::pending_interrupt(); }

}  // namespace pdamp::cli
