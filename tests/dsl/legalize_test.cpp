// The legalisation pass: what it turns table reads and integer division
// into, that its output is what backends accept, and that the rules it
// writes give the documented results on the reference interpreter.
#include <gtest/gtest.h>

#include <sh/ir/serialize.hpp>
#include <sh/sh.hpp>

#include <variant>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

std::string body_of(const ir::Program& p) {
  std::string text = ir::print(p);
  return text.substr(text.find("body\n") + 5);
}

bool contains(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

TEST(Legalize, FetchBecomesAClampedLoad) {
  Table1D<Attrib1f> t(4);
  Program p = SH_BEGIN_PROGRAM("fetch") {
    Input<Attrib1i> i;
    Output<Attrib1f> r;
    r = t[i];
  } SH_END;
  EXPECT_THROW(ir::verify_legal(p.ir()), Error);
  ir::Program legal = passes::legalize(p.ir());
  ir::verify(legal);
  ir::verify_legal(legal);
  std::string body = body_of(legal);
  EXPECT_TRUE(contains(body, "extent #0")) << body;
  EXPECT_TRUE(contains(body, "max %0, 0")) << body;
  EXPECT_TRUE(contains(body, "load #0")) << body;
  EXPECT_FALSE(contains(body, "fetch")) << body;
}

// The edge mode is the table's, printed with it; repeat wraps by mod,
// zero chooses between the clamped read and 0.
TEST(Legalize, EdgeModesWrapOrZeroTheRead) {
  Table2D<Attrib3f> repeat(4, 3), zero(4, 3);
  repeat.edge(Edge::Repeat);
  zero.edge(Edge::Zero);
  Program p = SH_BEGIN_PROGRAM("edges") {
    Input<Attrib2i> at;
    Output<Attrib3f> a, b;
    a = repeat[at];
    b = zero[at];
  } SH_END;
  std::string text = ir::print(p.ir());
  EXPECT_TRUE(contains(text, "table #0: f32x3 rank 2 edge repeat")) << text;
  EXPECT_TRUE(contains(text, "table #1: f32x3 rank 2 edge zero")) << text;
  ir::Program legal = passes::legalize(p.ir());
  ir::verify(legal);
  ir::verify_legal(legal);
  std::string body = body_of(legal);
  EXPECT_TRUE(contains(body, "mod %0, %")) << body;
  for (const char* step : {"ge %0, 0", "lt %0, %", "and", "cast f32", "cond"})
    EXPECT_TRUE(contains(body, step)) << step << " in\n" << body;
  EXPECT_EQ(ir::deserialize(ir::serialize(p.ir())).tables[1].edge, Edge::Zero);
}

TEST(Legalize, SampleScalesFloorsAndConvertsBeforeTheClamp) {
  Table2D<Attrib1f> t(4, 2);
  Program p = SH_BEGIN_PROGRAM("sample") {
    Input<Attrib2f> uv;
    Output<Attrib1f> r;
    r = t(uv);
  } SH_END;
  ir::Program legal = passes::legalize(p.ir());
  ir::verify_legal(legal);
  std::string body = body_of(legal);
  for (const char* step : {"extent #0", "cast f32", "mul", "floor", "cast i32", "load #0"})
    EXPECT_TRUE(contains(body, step)) << step << " in\n" << body;
  EXPECT_FALSE(contains(body, "sample")) << body;
}

TEST(Legalize, IntegerDivisionIsGuardedUnlessTheDivisorIsASafeConstant) {
  Program p = SH_BEGIN_PROGRAM("divide") {
    Input<Attrib1i> a;
    Input<Attrib1i> b;
    Output<Attrib1i> q;
    Output<Attrib1i> k;
    q = a / b;
    k = a / 3;
  } SH_END;
  ir::Program legal = passes::legalize(p.ir());
  ir::verify_legal(legal);
  std::string body = body_of(legal);
  EXPECT_TRUE(contains(body, "div %0, 3")) << body;  // a constant 3 cannot trap
  EXPECT_TRUE(contains(body, "eq %1, 0")) << body;
  EXPECT_TRUE(contains(body, "eq %1, -1")) << body;
}

TEST(Legalize, DefinedResultsOfIntegerDivisionOnTheReference) {
  Program p = SH_BEGIN_PROGRAM("defined") {
    Input<Attrib1i> a;
    Input<Attrib1i> b;
    Output<Attrib1i> q;
    Output<Attrib1i> m;
    q = a / b;
    m = a % b;
  } SH_END;
  Channel<Attrib1i> a(std::vector<std::int32_t>{7, INT32_MIN, INT32_MIN, -7, 0}),
      b(std::vector<std::int32_t>{0, -1, 1, 2, 0}), q, m;
  run(p, {a, b}, {q, m}, backend("interp"));
  std::vector<std::int32_t> want_q{0, INT32_MIN, INT32_MIN, -3, 0}, want_m{0, 0, 0, 1, 0};  // -7 % 2 takes 2's sign
  for (std::size_t i = 0; i < want_q.size(); ++i) {
    EXPECT_EQ(q[i], want_q[i]) << i;
    EXPECT_EQ(m[i], want_m[i]) << i;
  }
}

TEST(Legalize, ShiftsPastTheWidthShiftEverythingOut) {
  Program p = SH_BEGIN_PROGRAM("shifts") {
    Input<Attrib1i> a;
    Input<Attrib1i> n;
    Output<Attrib1i> left;
    Output<Attrib1i> right;
    Output<Attrib1i> by_three;
    left = shl(a, n);
    right = shr(a, n);
    by_three = shl(a, 3);
  } SH_END;
  std::string body = body_of(passes::legalize(p.ir()));
  EXPECT_TRUE(contains(body, "shl %0, 3")) << body;  // a constant count in range is left alone
  EXPECT_TRUE(contains(body, "gt %1, 31")) << body;
  Channel<Attrib1i> a(std::vector<std::int32_t>{1, 1, -8, -8, 5, 1}), n(std::vector<std::int32_t>{31, 32, 2, 40, -1, 0}), l, r, k;
  run(p, {a, n}, {l, r, k}, backend("interp"));
  std::vector<std::int32_t> want_l{INT32_MIN, 0, -32, 0, 0, 1}, want_r{0, 0, -2, -1, 0, 1};
  for (std::size_t i = 0; i < want_l.size(); ++i) {
    EXPECT_EQ(l[i], want_l[i]) << i;
    EXPECT_EQ(r[i], want_r[i]) << i;
  }
}

// A program that already holds what legalisation writes (a load, whose
// coordinates were never brought inside its table) is refused before any
// backend reads them: cpu, opencl and mpi read far outside and crashed.
TEST(Legalize, AProgramWithALoadOfItsOwnIsRefused) {
  Table1D<Attrib1f> t(4);
  t.assign({1.f, 2.f, 3.f, 4.f});
  Program p = SH_BEGIN_PROGRAM("own_load") {
    Input<Attrib1i> i;
    Output<Attrib1f> r;
    r = t[i];
  } SH_END;
  ir::Program edited = p.ir();
  for (ir::Stmt& s : edited.body)
    if (auto* a = std::get_if<ir::Assign>(&s.node); a && a->op == ir::Op::Fetch) {
      a->op = ir::Op::Load;
      a->args.push_back(a->args[0]);
    }
  ir::Program back = ir::deserialize(ir::serialize(edited));
  Channel<Attrib1i> at(std::vector<std::int32_t>{100000000});
  Channel<Attrib1f> out;
  for (const std::string& name : backend_names())
    expect_error([&] { run(p.with_ir(back), {at}, {out}, backend(name)); }, {"own_load", "`load` is written by legalisation only"});
}

TEST(Legalize, BackendsRefuseIllegalIr) {
  Table1D<Attrib1f> t(4);
  Program p = SH_BEGIN_PROGRAM("illegal") {
    Input<Attrib1i> i;
    Output<Attrib1f> r;
    r = t[i];
  } SH_END;
  for (const std::string& name : backend_names()) {
    expect_error([&] { find_backend(name).compile(p.ir(), Options{}); }, {"illegal", "fetch", "not legal IR"});
  }
}

}  // namespace
