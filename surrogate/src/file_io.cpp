// Safe reads, atomic file replacement and fsynced appends (POSIX), shared by field and sweep files.
#include "file_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "pdamp/strict_json/input_file.hpp"

namespace pdamp::surrogate::detail {

namespace {

std::string errno_text() { return std::strerror(errno); }

}  // namespace

std::string file_label(const std::filesystem::path& path) { return strict_json::printable(path.string()); }

std::string read_text_file(const std::filesystem::path& path) { return strict_json::read_input_file(path.string()); }

nlohmann::json read_json_file(const std::filesystem::path& path) {
  return strict_json::parse_json_document(read_text_file(path), path.string());
}

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

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  // The temporary sits in the same folder so that rename() stays on one file system
  // and is atomic; the pid keeps two concurrent writers apart.
  std::filesystem::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error(temporary.string() + ": cannot be created (" + errno_text() + ")");
  try {
    write_all_synced(fd, contents, temporary);
  } catch (...) {
    ::close(fd);
    ::unlink(temporary.c_str());
    throw;
  }
  if (::close(fd) != 0 || ::rename(temporary.c_str(), path.c_str()) != 0) {
    const std::string reason = errno_text();
    ::unlink(temporary.c_str());
    throw std::runtime_error(path.string() + ": cannot be replaced atomically (" + reason + ")");
  }
  sync_parent_folder(path);
}

}  // namespace pdamp::surrogate::detail
