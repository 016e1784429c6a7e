// Program algebra: programs are glued into one IR program.  Each part's
// variables are copied in, its interface variables become ordinary
// registers joined by moves, and the kinds are settled at the end from the
// roles the variables play in the result.
#include <algorithm>
#include <set>

#include "sh/error.hpp"
#include "sh/ir/visitor.hpp"
#include "sh/program.hpp"

namespace sh {
namespace {

class Glue {
 public:
  explicit Glue(std::string name) { out_.name = std::move(name); }

  // Copies `part` in; returns its variables' new ids and appends its body.
  std::vector<ir::VarId> add(const Program& part) {
    const ir::Program& p = part.ir();
    std::vector<ir::VarId> vars(p.vars.size());
    for (std::size_t u = 0; u < p.uniforms.size(); ++u) vars[p.uniforms[u]] = uniform(part.uniforms()[u], p.vars[p.uniforms[u]]);
    for (std::size_t i = 0; i < p.vars.size(); ++i)
      if (p.vars[i].kind != ir::VarKind::Uniform) vars[i] = out_.add_var(p.vars[i]);
    std::vector<int> tables(p.tables.size());
    for (std::size_t t = 0; t < p.tables.size(); ++t) tables[t] = table(part.tables()[t], p.tables[t]);
    Block body = p.body;
    remap(body, vars, tables);
    for (ir::Stmt& s : body) out_.body.push_back(std::move(s));
    return vars;
  }

  ir::VarId uniform(const std::shared_ptr<detail::VarNode>& node, const ir::Var& var) {
    for (std::size_t i = 0; i < uniforms_.size(); ++i)
      if (uniforms_[i] == node) return out_.uniforms[i];
    ir::VarId id = out_.add_var(var);
    out_.uniforms.push_back(id);
    uniforms_.push_back(node);
    return id;
  }

  void move(ir::VarId dest, ir::VarId src) {
    if (out_.type_of(dest) != out_.type_of(src))
      throw Error("program '" + out_.name + "': cannot connect " + ir::type_name(out_.type_of(src)) + " to " +
                  ir::type_name(out_.type_of(dest)));
    out_.body.push_back(ir::Stmt{ir::Assign{dest, ir::Swizzle::identity(out_.type_of(dest).width), ir::Op::Mov,
                                            {ir::whole(out_, src)}, -1}});
  }

  ir::Program& ir() { return out_; }

  // Gives every variable the kind its role in the result calls for.
  Program finish(std::vector<ir::VarId> inputs, std::vector<ir::VarId> outputs) {
    std::set<ir::VarId> written = written_vars(out_.body);
    std::set<ir::VarId> in(inputs.begin(), inputs.end()), outs(outputs.begin(), outputs.end());
    Block prologue;
    for (ir::Var& v : out_.vars)
      if (v.kind == ir::VarKind::Input || v.kind == ir::VarKind::Output || v.kind == ir::VarKind::InOut)
        v.kind = ir::VarKind::Temp;
    for (ir::VarId& id : inputs) {
      bool also_out = outs.count(id) > 0;
      if (also_out) { out_.vars[id].kind = ir::VarKind::InOut; continue; }
      if (!written.count(id)) { out_.vars[id].kind = ir::VarKind::Input; continue; }
      // A variable the result writes cannot be its input: read a fresh one.
      ir::Var fresh = out_.vars[id];
      fresh.kind = ir::VarKind::Input;
      ir::VarId source = out_.add_var(fresh);
      prologue.push_back(ir::Stmt{ir::Assign{id, ir::Swizzle::identity(fresh.type.width), ir::Op::Mov,
                                             {ir::whole(out_, source)}, -1}});
      id = source;
    }
    for (ir::VarId id : outputs)
      if (!in.count(id)) out_.vars[id].kind = ir::VarKind::Output;
    out_.body.insert(out_.body.begin(), std::make_move_iterator(prologue.begin()),
                     std::make_move_iterator(prologue.end()));
    out_.inputs = std::move(inputs);
    out_.outputs = std::move(outputs);
    return Program(std::move(out_), std::move(uniforms_), std::move(tables_));
  }

 private:
  using Block = ir::Block;

  // A part's table as the part recorded it: its edge mode then, not the
  // table's now (one table read with two edge modes is two entries).
  int table(const std::shared_ptr<detail::TableStorage>& storage, const ir::TableDecl& recorded) {
    for (std::size_t i = 0; i < tables_.size(); ++i)
      if (tables_[i] == storage && out_.tables[i].edge == recorded.edge) return static_cast<int>(i);
    tables_.push_back(storage);
    out_.tables.push_back(recorded);
    return static_cast<int>(tables_.size() - 1);
  }

  static void remap(Block& block, const std::vector<ir::VarId>& vars, const std::vector<int>& tables) {
    for (ir::Stmt& s : block) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        a->dest = vars[a->dest];
        for (ir::Operand& o : a->args) o.var = vars[o.var];
        if (a->table >= 0) a->table = tables[a->table];
      } else if (auto* i = std::get_if<ir::If>(&s.node)) {
        i->cond.var = vars[i->cond.var];
        remap(i->then_body, vars, tables);
        remap(i->else_body, vars, tables);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        l->cond.var = vars[l->cond.var];
        remap(l->header, vars, tables);
        remap(l->body, vars, tables);
        remap(l->update, vars, tables);
      } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
        sc->index.var = vars[sc->index.var];
        sc->value.var = vars[sc->value.var];
        sc->table = tables[sc->table];
      } else if (auto* pf = std::get_if<ir::Prefetch>(&s.node)) {
        pf->index.var = vars[pf->index.var];
        pf->table = tables[pf->table];
      }
    }
  }

  static std::set<ir::VarId> written_vars(const Block& body) {
    struct Writes : ir::Visitor {
      using ir::Visitor::visit;
      std::set<ir::VarId> ids;
      void visit(const ir::Assign& a) override { ids.insert(a.dest); }
    } w;
    w.visit(body);
    return w.ids;
  }

  ir::Program out_;
  std::vector<std::shared_ptr<detail::VarNode>> uniforms_;
  std::vector<std::shared_ptr<detail::TableStorage>> tables_;
};

