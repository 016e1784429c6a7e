// Matrix arithmetic (matrix_algebra.hpp) on every backend, against
// references computed here in double from the same float inputs.
//
// Bounds, as in library_more.cpp: u = 2^-24; a result reached through at
// most k roundings of sums and products is within gamma_k < (k + 1) u times
// the sum of its terms' magnitudes.  For a determinant that sum is the
// permanent of |M| (every term of the Leibniz expansion, unsigned).  One
// IEEE operation is exact to the rounding of its result (0 ulp from the
// float-rounded exact value, in f64 mode too: a double result of float
// operands rounds to the same float); fast math's division may take the
// table's fast bound for div, and its sums 8 times gamma_k.
#include <array>
#include <functional>

#include "harness.hpp"

namespace conformance {
namespace {

constexpr double kU = 0x1p-24;

using Square = std::vector<std::vector<double>>;

Square minor_of(const Square& m, std::size_t i, std::size_t j) {
  Square out;
  for (std::size_t r = 0; r < m.size(); ++r) {
    if (r == i) continue;
    out.emplace_back();
    for (std::size_t c = 0; c < m.size(); ++c)
      if (c != j) out.back().push_back(m[r][c]);
  }
  return out;
}

// Laplace expansion in double; with `magnitude`, every term unsigned (the
// permanent of |m|).
double expand(const Square& m, bool magnitude) {
  if (m.size() == 1) return magnitude ? std::fabs(m[0][0]) : m[0][0];
  double d = 0;
  for (std::size_t j = 0; j < m.size(); ++j) {
    double term = (magnitude ? std::fabs(m[0][j]) : m[0][j]) * expand(minor_of(m, 0, j), magnitude);
    d += magnitude || j % 2 == 0 ? term : -term;
  }
  return d;
}
double det(const Square& m) { return expand(m, false); }
double permanent(const Square& m) { return expand(m, true); }

double gamma(int k, double scale, bool fast) { return (k + 1) * kU * scale * (fast ? 8 : 1); }

// Rows of the 4x4 matrices the determinant test runs on: well and badly
// scaled, a rotation with a translation, the identity, a tridiagonal one,
// and a singular one (its second row twice its first; every leading block
// of two or more rows is singular too).
const std::vector<std::array<float, 16>>& square_cases() {
  static const std::vector<std::array<float, 16>> cases = {
      {4, 1, 0.5f, -1, 0.25f, 3, -1, 0.5f, 1, -0.5f, 5, 2, -2, 1, 0.75f, 6},
      {0.36f, 0.48f, -0.8f, 1, -0.8f, 0.6f, 0, 2, 0.48f, 0.64f, 0.6f, 3, 0, 0, 0, 1},
      {1000, 2, 3, 4, 1, 0.001f, 2, 3, 5, 6, 1000, 7, 0.5f, 0.25f, 0.125f, 0.01f},
      {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
      {2, -1, 0, 0, -1, 2, -1, 0, 0, -1, 2, -1, 0, 0, -1, 2},
      {0.1f, 0.7f, -0.3f, 0.9f, 0.6f, -0.2f, 0.8f, 0.4f, -0.5f, 0.3f, 0.2f, -0.7f, 0.9f, 0.1f, -0.6f, 0.5f},
      {1, 2, 3, 4, 2, 4, 6, 8, 1, 0, 1, 0, 0, 1, 0, 1},
  };
  return cases;
}

// The leading n x n block of case e.
Square leading(std::size_t e, int n) {
  Square m(n, std::vector<double>(n));
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) m[r][c] = square_cases()[e][4 * r + c];
  return m;
}

// What one size's outputs hold, row by row: det, trace, adjoint, inverse.
struct SizeResults {
  int n;
  sh::Channel<sh::Attrib1f> det, trace;
  std::vector<sh::Channel<sh::Attrib4f>> adjoint, inverse;  // rows, padded to 4
};

// Roundings on the way to a determinant of n rows (Laplace along row 0):
// n = 2: a product and a sum; 3: a 2x2 minor (2), the product, 2 sums;
// 4: a 3x3 minor as a triple product (5), the product, 3 sums.
constexpr int kDetRoundings[] = {0, 0, 2, 5, 9};

void check_size(const Conformance& t, const SizeResults& s, std::size_t e) {
  const int n = s.n;
  Square m = leading(e, n);
  double d = det(m), p = permanent(m);
  std::string where = std::to_string(n) + "x" + std::to_string(n) + " case " + std::to_string(e);
  EXPECT_LE(std::fabs(s.det[e] - d), gamma(kDetRoundings[n], p, t.fast())) << "det " << where << ": got " << s.det[e] << ", want " << d;
  double tr = 0, tr_scale = 0;
  for (int i = 0; i < n; ++i) {
    tr += m[i][i];
    tr_scale += std::fabs(m[i][i]);
  }
  EXPECT_LE(std::fabs(s.trace[e] - tr), gamma(n - 1, tr_scale, t.fast())) << "trace " << where;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      // adjoint(m)[i][j] is the cofactor (j, i): an (n-1)-row determinant.
      Square mn = n == 1 ? Square{} : minor_of(m, j, i);
      double adj = n == 1 ? 1 : ((i + j) % 2 ? -det(mn) : det(mn));
      double adj_scale = n == 1 ? 0 : permanent(mn);
      double adj_bound = gamma(kDetRoundings[n - 1], adj_scale, t.fast());
      float got_adj = s.adjoint[i][4 * e + j], got_inv = s.inverse[i][4 * e + j];
      std::string at = "[" + std::to_string(i) + "][" + std::to_string(j) + "] " + where;
      EXPECT_LE(std::fabs(got_adj - adj), adj_bound) << "adjoint" << at << ": got " << got_adj << ", want " << adj;
      if (d == 0) {
        // Division by a zero determinant: IEEE's infinities and NaNs.
        EXPECT_TRUE(t.fast() || !std::isfinite(got_inv)) << "inverse of a singular matrix" << at;
        continue;
      }
      // adj / det with both perturbed, to first order, doubled for the
      // second-order terms; then the quotient's own rounding.
      double inv = adj / d;
      double bound = 2 * (adj_bound + std::fabs(inv) * gamma(kDetRoundings[n], p, t.fast())) / std::fabs(d) +
                     gamma(1, std::fabs(inv), t.fast());
      EXPECT_LE(std::fabs(got_inv - inv), bound) << "inverse" << at << ": got " << got_inv << ", want " << inv;
    }
}

// det, trace, adjoint rows and inverse rows (padded to 4 components) of
// m4's leading N x N block, as outputs in that order.
template <int N>
void put_square(const sh::Matrix<4, 4>& m4) {
  sh::Output<sh::Attrib1f> d, tr;
  std::vector<sh::Output<sh::Attrib4f>> adj_rows(N), inv_rows(N);
  sh::Matrix<N, N> m;
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) m[r](c) = m4[r](c);
  d = sh::det(m);
  tr = sh::trace(m);
  sh::Matrix<N, N> adj = sh::adjoint(m), inv = sh::inverse(m);
  for (int r = 0; r < N; ++r) {
    adj_rows[r] = sh::cast<4>(adj[r]);
    inv_rows[r] = sh::cast<4>(inv[r]);
  }
}

