#include "sh/ir/eval.hpp"

#include <cmath>
#include <limits>

#include "sh/error.hpp"

namespace sh::ir {
namespace {

bool truthy(double v) { return v > 0; }

// Integers travel as doubles that hold an int32 exactly; arithmetic on them
// wraps in two's complement, as every target computes it.
std::int64_t whole(double v) { return static_cast<std::int64_t>(v); }
double wrap(std::int64_t v) { return static_cast<double>(static_cast<std::int32_t>(static_cast<std::uint32_t>(v))); }
double wrapped_product(double a, double b) {
  return wrap(static_cast<std::int64_t>(static_cast<std::uint64_t>(whole(a)) * static_cast<std::uint64_t>(whole(b))));
}

// Division and remainder by zero give 0; INT_MIN / -1 wraps to INT_MIN and
// INT_MIN % -1 is 0.
double int_divide(double a, double b) { return whole(b) == 0 ? 0 : wrap(whole(a) / whole(b)); }

// The remainder takes the sign of the divisor, as Sh's and GLSL's mod
// (a - b floor(a / b)): C's remainder (the sign of a), moved by one b where
// the signs differ.
double int_remainder(double a, double b) {
  if (whole(b) == 0) return 0;
  std::int64_t r = whole(a) % whole(b);
  return static_cast<double>(r != 0 && (r < 0) != (whole(b) < 0) ? r + whole(b) : r);
}

// The float remainder with the divisor's sign: the exact a - b floor(a / b),
// rounded once.  fmod is exact, and so is r + b but for that one rounding (a
// tiny r of the other sign rounds to b itself: mod(-1e-30, 1) is 1); Sh's
// a - b * floor(a / b) rounds three times.  A zero keeps a's sign, as fmod
// gives it.  For f32 operands r + b in double is then rounded to f32, which
// gives f32's own r + b: where r + b is inexact in double, |r| < 2^-28 |b|,
// too close to b for the sum to lie near a midpoint of f32.
double float_remainder(double a, double b) {
  double r = std::fmod(a, b);
  return r != 0 && (r < 0) != (b < 0) ? r + b : r;
}

// Halves toward +Inf, as Sh's floor(a + 0.5), but exact for every float:
// a - floor(a) is exact wherever it lies near 0.5 (it rounds only for tiny
// negative a, to near 1), where a + 0.5 rounds (0.49999997f + 0.5f is 1,
// and 8388609.0f + 0.5f is 8388610).
double round_half_up(double a) {
  double f = std::floor(a);
  return a - f >= 0.5 ? f + 1 : f;
}

// min and max of a NaN (quiet or signaling) and a number give the number,
// as LLVM's minnum and OpenCL's fmin do; C's fmin quiets a signaling one.
double either_not_nan(double a, double b, double (*f)(double, double)) {
  return std::isnan(a) ? b : std::isnan(b) ? a : f(a, b);
}

// A shift count outside [0, 31] shifts every bit out.
bool shifts_out(double count) { return count < 0 || count > 31; }
double shift_left(double a, double count) {
  return shifts_out(count) ? 0 : wrap(static_cast<std::int64_t>(static_cast<std::uint32_t>(whole(a)) << whole(count)));
}
double shift_right(double a, double count) { return static_cast<double>(whole(a) >> (shifts_out(count) ? 31 : whole(count))); }
double bits(double a, double b, std::int64_t (*f)(std::int64_t, std::int64_t)) { return wrap(f(whole(a), whole(b))); }

double cast(Scalar from, Scalar to, double v) {
  switch (to) {
    case Scalar::Bool: return truthy(v) ? 1 : 0;
    case Scalar::I32: return is_float(from) ? to_int32(v) : v;
    case Scalar::F32: case Scalar::F64: return v;
  }
  return v;
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

// Float-only operations (the table's Float domain) never see an integer:
// the verifier and the recorder refuse it.
double eval(Op op, Scalar operand, Scalar result, Precision p, double a, double b, double c) {
  const bool integer = !is_float(operand);
  auto f = [&](double v) { return hold(result, p, v); };
  switch (op) {
    case Op::Mov: return a;
    case Op::Cast: return f(cast(operand, result, a));
    case Op::Add: return integer ? wrap(whole(a) + whole(b)) : f(a + b);
    case Op::Sub: return integer ? wrap(whole(a) - whole(b)) : f(a - b);
    case Op::Mul: return integer ? wrapped_product(a, b) : f(a * b);
    case Op::Div: return integer ? int_divide(a, b) : f(a / b);
    case Op::Mod: return integer ? int_remainder(a, b) : f(float_remainder(a, b));
    case Op::Neg: return integer ? wrap(-whole(a)) : -a;
    case Op::Min: return integer ? std::min(a, b) : either_not_nan(a, b, std::fmin);
    case Op::Max: return integer ? std::max(a, b) : either_not_nan(a, b, std::fmax);
    case Op::Abs: return integer ? wrap(std::abs(whole(a))) : std::fabs(a);
    case Op::Sign: return a > 0 ? 1.0 : a < 0 ? -1.0 : a;  // keeps ±0 and NaN
    case Op::Floor: return std::floor(a);
    case Op::Ceil: return std::ceil(a);
    case Op::Round: return round_half_up(a);
    case Op::Sqrt: return f(std::sqrt(a));
    // Two roundings, as every backend computes it: the root, then its
    // reciprocal (so that normalize gives the same bits everywhere).
    case Op::Rsqrt: return f(1.0 / f(std::sqrt(a)));
    case Op::Rcp: return f(1.0 / a);
    case Op::Pow: return f(std::pow(a, b));
    case Op::Exp: return f(std::exp(a));
    case Op::Exp2: return f(std::exp2(a));
    case Op::Log: return f(std::log(a));
    case Op::Log2: return f(std::log2(a));
    case Op::Sin: return f(std::sin(a));
    case Op::Cos: return f(std::cos(a));
    case Op::Tan: return f(std::tan(a));
    case Op::Asin: return f(std::asin(a));
    case Op::Acos: return f(std::acos(a));
    case Op::Atan: return f(std::atan(a));
    case Op::Atan2: return f(std::atan2(a, b));
    case Op::Sinh: return f(std::sinh(a));
    case Op::Cosh: return f(std::cosh(a));
    case Op::Tanh: return f(std::tanh(a));
    case Op::Asinh: return f(std::asinh(a));
    case Op::Acosh: return f(std::acosh(a));
    case Op::Atanh: return f(std::atanh(a));
    case Op::Exp10: return f(std::pow(10.0, a));  // <cmath> has no exp10
    case Op::Log10: return f(std::log10(a));
    case Op::Cbrt: return f(std::cbrt(a));
    case Op::BitAnd: return bits(a, b, [](std::int64_t x, std::int64_t y) { return x & y; });
    case Op::BitOr: return bits(a, b, [](std::int64_t x, std::int64_t y) { return x | y; });
    case Op::BitXor: return bits(a, b, [](std::int64_t x, std::int64_t y) { return x ^ y; });
    case Op::BitNot: return wrap(~whole(a));
    case Op::Shl: return shift_left(a, b);
    case Op::Shr: return shift_right(a, b);
    case Op::Lt: return a < b;
    case Op::Le: return a <= b;
    case Op::Gt: return a > b;
    case Op::Ge: return a >= b;
    case Op::Eq: return a == b;
    case Op::Ne: return a != b;
    case Op::And: return truthy(a) && truthy(b);
    case Op::Or: return truthy(a) || truthy(b);
    case Op::Not: return !truthy(a);
    case Op::AnyLane: return truthy(a);  // the element alone: the group of one
    case Op::Cond: return truthy(a) ? b : c;
    case Op::Fetch: case Op::Sample: case Op::Extent: case Op::Load: case Op::Position: case Op::Element: case Op::Store: case Op::Fill:
      break;
  }
  throw Error(std::string("ir::eval: ") + op_name(op) + " reads memory or the launch domain; only a backend evaluates it");
}

}  // namespace sh::ir
