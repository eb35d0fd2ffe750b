// Test support for the surrogate readers: a FIFO and a folder where a file is expected,
// and a guard that turns a reader hanging on the FIFO into a test failure, not a hung test.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <exception>
#include <filesystem>
#include <functional>
#include <future>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

namespace pdamp::test {

/// A named pipe at `path` (no writer ever opens it: a blocking reader would wait forever).
inline void make_fifo(const std::filesystem::path& path) {
  if (::mkfifo(path.c_str(), 0600) != 0) throw std::runtime_error("mkfifo " + path.string() + " failed");
}

/// The std::invalid_argument message `read` throws, run on a separate thread so that a
/// reader blocking on the FIFO at `fifo` (the old code opened it with a blocking open)
/// fails the test after 10 s instead of hanging it. On a timeout the FIFO is opened for
/// writing and closed, which releases the reader with end-of-file, and
/// std::runtime_error("hung") is thrown. "no exception" if `read` returned normally;
/// other exceptions are rethrown.
inline std::string invalid_argument_within_timeout(const std::function<void()>& read,
                                                   const std::filesystem::path& fifo = {}) {
  std::packaged_task<std::string()> task([read] {
    try {
      read();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  });
  std::future<std::string> result = task.get_future();
  std::thread worker(std::move(task));
  if (result.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    // Release a reader blocked in open() or read() of the FIFO: open for writing once
    // the reader is waiting, then close (end of file); retry briefly if the reader is
    // not in open() yet.
    for (int attempt = 0; attempt < 100 && result.wait_for(std::chrono::milliseconds(10)) !=
                                                std::future_status::ready; ++attempt) {
      if (fifo.empty()) break;
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd >= 0) ::close(fd);
    }
    if (result.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
      worker.detach();  // still blocked: leave it, the process exit ends it
      throw std::runtime_error("hung: the reader blocked for more than 10 s");
    }
    worker.join();
    throw std::runtime_error("hung: the reader blocked for more than 10 s (released by opening the FIFO)");
  }
  worker.join();
  return result.get();
}

}  // namespace pdamp::test
