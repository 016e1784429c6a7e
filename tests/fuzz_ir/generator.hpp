#pragma once
// Random, well-typed IR programs with the data they run on.  Every program
// passes ir::verify, terminates (each loop counts up to a constant), keeps
// inexact values away from anything that needs an exact one
// (exactness.hpp), and initialises every register before the body reads it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

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
// whose coordinates must already be in range: only legalisation writes it).
std::vector<sh::ir::Op> generated_ops();

}  // namespace fuzz_ir
