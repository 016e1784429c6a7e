// Sh 0.8's conventions that Sh code depends on, as the recorder and the host
// (immediate mode) see them: writes to inputs go to a local copy,
// assignment converts between scalar types, && and || are min and max, any
// and all the largest and smallest component, and the geometric functions
// normalise as Sh's did (docs/sh-differences.md).  The conformance suite
// runs the same conventions on every backend (conformance/sh_conventions.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include <sh/ir/verifier.hpp>
#include <sh/ir/visitor.hpp>
#include <sh/sh.hpp>

namespace {

using namespace sh;

// How many assignments, at any depth, write `id`.
struct WritesTo : ir::Visitor {
  explicit WritesTo(ir::VarId id) : id(id) {}
  using ir::Visitor::visit;
  void visit(const ir::Assign& a) override { count += a.dest == id; }
  ir::VarId id;
  int count = 0;
};

int count_writes_to(const ir::Block& body, ir::VarId id) {
  WritesTo w(id);
  w.visit(body);
  return w.count;
}

TEST(InputWrites, GoToALocalCopyMadeAtTheStart) {
  Program p = SH_BEGIN_PROGRAM("writes_input") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    Attrib1f before = x * 2.0f;
    SH_IF(before > 1.0f) { x += 1.0f; }
    SH_ENDIF;
    r = x + before;
  } SH_END;
  const ir::Program& ir = p.ir();
  ir::VarId input = ir.inputs.at(0);
  EXPECT_EQ(count_writes_to(ir.body, input), 0) << print(p);
  // The copy is the first statement, outside the branch, so the read after
  // SH_ENDIF sees the input where the branch did not run.
  const auto* first = std::get_if<ir::Assign>(&ir.body.at(0).node);
  ASSERT_NE(first, nullptr) << print(p);
  EXPECT_EQ(first->op, ir::Op::Mov);
  EXPECT_EQ(first->args.at(0).var, input);
  EXPECT_EQ(ir.var(first->dest).kind, ir::VarKind::Temp);
  EXPECT_EQ(count_writes_to(ir.body, first->dest), 2) << print(p);  // the copy and x += 1
  EXPECT_NO_THROW(ir::verify(ir));
}

TEST(InputWrites, AProgramThatNeverWritesAnInputHasNoCopy) {
  Program p = SH_BEGIN_PROGRAM("reads_input") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = x + 1.0f;
  } SH_END;
  EXPECT_EQ(print(p).find("= mov %0\n"), std::string::npos) << print(p);
}

