#pragma once
// Attrib<N, T, S>: the value type of the language.  Inside a program an
// Attrib is a register and every operation on it is recorded; outside one it
// is a uniform whose value the host sets between runs.
#include <concepts>
#include <cstdint>
#include <type_traits>

#include "sh/detail/value.hpp"

namespace sh {

enum class Semantic { Attrib, Point, Vector, Normal, Color, TexCoord, Position };

template <class T>
struct scalar_of;
template <> struct scalar_of<float> { static constexpr ir::Scalar value = ir::Scalar::F32; };
template <> struct scalar_of<double> { static constexpr ir::Scalar value = ir::Scalar::F64; };
template <> struct scalar_of<std::int32_t> { static constexpr ir::Scalar value = ir::Scalar::I32; };
template <> struct scalar_of<bool> { static constexpr ir::Scalar value = ir::Scalar::Bool; };

template <class T>
concept Number = std::is_arithmetic_v<T>;

// The C++ types an Attrib's components can have.
template <class T>
concept ScalarType = requires { scalar_of<T>::value; };

namespace detail {
// Common base, so that functions can take any Attrib by its Value.
class ValueHolder {
 public:
  // A variable moved from holds none: reading it is an error, and an
  // assignment gives it a new one, as assigning a moved-from string does.
  const Value& value() const {
    if (!value_.node) moved_from();
    return value_;
  }

 protected:
  ValueHolder() = default;
  explicit ValueHolder(Value v) : value_(std::move(v)) {}
  bool copies_on_move() const { return copy_on_move_; }
  [[noreturn]] static void moved_from();
  // The variable an assignment writes, new where this was moved from.
  const Value& target(ir::Type type) {
    if (!value_.node) value_ = declare(type, Declared::Temp);
    return value_;
  }
  Value value_;
  bool copy_on_move_ = false;  // a swizzle of another variable, or a constant
};
struct FromValue {};  // tag: wrap an existing Value

// A program value, or a C++ number as a constant of scalar `number_type`.
template <class T>
Value value_or_constant(const T& x, ir::Scalar number_type) {
  if constexpr (Number<T>)
    return constant(number_type, static_cast<double>(x));
  else
    return x.value();
}

// Constructor arguments as four components; a single one fills them all.
template <class... U>
std::array<double, 4> components(U... xs) {
  if constexpr (sizeof...(U) == 1) {
    double v = (static_cast<double>(xs), ...);
    return {v, v, v, v};
  } else {
    return {static_cast<double>(xs)...};
  }
}
}  // namespace detail

template <int N, class T = float, Semantic S = Semantic::Attrib>
class Attrib;

template <class A>
concept AttribLike = std::derived_from<A, detail::ValueHolder> && requires {
  A::width;
  typename A::scalar_type;
};

template <int N, class T, Semantic S>
class SwizzleRef;

// What an operation whose result has N components of T takes beside that
// result: a C++ number (it becomes a constant of T), or an Attrib of T with
// N components or one (broadcast).  Compound assignment takes exactly these:
// ints and floats never mix in an operation without an explicit cast<T>().
template <class X, int N, class T>
concept OperandFor = Number<X> || (AttribLike<X> && std::same_as<typename X::scalar_type, T> &&
                                   (X::width == N || X::width == 1));

// What assignment to N components takes: an Attrib of any scalar type with
// N components or one.  Another scalar type is converted, as in Sh (a cast
// in the IR, with the defined float-to-int results of docs/operations.md).
template <class X, int N>
concept AssignableTo = AttribLike<X> && (X::width == N || X::width == 1);

// Compound assignment, and an overload for every other right-hand side
// that exists to say why, naming the operator, where the compiler would
// list the candidates that did not match (the same for = and in
// operators.hpp, library.hpp, matrix.hpp).
#define SH_COMPOUND_ASSIGNMENT(sym)                                                                           \
  template <OperandFor<N, T> U>                                                                               \
  Attrib& operator sym##=(const U& x) {                                                                       \
    return *this = *this sym x;                                                                               \
  }                                                                                                           \
  template <class U>                                                                                          \
    requires(!OperandFor<U, N, T>)                                                                            \
  Attrib& operator sym##=(const U&) {                                                                         \
    static_assert(OperandFor<U, N, T>,                                                                        \
                  "sh: Attrib " #sym "= takes a number or an Attrib of the same scalar type with the same "   \
                  "width or width 1 (ints and floats do not mix: convert with .cast<T>())");                 \
    return *this;                                                                                             \
  }

template <int N, class T, Semantic S>
class Attrib : public detail::ValueHolder {
  static_assert(N >= 1 && N <= 4, "an Attrib has 1 to 4 components");

 public:
  static constexpr int width = N;
  using scalar_type = T;
  static constexpr Semantic semantic = S;
  static constexpr ir::Type ir_type() { return {scalar_of<T>::value, N}; }

  Attrib() : ValueHolder(detail::declare(ir_type(), detail::Declared::Temp)) {}
  Attrib(detail::FromValue, detail::Value v) : ValueHolder(std::move(v)) {}

