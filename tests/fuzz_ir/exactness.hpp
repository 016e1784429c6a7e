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

// Whether `op` on operands of scalar `s` gives, from exact operands, a
// result every backend must reproduce (up to NaN payloads and the sign of
// zero, which compare equal): a precise bound of 0, and a result the
// contract defines fully.  min and max of floats leave open the sign of a
// zero result (min(+0, -0) is +0 on cpu and mpi, -0 on interp and
// opencl), and 1 / that is +inf or -inf; the contract leaves it open
// (docs/operations.md), so they count as inexact with a bound of 0.
bool exact_operation(sh::ir::Op op, sh::ir::Scalar s);

// How far a component may stray: `ulps`, and whether it is exact (may
// reach a condition, a comparison, a conversion or a coordinate).
struct Bound {
  std::uint32_t ulps = 0;
  bool exact = true;
};
using Tolerance = std::array<Bound, 4>;

// Per variable, per component: the ULPs by which a backend's value may
// differ from the interpreter's, over every path.
std::vector<Tolerance> tolerances(const sh::ir::Program& p);

// The first place where an inexact value reaches an operand that needs an
// exact one (a condition, a coordinate, an operation that is not
// error-preserving), printed; empty if there is none.
std::string inexact_leak(const sh::ir::Program& p);

}  // namespace fuzz_ir
