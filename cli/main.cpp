// pdamp command-line front end: dispatch to a subcommand, map errors to exit codes.
#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "distributed.hpp"
#include "errors.hpp"
#include "version.hpp"
#include "pdamp/report/external_program.hpp"
#include "pdamp/base/input_file.hpp"

namespace {

void print_overview() {
  std::cout << "pdamp " << pdamp::cli::version() << (pdamp::cli::distributed::built_with_mpi() ? " (MPI build)" : "") << ": design and optimisation of particle dampers\n\n"
            << "usage: pdamp <command> [options]   (pdamp <command> --help for its options)\n\ncommands:\n";
  for (const auto& command : pdamp::cli::commands()) {
    std::string name = "  " + command.spec.name;
    name.resize(std::max<std::size_t>(name.size() + 1, 12), ' ');
    std::cout << name << command.spec.summary.substr(0, command.spec.summary.find('\n')) << "\n";
  }
  std::cout << "\nUnits are SI (m, s, kg, Hz, Pa). Exit codes: 0 success, 1 other failure,\n"
               "2 bad input, 3 numerical failure at run time.\n";
}

/// One error line on stderr (docs/command_line.md); the message is made printable so that a
/// quoted input (a name with a newline, a binary CSV) cannot break it into lines.
int print_error(const std::string& what, int exit_code) {
  pdamp::cli::distributed::note_failure(what);  // a worker rank tells rank 0 in its replies
  std::cerr << "pdamp: error: " << pdamp::base::printable(what) << "\n";
  return exit_code;
}

/// Ends the process by `signal_number` with its default action, as if pdamp had not
/// caught it, once the staged files are removed: the caller (a shell, a job script)
/// sees "killed by SIGINT" and stops, as it would for any interrupted program.
[[noreturn]] void die_by(int signal_number) {
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
  std::_Exit(128 + signal_number);  // not reached: the default action ends the process
}

/// The command's exit code, unless stdout could not take the result (a full disk, a
/// closed pipe: exit 1, not a silent 0) or a signal arrived while it wrote its results
/// (they are complete then: said on stderr, then the signal's default action).
int finished(int exit_code) {
  std::cout.flush();
  if (!std::cout) return print_error("cannot write the result to standard output", pdamp::cli::kExitOther);
  if (const int s = pdamp::report::pending_interrupt(); s != 0) {
    std::cerr << "pdamp: error: interrupted after the results were written (they are complete)" << std::endl;
    die_by(s);
  }
  return exit_code;
}

/// The command `args` names.
const pdamp::cli::Command* find_command(const std::vector<std::string>& args, std::size_t& words) {
  // A two-word command ("field merge") before its one-word prefix ("field").
  const pdamp::cli::Command* match = nullptr;
  words = 0;
  for (const auto& command : pdamp::cli::commands()) {
    const std::string& name = command.spec.name;
    const bool two = name.find(' ') != std::string::npos;
    if (two ? (args.size() >= 2 && name == args[0] + " " + args[1]) : name == args[0]) {
      if (!match || (two ? 2u : 1u) > words) {
        match = &command;
        words = two ? 2 : 1;
      }
    }
  }
  return match;
}

/// The command `args` names, run; its exit code (classify_error: bad input 2, a numerical
/// failure 3, a signal its own end, anything else 1).
int run_command(const std::vector<std::string>& args) {
  using namespace pdamp::cli;
  if (args.empty()) return print_error("missing the command (usage: pdamp <command> [options]; see pdamp --help)", kExitBadInput);
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    print_overview();
    return kExitOk;
  }
  if (args[0] == "--version") {
    if (args.size() > 1) return print_error("--version: takes no further arguments", kExitBadInput);
    std::cout << pdamp::cli::version_text();
    return finished(kExitOk);
  }
  try {
    std::size_t words = 0;
    const Command* match = find_command(args, words);
    if (match == nullptr) throw InputError(args[0], "", "unknown command (see pdamp --help)");
    CommandContext context{distributed::executor(), false, match->spec.name};
    if (!context.executor.primary() && !match->runs_task) return kExitOk;  // rank 0 runs it; this rank waits
    const ParsedArgs parsed(match->spec, std::vector<std::string>(args.begin() + static_cast<std::ptrdiff_t>(words), args.end()));
    if (parsed.help_requested()) {
      std::cout << help_text(match->spec);
      return finished(kExitOk);
    }
    return finished(match->run(parsed, context));
  } catch (...) {
    const ErrorOutcome outcome = classify_error(std::current_exception(), args[0]);
    if (!outcome.message.empty()) print_error(outcome.message, outcome.exit_code);
    if (outcome.end_by_signal != 0) die_by(outcome.end_by_signal);
    return outcome.exit_code;
  }
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pdamp::cli;
  const distributed::Session mpi(&argc, &argv);  // under mpirun: until main returns
  pdamp::report::install_interrupt_handlers();
  const int exit_code = run_command(std::vector<std::string>(argv + 1, argv + argc));
  // Under mpirun rank 0 speaks for the run: another rank's failure reaches it in that
  // rank's replies (distributed.hpp), and an exit code here would make mpirun kill rank 0
  // while it reports the same bad input.
  return distributed::worker() ? kExitOk : exit_code;
}
