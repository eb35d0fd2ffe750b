// Jobs spread over MPI ranks: see distributed.hpp. Only this file knows MPI, and only when
// built with -DPDAMP_MPI=ON (PDAMP_WITH_MPI); the default build compiles the one-rank half.
#include "distributed.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <streambuf>
#include <thread>
#include <vector>

#ifdef PDAMP_WITH_MPI
#include <mpi.h>
#endif

namespace pdamp::cli::distributed {
namespace {

int g_rank = 0;
int g_ranks = 1;
std::string g_failure;  // why this rank's command failed, for its replies

/// The rank mpirun (Open MPI, or a PMI launcher such as Slurm's srun) gave this process,
/// or -1 when it was not started by one.
int launcher_rank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"}) {
    if (const char* value = std::getenv(name)) return std::atoi(value);
  }
  return -1;
}

/// What a job is asked by: its batch (every rank numbers its task's batches alike), its
/// index in the batch and the asker's fingerprint of its inputs (base::Jobs), exact.
using Request = std::array<std::uint64_t, 3>;

}  // namespace

int rank() { return g_rank; }
int ranks() { return g_ranks; }
void note_failure(const std::string& message) { g_failure = message; }

#ifndef PDAMP_WITH_MPI

bool built_with_mpi() { return false; }

// One rank: a build without MPI refuses to run as several (each copy would write the same
// files), and runs every job itself.
Session::Session(int*, char***) {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  if (size == nullptr) size = std::getenv("PMI_SIZE");
  if (size != nullptr && std::atoi(size) > 1) {
    if (launcher_rank() <= 0)
      std::fprintf(stderr, "pdamp: error: started as %s processes by mpirun, but this pdamp was built without MPI: "
                           "run it without mpirun, or build with cmake -DPDAMP_MPI=ON (docs/distributed.md)\n", size);
    std::exit(2);
  }
}
Session::~Session() = default;

base::Executor& executor() { return base::local_executor(); }

#else

