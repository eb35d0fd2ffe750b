// Distributed sweeps on MPI: see distributed.hpp. Only this file knows MPI, and only
// when built with -DPDAMP_MPI=ON (PDAMP_WITH_MPI); the default build compiles the
// one-rank half below.
#include "distributed.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <streambuf>
#include <thread>

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

// A field point as bytes: five doubles, the status, the motion-mode text.
std::string encode_point(const surrogate::FieldPoint& p) {
  const double values[5] = {p.eta_star, p.eta_star_stderr, p.e_diss_j, p.apparent_mass_kg, p.apparent_mass_fraction};
  const auto status = static_cast<std::int32_t>(p.status);
  std::string bytes(sizeof values + sizeof status, '\0');
  std::memcpy(bytes.data(), values, sizeof values);
  std::memcpy(bytes.data() + sizeof values, &status, sizeof status);
  return bytes + p.motion_mode;
}

surrogate::FieldPoint decode_point(const std::string& bytes) {
  double values[5];
  std::int32_t status = 0;
  if (bytes.size() < sizeof values + sizeof status)
    throw std::runtime_error("a field point of " + std::to_string(bytes.size()) + " bytes is too short");
  std::memcpy(values, bytes.data(), sizeof values);
  std::memcpy(&status, bytes.data() + sizeof values, sizeof status);
  surrogate::FieldPoint p;
  p.eta_star = values[0];
  p.eta_star_stderr = values[1];
  p.e_diss_j = values[2];
  p.apparent_mass_kg = values[3];
  p.apparent_mass_fraction = values[4];
  p.status = static_cast<surrogate::PointStatus>(status);
  p.motion_mode = bytes.substr(sizeof values + sizeof status);
  return p;
}

}  // namespace

void run_concurrently(std::size_t count, bool parallel, const std::function<void(std::size_t)>& run) {
  if (!parallel) {
    for (std::size_t k = 0; k < count; ++k) run(k);
    return;
  }
  std::vector<std::exception_ptr> errors(count);
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < count; ++k)
    threads.emplace_back([&, k] {
      try {
        run(k);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    });
  for (auto& t : threads) t.join();
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
}

int rank() { return g_rank; }
int ranks() { return g_ranks; }
void note_failure(const std::string& message) { g_failure = message; }

TaskFarm::TaskFarm(Evaluator local) : local_(std::move(local)) {
  points_.assign(static_cast<std::size_t>(g_ranks), 0);
  busy_s_.assign(static_cast<std::size_t>(g_ranks), 0.0);
  for (int r = g_ranks - 1; r >= 1; --r) free_.push_back(r);
}

int TaskFarm::threads(int serial_threads) const { return g_ranks > 1 ? g_ranks : serial_threads; }

void TaskFarm::account(int rank, std::chrono::steady_clock::time_point start) {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  ++points_[static_cast<std::size_t>(rank)];
  busy_s_[static_cast<std::size_t>(rank)] += std::chrono::duration<double>(now - start).count();
  last_ = std::max(last_, now);
}

PointFarm::PointFarm(LocalEvaluator local)
    : farm_([local = std::move(local)](const Request& request) { return encode_point(local(request)); }) {}

surrogate::FieldPoint PointFarm::evaluate(const Request& request) { return decode_point(farm_.evaluate(request)); }

nlohmann::json TaskFarm::balance() const {
  std::lock_guard lock(mutex_);
  if (g_ranks == 1) return nullptr;
  const double wall_s = started_ ? std::chrono::duration<double>(last_ - first_).count() : 0.0;
  nlohmann::json busy = nlohmann::json::array();
  for (const double b : busy_s_) busy.push_back(wall_s > 0.0 ? b / wall_s : 0.0);
  return {{"ranks", g_ranks}, {"points", points_}, {"busy_fraction", busy}, {"wall_time_s", wall_s}};
}

#ifndef PDAMP_WITH_MPI

bool built_with_mpi() { return false; }

// One rank: a build without MPI refuses to run as several (each copy would write the same
// files), and evaluates every task itself.
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

std::string TaskFarm::evaluate(const Request& request) { return local_(request); }
void TaskFarm::serve() {}

#else

namespace {

constexpr int kTagRequest = 1;
constexpr int kTagReply = 2;
constexpr int kTagStop = 3;
bool g_mpi = false;
bool g_stopped = false;  // a worker: rank 0 said stop
std::mutex g_mpi_mutex;  // rank 0's sweep threads: one MPI call at a time (MPI_THREAD_SERIALIZED)

/// Where a worker's output goes: rank 0 speaks for the run.
class NullBuffer : public std::streambuf {
 protected:
  int overflow(int c) override { return traits_type::not_eof(c); }
};
NullBuffer g_null;
std::streambuf* g_cout = nullptr;
std::streambuf* g_cerr = nullptr;

// A reply: one byte kind, then the task's result or an error message.
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

}  // namespace

bool built_with_mpi() { return true; }

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
                           "which rank 0's sweep threads need\n");
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
    const std::string why = g_failure.empty() ? "takes no part in this command's sweep"
                                              : "could not set up its part of the sweep: " + g_failure;
    while (!g_stopped && serve_one([&](const Request&) { return encode_error(why); })) {
    }
    std::cout.rdbuf(g_cout);
    std::cerr.rdbuf(g_cerr);
  }
  MPI_Finalize();
}

std::string TaskFarm::evaluate(const Request& request) {
  const auto start = std::chrono::steady_clock::now();
  int rank = 0;
  {
    std::lock_guard lock(mutex_);
    if (!started_) first_ = start, started_ = true;
    if (!free_.empty()) rank = free_.back(), free_.pop_back();
  }
  if (rank == 0) {
    auto result = local_(request);
    account(0, start);
    return result;
  }
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

void TaskFarm::serve() {
  if (!g_mpi || g_rank == 0) return;
  const auto answer = [&](const Request& request) {
    try {
      return encode_reply(kResult, local_(request));
    } catch (const std::exception& e) {
      return encode_error(e.what());
    } catch (...) {
      return encode_error("an unknown exception");
    }
  };
  while (serve_one(answer)) {
  }
}

#endif

}  // namespace pdamp::cli::distributed
