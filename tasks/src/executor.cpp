// The local executor and the concurrency helper of executor.hpp.
#include "pdamp/tasks/executor.hpp"

namespace pdamp::tasks {

namespace {

class LocalChannel : public JobChannel {
 public:
  std::optional<std::string> run_elsewhere(std::size_t, double) override { return std::nullopt; }
};

}  // namespace

std::unique_ptr<JobChannel> LocalExecutor::open(EncodedJob) {
  return std::make_unique<LocalChannel>();
}

LocalExecutor& local_executor() {
  static LocalExecutor executor;
  return executor;
}

void for_each_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& body) {
  if (!parallel) {
    for (std::size_t k = 0; k < count; ++k) body(k);
    return;
  }
  std::vector<std::exception_ptr> errors(count);
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < count; ++k)
    threads.emplace_back([&, k] {
      try {
        body(k);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    });
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace pdamp::tasks
