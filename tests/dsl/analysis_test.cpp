// The cost analysis: counts by class on the paper's ray-plane kernel, per
// loop iteration, and the critical path under parallel units.
#include <gtest/gtest.h>

#include <limits>
#include <set>

#include <sh/sh.hpp>

#include "../../examples/ray_plane.hpp"

namespace {

using namespace sh;
using analysis::Unit;

TEST(Analysis, RayPlaneCountsAsThePaperDoes) {
  analysis::OpCounts c = analysis::count_operations(ray_plane_program().ir()).outside_loops;
  EXPECT_EQ(c[Unit::Mul], 9u);
  EXPECT_EQ(c[Unit::Add], 7u);
  EXPECT_EQ(c[Unit::Div], 1u);
  EXPECT_EQ(c[Unit::Negate], 2u);
  EXPECT_EQ(c.total(), 19u);
}

TEST(Analysis, CriticalPathUnderParallelMultipliers) {
  ir::Program p = ray_plane_program().ir();
  analysis::Machine m;
  m.latency = {4, 1, 9, 1, 1, 1, 1};  // the paper's t_m = 4, t_a = 1; t_d = 9, t_l = 1
  m.one_at_a_time = true;
  EXPECT_EQ(analysis::critical_path(p, m), 54u) << "9*4 + 7*1 + 9 + 2*1, one operation at a time";
  m.one_at_a_time = false;
  m.units = {1, 1, 1, 1, 1, 1, 1};
  std::uint64_t one = analysis::critical_path(p, m);
  // One unit per class: nine multiplications in a row (36 cycles), then the
  // last product's add and the division (1 + 9), everything else hidden.
  EXPECT_EQ(one, 46u);
  m.units = {3, 1, 1, 1, 1, 1, 1};
  EXPECT_EQ(analysis::critical_path(p, m), 23u);
  m.units = {9, 3, 1, 1, 1, 1, 1};
  EXPECT_EQ(analysis::critical_path(p, m), 18u) << "the paper's 1 t_m + 3 t_a + t_d + 2 t_l";
  m.units = {0, 0, 0, 0, 0, 0, 0};
  EXPECT_EQ(analysis::critical_path(p, m), 18u) << "the dependence chain itself";
  // A negative latency had wrapped to 2^64 - 1 cycles, a negative unit
  // count read as unbounded: both are errors naming the class.
  m.latency[0] = -1;
  EXPECT_THROW(analysis::critical_path(p, m), Error);
  m.latency[0] = 4;
  m.units[0] = -2;
  try {
    analysis::critical_path(p, m);
    ADD_FAILURE() << "a negative unit count was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("class 0 has -2 units"), std::string::npos) << e.what();
  }
}

// Nothing waits on a prefetch: straight-line code that asks for an
// element ahead has the critical path it has without the ask.
TEST(Analysis, APrefetchIsNotOnTheCriticalPath) {
  Table1D<Attrib1f> t(4);
  auto program = [&](bool ask) {
    return SH_BEGIN_PROGRAM("asks") {
      InputAttrib1i i;
      OutputAttrib1f y;
      if (ask) t.prefetch(i + 1);
      y = t[i] * 3.0f + 1.0f;
    } SH_END;
  };
  analysis::Machine m;
  m.latency = {4, 1, 9, 1, 1, 1, 1};
  std::uint64_t without = analysis::critical_path(program(false).ir(), m);
  EXPECT_GT(without, 0u);
  EXPECT_EQ(analysis::critical_path(program(true).ir(), m), without);
}

// A read of a local array at an index known only as the program runs
// waits on every store to it: here the slow division stored at slot 0.
TEST(Analysis, ALocalArrayReadWaitsOnEveryStoreToIt) {
  Program p = SH_BEGIN_PROGRAM("slots") {
    InputAttrib1f x;
    InputAttrib1i i;
    OutputAttrib1f y;
    LocalArray<Attrib1f> slots(2, "slots");
    slots.store(0, x / 3.0f);
    slots.store(1, x + 1.0f);
    y = slots[i] * 2.0f;
  } SH_END;
  analysis::Machine m;
  m.latency = {4, 1, 9, 1, 1, 1, 1};
  m.units = {0, 0, 0, 0, 0, 0, 0};
  EXPECT_GE(analysis::critical_path(p.ir(), m), 13u) << "the division's 9 cycles, then the read, then the product's 4";
}

TEST(Analysis, LoopsReportPerIterationAndConstantTripCounts) {
  Program p = SH_BEGIN_PROGRAM("loops") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
    SH_FOR(Attrib1f i = 0.0f, i < 10.0f, i += 1.0f) { y = y * x + 1.0f; } SH_ENDFOR;
    SH_WHILE(y > 1.0f) { y = sqrt(y); } SH_ENDWHILE;
  } SH_END;
  analysis::Cost c = analysis::count_operations(optimize(p.ir()));
  ASSERT_EQ(c.loops.size(), 2u);
  EXPECT_EQ(c.loops[0].trips, std::optional<std::uint64_t>(10));
  EXPECT_EQ(c.loops[0].per_iteration[Unit::Mul], 1u);
  EXPECT_EQ(c.loops[0].per_iteration[Unit::Add], 2u);  // y*x+1 and the counter
  EXPECT_EQ(c.loops[0].per_iteration[Unit::Compare], 1u);
  EXPECT_EQ((*c.loops[0].total)[Unit::Mul], 10u);
  EXPECT_FALSE(c.loops[1].trips.has_value()) << "a data-dependent loop has no total";
  EXPECT_EQ(c.loops[1].per_iteration[Unit::Transcendental], 1u);
  EXPECT_EQ(c.outside_loops[Unit::Mul], 10u) << "the counted loop folds into the program's total";
  std::string text = analysis::describe(c);
  EXPECT_NE(text.find("10 iterations"), std::string::npos) << text;
  EXPECT_NE(text.find("depend on the data"), std::string::npos) << text;
}

