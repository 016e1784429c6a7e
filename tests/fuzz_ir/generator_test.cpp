// The fuzzer's own pieces: generated programs are valid, deterministic,
// cover the op table and the statement forms, and run on the interpreter;
// the exactness analysis and the minimiser do what fuzz_ir relies on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <sh/error.hpp>
#include <sh/ir/printer.hpp>
#include <sh/ir/verifier.hpp>
#include <sh/ir/visitor.hpp>

#include "exactness.hpp"
#include "generator.hpp"
#include "minimize.hpp"
#include "rng.hpp"
#include "runner.hpp"

namespace fuzz_ir {
namespace {

using namespace sh::ir;

constexpr int kPrograms = 400;

class Writes : public Visitor {
 public:
  using Visitor::visit;
  std::map<VarId, int> count;
  void visit(const Assign& a) override { ++count[a.dest]; }
};

// The variables that only `header` writes in the whole program.
std::set<VarId> written_only_by(const Block& header, const std::map<VarId, int>& everywhere) {
  Writes here;
  here.visit(header);
  std::set<VarId> out;
  for (const auto& [v, n] : here.count)
    if (everywhere.at(v) == n) out.insert(v);
  return out;
}

// Whether a statement of `body` reads one of `vars` before any statement
// of it (at its own level) writes that variable.
bool body_reads_before_writing(const Block& body, std::set<VarId> vars) {
  for (const Stmt& s : body) {
    if (const auto* a = std::get_if<Assign>(&s.node)) {
      for (const Operand& o : a->args)
        if (vars.count(o.var)) return true;
      vars.erase(a->dest);
    } else if (const auto* i = std::get_if<If>(&s.node)) {
      if (vars.count(i->cond.var) || body_reads_before_writing(i->then_body, vars) || body_reads_before_writing(i->else_body, vars))
        return true;
    }
  }
  return false;
}

class Census : public Visitor {
 public:
  using Visitor::visit;
  explicit Census(std::map<VarId, int> writes = {}) : writes_(std::move(writes)) {}
  std::set<Op> ops;
  std::set<std::string> forms;
  void visit(const Assign& a) override { ops.insert(a.op); }
  void visit(const If& s) override {
    forms.insert(s.else_body.empty() ? "if" : "if-else");
    Visitor::visit(s);
  }
  void visit(const Loop& s) override {
    forms.insert(s.test_at_top ? (s.update.empty() ? "while" : "for") : "do-until");
    // What a do/until test alone writes (besides its condition, which is
    // false whenever the loop ends, so the same in every element after
    // it), read by the body first: on its first trip the body reads it as
    // the element began it.
    if (!s.test_at_top) {
      std::set<VarId> test_only = written_only_by(s.header, writes_);
      test_only.erase(s.cond.var);
      if (body_reads_before_writing(s.body, test_only)) forms.insert("do-until body reading what only its test writes");
    }
    Visitor::visit(s);
  }
  void visit(const Break&) override { forms.insert("break"); }
  void visit(const Continue&) override { forms.insert("continue"); }
  void visit(const Scatter&) override { forms.insert("scatter"); }
  void visit(const Prefetch&) override { forms.insert("prefetch"); }

 private:
  std::map<VarId, int> writes_;
};

TEST(FuzzGenerator, ProgramsVerifyAndKeepInexactValuesOutOfConditions) {
  for (int k = 0; k < kPrograms; ++k) {
    Case c = generate(program_seed(7, k));
    ASSERT_NO_THROW(verify(c.program)) << print(c.program);
    EXPECT_EQ(inexact_leak(c.program), "") << print(c.program);
    EXPECT_EQ(c.inputs.size(), c.program.inputs.size());
    EXPECT_EQ(c.tables.size(), c.program.tables.size());
    for (const Data& d : c.inputs) EXPECT_EQ(d.values.size(), c.count * d.type.width);
  }
}

TEST(FuzzGenerator, SameSeedSameProgram) {
  for (std::uint64_t seed : {1ull, 42ull, 0xFFFFFFFFFFFFull}) {
    Case a = generate(seed), b = generate(seed);
    EXPECT_EQ(print(a.program), print(b.program));
    EXPECT_EQ(a.count, b.count);
  }
  EXPECT_NE(print(generate(1).program), print(generate(2).program));
}

TEST(FuzzGenerator, CoversEveryOperationScalarWidthAndStatementForm) {
  std::set<Op> ops;
  std::set<std::string> forms;
  std::set<std::pair<Scalar, int>> types;
  std::set<int> ranks;
  for (int k = 0; k < kPrograms; ++k) {
    Case c = generate(program_seed(7, k));
    Writes writes;
    writes.visit(c.program.body);
    Census census(writes.count);
    census.visit(c.program.body);
    ops.insert(census.ops.begin(), census.ops.end());
    forms.insert(census.forms.begin(), census.forms.end());
    for (const Var& v : c.program.vars) types.insert({v.type.scalar, v.type.width});
    for (const TableDecl& t : c.program.tables) ranks.insert(t.rank);
  }
  // Every row but legal IR's load and any_lane (whose answer depends on the
  // elements run together: conformance tests it by its bounds).
  std::vector<Op> drawn = generated_ops();
  for (int i = 0; i < kOpCount; ++i) {
    bool left_out = op_at(i) == Op::Load || is_lane_group(op_at(i));
    EXPECT_EQ(std::count(drawn.begin(), drawn.end(), op_at(i)), left_out ? 0 : 1) << op_name(op_at(i));
  }
  for (Op op : generated_ops()) EXPECT_TRUE(ops.count(op)) << op_name(op) << " never generated";
  for (const char* form : {"if", "if-else", "while", "for", "do-until", "do-until body reading what only its test writes",
                           "break", "continue", "scatter", "prefetch"})
    EXPECT_TRUE(forms.count(form)) << form << " never generated";
  EXPECT_EQ(types.size(), 16u) << "every scalar at every width";
  EXPECT_EQ(ranks, (std::set<int>{1, 2, 3}));
}

TEST(FuzzGenerator, ProgramsEndOnTheInterpreter) {
  for (int k = 0; k < 100; ++k) {
    Case c = generate(program_seed(3, k));
    for (sh::Precision p : {sh::Precision::F32, sh::Precision::F64}) {
      Result r = run(c, Mode{"interp", {}, p}, false);
      EXPECT_EQ(r.error, "") << print(c.program);
    }
  }
}

TEST(FuzzUlps, NanMatchesNanZerosMatchInfinityOnlyItself) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ulp_distance(Scalar::F32, nan, -nan), 0u);
  EXPECT_EQ(ulp_distance(Scalar::F32, 0.0, -0.0), 0u);
  EXPECT_EQ(ulp_distance(Scalar::F32, 1.0, std::nextafter(1.0f, 2.0f)), 1u);
  EXPECT_EQ(ulp_distance(Scalar::F64, 1.0, std::nextafter(1.0, 0.0)), 1u);
  EXPECT_EQ(ulp_distance(Scalar::F32, -std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::denorm_min()), 2u);
  EXPECT_EQ(ulp_distance(Scalar::F64, inf, std::numeric_limits<double>::max()), UINT64_MAX);
  EXPECT_EQ(ulp_distance(Scalar::F64, nan, 1.0), UINT64_MAX);
}

