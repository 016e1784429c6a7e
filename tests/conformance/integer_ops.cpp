// int32 arithmetic wraps in two's complement; the remainder takes the sign
// of the divisor (Sh's); division and remainder by zero give 0;
// comparisons give 0/1 in the operand's type, && and || are Sh's min and
// max.
#include "harness.hpp"

namespace conformance {
namespace {

using I = std::int32_t;

std::vector<I> int_values() {
  return {0, 1, -1, 2, -2, 7, -7, 100, -100, 123456, -98765, 46341, 65536,
          std::numeric_limits<I>::max(), std::numeric_limits<I>::min(), std::numeric_limits<I>::max() - 1};
}

I wrap(std::int64_t v) { return static_cast<I>(static_cast<std::uint32_t>(static_cast<std::uint64_t>(v))); }

// Sh's remainder, with the sign of b (b != 0).
I floor_remainder(std::int64_t a, std::int64_t b) {
  std::int64_t r = a % b;
  return static_cast<I>(r != 0 && (r < 0) != (b < 0) ? r + b : r);
}

template <int N>
void check_int_ops(const Conformance& t) {
  using A = sh::Attrib<N, I>;
  sh::Program p = SH_BEGIN_PROGRAM("int_ops") {
    sh::Input<A> x;
    sh::Input<A> y;
    sh::Output<A> add, sub, mul, div, mod, neg, abs_, mn, mx, sgn, lt, eq, land;
    add = x + y;
    sub = x - y;
    mul = x * y;
    div = x / y;
    mod = x % y;
    neg = -x;
    abs_ = sh::abs(x);
    mn = sh::min(x, y);
    mx = sh::max(x, y);
    sgn = sh::sign(x);
    lt = x < y;
    eq = x == y;
    land = x && y;
  } SH_END;
  std::vector<I> values = int_values();
  std::size_t n = values.size();
  std::vector<I> xs, ys;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (int c = 0; c < N; ++c) {
        xs.push_back(values[(i + c) % n]);
        ys.push_back(values[(j + c) % n]);
      }
  sh::Channel<A> cx(xs), cy(ys);
  std::vector<sh::Channel<A>> outs(13);
  std::vector<std::shared_ptr<sh::detail::Buffer>> out_buffers(outs.begin(), outs.end());
  sh::run(p, {cx, cy}, out_buffers, t.choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    std::int64_t a = xs[k], b = ys[k];
    I want[] = {wrap(a + b), wrap(a - b), wrap(a * b), b == 0 ? 0 : wrap(a / b), b == 0 ? 0 : floor_remainder(a, b),
                wrap(-a), wrap(a < 0 ? -a : a), static_cast<I>(std::min(a, b)), static_cast<I>(std::max(a, b)),
                a > 0 ? 1 : a < 0 ? -1 : 0, a < b, a == b, static_cast<I>(std::min(a, b))};  // && is Sh's min
    for (int o = 0; o < 13; ++o)
      EXPECT_EQ(outs[o][k], want[o]) << "op " << o << " on (" << a << ", " << b << ") width " << N;
  }
}

TEST_P(Conformance, IntegerOpsEveryWidth) {
  check_int_ops<1>(*this);
  check_int_ops<2>(*this);
  check_int_ops<3>(*this);
  check_int_ops<4>(*this);
}

TEST_P(Conformance, FloatComparisonsAndMasks) {
  using A = sh::Attrib4f;
  sh::Program p = SH_BEGIN_PROGRAM("compare") {
    sh::Input<A> x;
    sh::Input<A> y;
    sh::Output<A> lt, le, gt, ge, eq, ne, land, lor, lnot, sel;
    lt = x < y;
    le = x <= y;
    gt = x > y;
    ge = x >= y;
    eq = x == y;
    ne = x != y;
    land = x && y;
    lor = x || y;
    lnot = !x;
    sel = sh::cond(x, x, y);
  } SH_END;
  std::vector<float> v = {0.f, -0.f, 1.f, -1.f, 2.5f, std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
  std::vector<float> xs, ys;
  for (float a : v)
    for (float b : v) {
      xs.push_back(a);
      ys.push_back(b);
    }
  sh::Channel<A> cx(xs), cy(ys);
  std::vector<sh::Channel<A>> outs(10);
  std::vector<std::shared_ptr<sh::detail::Buffer>> bufs(outs.begin(), outs.end());
  sh::run(p, {cx, cy}, bufs, choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    float a = xs[k], b = ys[k];
    if (fast() && (!std::isfinite(a) || !std::isfinite(b))) continue;
    float want[] = {float(a < b), float(a <= b), float(a > b), float(a >= b), float(a == b), float(a != b),
                    std::fmin(a, b), std::fmax(a, b), float(!(a > 0)), a > 0 ? a : b};  // && and || are Sh's min and max
    for (int o = 0; o < 10; ++o) EXPECT_EQ(ulp_distance(outs[o][k], want[o]), 0u) << "op " << o << " on " << a << ", " << b;
  }
}

TEST_P(Conformance, ConversionsAreDefinedForEveryValue) {
  sh::Program p = SH_BEGIN_PROGRAM("casts") {
    sh::Input<sh::Attrib1f> x;
    sh::Input<sh::Attrib1i> i;
    sh::Output<sh::Attrib1i> to_int;
    sh::Output<sh::Attrib1f> from_int;
    sh::Output<sh::Attrib1b> to_bool;
    sh::Output<sh::Attrib1f> bool_back;
    sh::Output<sh::Attrib1d> to_double;
    to_int = x.cast<std::int32_t>();
    from_int = i.cast<float>();
    to_bool = x.cast<bool>();
    bool_back = x.cast<bool>().cast<float>();
    to_double = x.cast<double>();
  } SH_END;
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> xs = {0.f, -0.f, 1.9f, -1.9f, 2147483648.f, -2147483904.f, 1e20f, -1e20f, inf, -inf, nan, 0.5f,
                           2147483520.f, -2147483648.f};
  std::vector<std::int32_t> is = {0, 1, -1, 16777217, std::numeric_limits<std::int32_t>::max(),
                                  std::numeric_limits<std::int32_t>::min(), 7, -7, 3, 5, 9, 11, 123456789, -123456789};
  sh::Channel<sh::Attrib1f> cx(xs), from_int, bool_back;
  sh::Channel<sh::Attrib1i> ci(is), to_int;
  sh::Channel<sh::Attrib1b> to_bool;
  sh::Channel<sh::Attrib1d> to_double;
  sh::run(p, {cx, ci}, {to_int, from_int, to_bool, bool_back, to_double}, choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    float x = xs[k];
    std::int32_t want = std::isnan(x) ? 0
                        : x >= 2147483647.0f ? std::numeric_limits<std::int32_t>::max()
                        : x <= -2147483648.0f ? std::numeric_limits<std::int32_t>::min()
                                              : static_cast<std::int32_t>(x);
    if (!fast() || std::isfinite(x)) {
      EXPECT_EQ(to_int[k], want) << "int(" << x << ")";
      EXPECT_EQ(to_bool[k], x > 0 ? 1 : 0) << "bool(" << x << ")";
      EXPECT_EQ(bool_back[k], x > 0 ? 1.f : 0.f);
      EXPECT_EQ(ulp_distance(to_double[k], static_cast<double>(x)), 0u);
    }
    EXPECT_EQ(from_int[k], static_cast<float>(is[k])) << "float(" << is[k] << ")";
  }
}

// Doubles hold every int and the halves between them: the edges of the
// range are exact, and truncation toward 0 keeps 2^31 - 0.5 inside it.
TEST_P(Conformance, DoubleToIntTruncatesInsideTheRangeAndSaturatesBeyond) {
  sh::Program p = SH_BEGIN_PROGRAM("double_to_int") {
    sh::Input<sh::Attrib1d> x;
    sh::Output<sh::Attrib1i> to_int;
    to_int = x.cast<std::int32_t>();
  } SH_END;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> xs = {2147483647.5, 2147483647.0, 2147483648.0, -2147483648.5, -2147483648.0, -2147483649.0,
                            -1.5,         1e300,        -1e300,       inf,           -inf,          std::nan("")};
  sh::Channel<sh::Attrib1d> cx(xs);
  sh::Channel<sh::Attrib1i> to_int;
  sh::run(p, {cx}, {to_int}, choice());
  for (std::size_t k = 0; k < xs.size(); ++k) {
    double x = xs[k];
    std::int32_t want = std::isnan(x) ? 0
                        : x >= 2147483648.0 ? std::numeric_limits<std::int32_t>::max()
                        : x <= -2147483649.0 ? std::numeric_limits<std::int32_t>::min()
                                             : static_cast<std::int32_t>(x);
    if (!fast() || std::isfinite(x)) {
      EXPECT_EQ(to_int[k], want) << "int(" << x << ")";
    }
  }
}

}  // namespace
}  // namespace conformance
