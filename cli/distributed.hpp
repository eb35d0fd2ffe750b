// Distributed sweeps on MPI (issue 13 §1, docs/distributed.md). In a build with
// -DPDAMP_MPI=ON launched by mpirun, every rank runs the same command and the same
// checks; rank 0 runs the sweep engine as usual (results log, resume, progress, outputs)
// and hands each point to whichever rank is free (dynamic load balancing: DEM points
// differ tenfold in cost), itself included, while the other ranks only evaluate what they
// are sent. A point is evaluated by the same code with the same inputs wherever it runs,
// so the result equals the serial one point for point. Without MPI (the default build,
// or the MPI build run without mpirun) this is one rank and every call is a no-op.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pdamp/surrogate/effective_field.hpp"

namespace pdamp::cli::distributed {

/// MPI for the life of main: initialised when the process was started by mpirun (and
/// pdamp built with MPI), finalised by the destructor, which on rank 0 first tells every
/// other rank to stop and on another rank waits for that word, answering any request it
/// still gets with the failure noted by note_failure (so rank 0 reports it, never hangs).
/// The other ranks' standard output and error are silenced and their exit code is 0
/// (main): rank 0 speaks for the run.
class Session {
 public:
  Session(int* argc, char*** argv);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
};

bool built_with_mpi();  ///< this pdamp was built with -DPDAMP_MPI=ON
int rank();   ///< this process's rank, 0 without MPI
int ranks();  ///< processes in the run, 1 without MPI
inline bool worker() { return rank() != 0; }

/// Why this rank's command failed (a worker's only way to tell rank 0, in its replies).
void note_failure(const std::string& message);

/// What a task is asked by: a grid sweep's (frequency Hz, stroke m), a point sweep's
/// (index, unused), a command's own task number (index, unused). Sent as raw doubles, so a
/// worker evaluates bit for bit what rank 0 would.
using Request = std::array<double, 2>;

/// Runs run(k) for k < count, on a thread each when `parallel`, else one after the other.
/// An exception in a thread is carried to this one and rethrown after all end (the first
/// in order).
void run_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& run);

/// Independent tasks of one command spread over the ranks, their results as bytes (each
/// command encodes its own; doubles as bytes or CBOR, so nothing is rounded on the way).
/// Build it on every rank after the same checks and with the same evaluator; then a worker
/// calls serve() and returns, rank 0 runs its tasks through evaluate() on threads() threads.
class TaskFarm {
 public:
  using Evaluator = std::function<std::string(const Request&)>;
  explicit TaskFarm(Evaluator local);
  /// Tasks in flight at once: one per rank under MPI, `serial_threads` otherwise.
  int threads(int serial_threads) const;
  /// Rank 0, thread-safe: the task's result from a free rank, or from here if none is free.
  /// An exception on another rank is rethrown here as std::runtime_error naming that rank;
  /// one here keeps its type.
  std::string evaluate(const Request& request);
  /// A worker: evaluates what rank 0 sends until it says stop.
  void serve();
  /// Rank 0 after the tasks: {ranks, points[r], busy_fraction[r]} (time each rank spent
  /// on tasks over the wall time from the first to the last), or null without MPI.
  nlohmann::json balance() const;

 private:
  Evaluator local_;
  mutable std::mutex mutex_;  // free_, points_, busy_s_, first_, last_
  std::vector<int> free_;     // ranks > 0 waiting for a task
  std::vector<std::size_t> points_;
  std::vector<double> busy_s_;
  std::chrono::steady_clock::time_point first_{}, last_{};
  bool started_ = false;
  void account(int rank, std::chrono::steady_clock::time_point start);
};

/// A sweep's evaluator spread over the ranks (the engine of pdamp field and sensitivity):
/// a TaskFarm whose results are field points.
class PointFarm {
 public:
  using LocalEvaluator = std::function<surrogate::FieldPoint(const Request&)>;
  explicit PointFarm(LocalEvaluator local);
  int threads(int serial_threads) const { return farm_.threads(serial_threads); }
  surrogate::FieldPoint evaluate(const Request& request);
  void serve() { farm_.serve(); }
  nlohmann::json balance() const { return farm_.balance(); }

 private:
  TaskFarm farm_;
};

}  // namespace pdamp::cli::distributed
