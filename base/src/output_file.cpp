// Atomic replacement of files and fsynced writes (POSIX): output_file.hpp.
#include "pdamp/base/output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace pdamp::base {

namespace {

std::string errno_text() { return std::strerror(errno); }

}  // namespace

void write_all_synced(int fd, std::string_view data, const std::filesystem::path& path) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(path.string() + ": write failed (" + errno_text() + ")");
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
  if (::fsync(fd) != 0) throw std::runtime_error(path.string() + ": fsync failed (" + errno_text() + ")");
}

void sync_parent_folder(const std::filesystem::path& path) {
  const auto parent = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const int fd = ::open(parent.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: some file systems do not open folders
  (void)::fsync(fd);
  ::close(fd);
}

void write_file_synced(const std::filesystem::path& path, std::string_view contents,
                       const std::filesystem::path& shown_as) {
  const std::string shown = (shown_as.empty() ? path : shown_as).string();
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(shown + ": cannot be created (" + errno_text() + ")");
  try {
    write_all_synced(fd, contents, shown);
  } catch (...) {
    ::close(fd);
    ::unlink(path.c_str());
    throw;
  }
  // close() reports a write error that fsync did not (some network file systems).
  if (::close(fd) != 0) {
    const std::string reason = errno_text();
    ::unlink(path.c_str());
    throw std::runtime_error(shown + ": cannot be written (" + reason + ")");
  }
}

void sync_file(const std::filesystem::path& path, const std::filesystem::path& shown_as) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error(shown_as.string() + ": was not written (" + errno_text() + ")");
  struct stat info {};
  const bool regular = ::fstat(fd, &info) == 0 && S_ISREG(info.st_mode);
  const bool synced = regular && ::fsync(fd) == 0;
  const std::string reason = errno_text();
  ::close(fd);
  if (!regular) throw std::runtime_error(shown_as.string() + ": was not written as a regular file");
  if (!synced) throw std::runtime_error(shown_as.string() + ": cannot be written (" + reason + ")");
}

bool names_a_dead_process(std::string_view pid_digits) {
  if (pid_digits.empty() || pid_digits.size() > 9 || pid_digits.find_first_not_of("0123456789") != std::string_view::npos)
    return false;
  const auto pid = static_cast<pid_t>(std::stol(std::string(pid_digits)));
  return ::kill(pid, 0) != 0 && errno == ESRCH;
}

namespace {

/// Temporaries `<name>.tmp.<pid>` of writers that were killed (kill -9, a power cut) while
/// writing `path`: nothing else uses these names, so a later write removes them.
void remove_stale_temporaries(const std::filesystem::path& path) {
  const auto parent = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const std::string prefix = path.filename().string() + ".tmp.";
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(parent, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    if (names_a_dead_process(std::string_view(name).substr(prefix.size()))) std::filesystem::remove(entry.path(), error);
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  std::filesystem::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid());
  write_file_synced(temporary, contents, path);
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = errno_text();
    ::unlink(temporary.c_str());
    throw std::runtime_error(path.string() + ": cannot be replaced atomically (" + reason + ")");
  }
  sync_parent_folder(path);
  remove_stale_temporaries(path);
}

}  // namespace pdamp::base
