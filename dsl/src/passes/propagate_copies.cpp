// Copy propagation: a temporary assigned once, by a move of a value that
// cannot change while the temporary is read, is replaced by that value at
// every read the assignment dominates.  Registers are not SSA, so a
// temporary qualifies only if its one assignment comes before all its reads
// in the structured order, and the source is never written (a constant,
// uniform or unwritten input) or is itself assigned once before it.
#include <map>

#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

class Propagator {
 public:
  explicit Propagator(ir::Program& p) : p_(p), defs_(collect_definitions(p.body)) {
    for (const auto& [var, path] : defs_.single)
      if (qualifies(var, path)) candidates_.emplace(var, defs_.assign.at(var)->args[0]);
  }

  void run() {
    Path path;
    check(p_.body, path);
    for (ir::VarId bad : spoiled_) candidates_.erase(bad);
    if (!candidates_.empty()) rewrite(p_.body);
  }

 private:
  bool qualifies(ir::VarId var, const Path& path) const {
    const ir::Assign& a = *defs_.assign.at(var);
    if (p_.var(var).kind != ir::VarKind::Temp || a.op != ir::Op::Mov) return false;
    if (!a.mask.is_identity(p_.type_of(var).width)) return false;
    ir::VarId src = a.args[0].var;
    if (src == var) return false;
    if (never_written(p_, defs_, src)) return true;
    auto s = defs_.single.find(src);
    return p_.var(src).kind == ir::VarKind::Temp && s != defs_.single.end() && dominated(path, s->second.back());
  }

  void check(const ir::Block& b, Path& path) {
    for (std::size_t i = 0; i < b.size(); ++i) {
      path.push_back(Site{&b, i});
      const ir::Stmt& s = b[i];
      for_each_own_operand(s, [&](const ir::Operand& o) {
        if (candidates_.count(o.var) && !dominated(path, defs_.single.at(o.var).back())) spoiled_.push_back(o.var);
      });
      if (auto* f = std::get_if<ir::If>(&s.node)) {
        check(f->then_body, path);
        check(f->else_body, path);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        check(l->header, path);
        check(l->body, path);
        check(l->update, path);
      }
      path.pop_back();
    }
  }

  void rewrite(ir::Block& b) {
    for (ir::Stmt& s : b) {
      for_each_own_operand(s, [&](ir::Operand& o) { replace(o); });
      if (auto* f = std::get_if<ir::If>(&s.node)) {
        rewrite(f->then_body);
        rewrite(f->else_body);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        rewrite(l->header);
        rewrite(l->body);
        rewrite(l->update);
      }
    }
  }

  void replace(ir::Operand& o) const {
    auto it = candidates_.find(o.var);
    if (it == candidates_.end()) return;
    const ir::Operand& src = it->second;
    ir::Swizzle s;
    s.size = o.swizzle.size;
    for (int i = 0; i < s.size; ++i) s.index[i] = src.component(o.swizzle[i]);
    o = ir::Operand{src.var, s};
  }

  ir::Program& p_;
  Definitions defs_;
  std::map<ir::VarId, ir::Operand> candidates_;
  std::vector<ir::VarId> spoiled_;
};

}  // namespace

ir::Program propagate_copies(ir::Program p) {
  Propagator(p).run();
  return p;
}

}  // namespace sh::passes