// A counter stepped only in some passes (under an if, in an inner loop,
// past a continue) or bounded by an infinity or NaN gives no count: they
// had given 100 for 10 passes, 10 for 15, 0 for a runaway loop and 2^63.
TEST(Analysis, LoopsWhoseStepsTheIrDoesNotShowHaveNoTripCount) {
  Program p = SH_BEGIN_PROGRAM("uncounted") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
    Attrib1f i = 0.0f, j = 0.0f, k = 0.0f, m = 0.0f, n = 0.0f;
    SH_WHILE(i < 100.0f) {
      SH_FOR(Attrib1f a = 0.0f, a < 10.0f, a += 1.0f) { i += 1.0f; } SH_ENDFOR;
    } SH_ENDWHILE;
    SH_WHILE(j < 10.0f) {
      y = y * x;
      SH_IF(y > 2.0f) { j += 1.0f; } SH_ENDIF;
    } SH_ENDWHILE;
    SH_WHILE(k < 10.0f) {
      y = y + 1.0f;
      SH_CONTINUE(y > 3.0f);
      k += 1.0f;
    } SH_ENDWHILE;
    SH_WHILE(m < std::numeric_limits<float>::infinity()) { m += 1.0f; } SH_ENDWHILE;
    SH_WHILE(n < std::numeric_limits<float>::quiet_NaN()) { n += 1.0f; } SH_ENDWHILE;
    y = y + i + j + k + m + n;
  } SH_END;
  analysis::Cost c = analysis::count_operations(optimize(p.ir()));
  int outer = 0;
  for (const analysis::LoopCost& loop : c.loops) {
    if (loop.depth != 0) continue;
    EXPECT_FALSE(loop.trips.has_value()) << "loop " << outer << " (" << loop.loop << "): " << *loop.trips;
    ++outer;
  }
  EXPECT_EQ(outer, 5);
}

