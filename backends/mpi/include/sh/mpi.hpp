#pragma once
// The distributed backend: under `mpirun -np N`, rank 0 owns the streams
// and every rank (rank 0 too) computes chunks with a local backend
// (Options::local_backend: cpu by default, opencl or interp).  The stream
// is cut into many more chunks than ranks and handed out as ranks ask
// (settings["schedule"] = "dynamic"), or into one share per rank, rank r
// taking the r-th in every run ("static", the default for runs in waves,
// whose per-rank refiners keep what they built for their share); results
// land in order.  Tables and uniforms go out once per version.
// With settings["split_tables"] = N, tables of N bytes or more are split
// instead: blocks of settings["block_bytes"] (2048) dealt to the ranks in
// turn, each rank reading through an LRU cache of settings["cache_blocks"]
// (64) blocks per table, filled by one-sided MPI reads; hit rates come back
// in RunStats::caches.  Local kernels that cannot call back into the
// runtime (opencl) keep tables whole, and say so.
// Including this header registers it as "mpi".
//
// Ranks other than 0 serve rank 0 from the first time they compile an mpi
// kernel until rank 0 exits; call sh::mpi::start() at the top of main to
// make them do so at once (they then never run the rest of main).  Run
// without mpirun, it is one rank, and says so.
#include "sh/backend.hpp"

namespace sh::mpi {

void register_backend();

// Initialises MPI if needed; on ranks other than 0 serves and exits.
void start();
int rank();
int size();

namespace detail {
inline const bool registered = (register_backend(), true);
}  // namespace detail

}  // namespace sh::mpi
