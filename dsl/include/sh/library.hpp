#pragma once
// The library of functions kernels call.  Compound functions are expanded
// into the IR's component-wise operations here, once, so every backend
// evaluates them identically.  Conventions are Sh 0.8's (docs/operations.md,
// docs/sh-differences.md):
//   lerp(f, a, b) = f*a + (1-f)*b
//   reflect(a, n) = 2(a·n̂)n̂ - a, n̂ = normalize(n)   (a points away; keeps a's length)
//   refract(v, n, eta): v the view vector pointing away from the surface, n
//     the normal, eta the index of the side entered over the side left; v and
//     n normalised; the zero vector on total internal reflection
//   faceforward(a, b) = b where a·b > 0, else -b
//   any(a), all(a): the largest and the smallest component (Sh's || and &&)
// normalize of a zero vector gives zero, of one with a NaN NaN; length and
// normalize scale by the largest component first, so huge and tiny vectors
// do not over/underflow.
#include <algorithm>

#include "sh/operators.hpp"

namespace sh {
namespace detail {
Value lerp(const Value& f, const Value& a, const Value& b);
Value length(const Value& v);
Value normalize(const Value& v);
Value reflect(const Value& a, const Value& n);
Value refract(const Value& v, const Value& n, const Value& eta);
Value faceforward(const Value& a, const Value& b);
Value cond(const Value& c, const Value& a, const Value& b);
Value fold(ir::Op op, const Value& v);  // v.x op v.y op ...
Value frac(const Value& v);
Value fillcast(const Value& v, int width);
Value join(const Value& a, const Value& b);
}  // namespace detail

// A function whose operation takes only some scalars (ops.def's domain)
// fails to compile on the others, at the caller's line, naming itself.
#define SH_CHECK_DOMAIN(name, OP, A)                                                                  \
  static_assert(ir::accepts(ir::Op::OP, scalar_of<typename A::scalar_type>::value),                 \
                #name " does not take this scalar type (see ops.def: " #OP "); convert it first, e.g. " \
                "x.cast<float>()")

#define SH_UNARY_FUNCTION(name, OP)                                 \
  template <AttribLike A>                                           \
  Plain<A> name(const A& a) {                                       \
    SH_CHECK_DOMAIN(name, OP, A);                                   \
    return wrap<Plain<A>>(detail::apply(ir::Op::OP, {a.value()}));  \
  }
SH_UNARY_FUNCTION(abs, Abs)
SH_UNARY_FUNCTION(sign, Sign)
SH_UNARY_FUNCTION(floor, Floor)
SH_UNARY_FUNCTION(ceil, Ceil)
SH_UNARY_FUNCTION(round, Round)
SH_UNARY_FUNCTION(sqrt, Sqrt)
SH_UNARY_FUNCTION(rsqrt, Rsqrt)
SH_UNARY_FUNCTION(rcp, Rcp)
SH_UNARY_FUNCTION(exp, Exp)
SH_UNARY_FUNCTION(exp2, Exp2)
SH_UNARY_FUNCTION(log, Log)
SH_UNARY_FUNCTION(log2, Log2)
SH_UNARY_FUNCTION(sin, Sin)
SH_UNARY_FUNCTION(cos, Cos)
SH_UNARY_FUNCTION(tan, Tan)
SH_UNARY_FUNCTION(asin, Asin)
SH_UNARY_FUNCTION(acos, Acos)
SH_UNARY_FUNCTION(atan, Atan)
SH_UNARY_FUNCTION(sinh, Sinh)
SH_UNARY_FUNCTION(cosh, Cosh)
SH_UNARY_FUNCTION(tanh, Tanh)
SH_UNARY_FUNCTION(asinh, Asinh)
SH_UNARY_FUNCTION(acosh, Acosh)
SH_UNARY_FUNCTION(atanh, Atanh)
SH_UNARY_FUNCTION(exp10, Exp10)
SH_UNARY_FUNCTION(log10, Log10)
SH_UNARY_FUNCTION(cbrt, Cbrt)
SH_UNARY_FUNCTION(bit_not, BitNot)
// 1 where a > 0 in this element or in any element run beside it (SIMD
// lanes of one batch; a backend may run each element alone), else 0: a
// walk whose result does not depend on it can keep neighbouring elements
// together (see ops.def).
SH_UNARY_FUNCTION(any_lane, AnyLane)
#undef SH_UNARY_FUNCTION

// The element's place in its run's launch domain: x, y, z of a row-major
// grid (sh::LaunchDomain; a channel's shape() sets it), the first N of
// them.  A stencil reads a table at offsets from it (docs/stencils.md);
// neighbours along x sit in neighbouring SIMD lanes, so such reads are
// vector loads.
template <int N = 1>
Attrib<N, std::int32_t> position() {
  static_assert(N >= 1 && N <= 3, "position<N>(): a launch domain has 1 to 3 dimensions");
  return wrap<Attrib<N, std::int32_t>>(detail::position(N));
}

#define SH_BINARY_FUNCTION(name, OP)                                                      \
  template <AttribLike A, AttribLike B>                                                   \
    requires Compatible<A, B>                                                             \
  typename Result<A, B>::type name(const A& a, const B& b) {                              \
    SH_CHECK_DOMAIN(name, OP, A);                                                         \
    return wrap<typename Result<A, B>::type>(detail::apply(ir::Op::OP, {a.value(), b.value()})); \
  }                                                                                       \
  template <AttribLike A, AttribLike B>                                                   \
    requires(!Compatible<A, B>)                                                           \
  typename Result<A, B>::type name(const A&, const B&) {                                  \
    SH_REJECT_OPERANDS(#name "(a, b)");                                                   \
  }                                                                                       \
  template <AttribLike A, Number U>                                                       \
  Plain<A> name(const A& a, U b) {                                                        \
    SH_CHECK_DOMAIN(name, OP, A);                                                         \
    return wrap<Plain<A>>(detail::apply(ir::Op::OP, {a.value(), constant_like<A>(b)}));  \
  }                                                                                       \
  template <AttribLike A, Number U>                                                       \
  Plain<A> name(U a, const A& b) {                                                        \
    SH_CHECK_DOMAIN(name, OP, A);                                                         \
    return wrap<Plain<A>>(detail::apply(ir::Op::OP, {constant_like<A>(a), b.value()}));  \
  }
SH_BINARY_FUNCTION(min, Min)
SH_BINARY_FUNCTION(max, Max)
SH_BINARY_FUNCTION(pow, Pow)
SH_BINARY_FUNCTION(atan2, Atan2)
SH_BINARY_FUNCTION(mod, Mod)
// Bits of integers.  Functions, not operators: `|` and `^` are Sh's dot and
// cross products, and `<<` its program algebra.
SH_BINARY_FUNCTION(bit_and, BitAnd)
SH_BINARY_FUNCTION(bit_or, BitOr)
SH_BINARY_FUNCTION(bit_xor, BitXor)
SH_BINARY_FUNCTION(shl, Shl)  // a count outside [0, 31] gives 0
SH_BINARY_FUNCTION(shr, Shr)  // arithmetic; a count outside [0, 31] gives 0 or -1
#undef SH_BINARY_FUNCTION
#undef SH_CHECK_DOMAIN

template <AttribLike A>
Plain<A> frac(const A& a) {
  return wrap<Plain<A>>(detail::frac(a.value()));
}

template <class X>
constexpr int width_of() {
  if constexpr (AttribLike<X>) return X::width;
  else return 1;
}

// The result's width of a component-wise operation on these operands.
template <class... X>
inline constexpr int widest = std::max({width_of<X>()...});

// clamp(x, lo, hi): lo and hi numbers or Attribs of x's scalar type, each
// of x's width or width 1.
template <class A, class L, class H>
concept ClampBounds = OperandFor<L, A::width, typename A::scalar_type> && OperandFor<H, A::width, typename A::scalar_type>;

template <AttribLike A, class L, class H>
  requires ClampBounds<A, L, H>
Plain<A> clamp(const A& x, const L& lo, const H& hi) {
  return min(max(x, lo), hi);
}
template <AttribLike A, class L, class H>
  requires(!ClampBounds<A, L, H>)
Plain<A> clamp(const A&, const L&, const H&) {
  static_assert(ClampBounds<A, L, H>,
                "sh: clamp(x, lo, hi) takes lo and hi as numbers or Attribs of x's scalar type with x's width "
                "or width 1 (ints and floats do not mix: convert with .cast<T>())");
  return {};
}

// Saturate: clamp to [0, 1].
template <AttribLike A>
Plain<A> sat(const A& x) {
  return clamp(x, 0, 1);
}

// Positive part: max(x, 0).
template <AttribLike A>
Plain<A> pos(const A& x) {
  return max(x, 0);
}

// lerp(f, a, b): a and b Compatible, f a number or an Attrib of their
// scalar type with the result's width or width 1.
template <class F, class A, class B>
concept LerpOperands =
    Compatible<A, B> && OperandFor<F, Result<A, B>::width, typename A::scalar_type>;

template <class F, AttribLike A, AttribLike B>
  requires LerpOperands<F, A, B>
typename Result<A, B>::type lerp(const F& f, const A& a, const B& b) {
  detail::Value fv;
  if constexpr (Number<F>) fv = constant_like<A>(f);
  else fv = f.value();
  return wrap<typename Result<A, B>::type>(detail::lerp(fv, a.value(), b.value()));
}
template <class F, AttribLike A, AttribLike B>
  requires(!LerpOperands<F, A, B>)
typename Result<A, B>::type lerp(const F&, const A&, const B&) {
  static_assert(LerpOperands<F, A, B>,
                "sh: lerp(f, a, b) takes a and b of one scalar type, and f a number or an Attrib of that type, "
                "each of the result's width or width 1 (ints and floats do not mix: convert with .cast<T>())");
  return {};
}

// mad(a, b, c) = a * b + c: b and c numbers or Attribs of a's scalar type,
// every Attrib of the result's width or width 1.
template <class A, class B, class C>
concept MadOperands = AttribLike<A> && (A::width == widest<A, B, C> || A::width == 1) &&
                      OperandFor<B, widest<A, B, C>, typename A::scalar_type> &&
                      OperandFor<C, widest<A, B, C>, typename A::scalar_type>;

template <AttribLike A, class B, class C>
  requires MadOperands<A, B, C>
auto mad(const A& a, const B& b, const C& c) {
  return a * b + c;
}
template <AttribLike A, class B, class C>
  requires(!MadOperands<A, B, C>)
Plain<A> mad(const A&, const B&, const C&) {
  static_assert(MadOperands<A, B, C>,
                "sh: mad(a, b, c) takes b and c as numbers or Attribs of a's scalar type, each of the result's "
                "width or width 1 (ints and floats do not mix: convert with .cast<T>())");
  return {};
}

template <AttribLike A>
Attrib<1, typename A::scalar_type> length(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::length(v.value()));
}

template <AttribLike A, AttribLike B>
  requires Compatible<A, B>
Attrib<1, typename A::scalar_type> distance(const A& a, const B& b) {
  return length(a - b);
}

template <AttribLike A>
Plain<A> normalize(const A& v) {
  return wrap<Plain<A>>(detail::normalize(v.value()));
}

template <AttribLike A, AttribLike B>
  requires Compatible<A, B> && (A::width == B::width)
Plain<A> reflect(const A& a, const B& n) {
  return wrap<Plain<A>>(detail::reflect(a.value(), n.value()));
}

template <AttribLike A, AttribLike B, class E>
  requires Compatible<A, B> && (A::width == B::width) && OperandFor<E, A::width, typename A::scalar_type>
Plain<A> refract(const A& v, const B& n, const E& eta) {
  detail::Value e;
  if constexpr (Number<E>) e = constant_like<A>(eta);
  else e = eta.value();
  return wrap<Plain<A>>(detail::refract(v.value(), n.value(), e));
}

// b, or -b where it does not face the way a does (Sh's argument order).
template <AttribLike A, AttribLike B>
  requires Compatible<A, B> && (A::width == B::width)
Plain<B> faceforward(const A& a, const B& b) {
  return wrap<Plain<B>>(detail::faceforward(a.value(), b.value()));
}

template <class X>
concept NumberOrAttrib = Number<X> || AttribLike<X>;

// The Attrib among cond's branches a and b that gives the result its type.
template <class A, class B>
using Branch = std::conditional_t<AttribLike<A>, A, B>;

// cond(c, a, b): a and b numbers or Attribs of one scalar type, at least
// one an Attrib; c a number or an Attrib of any type; every Attrib of the
// result's width or width 1.
template <class C, class A, class B>
concept CondOperands = (AttribLike<A> || AttribLike<B>) && NumberOrAttrib<C> &&
                       OperandFor<A, widest<C, A, B>, typename Branch<A, B>::scalar_type> &&
                       OperandFor<B, widest<C, A, B>, typename Branch<A, B>::scalar_type> &&
                       (width_of<C>() == widest<C, A, B> || width_of<C>() == 1);

// c > 0 ? a : b, per component (a scalar c decides every component).  The
// condition may be of another type than a and b: it is converted.
template <class C, class A, class B>
  requires CondOperands<C, A, B>
auto cond(const C& c, const A& a, const B& b) {
  using R = std::conditional_t<AttribLike<A>, A, B>;
  using T = typename R::scalar_type;
  constexpr int W = std::max({width_of<C>(), width_of<A>(), width_of<B>()});
  auto value_of = [](const auto& x) {
    if constexpr (Number<std::decay_t<decltype(x)>>)
      return detail::constant(scalar_of<T>::value, static_cast<double>(x));
    else
      return x.value();
  };
  return wrap<Attrib<W, T, R::semantic>>(detail::cond(value_of(c), value_of(a), value_of(b)));
}
template <class C, class A, class B>
  requires(AttribLike<A> || AttribLike<B>) && (!CondOperands<C, A, B>)
Plain<Branch<A, B>> cond(const C&, const A&, const B&) {
  static_assert(CondOperands<C, A, B>,
                "sh: cond(c, a, b) takes a and b as numbers or Attribs of one scalar type, and c a number or "
                "an Attrib, each of the result's width or width 1 (ints and floats do not mix in a and b: "
                "convert with .cast<T>())");
  return {};
}

// Sh's any and all: v.x || v.y || ... and v.x && v.y && ..., that is the
// largest and the smallest component (1 and 0 on masks).
template <AttribLike A>
Attrib<1, typename A::scalar_type> any(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(recorded_op<A>(ir::Op::Or), v.value()));
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> all(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(recorded_op<A>(ir::Op::And), v.value()));
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> min_component(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(ir::Op::Min, v.value()));
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> max_component(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(ir::Op::Max, v.value()));
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> sum(const A& v) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(ir::Op::Add, v.value()));
}

// M components of v: extra ones repeat v's last component (Sh's fillcast),
// in a new variable (writing it never writes v).
template <int M, AttribLike A>
Attrib<M, typename A::scalar_type, A::semantic> fillcast(const A& v) {
  return wrap<Attrib<M, typename A::scalar_type, A::semantic>>(detail::fillcast(v.value(), M));
}

template <AttribLike A, AttribLike B>
  requires std::same_as<typename A::scalar_type, typename B::scalar_type> && (A::width + B::width <= 4)
Attrib<A::width + B::width, typename A::scalar_type> join(const A& a, const B& b) {
  return wrap<Attrib<A::width + B::width, typename A::scalar_type>>(detail::join(a.value(), b.value()));
}

}  // namespace sh
