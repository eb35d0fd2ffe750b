// Test executors: one that hands every job to "another process" (the job's bytes, as an MPI
// rank would return them), the other half of such a run (a process that served the batches,
// as an MPI worker does), and the counts of where jobs ran.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pdamp/base/executor.hpp"

namespace pdamp::test {

/// Runs every job through its encoded form (to_job_bytes, from_job_bytes), as if another
/// process had computed it: what the MPI executor does, without MPI. Its batches are numbered
/// as it opens them; a request names its batch, and one of a batch that is not the open one
/// is refused. `ended` keeps what each batch ended with: what a process that served it gets.
class BytesExecutor : public base::Executor {
 public:
  /// `other_inputs`: the other process set up other work (its fingerprints differ by 1).
  explicit BytesExecutor(bool other_inputs = false) : other_inputs_(other_inputs) {}
  int concurrency(int local_jobs) const override { return local_jobs; }
  int processes() const override { return 2; }
  std::unique_ptr<base::JobChannel> open(EncodedJob job) override {
    ended.emplace_back();
    return std::make_unique<Channel>(*this, ++batches, std::move(job));
  }
  std::atomic<int> jobs_elsewhere{0};
  std::uint64_t batches = 0;  ///< opened so far; the open one's number
  /// Per batch opened, in order: nothing while open; then the results it ended with (or
  /// none: ended without, as a sweep does).
  std::vector<std::optional<std::optional<std::string>>> ended;

 private:
  class Channel : public base::JobChannel {
   public:
    Channel(BytesExecutor& executor, std::uint64_t batch, EncodedJob job)
        : executor_(executor), batch_(batch), job_(std::move(job)) {}
    std::optional<std::string> run_elsewhere(std::size_t index, std::uint64_t fingerprint) override {
      ++executor_.jobs_elsewhere;
      // The request as it would travel: {batch, index, fingerprint}.
      const std::uint64_t request[3] = {batch_, index, fingerprint + (executor_.other_inputs_ ? 1u : 0u)};
      if (request[0] != executor_.batches)
        throw std::runtime_error("a job of batch " + std::to_string(request[0]) + " asked in batch " +
                                 std::to_string(executor_.batches));
      return job_(static_cast<std::size_t>(request[1]), request[2]);
    }
    void end(const std::optional<std::string>& results) override { executor_.ended.at(batch_ - 1) = results; }

   private:
    BytesExecutor& executor_;
    std::uint64_t batch_;
    EncodedJob job_;
  };
  bool other_inputs_;
};

/// The other half of a run on a BytesExecutor: a process that served its batches, handed
/// what each ended with (BytesExecutor::ended). Its run_jobs return the primary's results; a
/// batch ended without results, or primary_only, ends its task (JobsServedElsewhere).
class ServingExecutor : public base::Executor {
 public:
  explicit ServingExecutor(std::vector<std::optional<std::optional<std::string>>> ended) : ended_(std::move(ended)) {}
  int concurrency(int local_jobs) const override { return local_jobs; }
  int processes() const override { return 2; }
  bool primary() const override { return false; }
  void primary_only() override { throw base::JobsServedElsewhere(); }
  std::unique_ptr<base::JobChannel> open(EncodedJob) override {
    if (next_ >= ended_.size() || !ended_[next_]) throw std::logic_error("a batch the primary did not end");
    const std::optional<std::string>& results = *ended_[next_++];
    if (!results) throw base::JobsServedElsewhere();
    return std::make_unique<base::SharedResultsChannel>(*results);
  }
  std::size_t batches() const { return next_; }

 private:
  std::vector<std::optional<std::optional<std::string>>> ended_;
  std::size_t next_ = 0;
};

}  // namespace pdamp::test
