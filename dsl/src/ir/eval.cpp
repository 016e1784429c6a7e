#include "sh/ir/eval.hpp"

#include <cmath>
#include <limits>

namespace sh::ir {
namespace {

bool truthy(double v) { return v > 0; }

double int_op(Op op, double da, double db) {
  // Wrapping two's-complement arithmetic, as every target computes it.
  auto a = static_cast<std::int64_t>(da), b = static_cast<std::int64_t>(db);
  auto wrap = [](std::int64_t v) { return static_cast<double>(static_cast<std::int32_t>(static_cast<std::uint32_t>(v))); };
  switch (op) {
    case Op::Add: return wrap(a + b);
    case Op::Sub: return wrap(a - b);
    case Op::Mul: return wrap(static_cast<std::int64_t>(static_cast<std::uint64_t>(a) * static_cast<std::uint64_t>(b)));
    // Division by zero gives 0 rather than trapping; INT_MIN / -1 wraps.
    case Op::Div: return b == 0 ? 0 : wrap(a / b);
    case Op::Mod: return b == 0 ? 0 : wrap(a % b);
    case Op::Neg: return wrap(-a);
    case Op::Abs: return wrap(a < 0 ? -a : a);
    case Op::Sign: return a > 0 ? 1 : a < 0 ? -1 : 0;
    case Op::Min: return static_cast<double>(a < b ? a : b);
    case Op::Max: return static_cast<double>(a > b ? a : b);
    case Op::Floor: case Op::Ceil: case Op::Round: return da;
    default: return std::numeric_limits<double>::quiet_NaN();
  }
}

double cast(Scalar from, Scalar to, double v) {
  switch (to) {
    case Scalar::Bool: return truthy(v) ? 1 : 0;
    case Scalar::I32: return is_float(from) ? to_int32(v) : v;
    case Scalar::F32: case Scalar::F64: return v;
  }
  return v;
}

double float_op(Op op, double a, double b, double c) {
  switch (op) {
    case Op::Add: return a + b;
    case Op::Sub: return a - b;
    case Op::Mul: return a * b;
    case Op::Div: return a / b;
    case Op::Mod: return std::fmod(a, b);
    case Op::Neg: return -a;
    case Op::Min: return std::fmin(a, b);
    case Op::Max: return std::fmax(a, b);
    case Op::Abs: return std::fabs(a);
    case Op::Sign: return a > 0 ? 1.0 : a < 0 ? -1.0 : a;  // keeps ±0 and NaN
    case Op::Floor: return std::floor(a);
    case Op::Ceil: return std::ceil(a);
    case Op::Round: return std::round(a);
    case Op::Sqrt: return std::sqrt(a);
    case Op::Rcp: return 1.0 / a;
    case Op::Pow: return std::pow(a, b);
    case Op::Exp: return std::exp(a);
    case Op::Exp2: return std::exp2(a);
    case Op::Log: return std::log(a);
    case Op::Log2: return std::log2(a);
    case Op::Sin: return std::sin(a);
    case Op::Cos: return std::cos(a);
    case Op::Tan: return std::tan(a);
    case Op::Asin: return std::asin(a);
    case Op::Acos: return std::acos(a);
    case Op::Atan: return std::atan(a);
    case Op::Atan2: return std::atan2(a, b);
    default: (void)c; return std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace

double hold(Scalar s, Precision p, double v) {
  if (s == Scalar::F32 && p == Precision::F32) return static_cast<double>(static_cast<float>(v));
  return v;
}

std::int32_t to_int32(double v) {
  if (std::isnan(v)) return 0;
  if (v >= 2147483647.0) return std::numeric_limits<std::int32_t>::max();
  if (v <= -2147483648.0) return std::numeric_limits<std::int32_t>::min();
  return static_cast<std::int32_t>(v);
}

double eval(Op op, Scalar operand, Scalar result, Precision p, double a, double b, double c) {
  switch (op) {
    case Op::Mov: return a;
    case Op::Cast: return hold(result, p, cast(operand, result, a));
    case Op::Lt: return a < b;
    case Op::Le: return a <= b;
    case Op::Gt: return a > b;
    case Op::Ge: return a >= b;
    case Op::Eq: return a == b;
    case Op::Ne: return a != b;
    case Op::And: return truthy(a) && truthy(b);
    case Op::Or: return truthy(a) || truthy(b);
    case Op::Not: return !truthy(a);
    case Op::Cond: return truthy(a) ? b : c;
    default: break;
  }
  if (operand == Scalar::I32 || operand == Scalar::Bool) return int_op(op, a, b);
  // Two roundings, as every backend computes it: the root, then its
  // reciprocal (so that normalize gives the same bits everywhere).
  if (op == Op::Rsqrt) return hold(result, p, 1.0 / hold(result, p, std::sqrt(a)));
  return hold(result, p, float_op(op, a, b, c));
}

}  // namespace sh::ir
