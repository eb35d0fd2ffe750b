// Where a task's independent jobs run: in this process (one after the other or on
// threads), or spread over processes (the command line's MPI executor). A task hands its
// jobs to an Executor& in numbered batches and gets the results in order; a job's result
// crosses a process boundary as CBOR of its JSON form (to_json/from_json), so doubles
// arrive bit for bit. The task decides whether it is distributed (Executor::primary_only).
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace pdamp::base {

/// Thrown on a process that served a task's jobs to another (an MPI worker rank) when the
/// task ends there: a batch ended without results (a sweep), or the task runs on the primary
/// process alone (Executor::primary_only). It has no result of its own and must write and
/// print nothing; the command line ends it with success (the primary process reports).
class JobsServedElsewhere : public std::exception {
 public:
  const char* what() const noexcept override { return "this process served its jobs to the primary process"; }
};

/// FNV-1a (64 bits) of `text`: the fingerprint of a job from a text that names its inputs
/// (a design's slabs and softening, a bed), the same on every process that set up the same work.
std::uint64_t fingerprint(std::string_view text);

/// One batch of a task's jobs while it runs (Executor::open).
class JobChannel {
 public:
  virtual ~JobChannel() = default;
  /// Runs job `index` of this batch in another process when one is free and returns its
  /// result bytes; nothing when it should run here. `fingerprint` travels with the request:
  /// the other process refuses a job whose fingerprint differs from its own (it set up other
  /// work). Thread-safe.
  virtual std::optional<std::string> run_elsewhere(std::size_t index, std::uint64_t fingerprint) = 0;
  /// Job `index` ran here, from `start` until now (for the balance). Thread-safe.
  virtual void ran_here(std::chrono::steady_clock::time_point /*start*/) {}
  /// How the jobs spread: {ranks, points[r], busy_fraction[r], wall_time_s}, or null when
  /// every job ran in this process.
  virtual nlohmann::json balance() const { return nullptr; }
  /// The primary process, once every job of the batch has its result: the batch ends on every
  /// process that served it. With `results` (the bytes of all its results, in order) each of
  /// them returns them (shared_results) and goes on with the task, to the next batch; without
  /// (a sweep: the primary alone has every result, some from its log) each ends its task
  /// (JobsServedElsewhere) and serves no later batch, which then runs on the primary alone.
  virtual void end(const std::optional<std::string>& /*results*/) {}
  /// On a process that served the batch: the results the primary ended it with.
  virtual std::optional<std::string> shared_results() const { return std::nullopt; }
};

/// A batch this process served: it runs no job and holds the results the primary ended it
/// with (what a distributed executor opens on every process but the primary).
class SharedResultsChannel : public JobChannel {
 public:
  explicit SharedResultsChannel(std::string results) : results_(std::move(results)) {}
  std::optional<std::string> run_elsewhere(std::size_t, std::uint64_t) override {
    throw std::logic_error("a batch served to the primary process has no jobs left to run");
  }
  std::optional<std::string> shared_results() const override { return results_; }

 private:
  std::string results_;
};

/// Where a task's jobs run. A task opens its jobs in numbered batches (1, 2, ...: one at a
/// time, never inside a job); every process of a run runs the same task on the same inputs,
/// so it opens the same batches in the same order, and a request names its batch. The task
/// decides whether it is distributed: one that is hands its jobs to the executor batch by
/// batch; one that is not calls primary_only() at its start.
class Executor {
 public:
  virtual ~Executor() = default;
  /// Jobs to keep in flight at once for a task that would run `local_jobs` at once alone.
  virtual int concurrency(int local_jobs) const = 0;
  /// Processes the jobs spread over (1: this one).
  virtual int processes() const { return 1; }
  /// This process runs the task for its results and writes them (false: a process that
  /// computes the jobs another sends it, an MPI worker, which writes nothing).
  virtual bool primary() const { return true; }
  /// At the start of a task that runs on the primary process alone (one DEM run, closed
  /// forms): on a process that serves another this throws JobsServedElsewhere; on the
  /// primary the task goes on, and its batches, if any, run here.
  virtual void primary_only() {}
  /// A job as another process asks for it: its index in the batch and the fingerprint the
  /// asker computed.
  using EncodedJob = std::function<std::string(std::size_t index, std::uint64_t fingerprint)>;
  /// Opens the task's next batch of jobs; `encoded_job` computes one of them and returns its
  /// result bytes (called for the jobs another process asks for). On the primary this returns
  /// the batch's channel. On a process that serves another (an MPI worker) this serves the
  /// batch until the primary ends it, then returns a channel holding the results the primary
  /// shared (JobChannel::shared_results), or throws JobsServedElsewhere when it shared none.
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

/// One batch of a task's jobs, run through an executor: job(index) here or in another
/// process. On a process that serves another the constructor serves the batch, then either
/// holds the results the primary shared (shared_results) or throws JobsServedElsewhere.
template <class T>
class Jobs {
 public:
  /// A text naming what job `index` is computed from beyond its index (a design's slabs and
  /// softening, a bed); its fingerprint travels with the request, so that a process that set
  /// up other work refuses the job. None: every job's fingerprint is 0.
  using Inputs = std::function<std::string(std::size_t index)>;
  Jobs(Executor& executor, std::function<T(std::size_t)> job, Inputs inputs = {})
      : job_(std::move(job)),
        inputs_(std::move(inputs)),
        channel_(executor.open([this](std::size_t index, std::uint64_t asked) {
          if (fingerprint_of(index) != asked)
            throw std::runtime_error("job " + std::to_string(index) + " was set up differently here than by the primary "
                                     "process (another design or case): the processes differ");
          return to_job_bytes(job_(index));
        })) {}
  Jobs(const Jobs&) = delete;
  Jobs& operator=(const Jobs&) = delete;
  /// A batch not ended (an exception on the way) ends without results.
  ~Jobs() {
    try {
      end_once(std::nullopt);
    } catch (...) {
    }
  }

  /// Job `index`'s result (thread-safe when the job is).
  T operator()(std::size_t index) {
    if (auto bytes = channel_->run_elsewhere(index, fingerprint_of(index))) return from_job_bytes<T>(*bytes);
    const auto start = std::chrono::steady_clock::now();
    T result = job_(index);
    channel_->ran_here(start);
    return result;
  }
  /// The batch is complete, its results on this process alone (a sweep's): the processes that
  /// served it end their task.
  void end() { end_once(std::nullopt); }
  /// The batch is complete: the processes that served it get `results` and go on.
  void end(const std::vector<T>& results) { end_once(to_job_bytes(results)); }
  /// On a process that served the batch: the results the primary ended it with.
  std::optional<std::vector<T>> shared_results() const {
    const auto bytes = channel_->shared_results();
    if (!bytes) return std::nullopt;
    return from_job_bytes<std::vector<T>>(*bytes);
  }
  nlohmann::json balance() const { return channel_->balance(); }

 private:
  std::uint64_t fingerprint_of(std::size_t index) const { return inputs_ ? fingerprint(inputs_(index)) : 0; }
  void end_once(const std::optional<std::string>& results) {
    if (ended_) return;
    ended_ = true;
    channel_->end(results);
  }

  std::function<T(std::size_t)> job_;
  Inputs inputs_;
  std::unique_ptr<JobChannel> channel_;
  bool ended_ = false;
};

/// Runs body(k) for k < count, when `parallel` on up to `max_threads` threads (a thread per
/// job by default), each taking the next k in order; else one after the other. An exception
/// in a thread is carried to this one and rethrown after all end (the first in order).
void for_each_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& body,
                           std::size_t max_threads = std::numeric_limits<std::size_t>::max());

/// Every job of a batch, its results in order: jobs 0..count-1 through `executor`, at once
/// (a thread each, at most `max_threads`) when `parallel`. Every process gets the results: on
/// one that served the batch to another they are the ones the primary computed, so the task
/// goes on there as on the primary. `balance`, if given, receives Jobs::balance(); `inputs`:
/// Jobs::Inputs.
template <class T>
std::vector<T> run_jobs(Executor& executor, std::size_t count, bool parallel, std::function<T(std::size_t)> job,
                        nlohmann::json* balance = nullptr, typename Jobs<T>::Inputs inputs = {},
                        std::size_t max_threads = std::numeric_limits<std::size_t>::max()) {
  Jobs<T> jobs(executor, std::move(job), std::move(inputs));
  if (auto shared = jobs.shared_results()) {
    if (shared->size() != count)
      throw std::runtime_error("the primary process ran " + std::to_string(shared->size()) + " jobs in a batch of " +
                               std::to_string(count) + " here: the processes differ");
    if (balance) *balance = jobs.balance();
    return std::move(*shared);
  }
  std::vector<T> results(count);
  for_each_concurrently(count, parallel, [&](std::size_t k) { results[k] = jobs(k); }, max_threads);
  jobs.end(results);
  if (balance) *balance = jobs.balance();
  return results;
}

/// Whether two jobs can run at once here: more than one process, or two cores.
inline bool parallel_jobs(const Executor& executor, std::size_t count) {
  return count > 1 && executor.concurrency(std::thread::hardware_concurrency() >= 2 ? 2 : 1) > 1;
}

}  // namespace pdamp::base
