// Uniforms change between runs without recompiling; composed programs
// (<<, &, bind) run as one.
#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib3f;

TEST_P(Conformance, UniformChangesReachTheKernelWithoutRecompiling) {
  Attrib1f scale = 2.0f;
  Attrib3f offset(1.f, 2.f, 3.f);
  sh::Program p = SH_BEGIN_PROGRAM("scaled") {
    sh::Input<Attrib3f> x;
    sh::Output<Attrib3f> r;
    r = x * scale + offset;
  } SH_END;
  sh::Channel<Attrib3f> in(std::vector<float>{1, 1, 1, 2, 3, 4}), out;
  sh::RunStats first = run(p, {in}, {out});
  EXPECT_EQ(out[0], 3.f);
  EXPECT_EQ(out[5], 11.f);
  scale = 10.0f;
  offset(1) = -5.0f;
  sh::RunStats second = run(p, {in}, {out});
  EXPECT_FALSE(second.compiled) << "a new uniform value must not recompile";
  EXPECT_EQ(out[0], 11.f);
  EXPECT_EQ(out[1], 5.f);
  EXPECT_EQ(out[4], 25.f);
  (void)first;
}

TEST_P(Conformance, AlgebraConnectsCombinesAndBinds) {
  Attrib1f k = 3.0f;
  sh::Program square = SH_BEGIN_PROGRAM("square") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> y;
    y = x * x;
  } SH_END;
  sh::Program plus_k = SH_BEGIN_PROGRAM("plus_k") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> y;
    y = x + k;
  } SH_END;
  sh::Program sub = SH_BEGIN_PROGRAM("sub") {
    sh::Input<Attrib1f> a;
    sh::Input<Attrib1f> b;
    sh::Output<Attrib1f> d;
    d = a - b;
  } SH_END;
  sh::Program chained = plus_k << square;        // x*x + k
  sh::Program side = square & plus_k;            // (x*x, y + k)
  sh::Program bound = sub << k;                  // k - b
  sh::Channel<Attrib1f> xs(std::vector<float>{1, 2, -3}), a, b, c, d;
  run(chained, {xs}, {a});
  run(side, {xs, xs}, {b, c});
  run(bound, {xs}, {d});
  for (int i = 0; i < 3; ++i) {
    float x = xs[i];
    EXPECT_EQ(a[i], x * x + 3);
    EXPECT_EQ(b[i], x * x);
    EXPECT_EQ(c[i], x + 3);
    EXPECT_EQ(d[i], 3 - x);
  }
}

// A composed program reads each part's tables with the edge mode the part
// was recorded with, even where the table's setting changed since, or the
// other part reads the same table with another.
TEST_P(Conformance, AlgebraKeepsEachPartsEdgeMode) {
  sh::Table1D<Attrib1f> t(4);
  t.assign(std::vector<float>{1, 2, 3, 4});
  auto shifted = [&](const char* name, int by) {
    return SH_BEGIN_PROGRAM(name) {
      sh::Input<sh::Attrib1i> i;
      sh::Output<Attrib1f> r;
      r = t[i + by];
    } SH_END;
  };
  t.edge(sh::Edge::Clamp);
  sh::Program clamped = shifted("clamped", 2);
  t.edge(sh::Edge::Repeat);
  sh::Program wrapped = shifted("wrapped", 2);
  sh::Program both = clamped & wrapped;
  sh::Channel<sh::Attrib1i> is(std::vector<std::int32_t>{0, 1, 2, 3});
  sh::Channel<Attrib1f> alone_c, alone_w, c, w;
  run(clamped, {is}, {alone_c});
  run(wrapped, {is}, {alone_w});
  run(both, {is, is}, {c, w});
  EXPECT_EQ(alone_c.values(), (std::vector<float>{3, 4, 4, 4}));
  EXPECT_EQ(alone_w.values(), (std::vector<float>{3, 4, 1, 2}));
  EXPECT_EQ(c.values(), alone_c.values());
  EXPECT_EQ(w.values(), alone_w.values());
}

TEST_P(Conformance, InOutChannelIsReadAndWritten) {
  sh::Program p = SH_BEGIN_PROGRAM("accumulate") {
    sh::InOut<Attrib1f> acc;
    sh::Input<Attrib1f> x;
    acc = acc + x;
  } SH_END;
  sh::Channel<Attrib1f> acc(std::vector<float>{1, 2, 3}), x(std::vector<float>{10, 20, 30});
  run(p, {acc, x}, {acc});
  run(p, {acc, x}, {acc});
  EXPECT_EQ(acc[0], 21.f);
  EXPECT_EQ(acc[2], 63.f);
}

TEST_P(Conformance, EmptyStreamRunsNothing) {
  sh::Program p = SH_BEGIN_PROGRAM("empty") {
    sh::Input<Attrib1f> x;
    sh::Output<Attrib1f> y;
    y = x + 1.0f;
  } SH_END;
  sh::Channel<Attrib1f> in, out;
  sh::RunStats s = run(p, {in}, {out});
  EXPECT_EQ(s.elements, 0u);
  EXPECT_EQ(out.size(), 0u);
}

}  // namespace
}  // namespace conformance
