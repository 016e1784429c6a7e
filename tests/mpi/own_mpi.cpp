// Helper for the tests of a program that starts and ends MPI itself; it
// exits 0 where the test passes.
//   own_mpi finalize: MPI_Init, runs on the mpi backend, MPI_Finalize; the
//     serving ranks must be let go at MPI_Finalize (the job hung there).
//   own_mpi again: the same, then a run after MPI_Finalize, which must be
//     an sh::Error (MPI aborted the process).
//   own_mpi finalized: MPI_Init, MPI_Finalize, then the mpi backend's first
//     use, which must be an sh::Error too.
#include <mpi.h>

#include <cstdio>
#include <string>
#include <vector>

#include <sh/mpi.hpp>
#include <sh/sh.hpp>

namespace {

bool doubled_on_mpi() {
  using namespace sh;
  Program p = SH_BEGIN_PROGRAM("doubled") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>(1000, 1.5f)), out;
  run(p, {in}, {out}, backend("mpi"));
  return out.values() == std::vector<float>(1000, 3.0f);
}

// 0 where a run after MPI_Finalize is refused with an sh::Error.
int refused_after_finalize() {
  try {
    doubled_on_mpi();
  } catch (const sh::Error& e) {
    std::printf("refused: %s\n", e.what());
    return 0;
  }
  std::printf("FAIL: the mpi backend ran after MPI_Finalize\n");
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "";
  MPI_Init(&argc, &argv);
  if (mode == "finalize" || mode == "again") {
    sh::mpi::start();  // serving ranks stay in here
    bool right = doubled_on_mpi();
    MPI_Finalize();
    if (!right) {
      std::printf("FAIL: wrong results\n");
      return 1;
    }
    return mode == "again" ? refused_after_finalize() : 0;
  }
  if (mode == "finalized") {
    MPI_Finalize();
    return refused_after_finalize();
  }
  std::fprintf(stderr, "usage: own_mpi finalize|again|finalized\n");
  return 2;
}
