// Neighbouring elements that take different paths through nested loops,
// breaks, continues and table reads, at stream lengths around every SIMD
// width: what an SPMD backend's masks and stream tail must get right, and
// every other backend too.
#include <algorithm>
#include <limits>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib2f;
using sh::Attrib3f;

constexpr int kTableSize = 8;

struct Expected {
  float sum = 0, steps = 0;
};

// The program below, written in C++.
Expected reference(float n, float stop, float offset) {
  Expected e;
  for (float i = 0; i < n; i += 1) {
    if (i > stop) break;
    if (std::fmod(i, 3.f) == 1) continue;
    for (float j = 0; j < i; j += 1) {
      int index = std::clamp(static_cast<int>(j + offset), 0, kTableSize - 1);
      e.sum += static_cast<float>(index + 1);
      if (e.sum > 60) break;
    }
    e.steps += 1;
  }
  if (e.sum > 30) e.steps = -e.steps;
  return e;
}

TEST_P(Conformance, DivergentNeighboursAtEveryStreamLength) {
  sh::Table1D<Attrib1f> values(kTableSize);
  std::vector<float> ramp;
  for (int i = 0; i < kTableSize; ++i) ramp.push_back(static_cast<float>(i + 1));
  values.assign(ramp);
  sh::Program p = SH_BEGIN_PROGRAM("divergent") {
    sh::Input<Attrib3f> v;  // trip count, break point, table offset
    sh::Output<Attrib2f> r;
    Attrib1f sum = 0.0f, steps = 0.0f;
    SH_FOR(Attrib1f i = 0.0f, i < v(0), i += 1.0f) {
      SH_BREAK(i > v(1));
      SH_CONTINUE(i % 3.0f == 1.0f);
      SH_FOR(Attrib1f j = 0.0f, j < i, j += 1.0f) {
        sum += values[j + v(2)];
        SH_BREAK(sum > 60.0f);
      } SH_ENDFOR;
      steps += 1.0f;
    } SH_ENDFOR;
    SH_IF(sum > 30.0f) { steps = -steps; } SH_ENDIF;
    r = join(sum, steps);
  } SH_END;
  for (std::size_t length : {1, 3, 4, 5, 8, 15, 16, 17, 31, 33, 100, 1031}) {
    std::vector<float> in;
    for (std::size_t k = 0; k < length; ++k)
      in.insert(in.end(), {static_cast<float>(k * 7 % 13), static_cast<float>(k * 5 % 11), static_cast<float>(k % 9) - 2});
    sh::Channel<Attrib3f> input(in);
    sh::Channel<Attrib2f> out;
    run(p, {input}, {out});
    ASSERT_EQ(out.size(), length);
    for (std::size_t k = 0; k < length; ++k) {
      Expected e = reference(in[3 * k], in[3 * k + 1], in[3 * k + 2]);
      ASSERT_EQ(out[2 * k], e.sum) << "element " << k << " of " << length;
      ASSERT_EQ(out[2 * k + 1], e.steps) << "element " << k << " of " << length;
    }
  }
}

// Tests chained with Sh's && (min), || (max) and !, written under a
// divergent if, steering a loop and read back as numbers: an SPMD backend
// that holds such values as masks must give the 0 and 1 of the reference,
// NaN comparing false.
struct Truths {
  float both, either, low, count;
};

Truths truths_reference(float a, float b) {
  float low = a < b, both = std::min(low, static_cast<float>(a > -2));
  float either = std::max(static_cast<float>(!(both > 0)), static_cast<float>(b == 3));
  if (a > 0) both = std::min(either, static_cast<float>(!(low > 0)));
  float count = 0;
  while (std::min(static_cast<float>(count < 5), std::max(static_cast<float>(count < b), low)) > 0) count += 1;
  return {both, either, low, count};
}

TEST_P(Conformance, TestsChainedWithAndOrNotKeepTheirZeroOneValues) {
  sh::Program p = SH_BEGIN_PROGRAM("truths") {
    sh::Input<Attrib2f> v;
    sh::Output<sh::Attrib4f> r;
    Attrib1f low = v(0) < v(1);
    Attrib1f both = low && v(0) > -2.0f;
    Attrib1f either = !both || v(1) == 3.0f;
    Attrib1f count = 0.0f;
    SH_IF(v(0) > 0.0f) { both = either && !low; } SH_ENDIF;
    SH_WHILE(count < 5.0f && (count < v(1) || low)) { count += 1.0f; } SH_ENDWHILE;
    r = join(join(both, either), join(low, count));
  } SH_END;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> values = {-3, -1, 0, 0.5f, 1, 3, 4};
  if (!fast()) values.push_back(nan);  // fast math assumes no NaN
  std::vector<float> in;
  for (float a : values)
    for (float b : values) in.insert(in.end(), {a, b});
  sh::Channel<Attrib2f> input(in);
  sh::Channel<sh::Attrib4f> out;
  run(p, {input}, {out});
  for (std::size_t k = 0; k < in.size() / 2; ++k) {
    Truths t = truths_reference(in[2 * k], in[2 * k + 1]);
    const float expected[4] = {t.both, t.either, t.low, t.count};
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(out[4 * k + c], expected[c]) << "a " << in[2 * k] << ", b " << in[2 * k + 1] << ", component " << c;
  }
}

// Every lane of a batch may leave a loop while its body goes on (a break
// under an if the lanes agree on, or one every lane takes): a loop further
// down the body, steered by values the lanes agree on, must not run then,
// as no lane holds the values it would test.  Here it would never end.
TEST_P(Conformance, NoLoopRunsAfterEveryLaneLeft) {
  sh::Program p = SH_BEGIN_PROGRAM("all_left") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib2f> out;
    Attrib1f acc = 0.0f, votes = 0.0f;
    sh::Attrib1i i = 0;
    SH_WHILE(i.cast<float>() < x) {
      SH_BREAK(i >= 2);
      sh::Attrib1i k = 0;
      SH_WHILE(k != 1 - i) { k += 1; } SH_ENDWHILE;
      acc += k.cast<float>();
      i += 1;
    } SH_ENDWHILE;
    SH_WHILE(x > 0.0f) {
      SH_BREAK(x > 1.0f);
      Attrib1f j = x;
      SH_DO { j += 1.0f; } SH_UNTIL(sh::any_lane(j > 3.0f));
      votes += j;
      SH_BREAK();
    } SH_ENDWHILE;
    out = join(acc, votes);
  } SH_END;
  std::vector<float> xs;
  for (std::size_t e = 0; e < 37; ++e) xs.push_back(5.0f + static_cast<float>(e % 3));
  sh::Channel<Attrib1f> in(xs);
  sh::Channel<Attrib2f> out;
  run(p, {in}, {out});
  ASSERT_EQ(out.size(), xs.size());
  for (std::size_t e = 0; e < xs.size(); ++e) {
    EXPECT_EQ(out[2 * e], 1.0f) << "element " << e;
    EXPECT_EQ(out[2 * e + 1], 0.0f) << "element " << e;
  }
}

}  // namespace
}  // namespace conformance
