// Independent jobs spread over MPI ranks (docs/distributed.md). In a build with
// -DPDAMP_MPI=ON launched by mpirun, every rank runs the same command, the same checks and
// the same task; rank 0 runs it as usual (results log, resume, progress, outputs) and hands
// each job of a batch (a sweep's point, a stepped sine's direction, a bed's calibration, a
// verification's decay) to whichever rank is free (dynamic load balancing: DEM points differ
// tenfold in cost), itself included, while the other ranks compute what they are sent and,
// when rank 0 ends the batch with its results, go on with the task to its next batch. A job
// is computed by the same code with the same inputs wherever it runs, so the result equals
// the serial one bit for bit. The task decides whether it is distributed at all
// (base::Executor::primary_only). Without MPI (the default build, or the MPI build run
// without mpirun) this is one rank and the executor runs every job here.
#pragma once

#include <string>

#include "pdamp/base/executor.hpp"

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

/// The executor of this process: the ranks of mpirun (rank 0 hands a batch's jobs out, one
/// at a time to whichever rank is free, and works itself when none is; a worker serves them
/// until rank 0 ends the batch), or this process alone. Its primary() is rank 0.
base::Executor& executor();

}  // namespace pdamp::cli::distributed
