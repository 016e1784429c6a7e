// Helper for the killed-rank test: every rank writes its PID to
// DIR/rank<N>.pid, then rank 0 runs a long job on the mpi backend, and
// writes DIR/running once its first run has come back (every rank is then
// serving), while the test script kills a serving rank.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <sh/mpi.hpp>
#include <sh/sh.hpp>

int main(int argc, char** argv) {
  using namespace sh;
  if (argc < 2) return 2;
  std::ofstream(std::string(argv[1]) + "/rank" + std::to_string(mpi::rank()) + ".pid") << getpid() << "\n";
  mpi::start();  // serving ranks stay in here
  Program p = SH_BEGIN_PROGRAM("long") {
    InputAttrib1f x;
    OutputAttrib1f y;
    Attrib1f acc = 0.0f;
    SH_FOR(Attrib1f i = 0.0f, i < 2000.0f, i += 1.0f) { acc += sin(x * i); } SH_ENDFOR;
    y = acc;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>(200000, 0.5f)), out;
  run(p, {in}, {out}, backend("mpi"));
  std::ofstream(std::string(argv[1]) + "/running") << "1\n";
  for (int round = 1; round < 600; ++round) run(p, {in}, {out}, backend("mpi"));
  std::printf("finished without noticing\n");
  return 0;
}
