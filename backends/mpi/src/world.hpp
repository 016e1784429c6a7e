#pragma once
// The MPI world: started once per process, shut down when rank 0 exits
// or ends MPI.
#include <string>

namespace sh::mpi {

// Initialises MPI (once); returns this rank.
int ensure_started();
// MPI is started for calls from one thread (MPI_THREAD_FUNNELED): a
// compile or run of `program` from another throws sh::Error, where two
// threads' messages would cross and abort the job.
void check_thread(const std::string& program);
// Ranks other than 0: serve rank 0 until told to stop, then exit.
[[noreturn]] void serve();

}  // namespace sh::mpi
