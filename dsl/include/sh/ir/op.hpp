#pragma once
// The operations an assignment can perform, generated from ops.def (the one
// table of them).  All work component by component (an operand of width 1
// is broadcast); horizontal and compound library functions (dot, cross,
// normalize, lerp, ...) are expanded into these while recording, so every
// backend evaluates them in the same order.
#include <cstdint>

#include "sh/ir/type.hpp"

namespace sh::ir {

enum class Op : std::uint8_t {
#define SH_OP(Enum, ...) Enum,
#include "sh/ir/ops.def"
#undef SH_OP
};

inline constexpr int kOpCount = 0
#define SH_OP(...) +1
#include "sh/ir/ops.def"
#undef SH_OP
    ;

// The operand scalars an operation takes.
enum class Domain : std::uint8_t { Any, Numeric, Float, Integer };
// How the result's scalar follows from the operands': the operands', any
// (Cast), the table's element, i32 per table dimension, i32 per
// dimension of the launch domain, or the local array's element.
enum class ResultRule : std::uint8_t { SameAsOperands, Converted, TableElement, TableShape, ElementPosition, ArrayElement };
// Classes the cost analysis counts by.
enum class OpClass : std::uint8_t { Move, Add, Mul, Div, Negate, Compare, Transcendental, TableRead };

struct OpInfo {
  const char* name;
  int arity;
  Domain domain;
  ResultRule result;
  bool folds;
  OpClass cls;
  std::uint32_t ulp_precise, ulp_fast;
};

namespace detail {
inline constexpr OpInfo kOpTable[] = {
#define SH_OP(Enum, name, arity, domain, result, folds, cls, ulp, ulp_fast) \
  {name, arity, Domain::domain, ResultRule::result, folds, OpClass::cls, ulp, ulp_fast},
#include "sh/ir/ops.def"
#undef SH_OP
};
}  // namespace detail

constexpr Op op_at(int i) { return static_cast<Op>(i); }
constexpr const OpInfo& op_info(Op op) { return detail::kOpTable[static_cast<int>(op)]; }
constexpr const char* op_name(Op op) { return op_info(op).name; }
constexpr int op_arity(Op op) { return op_info(op).arity; }
// Legal IR (what backends are given) holds no fetch or sample.
constexpr bool is_legal(Op op) { return op != Op::Fetch && op != Op::Sample; }
// Reads a table's elements or its shape: names a table, and its result
// follows from the table's declaration.
constexpr bool is_table_read(Op op) {
  return op_info(op).result == ResultRule::TableElement || op_info(op).result == ResultRule::TableShape;
}
// Reads or writes a local array (ir::VarKind::Array).
constexpr bool is_array_access(Op op) { return op_info(op).result == ResultRule::ArrayElement; }

// Its result for one element depends on the others run with it
// (any_lane): the conformance suite and the fuzzer test it by its bounds
// (at least the element's own answer, at most the answer over
// kLaneGroupLimit consecutive elements), not against the reference.
constexpr bool is_lane_group(Op op) { return op == Op::AnyLane; }
inline constexpr int kLaneGroupLimit = 64;

constexpr bool accepts(Domain d, Scalar s) {
  switch (d) {
    case Domain::Any: return true;
    case Domain::Numeric: return s != Scalar::Bool;
    case Domain::Float: return s == Scalar::F32 || s == Scalar::F64;
    case Domain::Integer: return s == Scalar::I32;
  }
  return false;
}
constexpr bool accepts(Op op, Scalar s) { return accepts(op_info(op).domain, s); }
const char* domain_name(Domain d);  // "float", "numeric (f32, f64, i32)", ...

// The operation named `name` in the table, if any.
bool op_named(const char* name, Op& out);

}  // namespace sh::ir
