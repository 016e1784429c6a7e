// Table access analysis: per variable component, how it varies across the
// elements of one row of the launch domain that run side by side.  A forward
// walk repeated until nothing changes; a component only ever moves from
// Same to Consecutive to Scattered, so the walk ends.
#include <algorithm>

#include "sh/analysis.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::analysis {
namespace {

using Kinds = std::array<Access, 4>;

Access join(Access a, Access b) { return std::max(a, b); }

class TableAccess : public ir::Visitor {
 public:
  explicit TableAccess(const ir::Program& p) : p_(p), kinds_(p.vars.size()) {
    for (ir::VarId v : p.inputs) kinds_[v].fill(Access::Scattered);
  }

  std::unordered_map<const ir::Assign*, Access> run() {
    do {
      changed_ = false;
      visit(p_.body);
    } while (changed_);
    return reads_;
  }

  using ir::Visitor::visit;
  void visit(const ir::Assign& a) override {
    Kinds result{};
    for (int i = 0; i < a.mask.size; ++i) result[i] = component(a, i);
    if (ir::op_info(a.op).result == ir::ResultRule::TableElement) reads_[&a] = read(a.args[0]);
    for (int i = 0; i < a.mask.size; ++i) {
      Access& k = kinds_[a.dest][a.mask[i]];
      if (join(k, result[i]) != k) changed_ = true, k = join(k, result[i]);
    }
  }

 private:
  Access of(const ir::Operand& o, int i) const { return kinds_[o.var][o.swizzle[o.width() == 1 ? 0 : i]]; }

  // Consecutive along x (the first coordinate), the same in the others.
  Access read(const ir::Operand& coords) const {
    Access along = of(coords, 0);
    for (int d = 1; d < coords.width(); ++d)
      if (of(coords, d) != Access::Same) return Access::Scattered;
    return along;
  }

  Access component(const ir::Assign& a, int i) const {
    auto arg = [&](std::size_t k) { return of(a.args[k], i); };
    auto all_same = [&] {
      return std::all_of(a.args.begin(), a.args.end(), [&](const ir::Operand& o) { return of(o, i) == Access::Same; });
    };
    bool integer = p_.type_of(a.dest).scalar == ir::Scalar::I32;
    switch (a.op) {
      case ir::Op::Position: return i == 0 ? Access::Consecutive : Access::Same;
      case ir::Op::Extent: return Access::Same;
      case ir::Op::Mov: return arg(0);
      case ir::Op::Add:
        if (!integer) break;
        if (arg(0) == Access::Same) return arg(1);
        if (arg(1) == Access::Same) return arg(0);
        return Access::Scattered;
      case ir::Op::Sub:
        if (integer && arg(1) == Access::Same) return arg(0);
        break;
      case ir::Op::Min:
      case ir::Op::Max:  // a clamp to the edge keeps a run inside it
        if (!integer) break;
        if (arg(0) == Access::Same) return arg(1);
        if (arg(1) == Access::Same) return arg(0);
        return Access::Scattered;
      default: break;
    }
    return all_same() ? Access::Same : Access::Scattered;
  }

  const ir::Program& p_;
  std::vector<Kinds> kinds_;
  std::unordered_map<const ir::Assign*, Access> reads_;
  bool changed_ = false;
};

}  // namespace

const char* access_name(Access a) {
  switch (a) {
    case Access::Same: return "same";
    case Access::Consecutive: return "consecutive";
    case Access::Scattered: return "scattered";
  }
  return "?";
}

std::unordered_map<const ir::Assign*, Access> table_access(const ir::Program& p) { return TableAccess(p).run(); }

}  // namespace sh::analysis
