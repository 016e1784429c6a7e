#pragma once
// One program run on every linked backend, in each of the backend's
// variants (Backend::variants(): the cpu backend's scalar code and SIMD
// widths, ...) and math modes, each measured against the reference
// interpreter computing in f64: compile and run time, and per output the
// largest difference.
//
//   sh::Comparison c = sh::compare(saxpy, {xs, ys});
//   std::cout << c;   // one row per backend, variant and math mode
//
// A backend that throws (compiling or running) becomes its row's error; the
// other rows still run.  A program's accumulators are compared as its
// outputs are (each run starts from the sums they held when compare was
// called, and those sums are theirs again when it returns).  A NaN where
// the reference has a number, or a number where it has NaN, is a
// difference: it makes the largest difference infinite and is counted on
// its own.
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "sh/backend.hpp"

namespace sh {

struct CompareOptions {
  std::vector<std::string> backends;  // empty: every backend in this process (sh::backend_names())
  std::vector<MathMode> math = {MathMode::Precise, MathMode::Fast};
  Precision precision = Precision::F32;  // of every row; the reference is interp in f64 regardless
  Options options;                       // the rest (threads, loop cap, backends' own settings)
  int runs = 3;                          // runs per row; the fastest one's time counts (the first pays for warm-up)
  std::size_t elements = 0;              // stream length of a program without inputs
};

// One output of one row against the reference, over every component of
// every element.
struct OutputDifference {
  std::string name;  // the output's name, else "output K"; an accumulator's "accumulator 'NAME'" (or K)
  ir::Type type;
  double max_abs = 0;   // largest |value - reference|; infinite where NaN meets a number
  double max_ulps = 0;  // the same in units in the last place of the output's type (integers: the difference)
  std::size_t differing = 0;       // components that differ from the reference (NaN equals NaN)
  std::size_t nan_mismatches = 0;  // of those, where one side is NaN and the other is not
  std::size_t worst_element = 0;   // the element of the largest difference in ULPs (max_ulps')
};

struct CompareRow {
  std::string backend;
  std::string variant;  // empty where the backend has a single one
  MathMode math = MathMode::Precise;
  Precision precision = Precision::F32;
  std::string error;      // what the backend threw; then nothing else is measured
  bool compiled = false;  // false: the kernel came from the process's cache (compile_ms 0)
  bool from_disk = false; // compiled from the disk cache's machine code (RunStats::from_disk)
  double compile_ms = 0, run_ms = 0;
  std::vector<OutputDifference> outputs;  // empty where this row or the reference failed
  std::vector<std::string> notes;         // the backend's own figures (RunStats::details)

  std::string label() const;  // "cpu:w8", "interp"
  bool failed() const { return !error.empty(); }
  double max_ulps() const;  // over the outputs
};

struct Comparison {
  std::string program;
  std::size_t elements = 0;
  Precision precision = Precision::F32;  // of every row
  CompareRow reference;  // interp in f64
  std::vector<CompareRow> rows;

  // The row of a backend, variant and math mode; null where none ran.
  const CompareRow* find(const std::string& backend, const std::string& variant, MathMode math) const;
};

// Runs `program` over `inputs` (channels, as for run()) on every backend
// `options` names, in each variant and math mode; uniforms and tables as
// they are set now.  Throws only for what is wrong with the call itself
// (inputs that do not fit the program, runs < 1).
Comparison compare(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
                   const CompareOptions& options = {});

// The table as a user reads it: a header line, then per row the label, math
// mode, compile and run milliseconds, and per output its largest difference
// (absolute and in ULPs), how many components differ (NaN mismatches among
// them) and where the worst one is.
std::string to_string(const Comparison& c);
std::ostream& operator<<(std::ostream& os, const Comparison& c);

}  // namespace sh
