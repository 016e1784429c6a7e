// IEEE special values at the edges every backend shares: division by zero,
// roots and logarithms of negatives, inf - inf, signed zeros, denormals,
// overflow to infinity.  Fast math gives these up (see ulp_bounds.hpp), so
// this test holds in precise mode.
#include "harness.hpp"

namespace conformance {
namespace {

TEST_P(Conformance, IeeeSpecialValues) {
  if (fast()) GTEST_SKIP() << "fast math does not promise IEEE special values (documented in ulp_bounds.hpp)";
  using sh::Attrib1f;
  sh::Program p = SH_BEGIN_PROGRAM("specials") {
    sh::Input<Attrib1f> x;
    sh::Input<Attrib1f> y;
    sh::Output<Attrib1f> quo, root, logarithm, power, diff, prod, neg;
    quo = x / y;
    root = sh::sqrt(x);
    logarithm = sh::log(x);
    power = sh::pow(x, y);
    diff = x - y;
    prod = x * y;
    neg = -x;
  } SH_END;
  const float inf = std::numeric_limits<float>::infinity(), fmax = std::numeric_limits<float>::max();
  const float den = std::numeric_limits<float>::denorm_min();
  std::vector<float> xs = {1.f, -1.f, 0.f, inf, -4.f, -2.f, fmax, den, -0.f, 1e-30f};
  std::vector<float> ys = {0.f, 0.f, 0.f, inf, 2.f, 0.5f, 2.f, 0.5f, -0.f, 1e-30f};
  sh::Channel<Attrib1f> cx(xs), cy(ys), quo, root, logarithm, power, diff, prod, neg;
  run(p, {cx, cy}, {quo, root, logarithm, power, diff, prod, neg});
  EXPECT_EQ(quo[0], inf);                          // 1 / 0
  EXPECT_EQ(quo[1], -inf);                         // -1 / 0
  EXPECT_TRUE(std::isnan(quo[2]));                 // 0 / 0
  EXPECT_TRUE(std::isnan(diff[3]));                // inf - inf
  EXPECT_TRUE(std::isnan(root[4]));                // sqrt(-4)
  EXPECT_TRUE(std::isnan(logarithm[4]));           // log(-4)
  EXPECT_EQ(logarithm[2], -inf);                   // log(0)
  EXPECT_TRUE(std::isnan(power[5]));               // pow(-2, 0.5)
  EXPECT_EQ(prod[6], inf);                         // FLT_MAX * 2 overflows
  EXPECT_EQ(prod[7], 0.f);                         // denorm_min * 0.5 rounds to 0
  EXPECT_EQ(quo[7], 2 * den);                      // denormals are kept
  EXPECT_TRUE(std::signbit(neg[2]));               // -(+0) = -0
  EXPECT_TRUE(std::signbit(diff[8]) == false);     // -0 - -0 = +0
  EXPECT_EQ(quo[9], 1.f);                          // tiny / tiny
  EXPECT_EQ(prod[9], 0.f);                         // tiny * tiny underflows
  EXPECT_EQ(power[3], inf);                        // inf^inf
}

TEST_P(Conformance, DenormalsSurviveArithmetic) {
  if (fast()) GTEST_SKIP() << "fast math may flush denormals to zero";
  sh::Program p = SH_BEGIN_PROGRAM("denormals") {
    sh::Input<sh::Attrib1f> x;
    sh::Output<sh::Attrib1f> y;
    y = (x * 0.5f) * 4.0f;
  } SH_END;
  float m = std::numeric_limits<float>::min();
  sh::Channel<sh::Attrib1f> in(std::vector<float>{m, m / 8, -m / 2}), out;
  run(p, {in}, {out});
  EXPECT_EQ(out[0], 2 * m);
  EXPECT_EQ(out[1], m / 4);
  EXPECT_EQ(out[2], -m);
}

}  // namespace
}  // namespace conformance
