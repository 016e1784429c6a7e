#pragma once
// More of the library, as Sh 0.8 defined it (LibGeometry, LibArith,
// LibClamp, LibMisc), each expanded while recording into operations of
// the table, so every backend evaluates it in the same order:
//   length_1(a) = sum |a_i|        length_inf(a) = max |a_i|
//   distance_1(a, b) = length_1(a - b), distance_inf likewise
//   prod(a) = a_0 * a_1 * ...      max(a), min(a): the largest, smallest component
//   poly(x, c) = c_0 + c_1 x + c_2 x^2 + ... (Horner, per component of x)
//   lit(a, b, c) = (1, max(a, 0), a > 0 ? max(b, 0)^clamp(c, -128, 128) : 0, 1)
//   smoothstep(a, b, x): 0 below a, 1 above b, 3t^2 - 2t^3 between (GLSL's)
//   linstep(t, c, w) = clamp((t - c) / w + 1/2, 0, 1): a ramp of width w centred on c
//   smoothpulse(t, r0, r1, w) = linstep(t, r0, w) - linstep(t, r1, w)
//   sort(a): the components in increasing order (a sorting network of min/max)
//   cast<M>(a): M components, a's first ones then zeros (fillcast<M>
//     repeats the last one instead)
// smoothpulse is Sh's documented meaning ("linear smooth pulse of t between
// r0 and r1 with width w"); Sh 0.8's body passed its arguments to the
// three-argument smoothstep in another order.
#include <concepts>

#include "sh/library.hpp"

namespace sh {

template <AttribLike A>
Attrib<1, typename A::scalar_type> prod(const A& a) {
  return wrap<Attrib<1, typename A::scalar_type>>(detail::fold(ir::Op::Mul, a.value()));
}

template <AttribLike A>
Attrib<1, typename A::scalar_type> max(const A& a) {
  return max_component(a);
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> min(const A& a) {
  return min_component(a);
}

template <AttribLike A>
Attrib<1, typename A::scalar_type> length_1(const A& a) {
  return sum(abs(a));
}
template <AttribLike A>
Attrib<1, typename A::scalar_type> length_inf(const A& a) {
  return max(abs(a));
}
template <AttribLike A, AttribLike B>
  requires Compatible<A, B>
Attrib<1, typename A::scalar_type> distance_1(const A& a, const B& b) {
  return length_1(a - b);
}
template <AttribLike A, AttribLike B>
  requires Compatible<A, B>
Attrib<1, typename A::scalar_type> distance_inf(const A& a, const B& b) {
  return length_inf(a - b);
}

// Coefficients c_0 (the constant term) to c_{M-1}, the same for every
// component of x.
template <AttribLike X, AttribLike C>
  requires std::same_as<typename X::scalar_type, typename C::scalar_type>
Plain<X> poly(const X& x, const C& c) {
  Plain<X> r;
  r = c(C::width - 1);
  for (int j = C::width - 2; j >= 0; --j) r = x * r + c(j);
  return r;
}

// What lit, smoothstep, linstep and smoothpulse take beside their Attrib:
// numbers, or Attribs of its float type with its width or width 1.
template <class X>
concept FloatAttrib = AttribLike<X> && std::floating_point<typename X::scalar_type>;

template <FloatAttrib A, class B, class C>
  requires(A::width == 1) && OperandFor<B, 1, typename A::scalar_type> && OperandFor<C, 1, typename A::scalar_type>
Attrib<4, typename A::scalar_type> lit(const A& a, const B& b, const C& c) {
  using T = typename A::scalar_type;
  Attrib<1, T> x = max(a, 0), y = max(Attrib<1, T>(b), 0), w = clamp(Attrib<1, T>(c), -128, 128);
  Attrib<4, T> r(1);
  r(1) = x;
  r(2) = cond(x, pow(y, w), 0);
  return r;
}

template <class A, class B, FloatAttrib X>
  requires OperandFor<A, X::width, typename X::scalar_type> && OperandFor<B, X::width, typename X::scalar_type>
Plain<X> smoothstep(const A& a, const B& b, const X& x) {
  Plain<X> t = sat((x - a) / (b - a));
  return t * t * (3 - 2 * t);
}

template <FloatAttrib X, class C, class W>
  requires OperandFor<C, X::width, typename X::scalar_type> && OperandFor<W, X::width, typename X::scalar_type>
Plain<X> linstep(const X& t, const C& c, const W& w) {
  return sat((t - c) / w + 0.5);
}

template <FloatAttrib X, class R0, class R1, class W>
  requires OperandFor<R0, X::width, typename X::scalar_type> && OperandFor<R1, X::width, typename X::scalar_type> &&
           OperandFor<W, X::width, typename X::scalar_type>
Plain<X> smoothpulse(const X& t, const R0& r0, const R1& r1, const W& w) {
  return linstep(t, r0, w) - linstep(t, r1, w);
}

// min/max keep a number over a NaN, so a NaN component does not survive
// the sort: its place goes to a copy of the number it was compared with.
template <AttribLike A>
Plain<A> sort(const A& a) {
  Plain<A> r = a;
  [[maybe_unused]] auto order = [&r](int i, int j) {
    Attrib<1, typename A::scalar_type> lo = min(r(i), r(j)), hi = max(r(i), r(j));
    r(i) = lo;
    r(j) = hi;
  };
  if constexpr (A::width == 2) order(0, 1);
  if constexpr (A::width == 3) {
    order(0, 1);
    order(1, 2);
    order(0, 1);
  }
  if constexpr (A::width == 4) {
    order(0, 1);
    order(2, 3);
    order(0, 2);
    order(1, 3);
    order(1, 2);
  }
  return r;
}

namespace detail {
// a's first K components, as a view to read or write through.
template <int K, AttribLike A>
auto head(const A& a) {
  if constexpr (K == 1) return a(0);
  else if constexpr (K == 2) return a(0, 1);
  else if constexpr (K == 3) return a(0, 1, 2);
  else return a(0, 1, 2, 3);
}
}  // namespace detail

template <int M, AttribLike A>
  requires(M >= 1 && M <= 4)
Attrib<M, typename A::scalar_type, A::semantic> cast(const A& a) {
  Attrib<M, typename A::scalar_type, A::semantic> r(0);
  if constexpr (M <= A::width) r = detail::head<M>(a);
  else detail::head<A::width>(r) = a;
  return r;
}

}  // namespace sh
