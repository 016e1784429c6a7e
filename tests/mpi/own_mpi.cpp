// Helper for the tests of a program that starts and ends MPI itself.
//   own_mpi finalize: MPI_Init, runs on the mpi backend, MPI_Finalize; the
//     serving ranks must be let go at MPI_Finalize (the job hung there).
//   own_mpi finalized: MPI_Init, MPI_Finalize, then the mpi backend's first
//     use, which must be an sh::Error (MPI aborted the process).
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

}  // namespace

int main(int argc, char** argv) {
  std::string mode = argc > 1 ? argv[1] : "";
  MPI_Init(&argc, &argv);
  if (mode == "finalize") {
    sh::mpi::start();  // serving ranks stay in here
    bool right = doubled_on_mpi();
    MPI_Finalize();
    std::printf(right ? "PASS: ran on the mpi backend and ended MPI itself\n" : "FAIL: wrong results\n");
    return right ? 0 : 1;
  }
  if (mode == "finalized") {
    MPI_Finalize();
    try {
      doubled_on_mpi();
    } catch (const sh::Error& e) {
      std::printf("PASS: %s\n", e.what());
      return 0;
    }
    std::printf("FAIL: the mpi backend ran after MPI_Finalize\n");
    return 1;
  }
  std::fprintf(stderr, "usage: own_mpi finalize|finalized\n");
  return 2;
}
