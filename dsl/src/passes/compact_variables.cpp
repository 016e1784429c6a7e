// Renumbers variables so that those no statement mentions any more (after
// the other passes) disappear, keeping the interface ones in order.
#include <map>

#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

template <class F>
void each_operand_and_dest(ir::Block& b, F f) {
  for (ir::Stmt& s : b) {
    for_each_own_operand(s, [&](ir::Operand& o) { f(o.var); });
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      f(a->dest);
    } else if (auto* i = std::get_if<ir::If>(&s.node)) {
      each_operand_and_dest(i->then_body, f);
      each_operand_and_dest(i->else_body, f);
    } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
      each_operand_and_dest(l->header, f);
      each_operand_and_dest(l->body, f);
      each_operand_and_dest(l->update, f);
    }
  }
}

}  // namespace

ir::Program compact_variables(ir::Program p) {
  std::vector<bool> used(p.vars.size(), false);
  for (std::size_t i = 0; i < p.vars.size(); ++i) {
    ir::VarKind k = p.vars[i].kind;
    used[i] = k != ir::VarKind::Temp && k != ir::VarKind::Const && k != ir::VarKind::Array;
  }
  each_operand_and_dest(p.body, [&](ir::VarId& v) { used[v] = true; });
  std::vector<ir::VarId> renumber(p.vars.size(), -1);
  std::vector<ir::Var> vars;
  for (std::size_t i = 0; i < p.vars.size(); ++i) {
    if (!used[i]) continue;
    renumber[i] = static_cast<ir::VarId>(vars.size());
    vars.push_back(std::move(p.vars[i]));
  }
  p.vars = std::move(vars);
  for (auto* list : {&p.inputs, &p.outputs, &p.uniforms})
    for (ir::VarId& v : *list) v = renumber[v];
  each_operand_and_dest(p.body, [&](ir::VarId& v) { v = renumber[v]; });
  return p;
}

}  // namespace sh::passes