TEST_P(Conformance, MatrixDeterminantTraceAdjointInverseTranspose) {
  sh::Program p = SH_BEGIN_PROGRAM("matrix_det") {
    std::vector<sh::Input<sh::Attrib4f>> in(4);
    sh::Matrix<4, 4> m4;
    sh::Matrix<3, 4> m34;
    for (int r = 0; r < 4; ++r) m4[r] = in[r];
    for (int r = 0; r < 3; ++r) m34[r] = in[r];
    put_square<1>(m4);
    put_square<2>(m4);
    put_square<3>(m4);
    put_square<4>(m4);
    std::vector<sh::Output<sh::Attrib3f>> transposed(4);  // of the leading 3x4 block
    sh::Matrix<4, 3> t = sh::transpose(m34);
    for (int r = 0; r < 4; ++r) transposed[r] = t[r];
  } SH_END;
  const auto& cases = square_cases();
  std::vector<sh::Channel<sh::Attrib4f>> in;
  for (int r = 0; r < 4; ++r) {
    std::vector<float> row;
    for (const auto& m : cases) row.insert(row.end(), m.begin() + 4 * r, m.begin() + 4 * r + 4);
    in.emplace_back(row);
  }
  std::vector<SizeResults> sizes(4);
  std::vector<sh::Channel<sh::Attrib3f>> transposed(4);
  std::vector<std::shared_ptr<sh::detail::Buffer>> inputs(in.begin(), in.end()), outputs;
  for (int n = 1; n <= 4; ++n) {
    SizeResults& s = sizes[n - 1];
    s.n = n;
    s.adjoint.resize(n);
    s.inverse.resize(n);
    outputs.push_back(s.det);
    outputs.push_back(s.trace);
    for (auto& c : s.adjoint) outputs.push_back(c);
    for (auto& c : s.inverse) outputs.push_back(c);
  }
  for (auto& c : transposed) outputs.push_back(c);
  run(p, inputs, outputs);
  for (std::size_t e = 0; e < cases.size(); ++e) {
    for (const SizeResults& s : sizes) check_size(*this, s, e);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(transposed[r][3 * e + c], cases[e][4 * c + r]) << "transpose case " << e;
  }
}

