// Table access analysis: per variable component, how it varies across the
// elements of one row of the launch domain that run side by side.  Two
// forward walks, each repeated until nothing changes (a component only ever
// moves from Same to Consecutive to Scattered, so they end): the hint joins
// every write of a component; the proof takes only components written once,
// outside every if and loop, and reads them in program order.
#include <algorithm>
#include <cstdint>

#include "sh/analysis.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::analysis {
namespace {

using Kinds = std::array<Access, 4>;

Access join(Access a, Access b) { return std::max(a, b); }

// Writes per variable component over the whole program.
class WriteCounter : public ir::Visitor {
 public:
  explicit WriteCounter(const ir::Program& p) : writes(p.vars.size()) {}
  using ir::Visitor::visit;
  void visit(const ir::Assign& a) override {
    for (int i = 0; i < a.mask.size; ++i) ++writes[a.dest][a.mask[i]];
  }
  std::vector<std::array<int, 4>> writes;
};

class Walk : public ir::Visitor {
 public:
  Walk(const ir::Program& p, bool prove) : p_(p), prove_(prove), kinds_(p.vars.size()), affine_(p.vars.size()) {
    for (ir::VarId v : p.inputs) kinds_[v].fill(Access::Scattered);
    for (std::size_t v = 0; v < p.vars.size(); ++v)
      if (p.vars[v].kind == ir::VarKind::Const && p.vars[v].type.scalar == ir::Scalar::I32)
        for (int c = 0; c < p.vars[v].type.width; ++c) affine_[v][c] = Affine{-1, static_cast<long long>(p.vars[v].value[c])};
    if (prove_) {
      WriteCounter counter(p);
      counter.visit(p.body);
      writes_ = std::move(counter.writes);
    }
  }

  // Per read: the kind of its coordinates (clamped for a hint, as asked
  // for a proof).  A hint joins over the whole program until it settles; a
  // proof follows program order, so that a read sees only the writes before
  // it (and, in a loop, those of earlier iterations).
  std::unordered_map<const ir::Assign*, Access> run() {
    do {
      changed_ = false;
      visit(p_.body);
    } while (changed_ && !prove_);
    return reads_;
  }
  // After a proof: the reads at position() plus constants.
  const std::unordered_map<const ir::Assign*, std::array<int, 3>>& offsets() const { return offsets_; }

  using ir::Visitor::visit;
  void visit(const ir::Assign& a) override {
    if (ir::op_info(a.op).result == ir::ResultRule::TableElement) {
      reads_[&a] = read(prove_ && a.op == ir::Op::Load ? a.args[1] : a.args[0]);
      if (prove_ && a.op == ir::Op::Load) offset_of(a);
    }
    for (int i = 0; i < a.mask.size; ++i) {
      int c = a.mask[i];
      bool provable = !prove_ || (nested_ == 0 && writes_[a.dest][c] == 1);
      if (prove_) affine_[a.dest][c] = provable && nested_ == 0 ? affine(a, i) : std::nullopt;
      Access k = provable ? component(a, i) : Access::Scattered;
      Access& now = kinds_[a.dest][c];
      if (join(now, k) != now) changed_ = true, now = join(now, k);
    }
  }
  // A write inside an if or a loop may not happen, or happen for some lanes
  // only: a proof takes none of them.
  void visit(const ir::If& s) override {
    ++nested_;
    ir::Visitor::visit(s);
    --nested_;
  }
  void visit(const ir::Loop& s) override {
    ++nested_;
    if (!prove_) {
      ir::Visitor::visit(s);
    } else {  // until it settles: one iteration's writes reach the next's reads
      bool before = changed_, any = false;
      do {
        changed_ = false;
        ir::Visitor::visit(s);
        any = any || changed_;
      } while (changed_);
      changed_ = before || any;
    }
    --nested_;
  }

 private:
  Access of(const ir::Operand& o, int i) const { return kinds_[o.var][o.component(i)]; }

  // Consecutive along x (the first coordinate), the same in the others.
  Access read(const ir::Operand& coords) const {
    for (int d = 1; d < coords.width(); ++d)
      if (of(coords, d) != Access::Same) return Access::Scattered;
    return of(coords, 0);
  }

