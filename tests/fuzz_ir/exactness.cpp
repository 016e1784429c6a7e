#include "exactness.hpp"

#include <algorithm>

#include <sh/ir/printer.hpp>
#include <sh/ir/visitor.hpp>

namespace fuzz_ir {
namespace {

using namespace sh::ir;

// One pass over the assignments: raises each written component to the
// bound its operation adds or its operands carry.  Returns whether
// anything rose.
class Propagate : public Visitor {
 public:
  Propagate(const Program& p, std::vector<Tolerance>& t) : p_(p), t_(t) {}
  using Visitor::visit;
  bool changed = false;

  void visit(const Assign& a) override {
    bool exact = exact_operation(a.op, p_.type_of(a.dest).scalar);
    for (int i = 0; i < a.mask.size; ++i) {
      Bound bound{exact ? 0 : op_info(a.op).ulp_precise, exact};
      for (std::size_t k = 0; k < a.args.size(); ++k)
        if (passes_error_through(a.op, static_cast<int>(k))) {
          const Bound& from = t_[a.args[k].var][a.args[k].component(i)];
          bound = {std::max(bound.ulps, from.ulps), bound.exact && from.exact};
        }
      Bound& slot = t_[a.dest][a.mask[i]];
      if (bound.ulps > slot.ulps || (!bound.exact && slot.exact)) {
        slot = {std::max(bound.ulps, slot.ulps), slot.exact && bound.exact};
        changed = true;
      }
    }
  }

 private:
  const Program& p_;
  std::vector<Tolerance>& t_;
};

class FindLeak : public Visitor {
 public:
  FindLeak(const Program& p, const std::vector<Tolerance>& t) : p_(p), t_(t) {}
  using Visitor::visit;
  std::string leak;

  void visit(const Assign& a) override {
    for (std::size_t k = 0; k < a.args.size(); ++k)
      if (!passes_error_through(a.op, static_cast<int>(k)) || op_info(a.op).ulp_precise > 0 || is_table_read(a.op))
        check(a.args[k], Stmt{a});
  }
  void visit(const If& s) override {
    check(s.cond, Stmt{s});
    Visitor::visit(s);
  }
  void visit(const Loop& s) override {
    check(s.cond, Stmt{s});
    Visitor::visit(s);
  }
  void visit(const Scatter& s) override {
    check(s.index, Stmt{s});
    check(s.value, Stmt{s});
  }

 private:
  void check(const Operand& o, const Stmt& s) {
    for (int i = 0; i < o.width(); ++i)
      if (leak.empty() && !t_[o.var][o.swizzle[i]].exact) leak = "an inexact value reaches `" + print(p_, s) + "`";
  }
  const Program& p_;
  const std::vector<Tolerance>& t_;
};

}  // namespace

bool exact_operation(Op op, Scalar s) {
  if (is_float(s) && (op == Op::Min || op == Op::Max)) return false;
  return op_info(op).ulp_precise == 0;
}

bool passes_error_through(Op op, int arg) {
  if (op == Op::Mov || op == Op::Neg || op == Op::Abs || op == Op::Min || op == Op::Max) return true;
  return op == Op::Cond && arg > 0;
}

std::vector<Tolerance> tolerances(const Program& p) {
  std::vector<Tolerance> t(p.vars.size(), Tolerance{});
  for (;;) {
    Propagate pass(p, t);
    pass.visit(p.body);
    if (!pass.changed) return t;
  }
}

std::string inexact_leak(const Program& p) {
  std::vector<Tolerance> t = tolerances(p);
  FindLeak find(p, t);
  find.visit(p.body);
  return find.leak;
}

}  // namespace fuzz_ir
