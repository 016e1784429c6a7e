// Common subexpressions (Sh had none): where an operation on the same
// operands was already computed into a temporary that still holds it, the
// later assignment becomes a move of that temporary (copy propagation then
// removes the move).  Available expressions flow into nested blocks, and
// are dropped when an operand may be written: after a branch that writes
// it, and around any loop that does.  An across-elements operation
// (any_lane) answers for the elements running it: it is reused only
// between two control statements, where the same elements run.
#include <algorithm>

#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

struct Available {
  const ir::Assign* expr;  // computes into a temporary assigned only there
};

bool same_operand(const ir::Operand& a, const ir::Operand& b) { return a.var == b.var && a.swizzle == b.swizzle; }

bool same_expression(const ir::Program& p, const ir::Assign& a, const ir::Assign& b) {
  // The destination's type matters: a cast's result depends on it.
  if (p.type_of(a.dest) != p.type_of(b.dest)) return false;
  if (a.op != b.op || a.table != b.table || a.mask.size != b.mask.size || a.args.size() != b.args.size()) return false;
  for (std::size_t i = 0; i < a.args.size(); ++i)
    if (!same_operand(a.args[i], b.args[i])) return false;
  return true;
}

class Cse {
 public:
  explicit Cse(ir::Program& p) : p_(p), defs_(collect_definitions(p.body)) {}

  void block(ir::Block& b, std::vector<Available> avail) {
    for (ir::Stmt& s : b) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        assign(*a, avail);
        continue;
      }
      forget_lane_groups(avail);
      if (auto* f = std::get_if<ir::If>(&s.node)) {
        block(f->then_body, avail);
        block(f->else_body, avail);
        forget(avail, written_in(f->then_body));
        forget(avail, written_in(f->else_body));
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        forget(avail, written_in(*l));
        block(l->header, avail);
        block(l->body, avail);
        block(l->update, avail);
      }
    }
  }

 private:
  bool holds_for_good(const ir::Assign& a) const {
    return p_.var(a.dest).kind == ir::VarKind::Temp && defs_.single.count(a.dest) &&
           a.mask.is_identity(p_.type_of(a.dest).width);
  }

  void assign(ir::Assign& a, std::vector<Available>& avail) {
    if (a.op != ir::Op::Mov) {
      for (const Available& e : avail) {
        if (!same_expression(p_, *e.expr, a)) continue;
        a.op = ir::Op::Mov;
        a.table = -1;
        a.args = {ir::Operand{e.expr->dest, ir::Swizzle::identity(a.mask.size)}};
        break;
      }
    }
    forget(avail, {a.dest});
    bool reads_itself = std::any_of(a.args.begin(), a.args.end(), [&](const ir::Operand& o) { return o.var == a.dest; });
    if (a.op != ir::Op::Mov && holds_for_good(a) && !reads_itself) avail.push_back({&a});
  }

  static void forget_lane_groups(std::vector<Available>& avail) {
    std::erase_if(avail, [](const Available& e) { return ir::is_lane_group(e.expr->op); });
  }

  static void forget(std::vector<Available>& avail, const std::set<ir::VarId>& written) {
    std::erase_if(avail, [&](const Available& e) {
      if (written.count(e.expr->dest)) return true;
      for (const ir::Operand& o : e.expr->args)
        if (written.count(o.var)) return true;
      return false;
    });
  }

  ir::Program& p_;
  Definitions defs_;
};

}  // namespace

ir::Program eliminate_common_subexpressions(ir::Program p) {
  Cse cse(p);
  cse.block(p.body, {});
  return p;
}

}  // namespace sh::passes
