// any_lane, the one operation whose answer depends on other elements (the
// SIMD lanes run together): on every backend it is at least the element's
// own answer and at most the answer over kLaneGroupLimit elements either
// side; lanes that do not run the statement (the other side of a
// divergent if) take no part; the interpreter runs each element alone.
#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib2f;

constexpr std::size_t kElements = 300;

// True at a few elements, as far apart as the group limit allows to
// check; everywhere else 0, negative, or NaN.
float x_value(std::size_t e, int c) {
  if ((c == 0 && (e == 5 || e == 130)) || (c == 1 && e == 206)) return c == 0 ? 1.0f : 0.5f;
  const float falsy[] = {0.0f, -1.0f, -0.0f, std::numeric_limits<float>::quiet_NaN()};
  return falsy[(e + static_cast<std::size_t>(c)) % 4];
}

// Elements within the group limit of a true one in component c, among
// those with the parity given (-1: any).
bool true_nearby(std::size_t e, int c, int parity) {
  for (std::size_t k = 0; k < kElements; ++k) {
    std::size_t d = k > e ? k - e : e - k;
    if (d < static_cast<std::size_t>(sh::ir::kLaneGroupLimit) && x_value(k, c) > 0 &&
        (parity < 0 || static_cast<int>(k % 2) == parity))
      return true;
  }
  return false;
}

TEST_P(Conformance, AnyLaneIsTheElementsAnswerOrItsNeighboursAndOnlyRunningOnes) {
  sh::Program p = SH_BEGIN_PROGRAM("any_lane") {
    sh::Input<Attrib2f> x;
    sh::Input<Attrib1f> odd;
    sh::Output<Attrib2f> all, odd_only;
    all = sh::any_lane(x);
    odd_only = sh::ConstAttrib2f(0.0f, 0.0f);
    SH_IF(odd > 0.0f) { odd_only = sh::any_lane(x); } SH_ENDIF;
  } SH_END;
  std::vector<float> xs, odds;
  for (std::size_t e = 0; e < kElements; ++e) {
    xs.insert(xs.end(), {x_value(e, 0), x_value(e, 1)});
    odds.push_back(static_cast<float>(e % 2));
  }
  sh::Channel<Attrib2f> x(xs), all, odd_only;
  sh::Channel<Attrib1f> odd(odds);
  run(p, {x, odd}, {all, odd_only});
  ASSERT_EQ(all.size(), kElements);
  for (std::size_t e = 0; e < kElements; ++e)
    for (int c = 0; c < 2; ++c) {
      std::string where = "element " + std::to_string(e) + " component " + std::to_string(c);
      float own = x_value(e, c) > 0 ? 1.0f : 0.0f, got = all[e * 2 + c];
      EXPECT_TRUE(got == 0.0f || got == 1.0f) << where << ": " << got;
      EXPECT_GE(got, own) << where;
      if (!true_nearby(e, c, -1)) {
        EXPECT_EQ(got, 0.0f) << where << ": no true element near";
      }
      if (mode().backend == "interp") {
        EXPECT_EQ(got, own) << where << ": the interpreter runs elements alone";
      }
      float in_if = odd_only[e * 2 + c];
      if (e % 2 == 0) {
        EXPECT_EQ(in_if, 0.0f) << where << ": did not run the if";
      } else {
        EXPECT_GE(in_if, own) << where;
        if (!true_nearby(e, c, 1)) {
          EXPECT_EQ(in_if, 0.0f) << where << ": only even elements are true near it";
        }
      }
    }
}

}  // namespace
}  // namespace conformance