  // A component known as position() component `base` (or none: -1) plus
  // a constant, where it is written once at the top level.
  struct Affine {
    int base;
    long long constant;
  };
  std::optional<Affine> affine_of(const ir::Operand& o, int i) const {
    return affine_[o.var][o.component(i)];
  }

  static std::optional<Affine> shifted(int base, long long constant) {
    if (constant < INT32_MIN || constant > INT32_MAX) return std::nullopt;
    return Affine{base, constant};
  }

  std::optional<Affine> affine(const ir::Assign& a, int i) const {
    auto arg = [&](std::size_t k) { return affine_of(a.args[k], i); };
    switch (a.op) {
      case ir::Op::Position: return Affine{i, 0};
      case ir::Op::Mov: return arg(0);
      case ir::Op::Add: {  // at most one side varies with the position
        std::optional<Affine> x = arg(0), y = arg(1);
        if (!x || !y || (x->base >= 0 && y->base >= 0)) return std::nullopt;
        return shifted(std::max(x->base, y->base), x->constant + y->constant);
      }
      case ir::Op::Sub: {
        std::optional<Affine> x = arg(0), y = arg(1);
        if (!x || !y || y->base >= 0) return std::nullopt;
        return shifted(x->base, x->constant - y->constant);
      }
      default: return std::nullopt;
    }
  }

  // The read's coordinates as asked, if each is position() plus a constant
  // in its own dimension.
  void offset_of(const ir::Assign& a) {
    const ir::Operand& asked = a.args[1];
    std::array<int, 3> offset{};
    for (int d = 0; d < asked.width(); ++d) {
      std::optional<Affine> c = affine_of(asked, d);
      if (!c || c->base != d) return;
      offset[d] = static_cast<int>(c->constant);
    }
    offsets_[&a] = offset;
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
      case ir::Op::Max:  // a clamp to the edge keeps a run inside it: a hint only
        if (!integer || prove_) break;
        if (arg(0) == Access::Same) return arg(1);
        if (arg(1) == Access::Same) return arg(0);
        return Access::Scattered;
      default: break;
    }
    return all_same() ? Access::Same : Access::Scattered;
  }

  const ir::Program& p_;
  bool prove_;
  std::vector<Kinds> kinds_;
  std::vector<std::array<int, 4>> writes_;
  int nested_ = 0;  // enclosing ifs and loops
  std::unordered_map<const ir::Assign*, Access> reads_;
  std::vector<std::array<std::optional<Affine>, 4>> affine_;
  std::unordered_map<const ir::Assign*, std::array<int, 3>> offsets_;
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

std::unordered_map<const ir::Assign*, ReadAccess> table_access(const ir::Program& p) {
  Walk proof(p, true);
  std::unordered_map<const ir::Assign*, Access> hints = Walk(p, false).run(), proofs = proof.run();
  std::unordered_map<const ir::Assign*, ReadAccess> out;
  for (const auto& [read, hint] : hints) {
    ReadAccess& r = out[read] = {hint, proofs.at(read) == Access::Consecutive, std::nullopt};
    auto offset = proof.offsets().find(read);
    if (r.proven_run && offset != proof.offsets().end()) r.offset = offset->second;
  }
  return out;
}

std::vector<std::optional<TapSpan>> tap_spans(const ir::Program& p,
                                              const std::unordered_map<const ir::Assign*, ReadAccess>& access) {
  std::vector<std::optional<TapSpan>> spans(p.tables.size());
  for (const auto& [read, a] : access) {
    if (!a.proven_run || !a.offset) continue;
    std::optional<TapSpan>& s = spans[static_cast<std::size_t>(read->table)];
    if (!s) s = TapSpan{*a.offset, *a.offset};
    for (int d = 0; d < 3; ++d) {
      s->low[d] = std::min(s->low[d], (*a.offset)[d]);
      s->high[d] = std::max(s->high[d], (*a.offset)[d]);
    }
  }
  return spans;
}

}  // namespace sh::analysis