// Scaled identities far from 1: the determinant of 1e-12 I (1e-48) and of
// 1e12 I (1e48) leaves float's range, the inverse does not.
TEST_P(Conformance, InverseOfTinyAndHugeWellConditionedMatrices) {
  sh::Program p = SH_BEGIN_PROGRAM("inverse_scaled") {
    sh::Input<sh::Attrib1f> scale;
    sh::Output<sh::Attrib4f> diagonal;
    sh::Output<sh::Attrib3f> off;
    sh::Matrix<4, 4> m;
    for (int r = 0; r < 4; ++r) {
      m[r] = sh::Attrib4f(0.0f, 0.0f, 0.0f, 0.0f);
      m[r](r) = scale;
    }
    m[0](1) = scale * 0.5f;
    sh::Matrix<4, 4> inv = sh::inverse(m);
    diagonal = sh::join(sh::join(inv[0](0), inv[1](1)), sh::join(inv[2](2), inv[3](3)));
    off = sh::join(inv[0](1), sh::join(inv[1](0), inv[2](3)));
  } SH_END;
  const std::vector<float> scales{1e-12f, 1e12f, 1e-20f, 3e9f, 1.0f};
  sh::Channel<sh::Attrib1f> in(scales);
  sh::Channel<sh::Attrib4f> diagonal;
  sh::Channel<sh::Attrib3f> off;
  run(p, {in}, {diagonal, off});
  for (std::size_t e = 0; e < scales.size(); ++e) {
    double want = 1.0 / scales[e];
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(diagonal[4 * e + k], want, 1e-5 * want) << "scale " << scales[e];
    EXPECT_NEAR(off[3 * e], -0.5 * want, 1e-5 * want) << "scale " << scales[e];  // (1, 0.5; 0, 1)^-1 = (1, -0.5; 0, 1)
    EXPECT_EQ(off[3 * e + 1], 0.0f);
    EXPECT_EQ(off[3 * e + 2], 0.0f);
  }
}

// ---- component-wise arithmetic, the product, compound assignment ----

struct Operand3x3 {
  std::array<std::vector<float>, 3> rows;  // row r of every element
  float at(std::size_t e, int r, int c) const { return rows[r][3 * e + c]; }
};

constexpr std::size_t kElements = 5;

Operand3x3 operand(double base, double step) {
  Operand3x3 m;
  for (int r = 0; r < 3; ++r)
    for (std::size_t e = 0; e < kElements; ++e)
      for (int c = 0; c < 3; ++c) m.rows[r].push_back(float(base + step * ((3 * r + c) * 7 % 9 - 4.0 + 1.5 * e)));
  return m;
}

