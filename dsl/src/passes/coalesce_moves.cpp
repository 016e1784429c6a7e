// Move coalescing: recording gives `t = op(...); x.mask = mov t` for every
// assignment to an existing variable.  Where t is read only by that move,
// the operation writes x directly and t goes.
#include <map>

#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

class Coalescer {
 public:
  explicit Coalescer(const ir::Program& p) : p_(p), defs_(collect_definitions(p.body)) { count_reads(p.body); }

  void block(ir::Block& b) {
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (i + 1 < b.size()) merge(b, i);
      if (auto* f = std::get_if<ir::If>(&b[i].node)) {
        block(f->then_body);
        block(f->else_body);
      } else if (auto* l = std::get_if<ir::Loop>(&b[i].node)) {
        block(l->header);
        block(l->body);
        block(l->update);
      }
    }
  }

 private:
  void count_reads(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      for_each_own_operand(s, [&](const ir::Operand& o) { ++reads_[o.var]; });
      if (auto* f = std::get_if<ir::If>(&s.node)) {
        count_reads(f->then_body);
        count_reads(f->else_body);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        count_reads(l->header);
        count_reads(l->body);
        count_reads(l->update);
      }
    }
  }

  void merge(ir::Block& b, std::size_t i) {
    auto* def = std::get_if<ir::Assign>(&b[i].node);
    auto* mov = std::get_if<ir::Assign>(&b[i + 1].node);
    if (!def || !mov || mov->op != ir::Op::Mov) return;
    ir::VarId t = def->dest;
    const ir::Operand& src = mov->args[0];
    int width = p_.type_of(t).width;
    if (src.var != t || p_.var(t).kind != ir::VarKind::Temp || !defs_.single.count(t) || reads_[t] != 1) return;
    if (!def->mask.is_identity(width) || !src.swizzle.is_identity(width) || mov->mask.size != width) return;
    def->dest = mov->dest;
    def->mask = mov->mask;
    b.erase(b.begin() + static_cast<long>(i) + 1);
  }

  const ir::Program& p_;
  Definitions defs_;
  std::map<ir::VarId, int> reads_;
};

}  // namespace

ir::Program coalesce_moves(ir::Program p) {
  Coalescer c(p);
  c.block(p.body);
  return p;
}

}  // namespace sh::passes