TEST(Analysis, CriticalPathNeedsStraightLineCode) {
  Program p = SH_BEGIN_PROGRAM("branchy") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
    SH_IF(x > 0.0f) { y = x * 2.0f; } SH_ENDIF;
  } SH_END;
  EXPECT_THROW(analysis::critical_path(p.ir(), analysis::Machine{}), Error);
}

TEST(Analysis, CountsAreOnePerComponent) {
  Program p = SH_BEGIN_PROGRAM("wide") {
    InputAttrib4f a;
    OutputAttrib4f r;
    r = a * a + sqrt(a);
  } SH_END;
  analysis::OpCounts c = analysis::count_operations(p.ir()).outside_loops;
  EXPECT_EQ(c[Unit::Mul], 4u);
  EXPECT_EQ(c[Unit::Add], 4u);
  EXPECT_EQ(c[Unit::Transcendental], 4u);
}

// Reads at x + c of position(), clamped at the edge by legalisation: a run
// along the row; at a uniform index: the same element; at an input: anywhere.
TEST(Analysis, TableAccessFollowsPositionThroughOffsetsAndClamps) {
  Table2D<Attrib1f> image(8, 8);
  Table1D<Attrib1f> line(8);
  Attrib1i row_offset = 3;
  Program p = SH_BEGIN_PROGRAM("accesses") {
    InputAttrib1i any;
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib1i x = at(0) - 2;
    out = image[at + ConstAttrib2i(1, -1)] + line[x] + line[row_offset] + line[any] + image[at(1, 0)];
    SH_FOR(Attrib1i k = 0, k < 3, k += 1) { out += line[at(0) + k]; } SH_ENDFOR;
  } SH_END;
  ir::Program legal = passes::legalize(optimize(p.ir()));
  std::multiset<std::string> kinds;
  for (const auto& [read, access] : analysis::table_access(legal))
    kinds.insert(std::string(analysis::access_name(access.hint)) + (access.proven_run ? " proven" : ""));
  // image at (x + 1, y - 1) and line at x - 2: runs, proven (each value is
  // written once, outside ifs and loops); line at x + a loop counter: a run
  // by the hint only; line at a uniform: the same element; line at an
  // input and image at (y, x): anywhere.
  EXPECT_EQ(kinds, (std::multiset<std::string>{"consecutive proven", "consecutive proven", "consecutive", "same",
                                               "scattered", "scattered"}));
}

// A proven run at position() plus constants carries its offsets (a
// stencil's tap); at position() plus a uniform it is proven, with none.
TEST(Analysis, TableAccessGivesAStencilTapsOffsets) {
  Table2D<Attrib1f> image(8, 8);
  Attrib1i shift = 2;
  Program p = SH_BEGIN_PROGRAM("taps") {
    OutputAttrib1f out;
    Attrib2i at = position<2>();
    Attrib2i up = at - ConstAttrib2i(0, 1);
    out = image[up + ConstAttrib2i(-3, 0)] * 2.0f + image[at + join(shift, ConstAttrib1i(0))];
  } SH_END;
  std::multiset<std::string> found;
  for (const auto& [read, access] : analysis::table_access(passes::legalize(optimize(p.ir())))) {
    ASSERT_TRUE(access.proven_run);
    found.insert(access.offset ? std::to_string((*access.offset)[0]) + "," + std::to_string((*access.offset)[1]) : "none");
  }
  EXPECT_EQ(found, (std::multiset<std::string>{"-3,-1", "none"}));
}

// A value written inside an if may be the one from before it in some
// lanes: no proof, whatever the condition.
TEST(Analysis, TableAccessProvesNothingWrittenInsideAnIf) {
  Table1D<Attrib1f> line(8);
  Attrib1f flag = 1.0f;
  Program p = SH_BEGIN_PROGRAM("inside_if") {
    OutputAttrib1f out;
    Attrib1i x = 0;
    SH_IF(flag > 0.0f) { x = position(); } SH_ENDIF;
    out = line[x];
  } SH_END;
  auto reads = analysis::table_access(passes::legalize(optimize(p.ir())));
  ASSERT_EQ(reads.size(), 1u);
  EXPECT_FALSE(reads.begin()->second.proven_run);
}

