#pragma once
// Random, well-typed IR programs with the data they run on.  Every program
// passes ir::verify, terminates (each loop counts up to a constant of at
// most 4, in a register nothing else writes), and initialises every
// register before the body reads it.
//
// Comparisons stay sound: a backend may differ from the interpreter by an
// operation's ULP bound, and a value one ulp off that reaches a condition,
// a comparison, floor/ceil/round, a cast to an integer or a table
// coordinate may change the result by any amount without a bug.  So
// registers are exact (written only by operations whose precise bound is
// 0, from exact operands: every backend must agree bit for bit) or inexact
// (an inexact operation's result, read only by mov, neg, abs, min, max and
// cond's values on the way to an output, which keep an error's size);
// exactness.hpp tracks the bounds and checks that no inexact value leaks.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <sh/backend.hpp>
#include <sh/ir/program.hpp>

namespace fuzz_ir {

// count * width values, each a double holding the scalar's value exactly.
struct Data {
  sh::ir::Type type;
  std::vector<double> values;
};

struct TableData {
  std::array<int, 3> dims{1, 1, 1};
  Data data;  // an accumulator's starting sums
};

struct Case {
  std::uint64_t seed = 0;
  sh::ir::Program program;
  std::size_t count = 0;                          // stream elements
  sh::LaunchDomain domain;                        // where they lie (position())
  std::vector<Data> inputs;                       // parallel to program.inputs
  std::vector<std::array<double, 4>> uniforms;    // parallel to program.uniforms
  std::vector<TableData> tables;                  // parallel to program.tables
  int prologue = 0;  // the body's first statements: they initialise every register
};

struct GeneratorOptions {
  bool accumulators = true;  // declare accumulators and scatter-add into them
};

Case generate(std::uint64_t seed, const GeneratorOptions& options = {});

// The operations programs are drawn from: every row of the op table but
// the table reads that take more than coordinates (legal IR's `load`,
// whose coordinates must already be in range: only legalisation writes it)
// and any_lane (its answer depends on the elements run together, so the
// backends may rightly differ; conformance/lane_group.cpp tests it).
std::vector<sh::ir::Op> generated_ops();

}  // namespace fuzz_ir
