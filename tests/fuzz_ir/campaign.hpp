#pragma once
// A fuzzing run inside one process: programs generated in turn, run on the
// backend modes, disagreements printed (and the first ones minimised).
// fuzz_ir.cpp runs it in a worker process that it restarts after a crash.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "generator.hpp"
#include "tally.hpp"

namespace fuzz_ir {

struct Options {
  std::size_t programs = 300;
  std::uint64_t seed = 1;
  std::vector<std::string> backends;   // empty: every backend registered
  int minimize = 0;                    // disagreeing programs to minimise
  bool listing = false;                // with each minimised one, what the modes compiled
  std::size_t modes_per_program = 0;   // 0: all
  std::vector<std::uint64_t> replay;   // these programs instead of --programs
  GeneratorOptions generator;
  std::size_t jobs = 1;                // workers at once
  // A worker's programs: [start, end) of program_seeds() (end 0: to the last).
  std::size_t start = 0, end = 0;
  bool worker = false;
};

// The programs' seeds, in order.
std::vector<std::uint64_t> program_seeds(const Options& o);
std::string replay_command(std::uint64_t seed, const GeneratorOptions& options);

// Runs programs [o.start, o.end), printing every disagreement on stdout.
// Tells `control` (when not null), one line each, "run K MODE" before each
// backend runs program K and "done K <Tally::line()>" with the counts so
// far after it; then nothing is lost when a backend takes the process down.
Tally run_campaign(const Options& o, std::FILE* control);

}  // namespace fuzz_ir