// Ifs and loops in the order they begin, nested ones after their parent.
void collect_branches(const ir::Block& b, std::vector<const ir::Stmt*>& out) {
  for (const ir::Stmt& s : b) {
    if (auto* i = std::get_if<ir::If>(&s.node)) {
      out.push_back(&s);
      collect_branches(i->then_body, out);
      collect_branches(i->else_body, out);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      out.push_back(&s);
      collect_branches(l->header, out);
      collect_branches(l->body, out);
      collect_branches(l->update, out);
    }
  }
}

TEST(Analysis, AVoteAcrossLanesIsUniformAndSteersABranch) {
  Program p = SH_BEGIN_PROGRAM("vote") {
    InputAttrib1f x;
    OutputAttrib1f out;
    out = 0.0f;
    SH_IF(any_lane(x)) { out = 1.0f; } SH_ENDIF;
  } SH_END;
  ir::Program legal = passes::legalize(optimize(p.ir()));
  analysis::SpmdFacts facts = analysis::analyse_spmd(legal);
  std::vector<const ir::Stmt*> branches;
  collect_branches(legal.body, branches);
  ASSERT_EQ(branches.size(), 1u);
  EXPECT_FALSE(facts.divergent.at(branches[0])) << "every lane that voted takes the same side";
  EXPECT_FALSE(facts.varying[std::get<ir::If>(branches[0]->node).cond.var]);
}

// Under a varying if: a walk whose node only the lanes inside read stays
// uniform, so its loop branches; a count read after the if, and one whose
// loop lanes leave at different times, vary.
TEST(Analysis, ValuesOnlyTheLanesInsideADivergentIfReadStayUniform) {
  Table1D<Attrib1i> next(4);
  Program p = SH_BEGIN_PROGRAM("inside") {
    InputAttrib2f in;
    OutputAttrib2f out;
    Attrib1f tag = 0.0f, count = 0.0f;
    SH_IF(in(0) > 0.0f) {
      Attrib1i node = 0, steps = 0;
      SH_WHILE(node >= 0) {
        node = next[node];
        steps += 1;
      } SH_ENDWHILE;
      tag = steps.cast<float>();
      SH_WHILE(count < in(1)) { count += 1.0f; } SH_ENDWHILE;
    } SH_ENDIF;
    out = join(tag, count);
  } SH_END;
  ir::Program legal = passes::legalize(optimize(p.ir()));
  analysis::SpmdFacts facts = analysis::analyse_spmd(legal);
  std::vector<const ir::Stmt*> branches;
  collect_branches(legal.body, branches);
  ASSERT_EQ(branches.size(), 3u);
  EXPECT_TRUE(facts.divergent.at(branches[0]));
  EXPECT_FALSE(facts.divergent.at(branches[1])) << "the walk: its lanes agree on the node";
  EXPECT_FALSE(facts.varying[std::get<ir::Loop>(branches[1]->node).cond.var]);
  EXPECT_TRUE(facts.divergent.at(branches[2])) << "lanes stop counting at their own bound";
}