std::vector<ir::VarId> mapped(const std::vector<ir::VarId>& ids, const std::vector<ir::VarId>& map) {
  std::vector<ir::VarId> out;
  for (ir::VarId id : ids) out.push_back(map[id]);
  return out;
}

}  // namespace

Program operator<<(const Program& p, const Program& q) {
  const ir::Program &pi = p.ir(), &qi = q.ir();
  if (qi.outputs.size() != pi.inputs.size())
    throw Error("program '" + pi.name + "' << '" + qi.name + "': " + std::to_string(qi.outputs.size()) +
                " outputs cannot feed " + std::to_string(pi.inputs.size()) + " inputs");
  Glue glue(pi.name + "<<" + qi.name);
  std::vector<ir::VarId> qv = glue.add(q);
  ir::Block q_body = std::move(glue.ir().body);
  glue.ir().body.clear();
  std::vector<ir::VarId> pv = glue.add(p);
  ir::Block p_body = std::move(glue.ir().body);
  glue.ir().body = std::move(q_body);
  for (std::size_t k = 0; k < pi.inputs.size(); ++k) glue.move(pv[pi.inputs[k]], qv[qi.outputs[k]]);
  for (ir::Stmt& s : p_body) glue.ir().body.push_back(std::move(s));
  return glue.finish(mapped(qi.inputs, qv), mapped(pi.outputs, pv));
}

Program operator&(const Program& p, const Program& q) {
  Glue glue(p.ir().name + "&" + q.ir().name);
  std::vector<ir::VarId> pv = glue.add(p);
  std::vector<ir::VarId> qv = glue.add(q);
  std::vector<ir::VarId> inputs = mapped(p.ir().inputs, pv), outputs = mapped(p.ir().outputs, pv);
  for (ir::VarId id : mapped(q.ir().inputs, qv)) inputs.push_back(id);
  for (ir::VarId id : mapped(q.ir().outputs, qv)) outputs.push_back(id);
  return glue.finish(std::move(inputs), std::move(outputs));
}

Program bind(const Program& p, const detail::Value& value) {
  const ir::Program& pi = p.ir();
  if (pi.inputs.empty()) throw Error("program '" + pi.name + "': bind needs an input to bind, and it has none");
  if (value.node->kind != ir::VarKind::Uniform && value.node->kind != ir::VarKind::Const)
    throw Error("program '" + pi.name + "': only a uniform or a constant can be bound to an input");
  Glue glue(pi.name);
  ir::Var var;
  var.kind = value.node->kind;
  var.type = value.type();
  var.name = value.node->name;
  ir::VarId source;
  if (value.node->kind == ir::VarKind::Uniform) {
    var.type = value.node->type;
    source = glue.uniform(value.node, var);
  } else {
    var.value = value.node->value;
    var.type = value.node->type;
    source = glue.ir().add_var(var);
  }
  std::vector<ir::VarId> pv = glue.add(p);
  ir::VarId first = pv[pi.inputs[0]];
  ir::Block body = std::move(glue.ir().body);
  glue.ir().body.clear();
  ir::Type t = glue.ir().type_of(first);
  if (value.type() != t)
    throw Error("program '" + pi.name + "': cannot bind a " + ir::type_name(value.type()) + " to input of type " +
                ir::type_name(t));
  glue.ir().body.push_back(ir::Stmt{ir::Assign{first, ir::Swizzle::identity(t.width), ir::Op::Mov,
                                               {ir::Operand{source, value.swizzle}}, -1}});
  for (ir::Stmt& s : body) glue.ir().body.push_back(std::move(s));
  std::vector<ir::VarId> inputs = mapped(pi.inputs, pv);
  inputs.erase(inputs.begin());
  return glue.finish(std::move(inputs), mapped(pi.outputs, pv));
}

Program freeze(const Program& p, const detail::Value& uniform) {
  const ir::Program& pi = p.ir();
  auto it = std::find(p.uniforms().begin(), p.uniforms().end(), uniform.node);
  if (it == p.uniforms().end())
    throw Error("program '" + pi.name + "': freeze names a uniform the program does not read");
  std::size_t slot = static_cast<std::size_t>(it - p.uniforms().begin());
  ir::Program frozen = pi;
  ir::Var& v = frozen.vars[frozen.uniforms[slot]];
  v.kind = ir::VarKind::Const;
  v.value = uniform.node->value;
  frozen.uniforms.erase(frozen.uniforms.begin() + static_cast<long>(slot));
  std::vector<std::shared_ptr<detail::VarNode>> uniforms = p.uniforms();
  uniforms.erase(uniforms.begin() + static_cast<long>(slot));
  return Program(std::move(frozen), std::move(uniforms), p.tables());
}

}  // namespace sh
