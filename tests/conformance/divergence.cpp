// Neighbouring elements that take different paths through nested loops,
// breaks, continues and table reads, at stream lengths around every SIMD
// width: what an SPMD backend's masks and stream tail must get right, and
// every other backend too.
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

}  // namespace
}  // namespace conformance
