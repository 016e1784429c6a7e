#pragma once
// How a disagreement is shown: the program, the data one element read, and
// the values each side wrote.
#include <string>

#include "generator.hpp"
#include "runner.hpp"

namespace fuzz_ir {

// The inputs of stream element `element`, the uniforms and the tables.
std::string describe_data(const Case& c, std::size_t element);

std::string describe(const Mismatch& m, sh::ir::Scalar s, const std::string& mode);

// The operations of the body after the prologue (and "if", "loop",
// "break", "continue", "scatter", "prefetch" where they occur), sorted, joined by '+':
// what a minimised disagreement is counted under.
std::string operations_used(const Case& c);

// The scalar an output or accumulator slot holds (Mismatch::slot).
sh::ir::Scalar slot_scalar(const Case& c, int slot);

}  // namespace fuzz_ir
