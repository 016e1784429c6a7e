#pragma once
// The meaning of every operation on one component: the reference that the
// interpreter runs, that constant folding and host-side uniform arithmetic
// use, and that every backend must reproduce (the conformance suite checks
// it).  Values travel as doubles; an int32 or bool is held exactly.
#include <cstdint>

#include "sh/ir/op.hpp"
#include "sh/ir/type.hpp"

namespace sh::ir {

// f32: floats are IEEE binary32, each operation correctly rounded from the
// exact result where C++ gives it; f64: every float is computed as double.
enum class Precision : std::uint8_t { F32, F64 };

// The value a register of scalar kind `s` holds for `v` under precision `p`.
double hold(Scalar s, Precision p, double v);

// float -> int32: NaN gives 0, out-of-range values saturate, others truncate.
std::int32_t to_int32(double v);

// op(a, b, c) for operands of scalar kind `operand` giving kind `result`
// (they differ only for Cast).  Table reads are not evaluated here.
double eval(Op op, Scalar operand, Scalar result, Precision p, double a, double b = 0, double c = 0);

}  // namespace sh::ir
