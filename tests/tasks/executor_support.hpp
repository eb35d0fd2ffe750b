// Test executors: one that hands every job to "another process" (the job's bytes, as an MPI
// rank would return them), and the counts of where jobs ran.
#pragma once

#include <atomic>
#include <memory>

#include "pdamp/base/executor.hpp"

namespace pdamp::test {

/// Runs every job through its encoded form (to_job_bytes, from_job_bytes), as if another
/// process had computed it: what the MPI executor does, without MPI.
class BytesExecutor : public base::Executor {
 public:
  /// `other_inputs`: the other process set up other work (its fingerprints differ by 1).
  explicit BytesExecutor(bool other_inputs = false) : other_inputs_(other_inputs) {}
  int concurrency(int local_jobs) const override { return local_jobs; }
  int processes() const override { return 2; }
  std::unique_ptr<base::JobChannel> open(EncodedJob job) override {
    return std::make_unique<Channel>(std::move(job), jobs_elsewhere, other_inputs_ ? 1.0 : 0.0);
  }
  std::atomic<int> jobs_elsewhere{0};

 private:
  class Channel : public base::JobChannel {
   public:
    Channel(EncodedJob job, std::atomic<int>& count, double shift) : job_(std::move(job)), count_(count), shift_(shift) {}
    std::optional<std::string> run_elsewhere(std::size_t index, double fingerprint) override {
      ++count_;
      return job_(index, fingerprint + shift_);
    }

   private:
    EncodedJob job_;
    std::atomic<int>& count_;
    double shift_;
  };
  bool other_inputs_;
};

}  // namespace pdamp::test
