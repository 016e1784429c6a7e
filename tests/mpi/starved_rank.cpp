// Helper for the starved-rank test: rank 0 runs a kernel that reads a
// table of 256 MiB, which a serving rank started with too little memory
// cannot hold.  That rank must say so and end the job.
#include <cstdio>
#include <vector>

#include <sh/mpi.hpp>
#include <sh/sh.hpp>

int main() {
  using namespace sh;
  mpi::start();  // serving ranks stay in here
  Table1D<Attrib1f> big(std::size_t{1} << 26);
  big.assign(std::vector<float>(std::size_t{1} << 26, 1.0f));
  Program p = SH_BEGIN_PROGRAM("reads_big") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = big[i];
  } SH_END;
  Channel<Attrib1i> in(std::vector<std::int32_t>(1000, 7));
  Channel<Attrib1f> out;
  run(p, {in}, {out}, backend("mpi"));
  std::printf("finished: the starved rank held the table\n");
  return 0;
}
