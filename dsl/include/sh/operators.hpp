#pragma once
// Operators on Attribs: component-wise arithmetic and comparisons with
// scalar broadcast (C++ numbers convert to constants of the Attrib's type),
// masks (&&, ||, !, as Sh defined them), `|` the dot product and `^` the
// cross product.
#include "sh/attrib.hpp"

namespace sh {

template <class A, class B>
concept SameScalar = std::same_as<typename A::scalar_type, typename B::scalar_type>;

template <class A, class B>
concept Compatible = AttribLike<A> && AttribLike<B> && SameScalar<A, B> &&
                     (A::width == B::width || A::width == 1 || B::width == 1);

// The wider operand decides width and semantic; equal widths keep a shared
// semantic and otherwise give a plain Attrib.
template <AttribLike A, AttribLike B>
struct Result {
  static constexpr int width = A::width > B::width ? A::width : B::width;
  static constexpr Semantic semantic = A::width > B::width   ? A::semantic
                                       : B::width > A::width ? B::semantic
                                       : A::semantic == B::semantic ? A::semantic
                                                                    : Semantic::Attrib;
  using type = Attrib<width, typename A::scalar_type, semantic>;
};

template <AttribLike A>
using Plain = Attrib<A::width, typename A::scalar_type, A::semantic>;

template <AttribLike A, Number U>
detail::Value constant_like(U x) {
  return detail::constant(scalar_of<typename A::scalar_type>::value, static_cast<double>(x));
}

template <class R>
R wrap(detail::Value v) {
  return R(detail::FromValue{}, std::move(v));
}

// Two Attribs that are not Compatible: the first error says which rule
// they break, naming the operation (the compiler's "In instantiation of"
// line above it names the two types).  library.hpp's functions use it too.
#define SH_REJECT_OPERANDS(what)                                                                  \
  static_assert(SameScalar<A, B>, "sh: " what ": the operands have different scalar types (ints " \
                                  "and floats do not mix): convert one with .cast<T>()");         \
  static_assert(!SameScalar<A, B>, "sh: " what ": the operands' widths differ and neither is 1: " \
                                   "pick components with a swizzle, or fillcast<N>()");           \
  return {}

// Sh's && and || are min and max: "and" and "or" on masks of 0 and 1, and
// Sh's results on other values (2 && 0.5 is 0.5, -1 || -2 is -1).  Bools,
// which min and max do not take, keep the table's and/or.
template <AttribLike A>
constexpr ir::Op recorded_op(ir::Op op) {
  if (std::same_as<typename A::scalar_type, bool>) return op;
  if (op == ir::Op::And) return ir::Op::Min;
  if (op == ir::Op::Or) return ir::Op::Max;
  return op;
}

#define SH_BINARY_OPERATOR(sym, OP)                                                        \
  template <AttribLike A, AttribLike B>                                                    \
    requires Compatible<A, B>                                                              \
  typename Result<A, B>::type operator sym(const A& a, const B& b) {                       \
    return wrap<typename Result<A, B>::type>(detail::apply(recorded_op<A>(ir::Op::OP), {a.value(), b.value()})); \
  }                                                                                        \
  template <AttribLike A, AttribLike B>                                                    \
    requires(!Compatible<A, B>)                                                            \
  typename Result<A, B>::type operator sym(const A&, const B&) {                           \
    SH_REJECT_OPERANDS("operator " #sym);                                                  \
  }                                                                                        \
  template <AttribLike A, Number U>                                                        \
  Plain<A> operator sym(const A& a, U b) {                                                 \
    return wrap<Plain<A>>(detail::apply(recorded_op<A>(ir::Op::OP), {a.value(), constant_like<A>(b)})); \
  }                                                                                        \
  template <AttribLike A, Number U>                                                        \
  Plain<A> operator sym(U a, const A& b) {                                                 \
    return wrap<Plain<A>>(detail::apply(recorded_op<A>(ir::Op::OP), {constant_like<A>(a), b.value()})); \
  }

SH_BINARY_OPERATOR(+, Add)
SH_BINARY_OPERATOR(-, Sub)
SH_BINARY_OPERATOR(*, Mul)
SH_BINARY_OPERATOR(/, Div)
SH_BINARY_OPERATOR(%, Mod)
SH_BINARY_OPERATOR(<, Lt)
SH_BINARY_OPERATOR(<=, Le)
SH_BINARY_OPERATOR(>, Gt)
SH_BINARY_OPERATOR(>=, Ge)
SH_BINARY_OPERATOR(==, Eq)
SH_BINARY_OPERATOR(!=, Ne)
SH_BINARY_OPERATOR(&&, And)
SH_BINARY_OPERATOR(||, Or)
#undef SH_BINARY_OPERATOR

template <AttribLike A>
Plain<A> operator-(const A& a) {
  return wrap<Plain<A>>(detail::apply(ir::Op::Neg, {a.value()}));
}

template <AttribLike A>
Plain<A> operator!(const A& a) {
  return wrap<Plain<A>>(detail::apply(ir::Op::Not, {a.value()}));
}

namespace detail {
Value dot(const Value& a, const Value& b);
Value cross(const Value& a, const Value& b);
}  // namespace detail

template <AttribLike A, AttribLike B>
  requires Compatible<A, B>
Attrib<1, typename A::scalar_type> dot(const A& a, const B& b) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::dot(a.value(), b.value()));
}

template <AttribLike A, AttribLike B>
  requires Compatible<A, B> && (A::width == B::width)
Attrib<1, typename A::scalar_type> operator|(const A& a, const B& b) {
  return dot(a, b);
}

template <AttribLike A, AttribLike B>
  requires Compatible<A, B> && (A::width == 3) && (B::width == 3)
typename Result<A, B>::type cross(const A& a, const B& b) {
  return wrap<typename Result<A, B>::type>(detail::cross(a.value(), b.value()));
}

template <AttribLike A, AttribLike B>
  requires Compatible<A, B> && (A::width == 3) && (B::width == 3)
typename Result<A, B>::type operator^(const A& a, const B& b) {
  return cross(a, b);
}

}  // namespace sh