  // A copy is a new variable holding the value, as in Sh.
  Attrib(const Attrib& other) : Attrib() { detail::assign(value_, other.value()); }
  // A temporary result is adopted rather than copied; a swizzle view or a
  // constant is copied, so that a variable taken by value never aliases
  // another (a parameter never writes through to its argument).
  Attrib(Attrib&& other) : ValueHolder(other.copies_on_move() ? detail::Value{} : std::move(other.value_)) {
    if (other.copies_on_move()) {
      value_ = detail::declare(ir_type(), detail::Declared::Temp);
      detail::assign(value_, other.value());
    }
  }
  // Another semantic, or another scalar type (converted, as in Sh).
  template <class T2, Semantic S2>
  Attrib(const Attrib<N, T2, S2>& other) : Attrib() {
    detail::assign(value_, other.value());
  }
  template <Number... U>
    requires(sizeof...(U) == N || sizeof...(U) == 1)
  Attrib(U... components) : Attrib() {
    detail::assign(value_, detail::constant(ir_type(), detail::components(components...)));
  }

  Attrib& operator=(const Attrib& other) {
    detail::assign(target(ir_type()), other.value());
    return *this;
  }
  // Another scalar type is converted (detail::assign records the cast).
  template <AttribLike A>
    requires AssignableTo<A, N>
  Attrib& operator=(const A& other) {
    detail::assign(target(ir_type()), other.value());
    return *this;
  }
  template <AttribLike A>
    requires(!AssignableTo<A, N>)
  Attrib& operator=(const A&) {
    static_assert(AssignableTo<A, N>,
                  "sh: Attrib = takes an Attrib with the same width or width 1: pick components with a "
                  "swizzle, or widen with fillcast<N>()");
    return *this;
  }
  template <Number U>
  Attrib& operator=(U x) {
    detail::assign(target(ir_type()), detail::constant(scalar_of<T>::value, static_cast<double>(x)));
    return *this;
  }

  SH_COMPOUND_ASSIGNMENT(+)
  SH_COMPOUND_ASSIGNMENT(-)
  SH_COMPOUND_ASSIGNMENT(*)
  SH_COMPOUND_ASSIGNMENT(/)
  SH_COMPOUND_ASSIGNMENT(%)
  Attrib& operator++() { return *this += 1; }
  Attrib& operator--() { return *this -= 1; }
  void operator++(int) { *this += 1; }
  void operator--(int) { *this -= 1; }

  // Swizzles: read components, or write only those (v(0, 1) = ...).
  SwizzleRef<1, T, S> operator()(int a) const { return {detail::swizzle(value(), {a})}; }
  SwizzleRef<2, T, S> operator()(int a, int b) const { return {detail::swizzle(value(), {a, b})}; }
  SwizzleRef<3, T, S> operator()(int a, int b, int c) const { return {detail::swizzle(value(), {a, b, c})}; }
  SwizzleRef<4, T, S> operator()(int a, int b, int c, int d) const { return {detail::swizzle(value(), {a, b, c, d})}; }

  // A new variable: writing it never writes this one, even where U is T.
  template <ScalarType U>
  Attrib<N, U, S> cast() const {
    return {detail::FromValue{}, detail::cast(value(), scalar_of<U>::value)};
  }

  Attrib& name(const std::string& n) {
    detail::set_name(value(), n);
    return *this;
  }
  // Host-side value of a uniform (outside programs).
  T get(int i = 0) const {
    if (i < 0 || i >= N) detail::no_component(i, N);
    return static_cast<T>(detail::host_value(value())[i]);
  }
};

#undef SH_COMPOUND_ASSIGNMENT

// What a swizzle returns: reads like an Attrib; assignment writes through
// to the swizzled components of the original variable.  Copying it into an
// Attrib makes a new variable, so function parameters stay copies.
template <int N, class T, Semantic S>
class SwizzleRef : public Attrib<N, T, S> {
 public:
  SwizzleRef(detail::Value v) : Attrib<N, T, S>(detail::FromValue{}, std::move(v)) { this->copy_on_move_ = true; }
  SwizzleRef(const SwizzleRef& other) : SwizzleRef(other.value()) {}
  using Attrib<N, T, S>::operator=;
  SwizzleRef& operator=(const SwizzleRef& other) {
    detail::assign(this->value_, other.value());
    return *this;
  }
};

// Program interface variables.
template <class A>
class Input : public A {
 public:
  // Moving one copies it, as a swizzle does: the program's interface
  // variable stays this object's.
  Input() : A(detail::FromValue{}, detail::declare(A::ir_type(), detail::Declared::Input)) {
    this->copy_on_move_ = true;
  }
  using A::operator=;
};
template <class A>
class Output : public A {
 public:
  Output() : A(detail::FromValue{}, detail::declare(A::ir_type(), detail::Declared::Output)) {
    this->copy_on_move_ = true;
  }
  using A::operator=;
  Output& operator=(const Output& other) {
    A::operator=(other);
    return *this;
  }
};
template <class A>
class InOut : public A {
 public:
  InOut() : A(detail::FromValue{}, detail::declare(A::ir_type(), detail::Declared::InOut)) {
    this->copy_on_move_ = true;
  }
  using A::operator=;
  InOut& operator=(const InOut& other) {
    A::operator=(other);
    return *this;
  }
};

