#include "sh/analysis.hpp"

namespace sh::analysis {
namespace {

bool add(VarSet& to, const VarSet& from) {
  bool changed = false;
  for (std::size_t v = 0; v < to.size(); ++v)
    if (from[v] && !to[v]) changed = to[v] = true;
  return changed;
}

// ---- uniformity ---------------------------------------------------------------

// A forward walk repeated until no variable turns varying: a write is
// varying if an operand is, or if it happens where lanes may disagree and
// the variable is live where lanes that did not write it wait.  Lanes that
// run a statement together agree on what they compute from uniform values:
// a variable only those lanes read before it is written again (a tree
// walk's node inside a varying `if`) stays one value for all of them.  A
// vote across lanes (any_lane) is the same in every lane that votes.
class Uniformity {
 public:
  Uniformity(const ir::Program& p, SpmdFacts& facts) : p_(p), f_(facts) {}

  void run() {
    f_.varying.assign(p_.vars.size(), false);
    for (ir::VarId v : p_.inputs) f_.varying[v] = true;
    for (ir::VarId v : p_.outputs) f_.varying[v] = true;
    VarSet nobody_waits(p_.vars.size(), false);
    do changed_ = false, block(p_.body, nobody_waits);
    while (changed_);
  }

 private:
  bool varying(const ir::Operand& o) const { return f_.varying[o.var]; }

  void mark(ir::VarId v) {
    if (!f_.varying[v]) changed_ = f_.varying[v] = true;
  }

  // `waiting`: what is live where lanes outside this block wait, for
  // each divergent if and loop the block lies in.
  void block(const ir::Block& b, const VarSet& waiting) {
    for (const ir::Stmt& s : b) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        bool any = waiting[a->dest] || a->op == ir::Op::Position;  // x differs in every lane
        if (a->op != ir::Op::AnyLane)
          for (const ir::Operand& o : a->args) any = any || varying(o);
        if (any) mark(a->dest);
      } else if (auto* i = std::get_if<ir::If>(&s.node)) {
        bool d = varying(i->cond);
        f_.divergent[&s] = d;
        block(i->then_body, d ? joined(waiting, f_.live_during_then.at(&s)) : waiting);
        block(i->else_body, d ? joined(waiting, f_.live_at_rejoin.at(&s)) : waiting);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        // Lanes leave at different iterations if the test differs between
        // them or a break or continue is taken by some lanes only.
        bool d = varying(l->cond) || jumps_under_varying_if(l->body, false) || jumps_under_varying_if(l->update, false);
        f_.divergent[&s] = d;
        VarSet inside = d ? joined(waiting, f_.live_at_rejoin.at(&s)) : waiting;
        block(l->header, inside);
        block(l->body, inside);
        block(l->update, inside);
      }
    }
  }

  static VarSet joined(VarSet a, const VarSet& b) {
    add(a, b);
    return a;
  }

  // Breaks and continues of this loop (not of loops nested in it).
  bool jumps_under_varying_if(const ir::Block& b, bool under) const {
    for (const ir::Stmt& s : b) {
      if (std::holds_alternative<ir::Break>(s.node) || std::holds_alternative<ir::Continue>(s.node)) {
        if (under) return true;
      } else if (auto* i = std::get_if<ir::If>(&s.node)) {
        bool u = under || varying(i->cond);
        if (jumps_under_varying_if(i->then_body, u) || jumps_under_varying_if(i->else_body, u)) return true;
      }
    }
    return false;
  }

  const ir::Program& p_;
  SpmdFacts& f_;
  bool changed_ = false;
};

// ---- liveness at rejoin points --------------------------------------------------

// Backward liveness on the structured body, per lane (a lane follows the
// scalar program), component by component: a variable built a component
// at a time (a join) is dead above the writes that cover it, as one
// written whole is.  Loops iterate to a fixed point.  Each if and loop
// records what is live where its inactive lanes wait.
class RejoinLiveness {
 public:
  RejoinLiveness(const ir::Program& p, SpmdFacts& facts) : p_(p), f_(facts) {}

