// Operation counts by class: each operation counts once per component it
// computes.  Loops report their iteration's counts, and a total where the
// IR shows a constant trip count (a counter set to a constant before the
// loop, tested against a constant, stepped by a constant, written nowhere
// else, no break).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "units.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::analysis {

std::optional<Unit> unit_of(ir::Op op) {
  switch (op_info(op).cls) {
    case ir::OpClass::Move: return std::nullopt;
    case ir::OpClass::Add: return Unit::Add;
    case ir::OpClass::Mul: return Unit::Mul;
    case ir::OpClass::Div: return Unit::Div;
    case ir::OpClass::Negate: return Unit::Negate;
    case ir::OpClass::Compare: return Unit::Compare;
    case ir::OpClass::Transcendental: return Unit::Transcendental;
    case ir::OpClass::TableRead: return Unit::TableRead;
  }
  return std::nullopt;
}

namespace {

class Counter {
 public:
  explicit Counter(const ir::Program& p) : p_(p) {}

  Cost run() {
    Cost c;
    c.outside_loops = block(p_.body, 0, c);
    return c;
  }

 private:
  // Counts a block; loops inside it are reported, and folded in where
  // their trip count is known.
  OpCounts block(const ir::Block& b, int depth, Cost& cost) {
    OpCounts sum;
    for (std::size_t i = 0; i < b.size(); ++i) {
      const ir::Stmt& s = b[i];
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        if (auto u = unit_of(a->op)) sum[*u] += is_table_read(a->op) ? 1 : a->mask.size;
      } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
        sum[Unit::Add] += static_cast<std::uint64_t>(sc->value.width());
      } else if (auto* f = std::get_if<ir::If>(&s.node)) {
        sum += block(f->then_body, depth, cost);
        sum += block(f->else_body, depth, cost);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        std::size_t at = cost.loops.size();
        cost.loops.push_back({ir::print(p_, s), depth, {}, std::nullopt, std::nullopt});
        OpCounts iteration = block(l->header, depth + 1, cost);
        iteration += block(l->body, depth + 1, cost);
        iteration += block(l->update, depth + 1, cost);
        LoopCost& lc = cost.loops[at];
        lc.per_iteration = iteration;
        lc.trips = trip_count(b, i, *l);
        if (lc.trips) {
          lc.total = iteration.times(*lc.trips);
          sum += *lc.total;
        }
      }
    }
    return sum;
  }

  // The constant a straight run of assignments before `at` last set `v` to.
  std::optional<double> constant_before(const ir::Block& b, std::size_t at, ir::VarId v) const {
    for (std::size_t i = at; i-- > 0;) {
      auto* a = std::get_if<ir::Assign>(&b[i].node);
      if (!a) return std::nullopt;
      if (a->dest != v) continue;
      if (a->op != ir::Op::Mov || p_.var(a->args[0].var).kind != ir::VarKind::Const) return std::nullopt;
      return p_.var(a->args[0].var).value[a->args[0].swizzle[0]];
    }
    return std::nullopt;
  }

  std::optional<std::uint64_t> trip_count(const ir::Block& b, std::size_t at, const ir::Loop& l) const {
    if (!l.test_at_top || l.header.size() != 1 || has_break(l.body)) return std::nullopt;
    auto* test = std::get_if<ir::Assign>(&l.header[0].node);
    if (!test || test->dest != l.cond.var || (test->op != ir::Op::Lt && test->op != ir::Op::Le)) return std::nullopt;
    const ir::Operand &counter = test->args[0], &limit = test->args[1];
    if (p_.var(limit.var).kind != ir::VarKind::Const || p_.type_of(counter.var).width != 1) return std::nullopt;
    auto start = constant_before(b, at, counter.var);
    struct Writes : ir::Visitor {
      using ir::Visitor::visit;
      ir::VarId v = -1;
      std::vector<const ir::Assign*> found;
      void visit(const ir::Assign& a) override {
        if (a.dest == v) found.push_back(&a);
      }
    } w;
    w.v = counter.var;
    w.visit(l.body);
    w.visit(l.update);
    if (!start || w.found.size() != 1) return std::nullopt;
    const ir::Assign& step = *w.found[0];
    // The step runs once a pass only where it is a statement of the update,
    // or of the body with no continue to pass it by (not inside an if or
    // an inner loop).
    auto holds = [&](const ir::Block& block) {
      return std::any_of(block.begin(), block.end(),
                         [&](const ir::Stmt& s) { return std::get_if<ir::Assign>(&s.node) == &step; });
    };
    if (!holds(l.update) && !(holds(l.body) && !has_continue(l.body))) return std::nullopt;
    if (step.op != ir::Op::Add || step.args[0].var != counter.var || p_.var(step.args[1].var).kind != ir::VarKind::Const)
      return std::nullopt;
    double by = p_.var(step.args[1].var).value[step.args[1].swizzle[0]];
    double k = p_.var(limit.var).value[limit.swizzle[0]];
    if (by <= 0) return std::nullopt;
    double span = k - *start;
    if (!std::isfinite(span) || !std::isfinite(by)) return std::nullopt;  // a NaN or infinite bound: no count
    if (span < 0 || (span == 0 && test->op == ir::Op::Lt)) return 0;
    double n = test->op == ir::Op::Lt ? std::ceil(span / by) : std::floor(span / by) + 1;
    if (!(n < 0x1p40)) return std::nullopt;  // past any loop cap; counts times it would overflow
    return static_cast<std::uint64_t>(n);
  }

  static bool has_continue(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      if (std::holds_alternative<ir::Continue>(s.node)) return true;
      if (auto* f = std::get_if<ir::If>(&s.node))
        if (has_continue(f->then_body) || has_continue(f->else_body)) return true;
    }
    return false;
  }

  static bool has_break(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      if (std::holds_alternative<ir::Break>(s.node)) return true;
      if (auto* f = std::get_if<ir::If>(&s.node))
        if (has_break(f->then_body) || has_break(f->else_body)) return true;
    }
    return false;
  }

  const ir::Program& p_;
};

}  // namespace

const char* unit_name(Unit u) {
  static const char* names[] = {"mul", "add", "div", "neg", "cmp", "sqrt/transc", "table"};
  return names[static_cast<int>(u)];
}

std::uint64_t OpCounts::total() const {
  std::uint64_t t = 0;
  for (auto x : n) t += x;
  return t;
}

OpCounts& OpCounts::operator+=(const OpCounts& o) {
  for (int i = 0; i < kUnits; ++i) n[i] += o.n[i];
  return *this;
}

OpCounts OpCounts::times(std::uint64_t k) const {
  OpCounts out;
  for (int i = 0; i < kUnits; ++i) out.n[i] = n[i] * k;
  return out;
}

std::string OpCounts::describe() const {
  std::string out;
  for (int i = 0; i < kUnits; ++i)
    if (n[i]) out += (out.empty() ? "" : ", ") + std::to_string(n[i]) + " " + unit_name(static_cast<Unit>(i));
  return out.empty() ? "nothing" : out;
}

Cost count_operations(const ir::Program& p) { return Counter(p).run(); }

std::string describe(const Cost& c) {
  std::ostringstream out;
  out << "outside loops (both sides of branches): " << c.outside_loops.describe() << "\n";
  for (const LoopCost& l : c.loops) {
    out << std::string(2 * (l.depth + 1), ' ') << l.loop << ": per iteration " << l.per_iteration.describe();
    if (l.trips) out << "; " << *l.trips << " iterations, in all " << l.total->describe();
    else out << "; iterations depend on the data";
    out << "\n";
  }
  return out.str();
}

}  // namespace sh::analysis