// A constant: a value fixed while recording.
template <int N, class T = float, Semantic S = Semantic::Attrib>
class ConstAttrib : public Attrib<N, T, S> {
 public:
  template <Number... U>
    requires(sizeof...(U) == N || sizeof...(U) == 1)
  ConstAttrib(U... components)
      : Attrib<N, T, S>(detail::FromValue{},
                        detail::constant(Attrib<N, T, S>::ir_type(), detail::components(components...))) {
    this->copy_on_move_ = true;
  }
};

// ---- aliases ---------------------------------------------------------------

#define SH_INTERFACE_ALIASES(Name)                      \
  using Input##Name = Input<Name>;                      \
  using Output##Name = Output<Name>;                    \
  using InOut##Name = InOut<Name>;
#define SH_INTERFACE_FAMILY(Name) \
  SH_INTERFACE_ALIASES(Name##1f)  \
  SH_INTERFACE_ALIASES(Name##2f)  \
  SH_INTERFACE_ALIASES(Name##3f)  \
  SH_INTERFACE_ALIASES(Name##4f)  \
  SH_INTERFACE_ALIASES(Name##1i)  \
  SH_INTERFACE_ALIASES(Name##2i)  \
  SH_INTERFACE_ALIASES(Name##3i)  \
  SH_INTERFACE_ALIASES(Name##4i)  \
  SH_INTERFACE_ALIASES(Name##1d)  \
  SH_INTERFACE_ALIASES(Name##3d)

#define SH_ATTRIB_ALIASES(Name, Sem)                          \
  using Name##1f = Attrib<1, float, Semantic::Sem>;          \
  using Name##2f = Attrib<2, float, Semantic::Sem>;          \
  using Name##3f = Attrib<3, float, Semantic::Sem>;          \
  using Name##4f = Attrib<4, float, Semantic::Sem>;          \
  using Name##1d = Attrib<1, double, Semantic::Sem>;         \
  using Name##2d = Attrib<2, double, Semantic::Sem>;         \
  using Name##3d = Attrib<3, double, Semantic::Sem>;         \
  using Name##4d = Attrib<4, double, Semantic::Sem>;         \
  using Name##1i = Attrib<1, std::int32_t, Semantic::Sem>;   \
  using Name##2i = Attrib<2, std::int32_t, Semantic::Sem>;   \
  using Name##3i = Attrib<3, std::int32_t, Semantic::Sem>;   \
  using Name##4i = Attrib<4, std::int32_t, Semantic::Sem>;   \
  using Name##1b = Attrib<1, bool, Semantic::Sem>;           \
  using Name##2b = Attrib<2, bool, Semantic::Sem>;           \
  using Name##3b = Attrib<3, bool, Semantic::Sem>;           \
  using Name##4b = Attrib<4, bool, Semantic::Sem>;           \
  using Const##Name##1f = ConstAttrib<1, float, Semantic::Sem>; \
  using Const##Name##2f = ConstAttrib<2, float, Semantic::Sem>; \
  using Const##Name##3f = ConstAttrib<3, float, Semantic::Sem>; \
  using Const##Name##4f = ConstAttrib<4, float, Semantic::Sem>; \
  using Const##Name##1i = ConstAttrib<1, std::int32_t, Semantic::Sem>; \
  using Const##Name##2i = ConstAttrib<2, std::int32_t, Semantic::Sem>; \
  using Const##Name##3i = ConstAttrib<3, std::int32_t, Semantic::Sem>; \
  using Const##Name##4i = ConstAttrib<4, std::int32_t, Semantic::Sem>;

SH_ATTRIB_ALIASES(Attrib, Attrib)
SH_ATTRIB_ALIASES(Point, Point)
SH_ATTRIB_ALIASES(Vector, Vector)
SH_ATTRIB_ALIASES(Normal, Normal)
SH_ATTRIB_ALIASES(Color, Color)
SH_ATTRIB_ALIASES(TexCoord, TexCoord)
SH_ATTRIB_ALIASES(Position, Position)
#undef SH_ATTRIB_ALIASES
SH_INTERFACE_FAMILY(Attrib)
SH_INTERFACE_FAMILY(Point)
SH_INTERFACE_FAMILY(Vector)
SH_INTERFACE_FAMILY(Normal)
SH_INTERFACE_FAMILY(Color)
SH_INTERFACE_FAMILY(TexCoord)
SH_INTERFACE_FAMILY(Position)
#undef SH_INTERFACE_FAMILY
#undef SH_INTERFACE_ALIASES

}  // namespace sh
