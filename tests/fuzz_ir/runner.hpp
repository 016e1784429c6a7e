#pragma once
// Runs a generated case on one backend mode and compares what it wrote with
// the interpreter's results under the ULP contract.
#include <string>
#include <vector>

#include <sh/backend.hpp>

#include "exactness.hpp"
#include "generator.hpp"

namespace fuzz_ir {

struct Mode {
  std::string backend;
  sh::Backend::Variant variant;
  sh::Precision precision = sh::Precision::F32;
  std::string name() const;  // "cpu_w8_f64"
};

// Every variant of each named backend (all registered ones when `only` is
// empty), at f32 and f64 precision, precise math.
std::vector<Mode> all_modes(const std::vector<std::string>& only);

// What a run left: every output channel and accumulator, as doubles; or
// the error it threw.
struct Result {
  std::string error;
  std::vector<Data> outputs;  // parallel to program.outputs
  std::vector<Data> sums;     // parallel to program.tables (empty for read-only ones)
};

// Runs the program as it is (optimize false: the reference) or through the
// optimiser, then legalised, as sh::run does.  The kernel is compiled here
// and dropped after the run: sh::run's kernel cache would keep every one of
// the 10^5 kernels of a long run.  Loops are capped at kLoopCap iterations.
Result run(const Case& c, const Mode& m, bool optimize);
inline constexpr std::uint64_t kLoopCap = 1000;

// What `m` is given (the optimised, legalised IR) and what it makes of it
// (Kernel::listing), for --listing.
std::string listing(const Case& c, const Mode& m);

struct Mismatch {
  std::string where;  // "out1[7].y", "acc2[3].x", "error"
  std::string name;   // the output's or accumulator's name
  int slot = -1;      // output index, or program.outputs.size() + table index
  bool stream = true; // element is a stream element (else an accumulator's)
  std::size_t element = 0;
  int component = 0;
  double expected = 0, got = 0;
  std::uint32_t tolerance = 0;
  std::string detail;  // an error's message
};

// Where `got` differs from `reference` beyond each component's tolerance.
std::vector<Mismatch> compare(const Case& c, const Result& reference, const Result& got);

// Distance in units in the last place of `s` (f32 or f64); NaN matches any
// NaN, an infinity only itself, +0 matches -0.
std::uint64_t ulp_distance(sh::ir::Scalar s, double a, double b);

}  // namespace fuzz_ir
