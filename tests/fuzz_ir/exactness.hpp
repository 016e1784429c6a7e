#pragma once
// Which values of a program every backend must compute bit for bit, and how
// far the others may stray.
//
// Why the fuzzer tracks this: a backend may differ from the interpreter by an
// operation's ULP bound (ir::op_info(op).ulp_precise).  A value one ulp off
// that reaches a comparison, a branch, a loop condition, floor/ceil/round, a
// cast to an integer or a table coordinate can change the result by any
// amount (another branch, another element), and that is no bug.  So the
// generator keeps two classes of registers.  Exact registers are written
// only by operations whose precise bound is 0 from exact operands: every
// backend must give the interpreter's bits (NaN equal to any NaN, ±0 equal).
// Inexact registers (and the outputs) take an inexact operation's result,
// computed from exact operands, and are read only by operations that pass
// an error through without growing it in ULPs (mov, neg, abs, min, max and
// cond's value operands), into other inexact registers and the outputs.
// An output component may then differ by the largest bound of any inexact
// operation whose result can reach it.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <sh/ir/program.hpp>

namespace fuzz_ir {

// Operand `arg` of `op` passes an error through unchanged in ULPs (the
// result is that operand, its negation or magnitude, or a choice between
// operands made by an exact condition).
bool passes_error_through(sh::ir::Op op, int arg);

using Tolerance = std::array<std::uint32_t, 4>;

// Per variable, per component: the ULPs by which a backend's value may
// differ from the interpreter's (0 for exact values), over every path.
std::vector<Tolerance> tolerances(const sh::ir::Program& p);

// The first place where an inexact value reaches an operand that needs an
// exact one (a condition, a coordinate, an operation that is not
// error-preserving), printed; empty if there is none.
std::string inexact_leak(const sh::ir::Program& p);

}  // namespace fuzz_ir
