// Starting external programs (gnuplot) without a shell, and the interruption state
// that a signal leaves (docs/command_line.md: "No shell: external programs start with an
// argument vector; nothing in a case file or a path can run a command").
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace pdamp::report {

/// The executable `name` on PATH (an absolute path), or nothing. Searched directly,
/// never through `sh -c "command -v ..."`.
std::optional<std::filesystem::path> find_executable(const std::string& name);

/// Runs `program` with `arguments` (argv[1...], passed verbatim: no word splitting,
/// no globbing, no quoting, no substitution) in working directory `directory`, with
/// stdin from /dev/null and stdout and stderr appended to `log_file`. Returns the exit
/// status (0 success), or -1 when the program could not be started or was killed.
int run_program(const std::filesystem::path& program, const std::vector<std::string>& arguments,
                const std::filesystem::path& directory, const std::filesystem::path& log_file);

/// Installs pdamp's handlers for SIGINT, SIGTERM and SIGHUP. Outside an output phase a
/// signal ends the process at once as it would without pdamp's handler (nothing is
/// half-written then: results are only staged later; a staging folder left behind is
/// removed by the next run into that directory). Inside one (OutputDir staging and
/// committing files) the signal is recorded and the writer stops at its next step,
/// removes what it staged and ends by the signal's default action. SIGXFSZ is ignored,
/// so a file-size limit is a write error naming the file.
void install_interrupt_handlers();

/// Marks the output phase (nesting counts). While it lasts signals are deferred.
void begin_output_phase();
void end_output_phase();

/// An output phase for its lifetime: a checkpointed run defers signals to its next
/// checkpoint (structure_commands.hpp, DemCheckpoint).
class DeferredSignals {
 public:
  DeferredSignals() { begin_output_phase(); }
  ~DeferredSignals() { end_output_phase(); }
  DeferredSignals(const DeferredSignals&) = delete;
  DeferredSignals& operator=(const DeferredSignals&) = delete;
};

/// The signal received during an output phase, or 0.
int pending_interrupt();

/// Throws base::Interrupted when a signal arrived during the output phase.
void stop_if_interrupted();

/// A test hook at a named point of a run's ending ("run-ended", "commit", "committed"):
/// when the environment variable PDAMP_TEST_PAUSE_AT is "<point>:<marker file>", pdamp
/// creates the marker file and waits there (up to 10 minutes) until a signal is recorded or
/// ends it, so that a test can deliver a signal at exactly that point. Unset: nothing.
void test_pause_point(const char* point);

}  // namespace pdamp::report
