// Every recording error throws sh::Error naming the program and the fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <variant>

#include <sh/sh.hpp>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

TEST(RecordingErrors, ElseWithoutIf) {
  expect_error([] { SH_BEGIN_PROGRAM("p1") { SH_ELSE; } SH_END; }, {"p1", "SH_ELSE without SH_IF"});
}

TEST(RecordingErrors, EndifWithoutIf) {
  expect_error([] { SH_BEGIN_PROGRAM("p2") { SH_ENDIF; } SH_END; }, {"p2", "SH_ENDIF without SH_IF"});
}

TEST(RecordingErrors, MacroLeftOpen) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("open_if") {
          Attrib1f x = 1.0f;
          SH_IF(x > 0.0f) { x = 2.0f; }
        } SH_END;
      },
      {"open_if", "SH_IF", "left open"});
  expect_error([] { SH_BEGIN_PROGRAM("open_do") { SH_DO {} } SH_END; }, {"open_do", "SH_DO"});
}

TEST(RecordingErrors, MismatchedLoopEnds) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("mixed") {
          Attrib1f x = 1.0f;
          SH_WHILE(x > 0.0f) { x -= 1.0f; } SH_ENDIF;
        } SH_END;
      },
      {"mixed", "SH_ENDIF without SH_IF", "SH_WHILE"});
  expect_error([] { SH_BEGIN_PROGRAM("until") { SH_UNTIL(Attrib1f(1.0f)); } SH_END; }, {"until", "SH_UNTIL without SH_DO"});
}

TEST(RecordingErrors, BreakOutsideLoop) {
  expect_error([] { SH_BEGIN_PROGRAM("brk") { SH_BREAK(); } SH_END; }, {"brk", "SH_BREAK outside a loop"});
  expect_error([] { SH_BEGIN_PROGRAM("cnt") { SH_CONTINUE(Attrib1f(1.0f)); } SH_END; }, {"cnt", "SH_CONTINUE"});
}

TEST(RecordingErrors, ReadingAnOutputNeverWritten) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("read_output") {
          Output<Attrib1f> r;
          Attrib1f t = r + 1.0f;
        } SH_END;
      },
      {"read_output", "reads output", "before anything was written"});
}

TEST(RecordingErrors, SwizzleIndexOutOfRange) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("swz") {
          Attrib3f v(1, 2, 3);
          Attrib1f c = v(3);
        } SH_END;
      },
      {"swz", "swizzle index 3", "3-component"});
}

TEST(RecordingErrors, TypeMismatchInAlgebraAndConditions) {
  Program two = SH_BEGIN_PROGRAM("two") {
    Input<Attrib2f> a;
    Output<Attrib2f> b;
    b = a;
  } SH_END;
  Program three = SH_BEGIN_PROGRAM("three") {
    Input<Attrib3f> a;
    Output<Attrib3f> b;
    b = a;
  } SH_END;
  expect_error([&] { (void)(three << two); }, {"three<<two", "cannot connect f32x2 to f32x3"});
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("wide_cond") {
          Attrib3f v(1, 2, 3);
          SH_IF(v) {} SH_ENDIF;
        } SH_END;
      },
      {"wide_cond", "SH_IF condition has 3 components"});
}

TEST(RecordingErrors, UniformWrittenInsideProgram) {
  Attrib1f u = 1.0f;
  expect_error([&] { SH_BEGIN_PROGRAM("set_uniform") { u = 2.0f; } SH_END; }, {"set_uniform", "uniforms are set on the host"});
}

TEST(RecordingErrors, VariableOfAnotherProgram) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("outer") {
          Attrib1f inner_value = 1.0f;
          Program inner = SH_BEGIN_PROGRAM("inner") {
            Output<Attrib1f> r;
            r = inner_value;
          } SH_END;
        } SH_END;
      },
      {"inner", "another program"});
}

// A value kept from a recording that has ended is another program's too,
// though the next recording may live at the ended one's address.
TEST(RecordingErrors, VariableOfAnEndedProgram) {
  std::optional<Attrib1f> kept;
  SH_BEGIN_PROGRAM("first") {
    Output<Attrib1f> r;
    Attrib1f t = 1.0f;
    kept.emplace(t);
    r = t;
  } SH_END;
  for (int again = 0; again < 3; ++again)
    expect_error(
        [&] {
          SH_BEGIN_PROGRAM("second") {
            Output<Attrib1f> r;
            r = *kept;
          } SH_END;
        },
        {"second", "another program"});
}

TEST(RecordingErrors, ControlFlowOutsideProgram) {
  expect_error([] { SH_IF(Attrib1f(1.0f)); }, {"SH_IF", "outside"});
}

TEST(RecordingErrors, ScatterOfTheWrongShape) {
  Accumulator<Attrib3f> energy(8, "energy");
  expect_error(
      [&] {
        SH_BEGIN_PROGRAM("wrong_width") {
          InputAttrib2f x;
          energy.add(0, x);
        } SH_END;
      },
      {"wrong_width", "accumulator 'energy'", "2 components"});
  expect_error(
      [&] {
        SH_BEGIN_PROGRAM("wrong_index") {
          InputAttrib2i i;
          energy.add(i, ConstAttrib3f(1, 2, 3));
        } SH_END;
      },
      {"wrong_index", "accumulator 'energy'", "2 coordinates"});
  expect_error([&] { energy.add(0, ConstAttrib3f(1, 2, 3)); }, {"outside any program", "accumulators"});
  EXPECT_THROW(Accumulator<Attrib1f>(0), Error);
}

