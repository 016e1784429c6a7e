// Constant folding: an assignment whose operands are all constants becomes
// a move of the computed constant; an `if` on a constant keeps only the
// branch taken; a loop whose test fails before the first iteration goes.
#include <cmath>

#include "sh/ir/eval.hpp"
#include "sh/ir/visitor.hpp"
#include "sh/passes.hpp"

namespace sh::passes {
namespace {

class Folder : public ir::Mutator {
 public:
  Folder(ir::Program& p, ir::Precision precision) : p_(p), precision_(precision) {}
  using ir::Mutator::mutate;

  void mutate(ir::Assign a, ir::Block& out) override {
    if (a.op != ir::Op::Mov && ir::op_info(a.op).folds && all_constant(a)) {
      ir::Scalar from = p_.type_of(a.args[0].var).scalar, to = p_.type_of(a.dest).scalar;
      std::array<double, 4> v{};
      bool nan_made = false;
      for (int i = 0; i < a.mask.size; ++i) {
        double x[3] = {0, 0, 0};
        for (std::size_t k = 0; k < a.args.size(); ++k) x[k] = component(a.args[k], i);
        v[i] = ir::eval(a.op, from, to, precision_, x[0], x[1], x[2]);
        nan_made = nan_made || (std::isnan(v[i]) && !std::isnan(x[0]) && !std::isnan(x[1]) && !std::isnan(x[2]));
      }
      // A NaN made from numbers (0 / 0, inf - inf, sqrt(-1)) is left to
      // the run, where a checked run names the instruction that made it.
      if (nan_made) {
        out.push_back(ir::Stmt{std::move(a)});
        return;
      }
      ir::VarId c = p_.add_const({to, a.mask.size}, v);
      a.op = ir::Op::Mov;
      a.args = {ir::whole(p_, c)};
    }
    out.push_back(ir::Stmt{std::move(a)});
  }

  void mutate(ir::If s, ir::Block& out) override {
    if (is_constant(s.cond)) {
      ir::Block taken = mutate(component(s.cond, 0) > 0 ? std::move(s.then_body) : std::move(s.else_body));
      for (ir::Stmt& t : taken) out.push_back(std::move(t));
      return;
    }
    ir::Mutator::mutate(std::move(s), out);
  }

  void mutate(ir::Loop s, ir::Block& out) override {
    if (s.test_at_top && s.header.empty() && is_constant(s.cond) && !(component(s.cond, 0) > 0)) return;
    ir::Mutator::mutate(std::move(s), out);
  }

 private:
  bool is_constant(const ir::Operand& o) const { return p_.var(o.var).kind == ir::VarKind::Const; }
  bool all_constant(const ir::Assign& a) const {
    for (const ir::Operand& o : a.args)
      if (!is_constant(o)) return false;
    return true;
  }
  // As a register holds it: an f32 constant rounded to float, as every
  // backend reads it.
  double component(const ir::Operand& o, int i) const {
    return ir::hold(p_.type_of(o.var).scalar, precision_, p_.var(o.var).value[o.component(i)]);
  }

  ir::Program& p_;
  ir::Precision precision_;
};

}  // namespace

ir::Program fold_constants(ir::Program p, ir::Precision precision) {
  Folder f(p, precision);
  p.body = f.mutate(std::move(p.body));
  return p;
}

}  // namespace sh::passes
