// The command line's progress lines (cli/cli_hooks.cpp): one rewritten line on a terminal,
// a line every few seconds otherwise, an ETA where the run gives none.
#include <catch2/catch.hpp>

#include <chrono>
#include <iostream>
#include <sstream>
#include <thread>

#include "cli_hooks.hpp"

using namespace pdamp;

namespace {

/// std::cerr into a string for the life of the object.
struct CapturedStderr {
  std::ostringstream text;
  std::streambuf* saved = std::cerr.rdbuf(text.rdbuf());
  ~CapturedStderr() { std::cerr.rdbuf(saved); }
};

std::size_t count(const std::string& text, char ch) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), ch)); }

}  // namespace

TEST_CASE("progress away from a terminal is a line every few seconds over all runs, with an ETA", "[cli]") {
  CapturedStderr err;
  const auto started = std::chrono::steady_clock::now();
  {
    cli::CliHooks hooks(60.0, false, /*terminal=*/false);
    // Two runs reporting 2000 times each, as fast as they can (a DEM run reports twice a
    // second; the stepped sine of a structure once per 256 steps).
    for (int i = 0; i < 2000; ++i)
      for (const char* label : {"pdamp frf (dem) up", "pdamp frf (dem) down"})
        hooks.progress({label, "3/9 1.8 Hz transient", 0.01 * i, 20.0, false, 5e4, NAN, i / 2000.0});
  }
  const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::string text = err.text.str();
  INFO(text);
  // Each run's first report, then at most one line per 5 s of the loop (a loaded machine
  // makes the loop longer, and so allows more lines, never fewer).
  CHECK(count(text, '\n') >= 2);
  CHECK(count(text, '\n') <= 2 + static_cast<std::size_t>(elapsed_s / 5.0));
  CHECK(text.find("pdamp frf (dem) up: 3/9 1.8 Hz transient t =    0.000 / 20.000 s    50.00 k steps/s, ETA ?\n") == 0);
  CHECK(count(text, '\r') == 0);
}

TEST_CASE("progress on a terminal rewrites one line, and the ETA comes from the share done", "[cli]") {
  CapturedStderr err;
  {
    cli::CliHooks hooks(60.0, false, /*terminal=*/true);
    hooks.progress({"pdamp decay (dem)", "decay", 0.0, 10.0, false, NAN, NAN});
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // past the 250 ms between rewrites
    // Half done after >= 0.3 s: the other half takes about as long again. A fraction_done
    // given overrides done/total (here 0.1 of the simulated time, but half the run).
    hooks.progress({"pdamp decay (dem)", "decay", 1.0, 10.0, false, 1e4, NAN, 0.5});
    hooks.note("a note ends the line");
  }
  const std::string text = err.text.str();
  INFO(text);
  CHECK(text.find("\rpdamp decay (dem): decay     t =    0.000 / 10.000 s, ETA ?\x1b[K") == 0);
  const auto second = text.find("\rpdamp decay (dem): decay     t =    1.000 / 10.000 s    10.00 k steps/s, ETA ");
  REQUIRE(second != std::string::npos);
  // The ETA is the half left at the rate so far: at least the 0.3 s slept, rounded to whole seconds.
  const auto eta = text.substr(second).substr(text.substr(second).find("ETA ") + 4);
  CHECK(eta.find(" s\x1b[K\na note ends the line\n") != std::string::npos);
  CHECK(std::isdigit(static_cast<unsigned char>(eta.front())));
}