TEST(RecordingErrors, PrefetchOfTheWrongRankOrOutsideAProgram) {
  Table2D<Attrib1f> t(2, 2);
  t.name("grid");
  expect_error(
      [&] {
        SH_BEGIN_PROGRAM("one_coordinate") {
          InputAttrib1i i;
          t.prefetch(i);
        } SH_END;
      },
      {"one_coordinate", "table 'grid'", "2 dimensions", "prefetched with 1 coordinates"});
  expect_error([&] { t.prefetch(ConstAttrib2i(0, 1)); }, {"prefetch", "only be asked inside a program"});
}

// Control flow nests at most ir::kMaxNesting deep: at the limit a program
// records and runs; one level more is refused while recording (some 14 000
// levels overflowed the stack in the passes).
Program nested_ifs(int levels) {
  return SH_BEGIN_PROGRAM("deep") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x;
    for (int i = 0; i < levels; ++i) {
      SH_IF(x > static_cast<float>(i)) { r = r + 1.0f; }
    }
    for (int i = 0; i < levels; ++i) {
      SH_ENDIF;
    }
  } SH_END;
}

TEST(RecordingErrors, ControlFlowNestedPastTheLimit) {
  Channel<Attrib1f> x(std::vector<float>{2.5f}), r;
  run(nested_ifs(ir::kMaxNesting), {x}, {r}, backend("interp"));
  EXPECT_EQ(r[0], 2.5f + 3.0f);
  expect_error([] { nested_ifs(ir::kMaxNesting + 1); }, {"deep", "SH_IF nested deeper than 1000 levels"});
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("deep_loops") {
          Attrib1f n = 0.0f;
          for (int i = 0; i <= ir::kMaxNesting; ++i) {
            SH_WHILE(n < 0.0f) {}
          }
        } SH_END;
      },
      {"deep_loops", "a loop nested deeper than 1000 levels"});
  // IR built by hand (or by a pass) is held to the same limit by the
  // verifier, before anything walks it.
  ir::Program deeper = nested_ifs(ir::kMaxNesting).ir();
  auto top = std::find_if(deeper.body.begin(), deeper.body.end(),
                          [](const ir::Stmt& s) { return std::holds_alternative<ir::If>(s.node); });
  ASSERT_NE(top, deeper.body.end());
  ir::If wrapper = std::get<ir::If>(top->node);
  wrapper.then_body = {*top};
  wrapper.else_body.clear();
  *top = ir::Stmt{std::move(wrapper)};
  expect_error([&] { ir::verify(deeper); }, {"deep", "nested deeper than 1000 levels"});
}

// A variable std::move took from is an error to read, on the host and in
// a program, and assigning it makes it a variable again (it crashed).
TEST(RecordingErrors, AVariableMovedFromIsReadOnlyAfterAnAssignment) {
  Attrib1f a = 2.0f;
  Attrib1f b = std::move(a);
  EXPECT_EQ(b.get(), 2.0f);
  expect_error([&] { Attrib1f c = a + 1.0f; }, {"read after std::move took its variable"});
  expect_error([&] { a.get(); }, {"read after std::move"});
  a = 5.0f;
  EXPECT_EQ(a.get(), 5.0f);
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("moved") {
          InputAttrib1f x;
          OutputAttrib1f r;
          Attrib1f y = x * 2.0f;
          Attrib1f z = std::move(y);
          r = y + z;
        } SH_END;
      },
      {"read after std::move"});
  Program p = SH_BEGIN_PROGRAM("moved_then_assigned") {
    InputAttrib1f x;
    OutputAttrib1f r;
    Attrib1f y = x * 2.0f;
    Attrib1f z = std::move(y);
    y = x + 1.0f;
    r = y + z;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{3.0f}), out;
  run(p, {in}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 4.0f + 6.0f);
  // An output moved from is copied: it stays the program's output.
  Program q = SH_BEGIN_PROGRAM("moved_output") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x * 2.0f;
    Attrib1f t = std::move(r);
    r = t + 1.0f;
  } SH_END;
  run(q, {in}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 7.0f);
}

// A uniform's components on the host are 0 to its width less one; others
// read past its storage.
TEST(RecordingErrors, AComponentPastTheWidthIsAnError) {
  Attrib3f u(1.0f, 2.0f, 3.0f);
  EXPECT_EQ(u.get(2), 3.0f);
  for (int i : {3, -1, 100}) expect_error([&] { u.get(i); }, {"of a value of 3 (they are 0 to 2)"});
}

// get() of an input inside the program that declares it: the program is
// named, and the message says which values exist on the host.
TEST(RecordingErrors, AHostValueOfAnInputIsAnErrorNamingTheProgram) {
  expect_error(
      [] {
        SH_BEGIN_PROGRAM("asks_host") {
          InputAttrib1f x;
          x.name("speed");
          OutputAttrib1f r;
          r = x * x.get();
        } SH_END;
      },
      {"asks_host", "a host value was asked of a program variable 'speed'", "uniforms and constants have one"});
}

TEST(RecordingErrors, ProgramStateRecoversAfterAnError) {
  EXPECT_THROW(SH_BEGIN_PROGRAM("bad") { SH_ELSE; } SH_END, Error);
  // Outside any recording again: a variable is a uniform.
  Attrib1f u = 5.0f;
  EXPECT_EQ(u.get(), 5.0f);
}

}  // namespace
