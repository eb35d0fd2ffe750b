// The local executor, the job fingerprint and the concurrency helper of executor.hpp.
#include "pdamp/base/executor.hpp"

#include "pdamp/base/fnv1a.hpp"

#include <algorithm>
#include <atomic>

namespace pdamp::base {

namespace {

class LocalChannel : public JobChannel {
 public:
  std::optional<std::string> run_elsewhere(std::size_t, std::uint64_t) override { return std::nullopt; }
};

}  // namespace

std::uint64_t fingerprint(std::string_view text) { return fnv1a64(text); }

std::unique_ptr<JobChannel> LocalExecutor::open(EncodedJob) {
  return std::make_unique<LocalChannel>();
}

LocalExecutor& local_executor() {
  static LocalExecutor executor;
  return executor;
}

void for_each_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& body,
                           std::size_t max_threads) {
  if (!parallel || max_threads < 2) {
    for (std::size_t k = 0; k < count; ++k) body(k);
    return;
  }
  // Each thread takes the next job in order until none is left.
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < std::min(count, max_threads); ++t)
    threads.emplace_back([&] {
      for (std::size_t k = next++; k < count; k = next++) {
        try {
          body(k);
        } catch (...) {
          errors[k] = std::current_exception();
        }
      }
    });
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace pdamp::base
