#pragma once
// Arithmetic on matrices, as Sh 0.8 defined it (LibMatrix), expanded row by
// row into the operations of the table while recording:
//   a + b, a - b, a / b   component by component, a and b of one shape
//   a * b                 the matrix product, the same as a | b (Sh's
//                         spelling both ways); comp_mul(a, b) multiplies
//                         component by component (GLSL's matrixCompMult)
//   m op s, s op m        op in + - * /, every component with a scalar s
//                         (a number, or an Attrib of the matrix's type
//                         with one component)
//   -m, and a op= b for each of the above: always a = a op b
//   transpose(m), trace(m), det(m) (Laplace expansion along the first
//   row), adjoint(m) (the transposed matrix of cofactors), inverse(m) =
//   adjoint(m) / det(m), of m scaled by a power of two near its largest
//   entry and scaled back (exact), so that a well-conditioned matrix of
//   tiny or huge entries has a determinant in range (1e-12 I in float:
//   1e-48 unscaled)
// Two departures from Sh, both where Sh contradicted itself: its
// ShMatrix::operator*= multiplied component by component while its
// operator* was the product (here a *= b is a = a * b, so b is square),
// and its adjoint of a 1x1 matrix was the matrix itself (here it is (1), so
// that inverse(m) is (1 / m00)).  The inverse of a singular matrix divides
// by a zero determinant: infinities and NaNs, as IEEE division gives.
#include <array>
#include <concepts>
#include <limits>

#include "sh/matrix.hpp"

namespace sh {

template <class S, class T>
concept MatrixScalar = Number<S> || (AttribLike<S> && S::width == 1 && std::same_as<typename S::scalar_type, T>);

namespace detail {
// The matrix whose row r is row(r).
template <int R, int C, class T, class F>
Matrix<R, C, T> rows_of(const F& row) {
  Matrix<R, C, T> out;
  for (int r = 0; r < R; ++r) out[r] = row(r);
  return out;
}
}  // namespace detail

#define SH_MATRIX_WITH_SCALAR(sym)                                                     \
  template <int R, int C, class T, MatrixScalar<T> S>                                  \
  Matrix<R, C, T> operator sym(const Matrix<R, C, T>& m, const S& s) {                 \
    return detail::rows_of<R, C, T>([&](int r) { return m[r] sym s; });                \
  }                                                                                    \
  template <int R, int C, class T, MatrixScalar<T> S>                                  \
  Matrix<R, C, T> operator sym(const S& s, const Matrix<R, C, T>& m) {                 \
    return detail::rows_of<R, C, T>([&](int r) { return s sym m[r]; });                \
  }                                                                                    \
  template <int R, int C, class T, MatrixScalar<T> S>                                  \
  Matrix<R, C, T>& operator sym##=(Matrix<R, C, T>& m, const S& s) {                   \
    return m = m sym s;                                                                \
  }
#define SH_MATRIX_COMPONENTWISE(sym)                                                   \
  template <int R, int C, class T>                                                     \
  Matrix<R, C, T> operator sym(const Matrix<R, C, T>& a, const Matrix<R, C, T>& b) {   \
    return detail::rows_of<R, C, T>([&](int r) { return a[r] sym b[r]; });             \
  }                                                                                    \
  template <int R, int C, class T>                                                     \
  Matrix<R, C, T>& operator sym##=(Matrix<R, C, T>& a, const Matrix<R, C, T>& b) {     \
    return a = a sym b;                                                                \
  }                                                                                    \
  SH_MATRIX_WITH_SCALAR(sym)
SH_MATRIX_COMPONENTWISE(+)
SH_MATRIX_COMPONENTWISE(-)
SH_MATRIX_COMPONENTWISE(/)
SH_MATRIX_WITH_SCALAR(*)
#undef SH_MATRIX_COMPONENTWISE
#undef SH_MATRIX_WITH_SCALAR

template <int R, int K, int C, class T>
Matrix<R, C, T> operator*(const Matrix<R, K, T>& a, const Matrix<K, C, T>& b) {
  return a | b;
}
template <int R, int C, class T>
Matrix<R, C, T>& operator*=(Matrix<R, C, T>& a, const Matrix<C, C, T>& b) {
  return a = a * b;
}

template <int R, int C, class T>
Matrix<R, C, T> comp_mul(const Matrix<R, C, T>& a, const Matrix<R, C, T>& b) {
  return detail::rows_of<R, C, T>([&](int r) { return a[r] * b[r]; });
}

template <int R, int C, class T>
Matrix<R, C, T> operator-(const Matrix<R, C, T>& m) {
  return detail::rows_of<R, C, T>([&](int r) { return -m[r]; });
}

template <int R, int C, class T>
Matrix<C, R, T> transpose(const Matrix<R, C, T>& m) {
  return m.transpose();
}

template <int N, class T>
Attrib<1, T> trace(const Matrix<N, N, T>& m) {
  Attrib<1, T> t = m[0](0);
  for (int i = 1; i < N; ++i) t = t + m[i](i);
  return t;
}

namespace detail {
// 0 .. N-1 without `skip`.
template <int N>
std::array<int, N - 1> all_but(int skip) {
  std::array<int, N - 1> out{};
  for (int i = 0, k = 0; i < N; ++i)
    if (i != skip) out[k++] = i;
  return out;
}

// The determinant of m without row i and column j (N from 2 to 4).
template <int N, class T>
Attrib<1, T> minor_det(const Matrix<N, N, T>& m, int i, int j) {
  std::array<int, N - 1> r = all_but<N>(i), c = all_but<N>(j);
  if constexpr (N == 2) {
    return m[r[0]](c[0]);
  } else if constexpr (N == 3) {
    return m[r[0]](c[0]) * m[r[1]](c[1]) - m[r[0]](c[1]) * m[r[1]](c[0]);
  } else {
    static_assert(N == 4, "sh: det, adjoint and inverse take square matrices of 1 to 4 rows");
    auto row = [&](int k) { return m[r[k]](c[0], c[1], c[2]); };
    return dot(row(0), cross(row(1), row(2)));
  }
}

template <int N, class T>
Attrib<1, T> cofactor(const Matrix<N, N, T>& m, int i, int j) {
  Attrib<1, T> d = minor_det(m, i, j);
  if ((i + j) % 2) return -d;
  return d;
}
}  // namespace detail

template <int N, class T>
Attrib<1, T> det(const Matrix<N, N, T>& m) {
  if constexpr (N == 1) {
    return m[0](0);
  } else {
    Attrib<1, T> d = m[0](0) * detail::cofactor(m, 0, 0);
    for (int j = 1; j < N; ++j) d = d + m[0](j) * detail::cofactor(m, 0, j);
    return d;
  }
}

template <int N, class T>
Matrix<N, N, T> adjoint(const Matrix<N, N, T>& m) {
  Matrix<N, N, T> a;
  if constexpr (N == 1) {
    a[0] = 1;
  } else {
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) a[i](j) = detail::cofactor(m, j, i);
  }
  return a;
}

template <int N, class T>
Matrix<N, N, T> inverse(const Matrix<N, N, T>& m) {
  Attrib<1, T> largest = max_component(abs(m[0]));
  for (int r = 1; r < N; ++r) largest = max(largest, max_component(abs(m[r])));
  Attrib<1, T> s = exp2(-floor(log2(largest)));
  s = cond(largest > T(0) && largest < std::numeric_limits<T>::infinity(), s, Attrib<1, T>(T(1)));
  Matrix<N, N, T> scaled = m * s;
  return adjoint(scaled) / det(scaled) * s;
}

}  // namespace sh