// The lanes that wait while a then side runs read what it writes on their
// else side, and continuing lanes read at the update what the others
// write after the continue: both writes vary, though their values do not.
TEST(Analysis, AWriteThatWaitingLanesReadVaries) {
  Program p = SH_BEGIN_PROGRAM("waiting") {
    InputAttrib1f x;
    OutputAttrib2f out;
    Attrib1f a = 0.0f, b = 0.0f, seen = 0.0f;
    SH_IF(x > 0.0f) { a = 2.0f; } SH_ELSE { b = a + 1.0f; } SH_ENDIF;
    Attrib1f late = 0.0f;
    SH_FOR(Attrib1f i = 0.0f, i < 4.0f, i += late) {
      late = 1.0f;
      SH_CONTINUE(x > i);
      late = 2.0f;
    } SH_ENDFOR;
    seen = late;
    out = join(b, seen);
  } SH_END;
  ir::Program legal = passes::legalize(optimize(p.ir()));
  analysis::SpmdFacts facts = analysis::analyse_spmd(legal);
  std::vector<const ir::Stmt*> branches;
  collect_branches(legal.body, branches);
  ASSERT_GE(branches.size(), 2u);
  const auto& split = std::get<ir::If>(branches[0]->node);
  ASSERT_FALSE(split.then_body.empty());
  EXPECT_TRUE(facts.varying[std::get<ir::Assign>(split.then_body.back().node).dest]) << "the else side reads it";
  const ir::Stmt* loop = nullptr;
  for (const ir::Stmt* s : branches)
    if (std::holds_alternative<ir::Loop>(s->node)) loop = s;
  ASSERT_NE(loop, nullptr);
  const ir::Block& body = std::get<ir::Loop>(loop->node).body;
  EXPECT_TRUE(facts.divergent.at(loop));
  EXPECT_TRUE(facts.varying[std::get<ir::Assign>(body.back().node).dest]) << "the update reads it";
}

// Liveness goes component by component: a value built a component at a
// time inside a divergent branch in a loop is dead where the lanes that
// skipped the branch wait (each trip builds it again before reading it),
// so it stays one value for all lanes; one whose other component is read
// on a later trip varies.
TEST(Analysis, AValueBuiltAComponentAtATimeInABranchStaysUniform) {
  Attrib1f u = 1.5f;
  Program p = SH_BEGIN_PROGRAM("built") {
    InputAttrib1f x;
    OutputAttrib1f out;
    out = 0.0f;
    SH_FOR(Attrib1i j = 0, j < 3, j += 1) {
      SH_IF(x > j.cast<float>()) {
        Attrib2f built, half;
        built.name("built");
        half.name("half");
        built(0) = u;
        built(1) = u * 2.0f;
        half(0) = u * 3.0f;
        out += built(0) * built(1) + half(0) * half(1);
      } SH_ENDIF;
    } SH_ENDFOR;
  } SH_END;
  ir::Program legal = passes::legalize(optimize(p.ir()));
  analysis::SpmdFacts facts = analysis::analyse_spmd(legal);
  auto varying = [&](const std::string& name) {
    for (std::size_t v = 0; v < legal.vars.size(); ++v)
      if (legal.vars[v].name == name) return static_cast<int>(facts.varying[v]);
    return -1;
  };
  EXPECT_EQ(varying("built"), 0) << ir::print(legal);
  EXPECT_EQ(varying("half"), 1) << ir::print(legal);
}

// Bit c of a named variable's entry: component c may be read unwritten.
int unwritten(const ir::Program& p, const std::string& name) {
  std::vector<std::uint8_t> reads = analysis::unwritten_reads(p);
  for (std::size_t v = 0; v < p.vars.size(); ++v)
    if (p.vars[v].name == name) return reads[v];
  return -1;
}

