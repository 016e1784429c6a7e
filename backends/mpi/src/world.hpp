#pragma once
// The MPI world: started once per process, shut down when rank 0 exits.
namespace sh::mpi {

// Initialises MPI (once); returns this rank.
int ensure_started();
// Rank 0: tells the serving ranks to stop (at exit).
void shutdown_workers();
// Ranks other than 0: serve rank 0 until told to stop, then exit.
[[noreturn]] void serve();

}  // namespace sh::mpi
