// Dead-code elimination: keeps what can reach an output, an accumulator or
// a prefetch.  A variable is live if an output is it or a live assignment,
// a scatter, a prefetch or a kept control construct reads it; a loop is
// kept if it holds a live assignment or a scatter, and with it the
// conditions of the branches that leave or restart it.  A loop that would
// only prefetch goes with its prefetches: kept, it would cost its
// iterations (a runaway one its cap) for what changes no result.
// Everything else, including branches and loops left empty, goes.
#include "sh/ir/visitor.hpp"
#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

class Liveness {
 public:
  explicit Liveness(const ir::Program& p) : live_(p.vars.size(), false) {
    for (ir::VarId v : p.outputs) live_[static_cast<std::size_t>(v)] = true;
    while (grow(p.body)) {
    }
  }
  bool live(ir::VarId v) const { return live_[static_cast<std::size_t>(v)]; }

  // Does the block assign a live variable or scatter (at any depth), or
  // (with `prefetches`) prefetch?
  bool has_live_assign(const ir::Block& b, bool prefetches = true) const {
    struct Finder : ir::Visitor {
      using ir::Visitor::visit;
      const Liveness* l;
      bool prefetches;
      bool found = false;
      void visit(const ir::Assign& a) override { found = found || l->live(a.dest); }
      void visit(const ir::Scatter&) override { found = true; }
      void visit(const ir::Prefetch&) override { found = found || prefetches; }
    } f;
    f.l = this;
    f.prefetches = prefetches;
    f.visit(b);
    return f.found;
  }
  bool has_live_assign(const ir::Loop& l) const {
    return has_live_assign(l.header, false) || has_live_assign(l.body, false) || has_live_assign(l.update, false);
  }

 private:
  bool mark(ir::VarId v) {
    if (live(v)) return false;
    live_[static_cast<std::size_t>(v)] = true;
    return true;
  }

  // One sweep; true if anything new became live.  It runs backwards, as
  // liveness flows: a chain of assignments in a block becomes live in one
  // sweep, not one link a sweep; only loops need further sweeps.  `kept`:
  // the block is not inside a loop that goes, whose prefetches go with it.
  bool grow(const ir::Block& b, bool in_live_loop = false, bool kept = true) {
    bool changed = false;
    for (auto s = b.rbegin(); s != b.rend(); ++s) {
      if (auto* a = std::get_if<ir::Assign>(&s->node)) {
        if (live(a->dest))
          for (const ir::Operand& o : a->args) changed |= mark(o.var);
      } else if (auto* sc = std::get_if<ir::Scatter>(&s->node)) {
        changed |= mark(sc->index.var);
        changed |= mark(sc->value.var);
      } else if (auto* pf = std::get_if<ir::Prefetch>(&s->node)) {
        if (kept) changed |= mark(pf->index.var);
      } else if (auto* f = std::get_if<ir::If>(&s->node)) {
        changed |= grow(f->else_body, in_live_loop, kept);
        changed |= grow(f->then_body, in_live_loop, kept);
        bool needed = has_live_assign(f->then_body, kept) || has_live_assign(f->else_body, kept) ||
                      (in_live_loop && (has_jump(f->then_body) || has_jump(f->else_body)));
        if (needed) changed |= mark(f->cond.var);
      } else if (auto* l = std::get_if<ir::Loop>(&s->node)) {
        bool needed = has_live_assign(*l);
        changed |= grow(l->update, false, kept && needed);
        changed |= grow(l->body, needed, kept && needed);
        changed |= grow(l->header, false, kept && needed);
        if (needed) changed |= mark(l->cond.var);
      }
    }
    return changed;
  }

  // A break or continue that belongs to the enclosing loop.
  static bool has_jump(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      if (std::holds_alternative<ir::Break>(s.node) || std::holds_alternative<ir::Continue>(s.node)) return true;
      if (auto* f = std::get_if<ir::If>(&s.node))
        if (has_jump(f->then_body) || has_jump(f->else_body)) return true;
    }
    return false;
  }

  std::vector<bool> live_;  // by variable
};

class Sweeper : public ir::Mutator {
 public:
  explicit Sweeper(const Liveness& l) : l_(l) {}
  using ir::Mutator::mutate;

  void mutate(ir::Assign a, ir::Block& out) override {
    if (l_.live(a.dest)) out.push_back(ir::Stmt{std::move(a)});
  }
  void mutate(ir::If s, ir::Block& out) override {
    s.then_body = mutate(std::move(s.then_body));
    s.else_body = mutate(std::move(s.else_body));
    if (!s.then_body.empty() || !s.else_body.empty()) out.push_back(ir::Stmt{std::move(s)});
  }
  void mutate(ir::Loop s, ir::Block& out) override {
    if (!l_.has_live_assign(s)) return;
    ir::Mutator::mutate(std::move(s), out);
  }

 private:
  const Liveness& l_;
};

}  // namespace

ir::Program eliminate_dead_code(ir::Program p) {
  Liveness live(p);
  Sweeper sweep(live);
  p.body = sweep.mutate(std::move(p.body));
  return p;
}

}  // namespace sh::passes
