#pragma once
// Matrix<R, C, T>: R rows of C components, recorded as R variables.  `|` is
// the matrix product.  A matrix times a vector of one fewer component than
// it has columns treats the vector homogeneously by its semantic, as Sh
// did: a Point gets w = 1, a Vector w = 0, and a Normal is transformed by
// the cofactor matrix of the upper 3x3 (the inverse transpose up to the
// determinant's positive scale, so it stays a normal under non-uniform scale).
#include <array>

#include "sh/library.hpp"

namespace sh {

template <int R, int C, class T = float>
class Matrix {
 public:
  using Row = Attrib<C, T>;

  Matrix() = default;
  // Row-major components.
  template <Number... U>
    requires(sizeof...(U) == R * C)
  Matrix(U... components) {
    double v[] = {static_cast<double>(components)...};
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c) rows_[r](c) = v[r * C + c];
  }
  static Matrix identity() {
    Matrix m;
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c) m.rows_[r](c) = r == c ? 1 : 0;
    return m;
  }

  Row& operator[](int r) { return rows_.at(r); }
  const Row& operator[](int r) const { return rows_.at(r); }

  Matrix<C, R, T> transpose() const {
    Matrix<C, R, T> t;
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c) t[c](r) = rows_[r](c);
    return t;
  }

 private:
  std::array<Row, R> rows_;
};

// What m | v takes: v of the matrix's scalar type with C components, or
// C - 1 (homogeneous) where the matrix has 4 columns and 3 or more rows.
template <class V, int R, int C, class T>
concept MatrixOperand = AttribLike<V> && std::same_as<typename V::scalar_type, T> &&
                        (V::width == C || (V::width == C - 1 && C == 4 && R >= 3));

template <int R, int C, class T, AttribLike V>
  requires std::same_as<typename V::scalar_type, T> && (V::width == C)
Attrib<R, T, V::semantic> operator|(const Matrix<R, C, T>& m, const V& v) {
  Attrib<R, T, V::semantic> out;
  for (int r = 0; r < R; ++r) out(r) = dot(m[r], v);
  return out;
}

template <int R, int C, class T, AttribLike V>
  requires std::same_as<typename V::scalar_type, T> && (V::width == C - 1) && (C == 4) && (R >= 3)
Attrib<3, T, V::semantic> operator|(const Matrix<R, C, T>& m, const V& v) {
  Attrib<3, T, V::semantic> out;
  if constexpr (V::semantic == Semantic::Normal) {
    // Cofactor rows of the upper 3x3: each is the cross product of the
    // other two rows.
    Attrib<3, T> r0 = m[0](0, 1, 2), r1 = m[1](0, 1, 2), r2 = m[2](0, 1, 2);
    Attrib<3, T> c0 = cross(r1, r2), c1 = cross(r2, r0), c2 = cross(r0, r1);
    out(0) = dot(c0, v);
    out(1) = dot(c1, v);
    out(2) = dot(c2, v);
  } else {
    for (int r = 0; r < 3; ++r) {
      Attrib<1, T> d = dot(m[r](0, 1, 2), v);
      if constexpr (V::semantic == Semantic::Point || V::semantic == Semantic::Position)
        out(r) = d + m[r](3);
      else
        out(r) = d;
    }
  }
  return out;
}

template <int R, int C, class T, AttribLike V>
  requires(!MatrixOperand<V, R, C, T>)
Attrib<R, T, V::semantic> operator|(const Matrix<R, C, T>&, const V&) {
  static_assert(MatrixOperand<V, R, C, T>,
                "sh: Matrix<R, C, T> | v takes v of the matrix's scalar type T with C components, or C - 1 "
                "(homogeneous) where C is 4 and R at least 3 (ints and floats do not mix: convert with .cast<T>())");
  return {};
}

template <int R, int K, int C, class T>
Matrix<R, C, T> operator|(const Matrix<R, K, T>& a, const Matrix<K, C, T>& b) {
  Matrix<R, C, T> out;
  Matrix<C, K, T> bt = b.transpose();
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) out[r](c) = dot(a[r], bt[c]);
  return out;
}

using Matrix2x2f = Matrix<2, 2>;
using Matrix3x3f = Matrix<3, 3>;
using Matrix4x4f = Matrix<4, 4>;
using Matrix3x4f = Matrix<3, 4>;

}  // namespace sh
