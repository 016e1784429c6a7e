// Each pass on small programs, with golden IR text; every result goes
// through the verifier.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

namespace {

using namespace sh;

ir::Program checked(ir::Program p) {
  ir::verify(p);
  return p;
}

std::string body_of(const ir::Program& p) {
  std::string text = ir::print(p);
  return text.substr(text.find("body\n") + 5);
}

TEST(Passes, ConstantFoldingFoldsArithmeticAndDecidedBranches) {
  Program p = SH_BEGIN_PROGRAM("fold") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    Attrib1f two = 2.0f;
    Attrib1f k = two * 3.0f + 1.0f;
    SH_IF(k > 5.0f) { r = x * k; } SH_ELSE { r = x; } SH_ENDIF;
  } SH_END;
  ir::Program o = checked(optimize(p.ir()));
  EXPECT_EQ(body_of(o), "  %1 = mul %0, 7\n");
}

TEST(Passes, ConstantFoldingSingleStep) {
  Program p = SH_BEGIN_PROGRAM("fold1") {
    Output<Attrib2f> r;
    r = ConstAttrib2f(1.5f, -2.0f) * 2.0f;
  } SH_END;
  ir::Program o = checked(passes::fold_constants(p.ir(), ir::Precision::F32));
  EXPECT_EQ(body_of(o), "  %3 = mov (3, -4)\n  %0 = mov %3\n");
}

TEST(Passes, CopyPropagationSeesThroughMoves) {
  Program p = SH_BEGIN_PROGRAM("copies") {
    Input<Attrib3f> x;
    Output<Attrib1f> r;
    Attrib3f a = x;
    Attrib3f b = a;
    r = b(2) + b(0);
  } SH_END;
  ir::Program o = checked(passes::eliminate_dead_code(passes::propagate_copies(passes::propagate_copies(p.ir()))));
  EXPECT_EQ(body_of(o), "  %4 = add %0.z, %0.x\n  %1 = mov %4\n");
}

TEST(Passes, CopyPropagationLeavesLoopCarriedVariables) {
  Program p = SH_BEGIN_PROGRAM("carried") {
    Input<Attrib1f> n;
    Output<Attrib1f> r;
    Attrib1f i = 0.0f;
    SH_WHILE(i < n) { i += 1.0f; } SH_ENDWHILE;
    r = i;
  } SH_END;
  EXPECT_EQ(body_of(checked(optimize(p.ir()))),
            "  %2 = mov 0\n"
            "  loop test-first while %4 {\n"
            "  header:\n"
            "    %4 = lt %2, %0\n"
            "  body:\n"
            "    %2 = add %2, 1\n"
            "  }\n"
            "  %1 = mov %2\n");
}

TEST(Passes, CommonSubexpressionsComputedOnce) {
  Program p = SH_BEGIN_PROGRAM("cse") {
    Input<Attrib3f> a;
    Input<Attrib3f> b;
    Output<Attrib1f> r;
    r = dot(a, b) * dot(a, b);
  } SH_END;
  EXPECT_EQ(body_of(checked(optimize(p.ir()))),
            "  %3 = mul %0, %1\n"
            "  %4 = add %3.x, %3.y\n"
            "  %5 = add %4, %3.z\n"
            "  %2 = mul %5, %5\n");
}

TEST(Passes, CommonSubexpressionsNotAcrossAWrite) {
  Program p = SH_BEGIN_PROGRAM("cse_write") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    Attrib1f a = x;
    Attrib1f s1 = a * a;
    a += 1.0f;
    Attrib1f s2 = a * a;
    r = s1 + s2;
  } SH_END;
  std::string body = body_of(checked(optimize(p.ir())));
  EXPECT_EQ(std::count(body.begin(), body.end(), '\n'), 5) << body;
  EXPECT_NE(body.find("add"), std::string::npos) << body;
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// What one branch computes or forgets is not what the other sees: x * c
// computed in the then side is not there on the else side, and a * x,
// forgotten in the then side where a changes, is still there on the else
// side.
TEST(Passes, CommonSubexpressionsOfOneBranchAreNotTheOthers) {
  Program p = SH_BEGIN_PROGRAM("cse_branches") {
    Input<Attrib1f> x;
    Input<Attrib1f> c;
    Output<Attrib1f> r;
    Attrib1f a = x * 2.0f;
    Attrib1f s = a * x + 1.0f;
    Attrib1f t = 0.0f, u = 0.0f;
    SH_IF(c > 0.0f) {
      u = x * c + 1.0f;
      a = c;
      t = a * x + 1.0f;
    } SH_ELSE {
      u = x * c + 2.0f;
      t = a * x + 2.0f;
    } SH_ENDIF;
    r = s + t + u;
  } SH_END;
  std::string before = ir::print(p.ir());
  std::string after = ir::print(checked(passes::eliminate_common_subexpressions(p.ir())));
  EXPECT_EQ(count_of(before, "= mul"), 6u) << before;
  EXPECT_EQ(count_of(after, "= mul"), 5u) << after;
  EXPECT_EQ(count_of(after, "= mov") - count_of(before, "= mov"), 1u) << after;
}