namespace {

constexpr int kTagRequest = 1;
constexpr int kTagReply = 2;
constexpr int kTagStop = 3;
constexpr int kTagBatchEnd = 4;  // {batch, 1 with results}; then the results (kTagResults)
constexpr int kTagResults = 5;
bool g_mpi = false;
bool g_stopped = false;  // a worker: rank 0 said stop
std::mutex g_mpi_mutex;  // rank 0's job threads: one MPI call at a time (MPI_THREAD_SERIALIZED)

/// Where a worker's output goes: rank 0 speaks for the run.
class NullBuffer : public std::streambuf {
 protected:
  int overflow(int c) override { return traits_type::not_eof(c); }
};
NullBuffer g_null;
std::streambuf* g_cout = nullptr;
std::streambuf* g_cerr = nullptr;

// A reply: one byte kind, then the job's result or an error message.
constexpr char kResult = 'r';
constexpr char kError = 'e';

std::vector<char> encode_reply(char kind, const std::string& payload) {
  std::vector<char> bytes(1 + payload.size());
  bytes[0] = kind;
  std::memcpy(bytes.data() + 1, payload.data(), payload.size());
  return bytes;
}
std::vector<char> encode_error(const std::string& message) { return encode_reply(kError, message); }

/// The result a reply carries; its error rethrown naming the rank.
std::string decode_reply(const std::vector<char>& bytes, int from) {
  const std::string who = "MPI rank " + std::to_string(from);
  if (bytes.empty() || (bytes[0] != kResult && bytes[0] != kError))
    throw std::runtime_error(who + ": sent a reply that is not a result (" + std::to_string(bytes.size()) + " bytes)");
  std::string payload(bytes.begin() + 1, bytes.end());
  if (bytes[0] == kError) throw std::runtime_error(who + ": " + payload);
  return payload;
}

/// Waits for a message from `source` with `tag` (MPI_ANY_TAG for any) and returns its
/// status. Polls with a short sleep instead of MPI_Probe, which spins a core at 100% in
/// Open MPI: an idle rank must not slow down the busy ones sharing its cores.
MPI_Status wait_for(int source, int tag) {
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    {
      std::lock_guard lock(g_mpi_mutex);
      MPI_Iprobe(source, tag, MPI_COMM_WORLD, &arrived, &status);
    }
    if (arrived) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::vector<char> receive_bytes(const MPI_Status& status) {
  int count = 0;
  MPI_Get_count(&status, MPI_BYTE, &count);
  std::vector<char> bytes(static_cast<std::size_t>(count));
  MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return bytes;
}

/// Whether `size` bytes fit one MPI message (its count is an int).
bool fits_one_message(std::size_t size) { return size <= static_cast<std::size_t>(std::numeric_limits<int>::max()); }
std::string too_large(std::size_t size) {
  return "a result of " + std::to_string(size) + " bytes is beyond what one MPI message carries";
}

void send_bytes(const char* data, std::size_t size, int to, int tag) {
  MPI_Send(data, static_cast<int>(size), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}
void send_bytes(const std::vector<char>& bytes, int to, int tag) { send_bytes(bytes.data(), bytes.size(), to, tag); }

/// How rank 0 ended a batch, as a worker receives it.
struct BatchEnd {
  std::uint64_t batch = 0;
  std::optional<std::string> results;  ///< none: the worker's part of the task ends
};

/// A worker: answers rank 0's requests with `answer` until rank 0 ends a batch (returned) or
/// says stop (nothing).
std::optional<BatchEnd> serve(const std::function<std::vector<char>(const Request&)>& answer) {
  for (;;) {
    const MPI_Status status = wait_for(0, MPI_ANY_TAG);
    if (status.MPI_TAG == kTagStop) {
      MPI_Recv(nullptr, 0, MPI_BYTE, 0, kTagStop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      g_stopped = true;
      return std::nullopt;
    }
    if (status.MPI_TAG == kTagBatchEnd) {
      std::array<std::uint64_t, 2> header{};
      MPI_Recv(header.data(), 2, MPI_UINT64_T, 0, kTagBatchEnd, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      BatchEnd end{header[0], std::nullopt};
      if (header[1] != 0) {
        const auto bytes = receive_bytes(wait_for(0, kTagResults));
        end.results = std::string(bytes.begin(), bytes.end());
      }
      return end;
    }
    if (status.MPI_TAG != kTagRequest) {  // not of this protocol: dropped
      (void)receive_bytes(status);
      continue;
    }
    Request request{};
    MPI_Recv(request.data(), 3, MPI_UINT64_T, 0, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::vector<char> reply = answer(request);
    if (!fits_one_message(reply.size())) reply = encode_error(too_large(reply.size()));
    send_bytes(reply, 0, kTagReply);
  }
}

/// Rank 0's jobs: each to a free rank, or here when none is free; the balance per rank.
class RankChannel : public base::JobChannel {
 public:
  /// `ended_alone`: called when the batch ends without results (the workers leave the task).
  RankChannel(std::uint64_t batch, std::function<void()> ended_alone)
      : batch_(batch),
        ended_alone_(std::move(ended_alone)),
        points_(static_cast<std::size_t>(g_ranks), 0),
        busy_s_(static_cast<std::size_t>(g_ranks), 0.0) {
    for (int r = g_ranks - 1; r >= 1; --r) free_.push_back(r);
  }

  std::optional<std::string> run_elsewhere(std::size_t index, std::uint64_t fingerprint) override {
    const auto start = std::chrono::steady_clock::now();
    int rank = 0;
    {
      std::lock_guard lock(mutex_);
      if (!started_) first_ = start, started_ = true;
      if (free_.empty()) return std::nullopt;
      rank = free_.back();
      free_.pop_back();
    }
    const Request request{batch_, static_cast<std::uint64_t>(index), fingerprint};
    {
      std::lock_guard lock(g_mpi_mutex);
      MPI_Send(request.data(), 3, MPI_UINT64_T, rank, kTagRequest, MPI_COMM_WORLD);
    }
    const MPI_Status status = wait_for(rank, kTagReply);
    std::vector<char> reply;
    {
      std::lock_guard lock(g_mpi_mutex);
      reply = receive_bytes(status);
    }
    {
      std::lock_guard lock(mutex_);
      free_.push_back(rank);
    }
    account(rank, start);
    return decode_reply(reply, rank);
  }

  void ran_here(std::chrono::steady_clock::time_point start) override { account(0, start); }

  /// Every job has its result (none in flight): each worker learns that the batch ended,
  /// with its results or without.
  void end(const std::optional<std::string>& results) override {
    if (results && !fits_one_message(results->size())) throw std::runtime_error(too_large(results->size()));
    const std::array<std::uint64_t, 2> header{batch_, results ? 1u : 0u};
    {
      std::lock_guard lock(g_mpi_mutex);
      for (int r = 1; r < g_ranks; ++r) {
        MPI_Send(header.data(), 2, MPI_UINT64_T, r, kTagBatchEnd, MPI_COMM_WORLD);
        if (results) send_bytes(results->data(), results->size(), r, kTagResults);
      }
    }
    if (!results) ended_alone_();
  }

  nlohmann::json balance() const override {
    std::lock_guard lock(mutex_);
    const double wall_s = started_ ? std::chrono::duration<double>(last_ - first_).count() : 0.0;
    nlohmann::json busy = nlohmann::json::array();
    for (const double b : busy_s_) busy.push_back(wall_s > 0.0 ? b / wall_s : 0.0);
    return {{"ranks", g_ranks}, {"points", points_}, {"busy_fraction", busy}, {"wall_time_s", wall_s}};
  }

 private:
  void account(int rank, std::chrono::steady_clock::time_point start) {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard lock(mutex_);
    if (!started_) first_ = start, started_ = true;
    ++points_[static_cast<std::size_t>(rank)];
    busy_s_[static_cast<std::size_t>(rank)] += std::chrono::duration<double>(now - start).count();
    last_ = std::max(last_, now);
  }

  const std::uint64_t batch_;
  const std::function<void()> ended_alone_;
  mutable std::mutex mutex_;  // free_, points_, busy_s_, first_, last_
  std::vector<int> free_;     // ranks > 0 waiting for a job
  std::vector<std::size_t> points_;
  std::vector<double> busy_s_;
  std::chrono::steady_clock::time_point first_{}, last_{};
  bool started_ = false;
};

class MpiExecutor : public base::Executor {
 public:
  int concurrency(int local_jobs) const override { return spread() ? g_ranks : local_jobs; }
  int processes() const override { return g_ranks; }
  bool primary() const override { return g_rank == 0; }
  void primary_only() override {
    if (g_rank != 0) throw base::JobsServedElsewhere();
    alone_ = true;  // the workers leave this task: its batches run here
  }

  std::unique_ptr<base::JobChannel> open(EncodedJob encoded_job) override {
    if (!g_mpi || g_ranks == 1) return base::local_executor().open(std::move(encoded_job));
    const std::uint64_t batch = ++batches_;
    if (g_rank == 0) {
      if (alone_) return base::local_executor().open(std::move(encoded_job));
      return std::make_unique<RankChannel>(batch, [this] { alone_ = true; });
    }
    if (alone_) throw base::JobsServedElsewhere();
    // A worker: compute what rank 0 sends in this batch until it ends the batch.
    const auto answer = [&](const Request& request) {
      try {
        if (request[0] != batch)
          throw std::runtime_error("was asked for a job of batch " + std::to_string(request[0]) + " in batch " +
                                   std::to_string(batch) + " of its task: the processes run different tasks");
        return encode_reply(kResult, encoded_job(static_cast<std::size_t>(request[1]), request[2]));
      } catch (const std::exception& e) {
        return encode_error(e.what());
      } catch (...) {
        return encode_error("an unknown exception");
      }
    };
    const std::optional<BatchEnd> end = serve(answer);
    if (!end) throw base::JobsServedElsewhere();  // rank 0 ended the command
    if (end->batch != batch)
      throw std::runtime_error("rank 0 ended batch " + std::to_string(end->batch) + " while this rank served batch " +
                               std::to_string(batch) + ": the processes run different tasks");
    if (!end->results) {
      alone_ = true;
      throw base::JobsServedElsewhere();
    }
    return std::make_unique<base::SharedResultsChannel>(std::move(*end->results));
  }

 private:
  bool spread() const { return g_mpi && g_ranks > 1; }

  std::uint64_t batches_ = 0;  // opened by this process's task
  bool alone_ = false;         // the workers left the task (primary_only, a batch ended without results)
};

}  // namespace

bool built_with_mpi() { return true; }

base::Executor& executor() {
  static MpiExecutor mpi;
  return mpi;
}

Session::Session(int* argc, char*** argv) {
  if (launcher_rank() < 0) return;  // not under mpirun: one rank, no MPI (no singleton start-up)
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided);
  g_mpi = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_ranks);
  if (g_rank != launcher_rank()) {
    // Debian's sequential MUMPS (under Ipopt) exports stub MPI_Init, MPI_Comm_rank,
    // MPI_Finalize and MPI_Wtime; whichever library loads first wins. cli/CMakeLists.txt
    // links MPI first, and this catches a link line that lost that order.
    std::fprintf(stderr, "pdamp: error: MPI_Comm_rank says rank %d, mpirun says %d: a stub MPI library "
                         "(MUMPS's libmpiseq) is loaded before Open MPI; link MPI first\n", g_rank, launcher_rank());
    std::_Exit(1);
  }
  if (provided < MPI_THREAD_SERIALIZED) {
    if (g_rank == 0)
      std::fprintf(stderr, "pdamp: error: this MPI library gives no thread support (MPI_THREAD_SERIALIZED), "
                           "which rank 0's job threads need\n");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  if (g_rank != 0) {
    g_cout = std::cout.rdbuf(&g_null);
    g_cerr = std::cerr.rdbuf(&g_null);
  }
}

Session::~Session() {
  if (!g_mpi) return;
  if (g_rank == 0) {
    for (int r = 1; r < g_ranks; ++r) MPI_Send(nullptr, 0, MPI_BYTE, r, kTagStop, MPI_COMM_WORLD);
  } else {
    // This rank's command ended before rank 0's (it takes no part, or it failed): keep
    // answering, with the reason, so that rank 0 reports it instead of waiting.
    const std::string why = g_failure.empty() ? "takes no part in this command's jobs"
                                              : "could not set up its part of the jobs: " + g_failure;
    while (!g_stopped) (void)serve([&](const Request&) { return encode_error(why); });
    std::cout.rdbuf(g_cout);
    std::cerr.rdbuf(g_cerr);
  }
  MPI_Finalize();
}

#endif

}  // namespace pdamp::cli::distributed
