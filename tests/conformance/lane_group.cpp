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

// Inside a varying if, the lanes that took it walk a chain together: its
// node and step count are the same in each of them and die with the if
// (SPMD code keeps them as one value); what each lane picks up on the way,
// what it writes beside the if, and a count some lanes stop early are its
// own.
TEST_P(Conformance, LanesInsideADivergentIfAgreeOnWhatOnlyTheyRead) {
  constexpr int kChain = 7;
  sh::Table1D<sh::Attrib1i> next(kChain + 1);
  sh::Table1D<Attrib1f> value(kChain + 1);
  std::vector<std::int32_t> links;
  std::vector<float> values;
  for (int n = 0; n <= kChain; ++n) {
    links.push_back(n == 5 ? -1 : (n + 3) % (kChain + 1));  // 0 3 6 1 4 7 2 5, then the end
    values.push_back(static_cast<float>(10 * n + 1));
  }
  next.assign(links);
  value.assign(values);
  sh::Program p = SH_BEGIN_PROGRAM("together") {
    sh::Input<Attrib2f> in;  // taken, depth
    sh::Output<sh::Attrib3f> out;  // value at the depth, tag, count
    Attrib1f picked = -1.0f, tag = 0.0f, count = 0.0f;
    SH_IF(in(0) > 0.0f) {
      sh::Attrib1i node = 0, steps = 0;
      SH_WHILE(node >= 0) {
        SH_IF(steps.cast<float>() == in(1)) { picked = value[node]; } SH_ENDIF;
        node = next[node];
        steps += 1;
      } SH_ENDWHILE;
      tag = 7.0f;
      SH_WHILE(count < in(1)) { count += 1.0f; } SH_ENDWHILE;
    } SH_ENDIF;
    out = join(join(picked, tag), count);
  } SH_END;
  std::vector<int> chain;  // the nodes from 0 on
  for (int n = 0; n >= 0; n = links[static_cast<std::size_t>(n)]) chain.push_back(n);
  std::vector<float> ins;
  for (std::size_t e = 0; e < 100; ++e) ins.insert(ins.end(), {e % 3 == 0 ? 0.0f : 1.0f, static_cast<float>(e * 5 % 13)});
  sh::Channel<Attrib2f> input(ins);
  sh::Channel<sh::Attrib3f> out;
  run(p, {input}, {out});
  ASSERT_EQ(out.size(), 100u);
  for (std::size_t e = 0; e < 100; ++e) {
    bool taken = ins[2 * e] > 0;
    auto depth = static_cast<std::size_t>(ins[2 * e + 1]);
    float picked = taken && depth < chain.size() ? values[static_cast<std::size_t>(chain[depth])] : -1.0f;
    EXPECT_EQ(out[3 * e], picked) << "element " << e << " at depth " << depth;
    EXPECT_EQ(out[3 * e + 1], taken ? 7.0f : 0.0f) << "element " << e;
    EXPECT_EQ(out[3 * e + 2], taken ? static_cast<float>(depth) : 0.0f) << "element " << e;
  }
}

}  // namespace
}  // namespace conformance