TEST(Passes, DeadCodeRemovesUnusedWorkAndEmptyLoops) {
  Program p = SH_BEGIN_PROGRAM("dead") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    Attrib1f unused = sin(x) * 4.0f;
    Attrib1f i = 0.0f;
    SH_WHILE(i < x) { unused += 1.0f; i += 1.0f; } SH_ENDWHILE;
    r = x + 1.0f;
  } SH_END;
  EXPECT_EQ(body_of(checked(optimize(p.ir()))), "  %1 = add %0, 1\n");
}

// A prefetch is kept with what its coordinates need, but a loop that
// would only prefetch goes, with what it alone needed: it would cost its
// iterations (or its runaway cap) for no result.
TEST(Passes, DeadCodeKeepsPrefetchesButNotALoopThatOnlyPrefetches) {
  Table1D<Attrib1f> t(8);
  Program p = SH_BEGIN_PROGRAM("asks") {
    Input<Attrib1i> x;
    Output<Attrib1f> r;
    t.prefetch(x * 3);
    Attrib1i i = x * 5;
    SH_WHILE(i < 100) { t.prefetch(i); } SH_ENDWHILE;
    r = t[x];
  } SH_END;
  EXPECT_EQ(body_of(checked(optimize(p.ir()))),
            "  %3 = mul %0, 3\n"
            "  prefetch #0 %3\n"
            "  %1 = fetch #0 %0\n");
}

TEST(Passes, AlgebraSeamIsTransparentToDeadCode) {
  // q computes two things; p reads only the first: the second disappears.
  Program q = SH_BEGIN_PROGRAM("q") {
    Input<Attrib1f> x;
    Output<Attrib1f> used;
    Output<Attrib1f> ignored;
    used = x * 2.0f;
    ignored = sqrt(x) + exp(x);
  } SH_END;
  Program p = SH_BEGIN_PROGRAM("p") {
    Input<Attrib1f> a;
    Input<Attrib1f> b;
    Output<Attrib1f> r;
    r = a + 1.0f;
    (void)b;
  } SH_END;
  Program composed = p << q;
  ir::verify(composed.ir());
  std::string optimized = ir::print(checked(optimize(composed.ir())));
  EXPECT_EQ(optimized.find("sqrt"), std::string::npos) << optimized;
  EXPECT_EQ(optimized.find("exp"), std::string::npos) << optimized;
  EXPECT_EQ(body_of(optimize(composed.ir())), "  %2 = mul %0, 2\n  %3 = add %2, 1\n");
}

TEST(Passes, FreezeSpecialisesAndRemovesDecidedBranches) {
  Attrib1f use_shadows = 0.0f;
  Attrib1f gain = 3.0f;
  Program p = SH_BEGIN_PROGRAM("shade") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = x * gain;
    SH_IF(use_shadows) { r = r * 0.5f + sin(x); } SH_ENDIF;
  } SH_END;
  std::string general = print_optimized(p);
  EXPECT_NE(general.find("\n  if "), std::string::npos);
  Program frozen = freeze(p, use_shadows.value());
  std::string special = print_optimized(frozen);
  EXPECT_EQ(special.find("\n  if "), std::string::npos) << special;
  EXPECT_EQ(special.find("sin"), std::string::npos) << special;
  EXPECT_NE(special.find("uniform"), std::string::npos) << "gain stays a run-time parameter";
  EXPECT_NE(p.hash(), frozen.hash());
}

TEST(Passes, FoldingRespectsThePrecision) {
  Program p = SH_BEGIN_PROGRAM("third") {
    Output<Attrib1f> r;
    r = ConstAttrib1f(1.0f) / 3.0f * 3.0f - 1.0f;
  } SH_END;
  // In f32 (1/3)*3 rounds to exactly 1; in f64 it does not.
  EXPECT_EQ(body_of(optimize(p.ir(), ir::Precision::F32)), "  %0 = mov 0\n");
  EXPECT_EQ(body_of(optimize(p.ir(), ir::Precision::F64)), "  %0 = mov 0\n");
  Program q = SH_BEGIN_PROGRAM("tenth") {
    Output<Attrib1f> r;
    r = ConstAttrib1f(0.1f) * 3.0f;
  } SH_END;
  EXPECT_NE(body_of(optimize(q.ir(), ir::Precision::F32)), body_of(optimize(q.ir(), ir::Precision::F64)));
}

}  // namespace
