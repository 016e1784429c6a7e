#include "world.hpp"

#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "sh/error.hpp"
#include "sh/mpi.hpp"
#include "split_table.hpp"
#include "wire.hpp"

namespace sh::mpi {
namespace {

int world_rank = 0, world_size = 1;
bool finalised = false;

}  // namespace

int ensure_started() {
  static std::once_flag once;
  std::call_once(once, [] {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    // Every rank must cut messages alike, or they would wait for ever.
    try {
      message_bytes();
    } catch (const Error& e) {
      if (world_rank == 0) std::fprintf(stderr, "sh: %s\n", e.what());
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
    if (world_rank == 0) {
      std::atexit(shutdown_workers);
      if (world_size == 1)
        std::fprintf(stderr, "sh: mpi backend: running as one rank (start the program with mpirun -np N for more)\n");
    }
  });
  return world_rank;
}

void shutdown_workers() {
  if (finalised) return;
  finalised = true;
  if (world_size > 1) {
    Traffic ignored;
    Packer p;
    p.put(Command::Shutdown);
    broadcast(p.bytes(), ignored);
  }
  release_split_tables();
  MPI_Finalize();
}

void start() {
  if (ensure_started() != 0) serve();
}

int rank() { return ensure_started(); }

int size() {
  ensure_started();
  return world_size;
}

}  // namespace sh::mpi
