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

Value frac(const Value& v) { return apply(ir::Op::Sub, {v, apply(ir::Op::Floor, {v})}); }

Value lerp(const Value& f, const Value& a, const Value& b) {
  Value one_minus_f = apply(ir::Op::Sub, {k(f, 1), f});
  return apply(ir::Op::Add, {apply(ir::Op::Mul, {f, a}), apply(ir::Op::Mul, {one_minus_f, b})});
}

Value cond(const Value& c, const Value& a, const Value& b) {
  return apply(ir::Op::Cond, {as_scalar(c, a.scalar()), a, b});
}

// The largest magnitude m, and v / m, keep the squares in range.
static std::pair<Value, Value> scaled(const Value& v) {
  Value m = fold(ir::Op::Max, apply(ir::Op::Abs, {v}));
  Value safe_m = cond(apply(ir::Op::Gt, {m, k(m, 0)}), m, k(m, 1));
  return {m, apply(ir::Op::Div, {v, safe_m})};
}

Value length(const Value& v) {
  if (v.width() == 1) return apply(ir::Op::Abs, {v});
  auto [m, s] = scaled(v);
  Value len = apply(ir::Op::Mul, {m, apply(ir::Op::Sqrt, {dot(s, s)})});
  double inf = std::numeric_limits<double>::infinity();
  return cond(apply(ir::Op::Lt, {m, k(m, inf)}), len, m);
}

Value normalize(const Value& v) {
  auto [m, s] = scaled(v);
  Value unit = apply(ir::Op::Mul, {s, apply(ir::Op::Rsqrt, {dot(s, s)})});
  return cond(apply(ir::Op::Gt, {m, k(m, 0)}), unit, k(v, 0));
}

Value reflect(const Value& a, const Value& n) {
  Value twice = apply(ir::Op::Mul, {k(a, 2), dot(a, n)});
  return apply(ir::Op::Sub, {apply(ir::Op::Mul, {twice, n}), a});
}

Value refract(const Value& i, const Value& n, const Value& eta) {
  Value ni = dot(n, i);
  Value one = k(ni, 1);
  Value sin2 = apply(ir::Op::Sub, {one, apply(ir::Op::Mul, {ni, ni})});
  Value kk = apply(ir::Op::Sub, {one, apply(ir::Op::Mul, {apply(ir::Op::Mul, {eta, eta}), sin2})});
  Value along_n = apply(ir::Op::Add, {apply(ir::Op::Mul, {eta, ni}), apply(ir::Op::Sqrt, {apply(ir::Op::Max, {kk, k(kk, 0)})})});
  Value t = apply(ir::Op::Sub, {apply(ir::Op::Mul, {eta, i}), apply(ir::Op::Mul, {along_n, n})});
  // Total internal reflection gives the zero vector.
  return cond(apply(ir::Op::Ge, {kk, k(kk, 0)}), t, k(i, 0));
}

Value faceforward(const Value& n, const Value& v) {
  return cond(apply(ir::Op::Ge, {dot(n, v), k(n, 0)}), n, apply(ir::Op::Neg, {n}));
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
