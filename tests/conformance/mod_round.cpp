// Sh 0.8's `%` and round on every backend and mode (docs/sh-differences.md):
// the remainder takes the sign of the divisor (a - b floor(a / b), exact
// but for one rounding), with the defined integer results by 0 and -1, and
// round takes halves toward +Inf, exactly where floor(a + 0.5) would round.
// op_table.cpp compares both against the reference over the extreme
// values; these cases say what the reference must be.
#include <algorithm>

#include "harness.hpp"

namespace conformance {
namespace {

template <class T>
struct Case {
  T a, b, want;
  bool special;  // an infinity, NaN or a value fast math gives up
};

template <class T>
bool same(T got, T want) {
  return std::isnan(want) ? std::isnan(got) : got == want;
}

template <class T>
std::vector<Case<T>> float_mod_cases() {
  using L = std::numeric_limits<T>;
  const T inf = L::infinity(), nan = L::quiet_NaN();
  return {
      {T(5.5), T(2), T(1.5), false},
      {T(-5.5), T(2), T(0.5), false},
      {T(5.5), T(-2), T(-0.5), false},
      {T(-5.5), T(-2), T(-1.5), false},
      {T(7.5), T(-2), T(-0.5), false},
      {T(-4), T(2), T(0), false},
      {T(4), T(-2), T(0), false},
      // 1e10 is exact in float and leaves 1 divided by 3.
      {T(-1e10), T(3), T(2), false},
      {T(1e10), T(-3), T(-2), false},
      {T(1e10), T(3), T(1), false},
      // One rounding of the exact remainder: 1 - 0.1 in T.
      {T(-0.1), T(1), T(1) - T(0.1), false},
      {T(1e-20), T(3), T(1e-20), false},
      // The exact 3 - 1e-20 rounds to the divisor itself (Sh's and GLSL's
      // a - b floor(a / b) gives 3 too).
      {T(-1e-20), T(3), T(3), false},
      {T(1e-20), T(-3), T(-3), false},
      {L::max(), T(-1), T(0), false},
      {L::lowest(), T(2), T(0), false},
      {T(1), T(0), nan, true},
      {T(-1), T(0), nan, true},
      {T(0), T(0), nan, true},
      {inf, T(2), nan, true},
      {-inf, T(-2), nan, true},
      {T(1), inf, T(1), true},
      {T(-1), inf, inf, true},
      {T(1), -inf, -inf, true},
      {T(-1), -inf, T(-1), true},
      {nan, T(1), nan, true},
      {T(1), nan, nan, true},
      {-L::denorm_min(), T(1), T(1), true},
      // Exact: the largest denormal, not -min.
      {L::denorm_min(), -L::min(), -(L::min() - L::denorm_min()), true},
  };
}

template <class T>
std::vector<Case<T>> round_cases() {
  using L = std::numeric_limits<T>;
  const T below_half = std::nextafter(T(0.5), T(0));  // 0.49999997f, floor(a + 0.5) gives 1
  const T odd = T(1) / L::epsilon() + T(1);            // 2^23 + 1 in float: a + 0.5 rounds to the even 2^23 + 2
  const T half_past = T(1) / L::epsilon() / T(2) + T(0.5);  // 2^22 + 0.5 in float
  return {
      {T(-2.5), 0, T(-2), false},      {T(-1.5), 0, T(-1), false},    {T(-0.5), 0, T(0), false},
      {T(0.5), 0, T(1), false},        {T(1.5), 0, T(2), false},      {T(2.5), 0, T(3), false},
      {below_half, 0, T(0), false},    {-below_half, 0, T(0), false}, {T(0.75), 0, T(1), false},
      {T(-0.75), 0, T(-1), false},     {odd, 0, odd, false},          {-odd, 0, -odd, false},
      {half_past, 0, half_past + T(0.5), false},
      {-half_past, 0, -half_past + T(0.5), false},
      {T(1e30), 0, T(1e30), false},    {T(-1e30), 0, T(-1e30), false}, {T(0), 0, T(0), false},
      {L::max(), 0, L::max(), false},  {L::lowest(), 0, L::lowest(), false},
      {T(-1e-30), 0, T(0), true},      {L::denorm_min(), 0, T(0), true},
      {L::infinity(), 0, L::infinity(), true},
      {-L::infinity(), 0, -L::infinity(), true},
      {L::quiet_NaN(), 0, L::quiet_NaN(), true},
  };
}

template <class T>
void check_float(const Conformance& t) {
  using A = sh::Attrib<1, T>;
  sh::Program p = SH_BEGIN_PROGRAM("mod_round") {
    sh::Input<A> a, b;
    sh::Output<A> m, r;
    m = a % b;
    r = sh::round(a);
  } SH_END;
  std::vector<Case<T>> mods = float_mod_cases<T>(), rounds = round_cases<T>();
  std::size_t n = std::max(mods.size(), rounds.size());
  std::vector<T> as(2 * n, T(1)), bs(2 * n, T(1));
  for (std::size_t k = 0; k < mods.size(); ++k) {
    as[k] = mods[k].a;
    bs[k] = mods[k].b;
  }
  for (std::size_t k = 0; k < rounds.size(); ++k) as[n + k] = rounds[k].a;
  sh::Channel<A> ca(as), cb(bs), m, r;
  sh::run(p, {ca, cb}, {m, r}, t.choice());
  for (std::size_t k = 0; k < mods.size(); ++k) {
    const Case<T>& c = mods[k];
    if (t.fast() && c.special) continue;
    EXPECT_TRUE(same<T>(m[k], c.want)) << c.a << " % " << c.b << ": got " << m[k] << ", want " << c.want;
  }
  for (std::size_t k = 0; k < rounds.size(); ++k) {
    const Case<T>& c = rounds[k];
    if (t.fast() && c.special) continue;
    EXPECT_TRUE(same<T>(r[n + k], c.want)) << "round(" << c.a << "): got " << r[n + k] << ", want " << c.want;
  }
}

TEST_P(Conformance, FloatModAndRoundAreShs) { check_float<float>(*this); }
TEST_P(Conformance, DoubleModAndRoundAreShs) { check_float<double>(*this); }

// Divisors read from a stream (legalisation guards them) and constant ones
// (3 needs no guard; 0 and -1 do).
TEST_P(Conformance, IntegerModTakesTheSignOfTheDivisor) {
  using I = std::int32_t;
  const I lo = std::numeric_limits<I>::min(), hi = std::numeric_limits<I>::max();
  sh::Program p = SH_BEGIN_PROGRAM("int_mod") {
    sh::Input<sh::Attrib1i> a, b;
    sh::Output<sh::Attrib1i> m, by_three, by_zero, by_minus_one;
    m = a % b;
    by_three = a % 3;
    by_zero = a % 0;
    by_minus_one = a % -1;
  } SH_END;
  struct IntCase {
    I a, b, want;
  };
  const IntCase cases[] = {
      {7, 3, 1},        {-7, 3, 2},      {7, -3, -2},          {-7, -3, -1},          {6, -3, 0},
      {-6, 3, 0},       {5, 0, 0},       {-5, 0, 0},           {lo, -1, 0},           {lo, 1, 0},
      {lo, 3, 1},       {lo, 2, 0},      {lo, hi, hi - 1},     {hi, lo, -1},          {-1, lo, -1},
      {1, lo, lo + 1},  {hi, -2, -1},    {hi, 0, 0},           {lo, 0, 0},            {0, -5, 0},
  };
  std::vector<I> as, bs;
  for (const IntCase& c : cases) {
    as.push_back(c.a);
    bs.push_back(c.b);
  }
  sh::Channel<sh::Attrib1i> ca(as), cb(bs), m, by_three, by_zero, by_minus_one;
  run(p, {ca, cb}, {m, by_three, by_zero, by_minus_one});
  for (std::size_t k = 0; k < as.size(); ++k) {
    const IntCase& c = cases[k];
    EXPECT_EQ(m[k], c.want) << c.a << " % " << c.b;
    std::int64_t c_remainder = c.a % 3;
    EXPECT_EQ(by_three[k], c_remainder < 0 ? c_remainder + 3 : c_remainder) << c.a << " % 3";
    EXPECT_EQ(by_zero[k], 0) << c.a << " % 0";
    EXPECT_EQ(by_minus_one[k], 0) << c.a << " % -1";
  }
}

}  // namespace
}  // namespace conformance
