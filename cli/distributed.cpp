// Jobs spread over MPI ranks: see distributed.hpp. Only this file knows MPI, and only when
// built with -DPDAMP_MPI=ON (PDAMP_WITH_MPI); the default build compiles the one-rank half.
#include "distributed.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
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

/// What a job is asked by: its index and the asker's fingerprint (base::Jobs), as raw
/// doubles, so a worker computes bit for bit what rank 0 would.
using Request = std::array<double, 2>;

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

void send_bytes(const std::vector<char>& bytes, int to, int tag) {
  MPI_Send(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, to, tag, MPI_COMM_WORLD);
}

/// A worker: the next message from rank 0. A request is answered by `answer`; returns
/// false once rank 0 says stop.
bool serve_one(const std::function<std::vector<char>(const Request&)>& answer) {
  const MPI_Status status = wait_for(0, MPI_ANY_TAG);
  if (status.MPI_TAG == kTagStop) {
    MPI_Recv(nullptr, 0, MPI_BYTE, 0, kTagStop, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    g_stopped = true;
    return false;
  }
  Request request{};
  MPI_Recv(request.data(), 2, MPI_DOUBLE, 0, kTagRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  send_bytes(answer(request), 0, kTagReply);
  return true;
}

/// Rank 0's jobs: each to a free rank, or here when none is free; the balance per rank.
class RankChannel : public base::JobChannel {
 public:
  RankChannel() : points_(static_cast<std::size_t>(g_ranks), 0), busy_s_(static_cast<std::size_t>(g_ranks), 0.0) {
    for (int r = g_ranks - 1; r >= 1; --r) free_.push_back(r);
  }

  std::optional<std::string> run_elsewhere(std::size_t index, double fingerprint) override {
    const auto start = std::chrono::steady_clock::now();
    int rank = 0;
    {
      std::lock_guard lock(mutex_);
      if (!started_) first_ = start, started_ = true;
      if (free_.empty()) return std::nullopt;
      rank = free_.back();
      free_.pop_back();
    }
    const Request request{static_cast<double>(index), fingerprint};
    {
      std::lock_guard lock(g_mpi_mutex);
      MPI_Send(request.data(), 2, MPI_DOUBLE, rank, kTagRequest, MPI_COMM_WORLD);
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

  mutable std::mutex mutex_;  // free_, points_, busy_s_, first_, last_
  std::vector<int> free_;     // ranks > 0 waiting for a job
  std::vector<std::size_t> points_;
  std::vector<double> busy_s_;
  std::chrono::steady_clock::time_point first_{}, last_{};
  bool started_ = false;
};

class MpiExecutor : public base::Executor {
 public:
  int concurrency(int local_jobs) const override { return g_ranks > 1 ? g_ranks : local_jobs; }
  int processes() const override { return g_ranks; }
  std::unique_ptr<base::JobChannel> open(EncodedJob encoded_job) override {
    if (!g_mpi || g_ranks == 1) return base::local_executor().open(std::move(encoded_job));
    if (g_rank == 0) return std::make_unique<RankChannel>();
    // A worker: compute what rank 0 sends until it says stop; it has no result of its own.
    const auto answer = [&](const Request& request) {
      try {
        return encode_reply(kResult, encoded_job(static_cast<std::size_t>(request[0]), request[1]));
      } catch (const std::exception& e) {
        return encode_error(e.what());
      } catch (...) {
        return encode_error("an unknown exception");
      }
    };
    while (serve_one(answer)) {
    }
    throw base::JobsServedElsewhere();
  }
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
    while (!g_stopped && serve_one([&](const Request&) { return encode_error(why); })) {
    }
    std::cout.rdbuf(g_cout);
    std::cerr.rdbuf(g_cerr);
  }
  MPI_Finalize();
}

#endif

}  // namespace pdamp::cli::distributed
