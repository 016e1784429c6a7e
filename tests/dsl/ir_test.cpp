// The IR's printer, verifier and hash.
#include <gtest/gtest.h>

#include <cmath>

#include <sh/sh.hpp>

namespace {

using namespace sh;

Program saxpy_like(Attrib1f& scale) {
  return SH_BEGIN_PROGRAM("saxpy") {
    Input<Attrib1f> x;
    Input<Attrib1f> y;
    Output<Attrib1f> r;
    r = scale * x + y;
  } SH_END;
}

TEST(Printer, StableTextForm) {
  Attrib1f scale = 2.0f;
  scale.name("scale");
  Program p = saxpy_like(scale);
  EXPECT_EQ(print(p),
            "program saxpy\n"
            "  input %0: f32\n"
            "  input %1: f32\n"
            "  output %2: f32\n"
            "  uniform %3 scale: f32\n"
            "body\n"
            "  %4 = mul %3, %0\n"
            "  %5 = add %4, %1\n"
            "  %2 = mov %5\n");
}

TEST(Printer, ControlFlowSwizzlesTablesAndCasts) {
  Table1D<Attrib2f> t(4);
  t.name("t");
  Program p = SH_BEGIN_PROGRAM("shapes") {
    Input<Attrib3f> v;
    Output<Attrib2f> r;
    r = t[v(0)];
    SH_DO { r(1, 0) = r(0, 1); } SH_UNTIL(r(0) > 1.0f);
  } SH_END;
  EXPECT_EQ(print(p),
            "program shapes\n"
            "  input %0: f32x3\n"
            "  output %1: f32x2\n"
            "  table #0 t: f32x2 rank 1\n"
            "body\n"
            "  %2 = cast i32 %0.x\n"
            "  %3 = fetch #0 %2\n"
            "  %1 = mov %3\n"
            "  loop test-last while %6 {\n"
            "  header:\n"
            "    %5 = gt %1.x, 1\n"
            "    %6 = not %5\n"
            "  body:\n"
            "    %1.yx = mov %1\n"
            "  }\n");
}

// A scatter survives the passes though no output reads what it adds, and
// the verifier keeps accumulators and read-only tables apart.
TEST(Scatter, PrintedKeptByThePassesAndVerified) {
  Accumulator<Attrib2f> sums(3, "sums");
  Table1D<Attrib1f> t(2);
  t.name("t");
  t.assign({1.f, 2.f});
  Program p = SH_BEGIN_PROGRAM("scatters") {
    Input<Attrib1i> i;
    Attrib1f unused = 5.0f;
    SH_IF(i > 0) { sums.add(i, join(t[i], unused * 2.0f)); } SH_ENDIF;
  } SH_END;
  ir::Program o = optimize(p.ir());
  EXPECT_EQ(print(o),
            "program scatters\n"
            "  input %0: i32\n"
            "  table #0 t: f32 rank 1\n"
            "  accumulator #1 sums: f32x2 rank 1\n"
            "body\n"
            "  %2 = gt %0, 0\n"
            "  if %2 {\n"
            "    %3.x = fetch #0 %0\n"
            "    %3.y = mov 10\n"
            "    scatter-add #1 %0, %3\n"
            "  }\n");

  ir::Program into_table = o;
  std::get<ir::Scatter>(std::get<ir::If>(into_table.body[1].node).then_body[2].node).table = 0;
  EXPECT_THROW(ir::verify(into_table), Error);
  ir::Program reads_sums = o;
  std::get<ir::Assign>(std::get<ir::If>(reads_sums.body[1].node).then_body[0].node).table = 1;
  EXPECT_THROW(ir::verify(reads_sums), Error);
}

// A prefetch, like a scatter, survives the passes though no output reads
// it, and keeps what its coordinates are computed from; legalisation
// leaves them as asked (a backend keeps a prefetch outside the table
// harmless), where it clamps a read's; the verifier refuses an accumulator
// or coordinates of the wrong rank.
TEST(Prefetch, PrintedKeptByThePassesUnclampedAndVerified) {
  Table2D<Attrib1f> t(4, 3);
  t.name("t");
  Accumulator<Attrib1f> sums(2, "sums");
  Program p = SH_BEGIN_PROGRAM("prefetches") {
    Input<Attrib1i> i;
    Output<Attrib1f> r;
    Attrib1i unused = i * 7;
    t.prefetch(join(i + 1, i * 2));
    r = t[join(i, i)];
    sums.add(0, r);
  } SH_END;
  ir::Program o = optimize(p.ir());
  EXPECT_EQ(print(o),
            "program prefetches\n"
            "  input %0: i32\n"
            "  output %1: f32\n"
            "  table #0 t: f32 rank 2\n"
            "  accumulator #1 sums: f32 rank 1\n"
            "body\n"
            "  %3 = mul %0, 2\n"
            "  %5.x = add %0, 1\n"
            "  %5.y = mov %3\n"
            "  prefetch #0 %5\n"
            "  %6.x = mov %0\n"
            "  %6.y = mov %0\n"
            "  %1 = fetch #0 %6\n"
            "  scatter-add #1 0, %1\n");
  std::string legal = print(passes::legalize(o));
  EXPECT_NE(legal.find("  %5.y = mov %3\n"
                       "  prefetch #0 %5\n"),
            std::string::npos)
      << legal;
  EXPECT_NE(legal.find("min %"), std::string::npos) << "the fetch's coordinates are clamped: " << legal;

  ir::Program from_sums = o;
  std::get<ir::Prefetch>(from_sums.body[3].node).table = 1;
  EXPECT_THROW(ir::verify(from_sums), Error);
  ir::Program one_coordinate = o;
  std::get<ir::Prefetch>(one_coordinate.body[3].node).index.swizzle = ir::Swizzle::identity(1);
  EXPECT_THROW(ir::verify(one_coordinate), Error);
}

TEST(Verifier, AcceptsRecordedProgramsAndRejectsBrokenOnes) {
  Attrib1f scale = 1.0f;
  ir::Program p = saxpy_like(scale).ir();
  EXPECT_NO_THROW(ir::verify(p));

  ir::Program bad_width = p;
  std::get<ir::Assign>(bad_width.body[0].node).args[1].swizzle = ir::Swizzle::identity(1);
  std::get<ir::Assign>(bad_width.body[0].node).args[1].swizzle.index[0] = 2;
  EXPECT_THROW(ir::verify(bad_width), Error);

  ir::Program writes_input = p;
  std::get<ir::Assign>(writes_input.body[0].node).dest = 0;
  try {
    ir::verify(writes_input);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("writes a variable of kind input"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("saxpy"), std::string::npos);
  }

  ir::Program stray_break = p;
  stray_break.body.push_back(ir::Stmt{ir::Break{}});
  EXPECT_THROW(ir::verify(stray_break), Error);

  ir::Program bad_type = p;
  bad_type.vars[4].type.scalar = ir::Scalar::I32;
  EXPECT_THROW(ir::verify(bad_type), Error);
}

// What a program read from bytes could hold and the recorder never makes:
// a uniform in no list (it would have no value), an integer constant no
// int32 holds (0.5, NaN: the folder and the backends would each cast it
// their way), a break in a loop's update (whose loop would it leave?).
TEST(Verifier, RejectsWhatOnlyBytesCouldHold) {
  auto message = [](const ir::Program& q) {
    try {
      ir::verify(q);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  Attrib1f scale = 1.0f;
  ir::Program p = saxpy_like(scale).ir();
  ASSERT_EQ(p.uniforms.size(), 1u);
  ir::Program unlisted = p;
  unlisted.uniforms.clear();
  EXPECT_NE(message(unlisted).find("of kind uniform is in none of the program's lists"), std::string::npos) << message(unlisted);

  for (double bad : {0.5, std::nan(""), 3e9}) {
    ir::Program q = p;
    q.vars.push_back(ir::Var{ir::VarKind::Const, ir::Type{ir::Scalar::I32, 1}, "", {bad, 0, 0, 0}, 0});
    EXPECT_NE(message(q).find("which that type cannot"), std::string::npos) << bad << ": " << message(q);
  }
  ir::Program truth = p;
  truth.vars.push_back(ir::Var{ir::VarKind::Const, ir::Type{ir::Scalar::Bool, 1}, "", {2, 0, 0, 0}, 0});
  EXPECT_NE(message(truth).find("which that type cannot"), std::string::npos) << message(truth);

  Program looping = SH_BEGIN_PROGRAM("looping") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = x;
    SH_FOR(Attrib1f i = 0.0f, i < x, i += 1.0f) { r += i; } SH_ENDFOR;
  } SH_END;
  ir::Program q = looping.ir();
  EXPECT_EQ(message(q), "accepted");
  for (ir::Stmt& s : q.body)
    if (auto* loop = std::get_if<ir::Loop>(&s.node)) loop->update.push_back(ir::Stmt{ir::Break{}});
  EXPECT_NE(message(q).find("in a loop's header or update"), std::string::npos) << message(q);
}

TEST(Hash, IgnoresNamesAndUniformValuesButNotStructure) {
  Attrib1f a = 1.0f, b = 7.0f;
  Program p = saxpy_like(a), q = saxpy_like(b);
  EXPECT_EQ(p.hash(), q.hash());
  a = 100.0f;
  a.name("renamed");
  EXPECT_EQ(saxpy_like(a).hash(), p.hash());
  Program different = SH_BEGIN_PROGRAM("saxpy") {
    Input<Attrib1f> x;
    Input<Attrib1f> y;
    Output<Attrib1f> r;
    r = a * x - y;
  } SH_END;
  EXPECT_NE(different.hash(), p.hash());
}

TEST(Recording, CppFunctionsInlineIntoTheKernel) {
  auto smoothstep = [](const Attrib1f& e0, const Attrib1f& e1, const Attrib1f& x) {
    Attrib1f t = sat((x - e0) / (e1 - e0));
    return t * t * (3.0f - 2.0f * t);
  };
  Program p = SH_BEGIN_PROGRAM("inline") {
    Input<Attrib1f> x;
    Output<Attrib1f> r;
    r = smoothstep(ConstAttrib1f(0.0f), ConstAttrib1f(1.0f), x);
  } SH_END;
  std::string text = print(p);
  EXPECT_NE(text.find("min"), std::string::npos);  // sat inlined
  Channel<Attrib1f> in(std::vector<float>{-1, 0.5f, 2}), out;
  run(p, {in}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 0.f);
  EXPECT_EQ(out[1], 0.5f);
  EXPECT_EQ(out[2], 1.f);
}

TEST(Recording, SwizzleParameterIsACopy) {
  auto bump = [](Attrib1f v) {
    v += 1.0f;
    return v;
  };
  Program p = SH_BEGIN_PROGRAM("copy") {
    Input<Attrib2f> x;
    Output<Attrib2f> r;
    Attrib2f a = x;
    Attrib1f b = bump(a(0));
    r = join(a(0), b);
  } SH_END;
  Channel<Attrib2f> in(std::vector<float>{5, 0}), out;
  run(p, {in}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 5.f);
  EXPECT_EQ(out[1], 6.f);
}

TEST(Recording, VariableInitialisedFromAConstantIsWritable) {
  Program p = SH_BEGIN_PROGRAM("from_const") {
    Output<Attrib2f> r;
    Attrib2f z = ConstAttrib2f(1.0f, 2.0f);
    z(0) = 5.0f;
    r = z;
  } SH_END;
  Channel<Attrib2f> out(1);
  run(p, {}, {out}, backend("interp"));
  EXPECT_EQ(out[0], 5.f);
  EXPECT_EQ(out[1], 2.f);
}

TEST(HostUniforms, ArithmeticOutsideProgramsComputesOnTheHost) {
  Attrib3f a(1.f, 2.f, 3.f);
  Attrib3f b = a * 2.0f + 1.0f;
  EXPECT_EQ(b.get(0), 3.f);
  EXPECT_EQ(b.get(2), 7.f);
  Attrib1f d = dot(a, b);
  EXPECT_EQ(d.get(), 1 * 3.f + 2 * 5.f + 3 * 7.f);
}

}  // namespace
