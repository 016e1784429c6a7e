#pragma once
// The operations an assignment can perform.  All of them work component by
// component (an operand of width 1 is broadcast); horizontal and compound
// library functions (dot, cross, normalize, lerp, ...) are expanded into
// these while recording, so every backend evaluates them in the same order.
#include <cstdint>

namespace sh::ir {

enum class Op : std::uint8_t {
  // data movement and conversion
  Mov, Cast,
  // arithmetic
  Add, Sub, Mul, Div, Mod, Neg,
  Min, Max, Abs, Sign, Floor, Ceil, Round,
  // square roots and transcendentals
  Sqrt, Rsqrt, Rcp, Pow, Exp, Exp2, Log, Log2,
  Sin, Cos, Tan, Asin, Acos, Atan, Atan2,
  // comparisons and masks: 0/1 in the operand's type, true where > 0
  Lt, Le, Gt, Ge, Eq, Ne, And, Or, Not, Cond,
  // table reads: integer element coordinates, or coordinates in [0, 1]
  Fetch, Sample,
};

// Classes the cost analysis counts by.
enum class OpClass : std::uint8_t { Move, Add, Mul, Div, Negate, Compare, Transcendental, TableRead };

struct OpInfo {
  const char* name;
  int arity;
  OpClass cls;
};

const OpInfo& op_info(Op op);
inline const char* op_name(Op op) { return op_info(op).name; }
inline int op_arity(Op op) { return op_info(op).arity; }
bool is_comparison(Op op);  // result is a 0/1 mask
bool is_table_read(Op op);

}  // namespace sh::ir
