#pragma once
// The counts a fuzzing run reports, which a worker process sends its
// supervisor after every program (one line) and the supervisor adds up.
#include <cstddef>
#include <map>
#include <string>

namespace fuzz_ir {

struct Tally {
  std::size_t programs = 0, runs = 0, disagreements = 0, failing_programs = 0, invalid = 0;
  std::size_t accumulator_only = 0;  // disagreements in accumulator sums alone
  std::size_t crashes = 0, hangs = 0;  // counted among the disagreements too
  std::map<std::string, std::size_t> by_mode, by_backend, by_operations;

  Tally& operator+=(const Tally& more);
  // One line without spaces inside names ("tally 3 54 0 ... m cpu_w4_f32 1 ...").
  std::string line() const;
  static Tally parse(const std::string& line);  // a line() back; garbage gives zeros
  bool clean() const { return disagreements == 0 && invalid == 0; }
};

// The summary line (CTest matches it) and the counts by backend, mode and
// minimised operations, on stdout.
void print_summary(const Tally& t, unsigned long long seed, double seconds);

}  // namespace fuzz_ir
