// Test support: runs the built pdamp binary with an argument vector (fork/exec, no
// shell: a hostile argument reaches pdamp verbatim and the test's own shell cannot run
// it), capturing exit code, stdout and stderr, with a time limit so that a hang is a
// failure, not a stuck test.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace pdamp::test {

struct RunResult {
  int exit_code = -1;     ///< the exit status; 128 + n when ended by signal n; -2 on time-out
  std::string out;
  std::string err;
};

struct RunOptions {
  std::filesystem::path directory;                 ///< working directory (empty: the test's)
  /// Killed (exit_code -2) after this: a hang guard, ten times the longest idle run (the
  /// shipped DEM verification, about 90 s), so that a loaded machine does not fail a test.
  double time_limit_s = 900.0;
  /// Called with the child's pid once it runs (e.g. to send it a signal); may be empty.
  std::function<void(pid_t)> while_running;
  /// Added to the child's environment, "NAME=value" each.
  std::vector<std::string> environment;
  /// A file-size limit for the child (ulimit -f; 0: none): a write beyond it fails, an
  /// injected write failure without a full disk.
  unsigned long file_size_limit_bytes = 0;
};

inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Runs the program argv_text[0] (a path) with argv_text[1..], verbatim.
inline RunResult run_program(std::vector<std::string> argv_text, const RunOptions& options = {}) {
  static int counter = 0;
  const auto base = std::filesystem::temp_directory_path() /
                    ("pdamp_run_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  const std::string out_file = base.string() + ".out", err_file = base.string() + ".err";
  std::vector<std::string> environment = options.environment;
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string dir = options.directory.string();

  const pid_t child = ::fork();
  if (child == 0) {
    ::setpgid(0, 0);  // its own process group: a signal test can hit pdamp and gnuplot
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0) ::_exit(126);
    if (!dir.empty() && ::chdir(dir.c_str()) != 0) ::_exit(126);
    for (auto& variable : environment) ::putenv(variable.data());
    if (options.file_size_limit_bytes > 0) {
      const rlimit limit{options.file_size_limit_bytes, options.file_size_limit_bytes};
      if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  RunResult result;
  if (child < 0) return result;
  if (options.while_running) options.while_running(child);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(options.time_limit_s);
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child) {
      result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      break;
    }
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(-child, SIGKILL);
      ::waitpid(child, &status, 0);
      result.exit_code = -2;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  result.out = slurp(out_file);
  result.err = slurp(err_file);
  std::filesystem::remove(out_file);
  std::filesystem::remove(err_file);
  return result;
}

/// Runs PDAMP_BINARY with `args` (argv[1..], verbatim).
inline RunResult run_pdamp(const std::vector<std::string>& args, const RunOptions& options = {}) {
  std::vector<std::string> argv_text{PDAMP_BINARY};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  return run_program(std::move(argv_text), options);
}

/// The same with the arguments given as one string split at blanks (for fixed
/// arguments without blanks; no shell is involved either way).
inline RunResult run_pdamp(const std::string& args, const RunOptions& options = {}) {
  std::istringstream words(args);
  std::vector<std::string> list{std::istream_iterator<std::string>(words), std::istream_iterator<std::string>()};
  return run_pdamp(list, options);
}

}  // namespace pdamp::test