// in -> sin -> t (inexact) -> max with in -> out; then an If on t.
Program inexact_program(bool leak) {
  Program p;
  p.name = "inexact";
  VarId in = p.add_var({VarKind::Input, {Scalar::F32, 1}, "in", {}});
  VarId t = p.add_var({VarKind::Temp, {Scalar::F32, 1}, "t", {}});
  VarId out = p.add_var({VarKind::Output, {Scalar::F32, 2}, "out", {}});
  p.inputs = {in};
  p.outputs = {out};
  Swizzle x = Swizzle::identity(1), y = x;
  y.index[0] = 1;
  p.body.push_back(Stmt{Assign{out, Swizzle::identity(2), Op::Mov, {Operand{in, x}}, -1}});
  p.body.push_back(Stmt{Assign{t, x, Op::Sin, {Operand{in, x}}, -1}});
  p.body.push_back(Stmt{Assign{out, y, Op::Max, {Operand{t, x}, Operand{in, x}}, -1}});
  if (leak) p.body.push_back(Stmt{If{Operand{t, x}, {}, {}}});
  return p;
}

TEST(FuzzExactness, BoundsFlowThroughErrorPreservingOperationsOnly) {
  Program p = inexact_program(false);
  std::vector<Tolerance> t = tolerances(p);
  EXPECT_EQ(t[2][0].ulps, 0u) << "out.x is a copy of the input";
  EXPECT_TRUE(t[2][0].exact);
  EXPECT_EQ(t[2][1].ulps, op_info(Op::Sin).ulp_precise) << "out.y is max(sin(in), in)";
  EXPECT_FALSE(t[2][1].exact);
  EXPECT_EQ(inexact_leak(p), "");
  EXPECT_NE(inexact_leak(inexact_program(true)), "");
}

TEST(FuzzExactness, FloatMinAndMaxLeaveTheSignOfZeroOpen) {
  EXPECT_FALSE(exact_operation(Op::Min, Scalar::F32));
  EXPECT_FALSE(exact_operation(Op::Max, Scalar::F64));
  EXPECT_TRUE(exact_operation(Op::Min, Scalar::I32));
  EXPECT_TRUE(exact_operation(Op::Add, Scalar::F64));
  EXPECT_FALSE(exact_operation(Op::Sin, Scalar::F32));
}

class HasOp : public Visitor {
 public:
  explicit HasOp(Op op) : op_(op) {}
  using Visitor::visit;
  bool found = false;
  void visit(const Assign& a) override { found = found || a.op == op_; }

 private:
  Op op_;
};

TEST(FuzzMinimize, KeepsWhatTheFailureNeedsAndDropsTheRest) {
  for (int k = 0; k < 200; ++k) {
    Case c = generate(program_seed(11, k));
    HasOp has(Op::Rsqrt);
    has.visit(c.program.body);
    if (!has.found) continue;
    auto fails = [](const Case& candidate) {
      HasOp h(Op::Rsqrt);
      h.visit(Block(candidate.program.body.begin() + candidate.prologue, candidate.program.body.end()));
      return h.found;
    };
    if (!fails(c)) continue;
    Case small = minimize(c, c.count - 1, "", fails);
    EXPECT_EQ(small.count, 1u);
    EXPECT_NO_THROW(verify(small.program));
    ASSERT_EQ(static_cast<int>(small.program.body.size()), small.prologue + 1) << print(small.program);
    EXPECT_EQ(std::get<Assign>(small.program.body.back().node).op, Op::Rsqrt);
    return;
  }
  FAIL() << "no generated program used rsqrt";
}

}  // namespace
}  // namespace fuzz_ir