TEST_P(Conformance, MatrixComponentwiseProductAndCompoundAssignment) {
  using sh::Matrix3x3f;
  // Results, in order: what each computes from a, b, s (f: the float ops).
  enum Result { Sum, Difference, Quotient, CompMul, TimesS, STimes, OverS, PlusTwo, TwoMinus, Negated,
                Product, Bar, AddAssign, SubAssignS, MulAssignTwo, DivAssign, MulAssign, DivAssignS, kResults };
  sh::Program p = SH_BEGIN_PROGRAM("matrix_arith") {
    std::vector<sh::Input<sh::Attrib3f>> in(6);
    sh::Input<sh::Attrib1f> s;
    std::vector<sh::Output<sh::Attrib3f>> out(3 * kResults);
    Matrix3x3f a, b;
    for (int r = 0; r < 3; ++r) {
      a[r] = in[r];
      b[r] = in[3 + r];
    }
    Matrix3x3f c1 = a, c2 = a, c3 = a, c4 = a, c5 = a, c6 = a;
    c1 += b;
    c2 -= s;
    c3 *= 2.f;
    c4 /= b;
    c5 *= b;
    c6 /= s;
    const Matrix3x3f results[kResults] = {a + b, a - b, a / b, sh::comp_mul(a, b), a * s, s * a, a / s,
                                          a + 2.f, 2.f - a, -a, a * b, a | b, c1, c2, c3, c4, c5, c6};
    for (int k = 0; k < kResults; ++k)
      for (int r = 0; r < 3; ++r) out[3 * k + r] = results[k][r];
  } SH_END;
  Operand3x3 a = operand(0.37, 0.61), b = operand(5.25, 0.5);
  std::vector<float> ss;
  for (std::size_t e = 0; e < kElements; ++e) ss.push_back(1.5f + 0.75f * float(e));
  std::vector<sh::Channel<sh::Attrib3f>> in, out(3 * kResults);
  for (int r = 0; r < 3; ++r) in.emplace_back(a.rows[r]);
  for (int r = 0; r < 3; ++r) in.emplace_back(b.rows[r]);
  sh::Channel<sh::Attrib1f> cs(ss);
  std::vector<std::shared_ptr<sh::detail::Buffer>> inputs(in.begin(), in.end()), outputs(out.begin(), out.end());
  inputs.push_back(cs);
  run(p, inputs, outputs);

  UlpBound div = ulp_bound("div");
  for (std::size_t e = 0; e < kElements; ++e)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        float x = a.at(e, r, c), y = b.at(e, r, c), s = ss[e];
        double product = 0, scale = 0;
        for (int k = 0; k < 3; ++k) {
          product += double(a.at(e, r, k)) * b.at(e, k, c);
          scale += std::fabs(double(a.at(e, r, k)) * b.at(e, k, c));
        }
        auto got = [&](Result k) { return out[3 * k + r][3 * e + c]; };
        std::string at = "[" + std::to_string(r) + "][" + std::to_string(c) + "] element " + std::to_string(e);
        const std::pair<Result, float> exact[] = {{Sum, x + y},        {Difference, x - y}, {CompMul, x * y},
                                                  {TimesS, x * s},     {STimes, s * x},     {PlusTwo, x + 2},
                                                  {TwoMinus, 2 - x},   {Negated, -x},       {AddAssign, x + y},
                                                  {SubAssignS, x - s}, {MulAssignTwo, x * 2}};
        for (auto [k, want] : exact) EXPECT_EQ(got(k), want) << "result " << k << at;
        const std::pair<Result, float> quotients[] = {{Quotient, x / y}, {OverS, x / s}, {DivAssign, x / y}, {DivAssignS, x / s}};
        for (auto [k, want] : quotients)
          EXPECT_LE(ulp_distance<float>(got(k), want), fast() ? div.fast : div.precise) << "result " << k << at;
        // The product: a dot product of 3 terms, 3 roundings.
        for (Result k : {Product, Bar, MulAssign})
          EXPECT_LE(std::fabs(got(k) - product), gamma(3, scale, fast())) << "result " << k << at;
        if (!fast()) {
          EXPECT_EQ(got(Product), got(Bar)) << "a * b is a | b" << at;
          EXPECT_EQ(got(MulAssign), got(Product)) << "a *= b is a = a * b" << at;
        }
      }
}

}  // namespace
}  // namespace conformance