TEST(Analysis, UnwrittenReadsAreThoseSomePathReachesBeforeAWrite) {
  Program p = SH_BEGIN_PROGRAM("unwritten") {
    InputAttrib1f x;
    OutputAttrib1f out;
    OutputAttrib1f never;
    never.name("never");
    Attrib1f first, later, one_side, both_sides, in_loop, carried, before_loop, after_loop;
    Attrib2f half;
    first.name("first");
    later.name("later");
    one_side.name("one_side");
    both_sides.name("both_sides");
    in_loop.name("in_loop");
    carried.name("carried");
    before_loop.name("before_loop");
    after_loop.name("after_loop");
    half.name("half");
    first = x * 2.0f;
    Attrib1f sum = first + later;
    later = x;
    SH_IF(x > 0.0f) {
      one_side = x;
      both_sides = x;
    } SH_ELSE {
      both_sides = -x;
    } SH_ENDIF;
    sum += one_side + both_sides;
    before_loop = x;
    SH_FOR(Attrib1i j = 0, j < 3, j += 1) {
      in_loop = x + j.cast<float>();
      sum += in_loop + carried + before_loop;
      carried = x;
      after_loop = x;
    } SH_ENDFOR;
    half(0) = x;
    out = sum + after_loop + half(0) + half(1);
  } SH_END;
  const ir::Program& ir = p.ir();
  EXPECT_EQ(unwritten(ir, "first"), 0);
  EXPECT_EQ(unwritten(ir, "later"), 1) << "read before its write";
  EXPECT_EQ(unwritten(ir, "one_side"), 1) << "the else side does not write it";
  EXPECT_EQ(unwritten(ir, "both_sides"), 0);
  EXPECT_EQ(unwritten(ir, "in_loop"), 0);
  EXPECT_EQ(unwritten(ir, "carried"), 1) << "the first trip reads it before the write";
  EXPECT_EQ(unwritten(ir, "before_loop"), 0);
  EXPECT_EQ(unwritten(ir, "after_loop"), 1) << "the loop may not run";
  EXPECT_EQ(unwritten(ir, "half"), 2) << "component 1 only";
  EXPECT_EQ(unwritten(ir, "never"), 1) << "an output read as the element ends";
}

// A do/until loop tests at the bottom: its body runs before the test's
// writes.  A break or continue leaves the rest of a trip unwritten, and a
// loop inside a loop runs its first trip on what came before it.
TEST(Analysis, UnwrittenReadsFollowTheLoopsOrder) {
  Program p = SH_BEGIN_PROGRAM("loop_order") {
    InputAttrib1f x;
    OutputAttrib1f out;
    Attrib1f tested, before_break, before_continue, inner;
    tested.name("tested");
    before_break.name("before_break");
    before_continue.name("before_continue");
    inner.name("inner");
    Attrib1f sum = 0.0f;
    SH_DO { sum += tested; } SH_UNTIL((tested = x) > 0.0f);
    SH_FOR(Attrib1i j = 0, j < 3, j += 1) {
      SH_BREAK(x > j.cast<float>());
      before_break = x;
    } SH_ENDFOR;
    SH_FOR(Attrib1i j = 0, j < 3, j += sum.cast<std::int32_t>() + before_continue.cast<std::int32_t>()) {
      SH_CONTINUE(x > j.cast<float>());
      before_continue = x;
    } SH_ENDFOR;
    SH_FOR(Attrib1i i = 0, i < 2, i += 1) {
      SH_FOR(Attrib1i j = 0, j < 2, j += 1) {
        sum += inner;
        inner = x;
      } SH_ENDFOR;
    } SH_ENDFOR;
    out = sum + before_break;
  } SH_END;
  const ir::Program& ir = p.ir();
  EXPECT_EQ(unwritten(ir, "tested"), 1) << "the body's read comes before the test writes it";
  EXPECT_EQ(unwritten(ir, "before_break"), 1) << "read after a loop that may break first";
  EXPECT_EQ(unwritten(ir, "before_continue"), 1) << "the update after a continue";
  EXPECT_EQ(unwritten(ir, "inner"), 1) << "the inner loop's first trip";
}

TEST(Analysis, AnArrayIsWrittenByItsFillNotByAStore) {
  Program p = SH_BEGIN_PROGRAM("arrays") {
    InputAttrib1i i;
    OutputAttrib1f out;
    LocalArray<Attrib1f> declared(4, "declared");
    declared.store(i, 1.0f);
    out = declared[i + 1];
  } SH_END;
  const ir::Program& ir = p.ir();
  EXPECT_EQ(unwritten(ir, "declared"), 0) << "its declaration fills it";
  ir::Program stored = ir;
  // Without the fill only stores write it: the other elements are unwritten.
  std::erase_if(stored.body, [](const ir::Stmt& s) {
    const auto* a = std::get_if<ir::Assign>(&s.node);
    return a && a->op == ir::Op::Fill;
  });
  EXPECT_EQ(unwritten(stored, "declared"), 1) << ir::print(stored);
}

}  // namespace
