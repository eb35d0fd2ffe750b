// Where a task's independent jobs run: in this process (one after the other or on
// threads), or spread over processes (the command line's MPI executor). A task hands its
// jobs to an Executor& and gets the results in order; a job's result crosses a process
// boundary as CBOR of its JSON form (to_json/from_json), so doubles arrive bit for bit.
#pragma once

#include <chrono>
#include <cstddef>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace pdamp::base {

/// Thrown on a process that served a task's jobs to another (an MPI worker rank): it has no
/// result of its own and must write and print nothing; the command line ends it with
/// success (the primary process reports).
class JobsServedElsewhere : public std::exception {
 public:
  const char* what() const noexcept override { return "this process served its jobs to the primary process"; }
};

/// The jobs of one task while they run (Executor::open).
class JobChannel {
 public:
  virtual ~JobChannel() = default;
  /// Runs job `index` in another process when one is free and returns its result bytes;
  /// nothing when it should run here. `fingerprint` travels with the request: the other
  /// process refuses a job whose fingerprint differs from its own (it set up other work).
  /// Thread-safe.
  virtual std::optional<std::string> run_elsewhere(std::size_t index, double fingerprint) = 0;
  /// Job `index` ran here, from `start` until now (for the balance). Thread-safe.
  virtual void ran_here(std::chrono::steady_clock::time_point /*start*/) {}
  /// How the jobs spread: {ranks, points[r], busy_fraction[r], wall_time_s}, or null when
  /// every job ran in this process.
  virtual nlohmann::json balance() const { return nullptr; }
};

class Executor {
 public:
  virtual ~Executor() = default;
  /// Jobs to keep in flight at once for a task that would run `local_jobs` at once alone.
  virtual int concurrency(int local_jobs) const = 0;
  /// Processes the jobs spread over (1: this one).
  virtual int processes() const { return 1; }
  /// A job as another process asks for it: its index and the fingerprint the asker computed.
  using EncodedJob = std::function<std::string(std::size_t index, double fingerprint)>;
  /// Opens the jobs of one task; `encoded_job` computes a job and returns its result bytes
  /// (called for jobs another process asks for). On a process that serves another (an MPI
  /// worker) this serves until the primary is done and throws JobsServedElsewhere. One task
  /// opens its jobs once per process.
  virtual std::unique_ptr<JobChannel> open(EncodedJob encoded_job) = 0;
};

/// Every job in this process (the default; tests, benchmarks, the Python module).
class LocalExecutor : public Executor {
 public:
  int concurrency(int local_jobs) const override { return local_jobs; }
  std::unique_ptr<JobChannel> open(EncodedJob) override;
};
LocalExecutor& local_executor();

/// A job's result as bytes for another process and back: CBOR of its JSON form (CBOR keeps
/// every double exact and NaN a NaN). T needs to_json/from_json (nlohmann ADL).
template <class T>
std::string to_job_bytes(const T& value) {
  const auto bytes = nlohmann::json::to_cbor(nlohmann::json(value));
  return std::string(bytes.begin(), bytes.end());
}
template <class T>
T from_job_bytes(const std::string& bytes) {
  return nlohmann::json::from_cbor(bytes).get<T>();
}

/// The jobs of a task, run through an executor: job(index) here or in another process.
template <class T>
class Jobs {
 public:
  /// What identifies job `index`'s inputs beyond the index (a design's slabs), so that a
  /// process that set up other work refuses it; none: 0 for every job.
  using Fingerprint = std::function<double(std::size_t index)>;
  /// On a process that serves another this serves and throws JobsServedElsewhere.
  Jobs(Executor& executor, std::function<T(std::size_t)> job, Fingerprint fingerprint = {})
      : job_(std::move(job)),
        fingerprint_(std::move(fingerprint)),
        channel_(executor.open([this](std::size_t index, double asked) {
          if (fingerprint_of(index) != asked)
            throw std::runtime_error("job " + std::to_string(index) + " was set up differently here than by the primary "
                                     "process (another design or case): the processes differ");
          return to_job_bytes(job_(index));
        })) {}
  /// Job `index`'s result (thread-safe when the job is).
  T operator()(std::size_t index) {
    if (auto bytes = channel_->run_elsewhere(index, fingerprint_of(index))) return from_job_bytes<T>(*bytes);
    const auto start = std::chrono::steady_clock::now();
    T result = job_(index);
    channel_->ran_here(start);
    return result;
  }
  nlohmann::json balance() const { return channel_->balance(); }

 private:
  double fingerprint_of(std::size_t index) const { return fingerprint_ ? fingerprint_(index) : 0.0; }

  std::function<T(std::size_t)> job_;
  Fingerprint fingerprint_;
  std::unique_ptr<JobChannel> channel_;
};

/// Runs body(k) for k < count, when `parallel` on up to `max_threads` threads (a thread per
/// job by default), each taking the next k in order; else one after the other. An exception
/// in a thread is carried to this one and rethrown after all end (the first in order).
void for_each_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& body,
                           std::size_t max_threads = std::numeric_limits<std::size_t>::max());

/// Every job of a task, its results in order: jobs 0..count-1 through `executor`, at once
/// (a thread each, at most `max_threads`) when `parallel`. `balance`, if given, receives
/// Jobs::balance().
template <class T>
std::vector<T> run_jobs(Executor& executor, std::size_t count, bool parallel, std::function<T(std::size_t)> job,
                        nlohmann::json* balance = nullptr, typename Jobs<T>::Fingerprint fingerprint = {},
                        std::size_t max_threads = std::numeric_limits<std::size_t>::max()) {
  Jobs<T> jobs(executor, std::move(job), std::move(fingerprint));
  std::vector<T> results(count);
  for_each_concurrently(count, parallel, [&](std::size_t k) { results[k] = jobs(k); }, max_threads);
  if (balance) *balance = jobs.balance();
  return results;
}

/// Whether two jobs can run at once here: more than one process, or two cores.
inline bool parallel_jobs(const Executor& executor, std::size_t count) {
  return count > 1 && executor.concurrency(std::thread::hardware_concurrency() >= 2 ? 2 : 1) > 1;
}

}  // namespace pdamp::base
