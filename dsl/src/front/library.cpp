#include "sh/library.hpp"

#include <limits>
#include <utility>


namespace sh::detail {
namespace {

Value k(const Value& like, double v) { return constant(like.scalar(), v); }

}  // namespace

Value fold(ir::Op op, const Value& v) {
  if (v.width() == 1) return copy(v);  // the result is a new value, never a view of v
  Value acc = component(v, 0);
  for (int i = 1; i < v.width(); ++i) acc = apply(op, {acc, component(v, i)});
  return acc;
}

Value dot(const Value& a, const Value& b) { return fold(ir::Op::Add, apply(ir::Op::Mul, {a, b})); }

Value cross(const Value& a, const Value& b) {
  Value l = apply(ir::Op::Mul, {swizzle(a, {1, 2, 0}), swizzle(b, {2, 0, 1})});
  Value r = apply(ir::Op::Mul, {swizzle(a, {2, 0, 1}), swizzle(b, {1, 2, 0})});
  return apply(ir::Op::Sub, {l, r});
}

// Below 1 always: a tiny negative a gives a - floor(a) = 1 once rounded
// (frac(-1e-8) would read past a repeating table's last element).  A NaN
// stays NaN.
Value frac(const Value& v) {
  double below_one = v.scalar() == ir::Scalar::F64 ? 1 - 0x1p-53 : 1 - 0x1p-24;
  Value f = apply(ir::Op::Sub, {v, apply(ir::Op::Floor, {v})});
  return cond(apply(ir::Op::Ge, {f, k(f, 1)}), k(f, below_one), f);
}

Value lerp(const Value& f, const Value& a, const Value& b) {
  Value one_minus_f = apply(ir::Op::Sub, {k(f, 1), f});
  return apply(ir::Op::Add, {apply(ir::Op::Mul, {f, a}), apply(ir::Op::Mul, {one_minus_f, b})});
}

Value cond(const Value& c, const Value& a, const Value& b) {
  return apply(ir::Op::Cond, {as_scalar(c, a.scalar()), a, b});
}

// The largest magnitude, by a compare and a choice per component: one
// machine instruction each, where the language's max (which gives the
// other operand for a NaN) takes several.  A NaN is passed over wherever
// it lies (it is never greater); it is still in v, and reaches the result
// through v / d below.
static Value largest_magnitude(const Value& v) {
  Value magnitude = apply(ir::Op::Abs, {v});
  Value acc = k(magnitude, 0);
  for (int i = 0; i < v.width(); ++i) {
    Value next = component(magnitude, i);
    acc = cond(apply(ir::Op::Gt, {next, acc}), next, acc);
  }
  return acc;
}

// The largest magnitude m, a divisor d near it, v / d, which keeps the
// squares in range, and their sum q (0 only for a zero v, NaN with v).  d
// is at most 2^125 (2^1021 in double), whose reciprocal stays clear of the
// denormals even approximated: fast math may divide through an
// approximate reciprocal and flush it to 0.
struct Scaled {
  Value m, d, s, q;
};
static Scaled scaled(const Value& v) {
  Value m = largest_magnitude(v);
  double most = v.scalar() == ir::Scalar::F64 ? 0x1p1021 : 0x1p125;
  Value d = cond(apply(ir::Op::Gt, {m, k(m, most)}), k(m, most), cond(apply(ir::Op::Gt, {m, k(m, 0)}), m, k(m, 1)));
  Value s = apply(ir::Op::Div, {v, d});
  return {m, d, s, dot(s, s)};
}

Value length(const Value& v) {
  if (v.width() == 1) return apply(ir::Op::Abs, {v});
  auto [m, d, s, q] = scaled(v);
  Value len = apply(ir::Op::Mul, {d, apply(ir::Op::Sqrt, {q})});
  double inf = std::numeric_limits<double>::infinity();
  // An infinite component: infinity, unless another is NaN (q is then NaN).
  Value infinite = cond(apply(ir::Op::Eq, {q, q}), m, q);
  return cond(apply(ir::Op::Lt, {m, k(m, inf)}), len, infinite);
}

Value normalize(const Value& v) {
  auto [m, d, s, q] = scaled(v);
  Value unit = apply(ir::Op::Mul, {s, apply(ir::Op::Rsqrt, {q})});
  return cond(apply(ir::Op::Eq, {q, k(q, 0)}), k(v, 0), unit);
}

// Sh 0.8's definitions (docs/sh-differences.md): reflect normalises the
// normal only, so the result keeps a's length.
Value reflect(const Value& a, const Value& n) {
  Value unit_n = normalize(n);
  Value twice = apply(ir::Op::Mul, {k(a, 2), dot(a, unit_n)});
  return apply(ir::Op::Sub, {apply(ir::Op::Mul, {twice, unit_n}), a});
}

// With c = v̂·n̂ and r = 1 / eta the ratio of the index left over the index
// entered: k = 1 + r²(c² - 1) and the result (r c - sqrt(k)) n̂ - r v̂, or
// zero where k < 0 (total internal reflection) or where v or n is zero (no
// direction to bend).  Sh clamps k to [0, 1].
Value refract(const Value& v, const Value& n, const Value& eta) {
  Value unit_v = normalize(v), unit_n = normalize(n);
  Value c = dot(unit_v, unit_n);
  Value r = apply(ir::Op::Rcp, {eta});
  Value one = k(c, 1);
  Value below_one = apply(ir::Op::Sub, {apply(ir::Op::Mul, {c, c}), one});
  Value kk = apply(ir::Op::Add, {one, apply(ir::Op::Mul, {apply(ir::Op::Mul, {r, r}), below_one})});
  Value root = apply(ir::Op::Sqrt, {apply(ir::Op::Min, {apply(ir::Op::Max, {kk, k(kk, 0)}), one})});
  Value along_n = apply(ir::Op::Sub, {apply(ir::Op::Mul, {r, c}), root});
  Value t = apply(ir::Op::Sub, {apply(ir::Op::Mul, {along_n, unit_n}), apply(ir::Op::Mul, {r, unit_v})});
  auto zero = [](const Value& x) { return apply(ir::Op::Eq, {largest_magnitude(x), k(x, 0)}); };
  Value none = apply(ir::Op::Or, {apply(ir::Op::Lt, {kk, k(kk, 0)}), apply(ir::Op::Or, {zero(v), zero(n)})});
  return cond(none, k(v, 0), t);
}

Value faceforward(const Value& a, const Value& b) {
  return cond(apply(ir::Op::Gt, {dot(a, b), k(b, 0)}), b, apply(ir::Op::Neg, {b}));
}

Value fillcast(const Value& v, int width) { return copy(widened(v, width)); }

Value join(const Value& a, const Value& b) {
  Value out = declare({a.scalar(), a.width() + b.width()}, Declared::Temp);
  Value lo = out, hi = out;
  lo.swizzle = ir::Swizzle::identity(a.width());
  hi.swizzle.size = b.width();
  for (int i = 0; i < b.width(); ++i) hi.swizzle.index[i] = static_cast<std::uint8_t>(a.width() + i);
  assign(lo, a);
  assign(hi, b);
  return out;
}

}  // namespace sh::detail