  void run() {
    Live at_end(p_.vars.size(), 0);
    for (ir::VarId v : p_.outputs) at_end[v] = ir::Swizzle::identity(p_.type_of(v).width).bits();
    block(p_.body, at_end);
  }

 private:
  using Live = std::vector<std::uint8_t>;  // by VarId: the components live

  struct Targets {
    Live exit, update;
  };

  static bool add(Live& to, const Live& from) {
    bool changed = false;
    for (std::size_t v = 0; v < to.size(); ++v)
      if (from[v] & ~to[v]) changed = true, to[v] = static_cast<std::uint8_t>(to[v] | from[v]);
    return changed;
  }
  static VarSet any_component(const Live& live) {
    VarSet out(live.size(), false);
    for (std::size_t v = 0; v < live.size(); ++v) out[v] = live[v] != 0;
    return out;
  }

  void use(Live& live, const ir::Operand& o) const { live[o.var] = static_cast<std::uint8_t>(live[o.var] | o.swizzle.bits()); }

  Live block(const ir::Block& b, Live live) {
    for (auto s = b.rbegin(); s != b.rend(); ++s) live = statement(*s, std::move(live));
    return live;
  }

  Live statement(const ir::Stmt& s, Live live) {
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      if (ir::overwrites(*a)) live[a->dest] = static_cast<std::uint8_t>(live[a->dest] & ~a->mask.bits());
      for (const ir::Operand& o : a->args) use(live, o);
      return live;
    }
    if (auto* i = std::get_if<ir::If>(&s.node)) {
      // The then side runs first: its inactive lanes wait to run the else
      // side, so what the else side reads is live for them too.
      Live else_in = block(i->else_body, live);
      Live during_then = live;
      add(during_then, else_in);
      f_.live_at_rejoin[&s] = any_component(live);
      f_.live_during_then[&s] = any_component(during_then);
      Live in = block(i->then_body, live);
      add(in, else_in);
      use(in, i->cond);
      return in;
    }
    if (auto* l = std::get_if<ir::Loop>(&s.node)) return loop(s, *l, std::move(live));
    if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
      use(live, sc->index);
      use(live, sc->value);
      return live;
    }
    if (auto* pf = std::get_if<ir::Prefetch>(&s.node)) {
      use(live, pf->index);
      return live;
    }
    return std::holds_alternative<ir::Break>(s.node) ? loops_.back().exit : loops_.back().update;
  }

  Live loop(const ir::Stmt& s, const ir::Loop& l, Live exit) {
    Live top(exit.size(), 0);
    Live update_in;
    for (bool changed = true; changed;) {
      Live after_test = exit;
      use(after_test, l.cond);
      Live test_in, body_in;
      if (l.test_at_top) {
        update_in = block(l.update, top);
        loops_.push_back({exit, update_in});
        body_in = block(l.body, update_in);
        loops_.pop_back();
        add(after_test, body_in);
        test_in = block(l.header, after_test);
        changed = add(top, test_in);
      } else {
        add(after_test, top);
        test_in = block(l.header, after_test);
        update_in = block(l.update, test_in);
        loops_.push_back({exit, update_in});
        body_in = block(l.body, update_in);
        loops_.pop_back();
        changed = add(top, body_in);
      }
    }
    // Lanes that left wait at the exit; lanes that continued, at the update.
    Live rejoin = exit;
    if (continues(l.body)) add(rejoin, update_in);
    f_.live_at_rejoin[&s] = any_component(rejoin);
    return top;
  }

  const ir::Program& p_;
  SpmdFacts& f_;
  std::vector<Targets> loops_;
};

}  // namespace

bool continues(const ir::Block& body) {
  for (const ir::Stmt& s : body) {
    if (std::holds_alternative<ir::Continue>(s.node)) return true;
    if (auto* i = std::get_if<ir::If>(&s.node))
      if (continues(i->then_body) || continues(i->else_body)) return true;
  }
  return false;
}

SpmdFacts analyse_spmd(const ir::Program& p) {
  SpmdFacts facts;
  RejoinLiveness(p, facts).run();
  Uniformity(p, facts).run();
  return facts;
}

}  // namespace sh::analysis
