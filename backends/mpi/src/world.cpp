#include "world.hpp"

#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

#include "sh/error.hpp"
#include "sh/mpi.hpp"
#include "split_table.hpp"
#include "wire.hpp"

namespace sh::mpi {
namespace {

int world_rank = 0, world_size = 1;
bool workers_stopped = false;
std::thread::id mpi_thread;  // the one that started MPI

// Rank 0: the serving ranks wait on it for their next command until told to
// stop; stopped once, by whichever comes first of the two below.
void stop_workers() {
  if (workers_stopped) return;
  workers_stopped = true;
  if (world_size > 1) {
    Traffic ignored;
    Packer p;
    p.put(Command::Shutdown);
    broadcast(p.bytes(), ignored);
  }
  release_split_tables();
}

// A program that started MPI itself ends it itself: MPI_Finalize deletes
// MPI_COMM_SELF's attributes first, while MPI still works, so the serving
// ranks are stopped there (they would otherwise wait for rank 0, and rank
// 0's MPI_Finalize for them).
extern "C" int stop_at_finalize(MPI_Comm, int, void*, void*) {
  if (world_rank != 0) return MPI_SUCCESS;
  try {  // nothing may leave through MPI's own frames
    stop_workers();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sh: rank 0: mpi backend: stopping the serving ranks at MPI_Finalize: %s\n", e.what());
    return MPI_ERR_OTHER;
  }
  return MPI_SUCCESS;
}

// At exit: the serving ranks stopped and MPI ended, unless the program
// ended MPI already.
void finish_at_exit() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized) return;
  stop_workers();
  MPI_Finalize();
}

void start_mpi() {
  int finalized = 0, initialised = 0;
  MPI_Finalized(&finalized);
  if (finalized)
    throw Error("mpi backend: MPI was finalized before the backend's first use: use the mpi backend (or call "
                "sh::mpi::start()) before MPI_Finalize");
  MPI_Initialized(&initialised);
  if (!initialised) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  int key = MPI_KEYVAL_INVALID;
  MPI_Comm_create_keyval(MPI_COMM_NULL_COPY_FN, stop_at_finalize, &key, nullptr);
  MPI_Comm_set_attr(MPI_COMM_SELF, key, nullptr);
}

}  // namespace

int ensure_started() {
  static std::once_flag once;
  std::call_once(once, [] {
    start_mpi();
    mpi_thread = std::this_thread::get_id();
    MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
    MPI_Comm_size(MPI_COMM_WORLD, &world_size);
    // Every rank must cut messages alike, or they would wait for ever (or
    // truncate what they receive): each checks its own setting, then they
    // compare them, and rank 0 ends the job on a bad or unequal one.
    long long mine = 0, least = 0, most = 0;
    try {
      mine = static_cast<long long>(message_bytes());
    } catch (const Error& e) {
      std::fprintf(stderr, "sh: rank %d: %s\n", world_rank, e.what());
    }
    MPI_Allreduce(&mine, &least, 1, MPI_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&mine, &most, 1, MPI_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
    if (world_rank == 0 && least > 0 && least != most)
      std::fprintf(stderr,
                   "sh: mpi backend: SH_MPI_MESSAGE_BYTES differs between ranks (%lld on some, %lld on others): every "
                   "rank must cut messages alike\n",
                   least, most);
    if (world_rank == 0 && (least == 0 || least != most)) MPI_Abort(MPI_COMM_WORLD, 2);
    if (world_rank == 0) {
      std::atexit(finish_at_exit);
      if (world_size == 1)
        std::fprintf(stderr, "sh: mpi backend: running as one rank (start the program with mpirun -np N for more)\n");
    }
  });
  return world_rank;
}

void check_thread(const std::string& program) {
  ensure_started();
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized)
    throw Error("program '" + program + "': mpi backend: MPI was finalized (MPI_Finalize): the mpi backend runs "
                "nothing after it");
  if (std::this_thread::get_id() != mpi_thread)
    throw Error("program '" + program + "': mpi backend: compiles and runs only on the thread that started MPI "
                "(it is started for one thread's calls); this is another thread");
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
