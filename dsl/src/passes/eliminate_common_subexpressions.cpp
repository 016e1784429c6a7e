// Common subexpressions (Sh had none): where an operation on the same
// operands was already computed into a temporary that still holds it, the
// later assignment becomes a move of that temporary (copy propagation then
// removes the move).  Available expressions flow into nested blocks, and
// are dropped when an operand may be written: after a branch that writes
// it, and around any loop that does.  An across-elements operation
// (any_lane) answers for the elements running it: it is reused only
// between two control statements, where the same elements run.
#include <algorithm>
#include <cstdint>
#include <unordered_map>

#include "sh/passes.hpp"
#include "uses.hpp"

namespace sh::passes {
namespace {

bool same_operand(const ir::Operand& a, const ir::Operand& b) { return a.var == b.var && a.swizzle == b.swizzle; }

bool same_expression(const ir::Program& p, const ir::Assign& a, const ir::Assign& b) {
  // The destination's type matters: a cast's result depends on it.
  if (p.type_of(a.dest) != p.type_of(b.dest)) return false;
  if (a.op != b.op || a.table != b.table || a.mask.size != b.mask.size || a.args.size() != b.args.size()) return false;
  for (std::size_t i = 0; i < a.args.size(); ++i)
    if (!same_operand(a.args[i], b.args[i])) return false;
  return true;
}

// What same_expression compares, but the destination's type, in one number.
std::uint64_t shape(const ir::Assign& a) {
  std::uint64_t h = static_cast<std::uint64_t>(a.op) * 0x9E3779B97F4A7C15ull;
  auto mix = [&h](std::uint64_t v) { h = (h ^ v) * 0x100000001B3ull; };
  mix(static_cast<std::uint64_t>(a.table + 1));
  mix(static_cast<std::uint64_t>(a.mask.size));
  for (const ir::Operand& o : a.args) {
    mix(static_cast<std::uint64_t>(o.var));
    for (int i = 0; i < o.swizzle.size; ++i) mix(o.swizzle[i]);
    mix(static_cast<std::uint64_t>(o.swizzle.size) << 8);
  }
  return h;
}

// The expressions available at a point of the program, found by their
// shape and by the variables they read or write.  A nested block starts
// from what is available before it: what it adds or forgets is undone
// (undo_to a mark) when it ends.
class Available {
 public:
  // The earliest available expression that a computes again.
  const ir::Assign* find(const ir::Program& p, const ir::Assign& a) const {
    auto it = by_shape_.find(shape(a));
    if (it == by_shape_.end()) return nullptr;
    for (std::size_t id : it->second)
      if (live_[id] && same_expression(p, *exprs_[id], a)) return exprs_[id];
    return nullptr;
  }
  void add(const ir::Assign& a) {
    std::size_t id = exprs_.size();
    exprs_.push_back(&a);
    live_.push_back(true);
    by_shape_[shape(a)].push_back(id);
    for_each_var(a, [&](ir::VarId v) { by_var_[v].push_back(id); });
    if (ir::is_lane_group(a.op)) lane_groups_.push_back(id);
    log_.push_back({id, true});
  }
  // Expressions that read or write v.
  void forget(ir::VarId v) {
    auto it = by_var_.find(v);
    if (it == by_var_.end()) return;
    for (std::size_t id : it->second) kill(id);
  }
  void forget(const std::set<ir::VarId>& written) {
    for (ir::VarId v : written) forget(v);
  }
  // An across-elements operation answers for the elements running it.
  void forget_lane_groups() {
    for (std::size_t id : lane_groups_) kill(id);
  }
  std::size_t mark() const { return log_.size(); }
  void undo_to(std::size_t mark) {
    for (; log_.size() > mark; log_.pop_back()) {
      auto [id, added] = log_.back();
      if (!added) {
        live_[id] = true;
        continue;
      }
      // The last expression added: the last entry of every list it joined.
      const ir::Assign& a = *exprs_[id];
      by_shape_[shape(a)].pop_back();
      for_each_var(a, [&](ir::VarId v) { by_var_[v].pop_back(); });
      if (ir::is_lane_group(a.op)) lane_groups_.pop_back();
      exprs_.pop_back();
      live_.pop_back();
    }
  }

 private:
  // The variables an expression writes or reads, once for each place.
  template <class F>
  static void for_each_var(const ir::Assign& a, F f) {
    f(a.dest);
    for (const ir::Operand& o : a.args) f(o.var);
  }
  void kill(std::size_t id) {
    if (!live_[id]) return;
    live_[id] = false;
    log_.push_back({id, false});
  }

  std::vector<const ir::Assign*> exprs_;  // each computes into a temporary assigned only there
  std::vector<bool> live_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> by_shape_;
  std::unordered_map<ir::VarId, std::vector<std::size_t>> by_var_;
  std::vector<std::size_t> lane_groups_;
  std::vector<std::pair<std::size_t, bool>> log_;  // (expression, added: else forgotten)
};

class Cse {
 public:
  explicit Cse(ir::Program& p) : p_(p), defs_(collect_definitions(p.body)) {}

  void block(ir::Block& b) {
    for (ir::Stmt& s : b) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        assign(*a);
        continue;
      }
      avail_.forget_lane_groups();
      if (auto* f = std::get_if<ir::If>(&s.node)) {
        nested(f->then_body);
        nested(f->else_body);
        avail_.forget(written_in(f->then_body));
        avail_.forget(written_in(f->else_body));
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        avail_.forget(written_in(*l));
        nested(l->header);
        nested(l->body);
        nested(l->update);
      }
    }
  }

 private:
  // A nested block sees what is available before it and leaves it so.
  void nested(ir::Block& b) {
    std::size_t before = avail_.mark();
    block(b);
    avail_.undo_to(before);
  }

  bool holds_for_good(const ir::Assign& a) const {
    return p_.var(a.dest).kind == ir::VarKind::Temp && defs_.single.count(a.dest) &&
           a.mask.is_identity(p_.type_of(a.dest).width);
  }

  void assign(ir::Assign& a) {
    if (a.op != ir::Op::Mov)
      if (const ir::Assign* e = avail_.find(p_, a)) {
        a.op = ir::Op::Mov;
        a.table = -1;
        a.args = {ir::Operand{e->dest, ir::Swizzle::identity(a.mask.size)}};
      }
    avail_.forget(a.dest);
    bool reads_itself = std::any_of(a.args.begin(), a.args.end(), [&](const ir::Operand& o) { return o.var == a.dest; });
    if (a.op != ir::Op::Mov && holds_for_good(a) && !reads_itself) avail_.add(a);
  }

  ir::Program& p_;
  Definitions defs_;
  Available avail_;
};

}  // namespace

ir::Program eliminate_common_subexpressions(ir::Program p) {
  Cse cse(p);
  cse.block(p.body);
  return p;
}

}  // namespace sh::passes
