// External programs through fork/exec with an argument vector, and signal handling.
#include "pdamp/report/external_program.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <sstream>

#include "pdamp/base/run_errors.hpp"

namespace pdamp::report {

namespace fs = std::filesystem;

namespace {
// Signal state: written by the handler, read by the writers (sig_atomic_t / atomic).
std::atomic<int> g_output_phase{0};
volatile sig_atomic_t g_pending_signal = 0;
volatile sig_atomic_t g_child = 0;  // the running external program, 0 if none
}  // namespace

std::optional<fs::path> find_executable(const std::string& name) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty() || dir[0] != '/') continue;  // relative PATH entries would depend on -o
    const fs::path candidate = fs::path(dir) / name;
    struct stat info {};
    if (::stat(candidate.c_str(), &info) == 0 && S_ISREG(info.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
  }
  return std::nullopt;
}

int run_program(const fs::path& program, const std::vector<std::string>& arguments, const fs::path& directory,
                const fs::path& log_file) {
  // Everything the child needs is prepared before fork(): after it, only
  // async-signal-safe calls (open, dup2, chdir, execv, _exit).
  std::vector<std::string> argv_text;
  argv_text.push_back(program.string());
  argv_text.insert(argv_text.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string dir = directory.string(), log = log_file.string();

  const pid_t parent = ::getpid();
  const pid_t child = ::fork();
  if (child < 0) return -1;
  if (child == 0) {
    // The child takes the default signal actions: a Ctrl-C ends it as it ends pdamp.
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    ::signal(SIGHUP, SIG_DFL);
    // It dies with pdamp (a SIGKILLed pdamp must not leave gnuplot drawing in a
    // staging folder for minutes); the check closes the race with an early death.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    const int in = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (in < 0 || out < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(out, 2) < 0) ::_exit(127);
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  g_child = child;
  int status = 0;
  while (::waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) {
      g_child = 0;
      return -1;
    }
  }
  g_child = 0;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace {


extern "C" void on_interrupt(int signal_number) {
  if (g_output_phase.load() > 0) {
    g_pending_signal = signal_number;
    // A signal to pdamp alone (kill PID, not the group) must not wait for the drawing:
    // its pictures are discarded anyway.
    if (const pid_t child = g_child; child > 0) ::kill(child, SIGTERM);
    return;
  }
  // Outside the output phase: end as the default action would (the signal is blocked
  // while this handler runs and is delivered again, with SIG_DFL, when it returns),
  // after one line that says so (write() is async-signal-safe; iostreams are not).
  static const char kMessage[] = "pdamp: error: interrupted; no result was written\n";
  [[maybe_unused]] const auto written = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: a deferred signal must not make a write of the output phase fail with
  // EINTR (that would report a write error instead of the interruption).
  action.sa_flags = SA_RESTART;
  for (int s : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(s, &action, nullptr);
  // A file-size limit (ulimit -f) then fails a write with EFBIG, which the writer reports
  // naming the file and cleans up after, instead of SIGXFSZ killing pdamp mid-write and
  // leaving a temporary behind. gnuplot inherits the ignored signal: its cut-short
  // pictures are caught by OutputDir.
  ::signal(SIGXFSZ, SIG_IGN);
}

void begin_output_phase() { ++g_output_phase; }
void end_output_phase() { --g_output_phase; }
int pending_interrupt() { return g_pending_signal; }

void stop_if_interrupted() {
  if (const int s = g_pending_signal; s != 0) throw base::Interrupted(s);
}

void test_pause_point(const char* point) {
  const char* wanted = std::getenv("PDAMP_TEST_PAUSE_AT");
  if (wanted == nullptr) return;
  const std::string setting = wanted;
  const auto colon = setting.find(':');
  if (colon == std::string::npos || setting.compare(0, colon, point) != 0) return;
  const std::string marker = setting.substr(colon + 1);
  const int fd = ::open(marker.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd >= 0) ::close(fd);
  // A deferred signal is recorded; any other ends the process during the wait.
  for (int k = 0; k < 60000 && g_pending_signal == 0; ++k) ::usleep(10000);
}

}  // namespace pdamp::report