TEST(Conversion, AssignmentInAProgramRecordsACast) {
  Program p = SH_BEGIN_PROGRAM("converts") {
    Input<Attrib2f> x;
    Output<Attrib2i> r;
    Output<Attrib1f> back;
    r = x;
    Attrib1i i = x(0);
    back = i;
  } SH_END;
  std::string text = print(p);
  EXPECT_NE(text.find("cast i32 %0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("cast f32"), std::string::npos) << text;
}

TEST(Conversion, AssignmentOnTheHostConvertsAsDefined) {
  Attrib1f f = 2.75f;
  Attrib1i i = f;
  EXPECT_EQ(i.get(), 2);
  f = -7.5f;
  i = f;
  EXPECT_EQ(i.get(), -7);
  f = std::numeric_limits<float>::quiet_NaN();
  i = f;
  EXPECT_EQ(i.get(), 0);
  f = 3e9f;
  i = f;
  EXPECT_EQ(i.get(), std::numeric_limits<std::int32_t>::max());
  f = -std::numeric_limits<float>::infinity();
  i = f;
  EXPECT_EQ(i.get(), std::numeric_limits<std::int32_t>::min());
  Attrib1i seven = 7;
  Attrib1f g = seven;
  EXPECT_EQ(g.get(), 7.0f);
  Attrib3b mask;
  mask = Attrib3f(0.5f, 0.0f, -1.0f);
  EXPECT_TRUE(mask.get(0));
  EXPECT_FALSE(mask.get(1));
  EXPECT_FALSE(mask.get(2));
}

TEST(LogicOperators, AreMinAndMaxOnNumbersAndAndOrOnBools) {
  Attrib1f a = 2.0f, b = 0.5f, m = -1.0f, n = -2.0f;
  EXPECT_EQ((a && b).get(), 0.5f);
  EXPECT_EQ((m || n).get(), -1.0f);
  EXPECT_EQ((a || 3).get(), 3.0f);
  EXPECT_EQ((b && 0).get(), 0.0f);
  EXPECT_EQ((!a).get(), 0.0f);
  EXPECT_EQ((!m).get(), 1.0f);
  Attrib3f v(-1.0f, 0.25f, 0.5f);
  EXPECT_EQ(any(v).get(), 0.5f);
  EXPECT_EQ(all(v).get(), -1.0f);
  Attrib2b t(1, 0);
  EXPECT_EQ(any(t).get(), true);
  EXPECT_EQ(all(t).get(), false);

  Program p = SH_BEGIN_PROGRAM("logic") {
    Input<Attrib1f> x, y;
    Input<Attrib1b> c, d;
    Output<Attrib1f> r;
    Output<Attrib1b> s;
    r = (x && y) + (x || y);
    s = c && d;
  } SH_END;
  std::string text = print(p);
  EXPECT_NE(text.find("min %0, %1"), std::string::npos) << text;
  EXPECT_NE(text.find("max %0, %1"), std::string::npos) << text;
  EXPECT_NE(text.find("and %2, %3"), std::string::npos) << text;
}

// Sh's % (the sign of the divisor) and round (halves toward +Inf), on the
// host and where the constant folder evaluates them.
TEST(ModAndRound, AreShsOnTheHostAndWhenFolded) {
  Attrib1f a = -5.5f, b = 2.0f;
  EXPECT_EQ((a % b).get(), 0.5f);
  EXPECT_EQ(mod(-a, -b).get(), -0.5f);
  Attrib1i i = -7, j = 3;
  EXPECT_EQ((i % j).get(), 2);
  EXPECT_EQ((-i % -j).get(), -2);
  EXPECT_EQ(round(Attrib1f(-2.5f)).get(), -2.0f);
  EXPECT_EQ(round(Attrib1f(0.49999997f)).get(), 0.0f);
  EXPECT_EQ(round(Attrib1f(2.5f)).get(), 3.0f);

  Program p = SH_BEGIN_PROGRAM("folded") {
    Output<Attrib3f> r;
    r = join(join(ConstAttrib1f(-5.5f) % 2.0f, round(ConstAttrib1f(-2.5f))), round(ConstAttrib1f(0.49999997f)));
  } SH_END;
  std::string text = print(optimize(p));
  EXPECT_EQ(text.find("mod"), std::string::npos) << text;
  EXPECT_EQ(text.find("round"), std::string::npos) << text;
  for (const char* folded : {"mov 0.5\n", "mov -2\n", "mov 0\n"}) EXPECT_NE(text.find(folded), std::string::npos) << text;
}

// About a normal of length 5: unnormalised, 2 (a·n) n - a would give z = 245.
TEST(Geometry, ReflectNormalisesTheNormalOnly) {
  Attrib3f a(3.0f, 4.0f, 5.0f), n(0.0f, 0.0f, 5.0f);
  Attrib3f r = reflect(a, n);
  EXPECT_FLOAT_EQ(r.get(0), -3.0f);
  EXPECT_FLOAT_EQ(r.get(1), -4.0f);
  EXPECT_FLOAT_EQ(r.get(2), 5.0f);  // 2 (a·n̂) n̂ - a keeps a's length
}

TEST(Geometry, RefractTakesTheViewVectorAndTheRatioOfTheIndexEntered) {
  // Straight on: the view vector and the normal agree, the ray goes
  // straight through, whatever their lengths.
  Attrib3f v(0.0f, 0.0f, 2.0f), n(0.0f, 0.0f, 3.0f);
  Attrib3f t = refract(v, n, 1.5f);
  EXPECT_NEAR(t.get(0), 0.0f, 1e-7);
  EXPECT_NEAR(t.get(2), -1.0f, 1e-6);
  // At 45 degrees into glass: sin of the angle out is sin(45°) / 1.5.
  Attrib3f slanted(1.0f, 0.0f, 1.0f);
  Attrib3f s = refract(slanted, n, 1.5f);
  EXPECT_NEAR(s.get(0), -std::sqrt(0.5) / 1.5, 1e-6);
  EXPECT_NEAR(s.get(0) * s.get(0) + s.get(2) * s.get(2), 1.0, 1e-6);
  // Leaving glass past the critical angle: total internal reflection, zero.
  Attrib3f grazing(1.0f, 0.0f, 0.2f);
  Attrib3f z = refract(grazing, n, 1.0f / 1.5f);
  EXPECT_EQ(z.get(0), 0.0f);
  EXPECT_EQ(z.get(2), 0.0f);
}

TEST(Geometry, FaceforwardTurnsTheSecondArgument) {
  Attrib3f a(0.0f, 0.0f, -1.0f), b(0.0f, 2.0f, 3.0f);
  Attrib3f f = faceforward(a, b);
  EXPECT_EQ(f.get(1), -2.0f);
  EXPECT_EQ(f.get(2), -3.0f);
  Attrib3f side(1.0f, 0.0f, 0.0f);
  EXPECT_EQ(faceforward(side, b).get(2), -3.0f);  // a·b = 0 is not > 0
}

}  // namespace
