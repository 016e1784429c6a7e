// Legalisation: the rules every backend would otherwise re-implement are
// written here once, as IR, between the optimiser and the backends.
//   - Table reads: a fetch's coordinates are brought inside the table by
//     its edge mode: clamped to the edge (extent - 1 and 0), wrapped around
//     (mod extent), or clamped with the element read replaced by zero where
//     a coordinate was outside; a sample's coordinates in [0, 1] are scaled
//     by the extent, floored and converted (NaN gives 0, out of range
//     saturates) first.  Both become `load`, whose coordinates are in
//     range; it keeps the coordinates as asked so that a checked run can
//     say which read was clamped.  Scatter indices are always clamped.
//     Prefetch coordinates are not: a prefetch only names memory to bring,
//     and each backend keeps one outside the table harmless its own way
//     (docs/operations.md).  The clamp's four operations at each of the
//     BVH walk's prefetches made its rays 15 % slower.
//   - Integer division and remainder: x / 0 and x % 0 give 0, INT_MIN / -1
//     gives INT_MIN and INT_MIN % -1 gives 0.  The divisor a backend sees is
//     never 0 or -1, so its native division cannot trap.
//   - Shifts: a count outside [0, 31] shifts every bit out.  The count a
//     backend sees is in range, where its native shift is defined.
//   - Local arrays: an element or store index is clamped to [0, length - 1]
//     unless it is a constant inside, so a backend indexes its memory
//     without a test.
// Legal IR holds no fetch or sample, no integer division that could trap
// and no shift past the width; backends lower only that.
#include "sh/error.hpp"
#include "sh/ir/visitor.hpp"
#include "sh/passes.hpp"

namespace sh::passes {
namespace {

class Legalizer : public ir::Mutator {
 public:
  explicit Legalizer(ir::Program& p) : p_(p) {}
  using ir::Mutator::mutate;

  void mutate(ir::Assign a, ir::Block& out) override {
    // A load given to this pass (which writes them) has coordinates never
    // brought inside its table, and a backend reads them as they are.
    if (a.op == ir::Op::Load)
      throw Error("program '" + p_.name + "': `load` is written by legalisation only; a program reads its tables with "
                  "fetch or sample");
    if (a.op == ir::Op::Fetch || a.op == ir::Op::Sample) return table_read(std::move(a), out);
    if ((a.op == ir::Op::Div || a.op == ir::Op::Mod) && p_.type_of(a.dest).scalar == ir::Scalar::I32 && may_trap(a.args[1]))
      return integer_division(std::move(a), out);
    if ((a.op == ir::Op::Shl || a.op == ir::Op::Shr) && !count_in_range(a.args[1])) return shift(std::move(a), out);
    if (a.op == ir::Op::Element || a.op == ir::Op::Store) array_index(a, out);
    out.push_back(ir::Stmt{std::move(a)});
  }

  void mutate(ir::Scatter s, ir::Block& out) override {
    s.index = clamped(s.table, s.index, out);
    out.push_back(ir::Stmt{s});
  }

 private:
  ir::Operand temp(ir::Type t) { return ir::whole(p_, p_.add_var({ir::VarKind::Temp, t, "", {}})); }
  ir::Operand number(ir::Scalar s, double v) { return ir::whole(p_, p_.add_const({s, 1}, {v, v, v, v})); }

  ir::Operand emit(ir::Block& out, ir::Type t, ir::Op op, std::vector<ir::Operand> args, int table = -1) {
    ir::Operand r = temp(t);
    out.push_back(ir::Stmt{ir::Assign{r.var, r.swizzle, op, std::move(args), table}});
    return r;
  }

  ir::Operand extent(int table, ir::Block& out) {
    return emit(out, {ir::Scalar::I32, p_.tables[table].rank}, ir::Op::Extent, {}, table);
  }

  // Integer coordinates clamped to [0, extent - 1] in every dimension.
  ir::Operand clamped(int table, const ir::Operand& coords, ir::Block& out) {
    ir::Type t{ir::Scalar::I32, coords.width()};
    ir::Operand last = emit(out, t, ir::Op::Sub, {extent(table, out), number(ir::Scalar::I32, 1)});
    ir::Operand low = emit(out, t, ir::Op::Max, {coords, number(ir::Scalar::I32, 0)});
    return emit(out, t, ir::Op::Min, {low, last});
  }

  void table_read(ir::Assign a, ir::Block& out) {
    ir::Operand asked = a.args[0];
    if (a.op == ir::Op::Sample) {
      ir::Scalar s = p_.type_of(asked.var).scalar;
      ir::Type t{s, asked.width()};
      ir::Operand size = emit(out, t, ir::Op::Cast, {extent(a.table, out)});
      ir::Operand scaled = emit(out, t, ir::Op::Mul, {asked, size});
      ir::Operand floored = emit(out, t, ir::Op::Floor, {scaled});
      asked = emit(out, {ir::Scalar::I32, asked.width()}, ir::Op::Cast, {floored});
    }
    a.op = ir::Op::Load;
    switch (p_.tables[a.table].edge) {
      case ir::Edge::Clamp: a.args = {clamped(a.table, asked, out), asked}; break;
      case ir::Edge::Repeat: a.args = {wrapped(a.table, asked, out), asked}; break;
      case ir::Edge::Zero: return zero_outside(std::move(a), asked, out);
    }
    out.push_back(ir::Stmt{std::move(a)});
  }

  // Coordinates wrapped into [0, extent - 1] in every dimension: the
  // remainder that takes the divisor's sign (mod), so -1 is extent - 1.
  ir::Operand wrapped(int table, const ir::Operand& coords, ir::Block& out) {
    return emit(out, {ir::Scalar::I32, coords.width()}, ir::Op::Mod, {coords, extent(table, out)});
  }

  static ir::Operand component(ir::Operand o, int i) {
    o.swizzle.index[0] = o.swizzle[i];
    o.swizzle.size = 1;
    return o;
  }

  // The element at the clamped coordinates where every coordinate is inside
  // the table, else zero: the read, then a choice between it and zero.
  void zero_outside(ir::Assign read, const ir::Operand& asked, ir::Block& out) {
    const ir::TableDecl& t = p_.tables[read.table];
    ir::Type coords{ir::Scalar::I32, asked.width()}, one{ir::Scalar::I32, 1};
    ir::Operand from_start = emit(out, coords, ir::Op::Ge, {asked, number(ir::Scalar::I32, 0)});
    ir::Operand before_end = emit(out, coords, ir::Op::Lt, {asked, extent(read.table, out)});
    ir::Operand each = emit(out, coords, ir::Op::And, {from_start, before_end});
    ir::Operand inside = component(each, 0);
    for (int d = 1; d < asked.width(); ++d) inside = emit(out, one, ir::Op::And, {inside, component(each, d)});
    if (t.element.scalar != ir::Scalar::I32) inside = emit(out, {t.element.scalar, 1}, ir::Op::Cast, {inside});
    ir::Operand element = temp(t.element);
    ir::Assign choice{read.dest, read.mask, ir::Op::Cond, {inside, element, number(t.element.scalar, 0)}, -1};
    read.dest = element.var;
    read.mask = element.swizzle;
    read.args = {clamped(read.table, asked, out), asked};
    out.push_back(ir::Stmt{std::move(read)});
    out.push_back(ir::Stmt{std::move(choice)});
  }

  void array_index(ir::Assign& a, ir::Block& out) {
    bool store = a.op == ir::Op::Store;
    ir::Operand& index = a.args[store ? 0 : 1];
    int length = p_.var(store ? a.dest : a.args[0].var).length;
    const ir::Var& v = p_.var(index.var);
    if (v.kind == ir::VarKind::Const && v.value[index.swizzle[0]] >= 0 && v.value[index.swizzle[0]] < length) return;
    ir::Type one{ir::Scalar::I32, 1};
    ir::Operand low = emit(out, one, ir::Op::Max, {index, number(ir::Scalar::I32, 0)});
    index = emit(out, one, ir::Op::Min, {low, number(ir::Scalar::I32, length - 1)});
  }

  // A constant divisor with no component 0 or -1 cannot trap.
  bool may_trap(const ir::Operand& divisor) const {
    const ir::Var& v = p_.var(divisor.var);
    if (v.kind != ir::VarKind::Const) return true;
    for (int i = 0; i < divisor.width(); ++i) {
      double d = v.value[divisor.swizzle[i]];
      if (d == 0 || d == -1) return true;
    }
    return false;
  }

  void integer_division(ir::Assign a, ir::Block& out) {
    ir::Type t{ir::Scalar::I32, a.mask.size};
    const ir::Operand x = a.args[0], by = a.args[1];
    ir::Operand zero = emit(out, t, ir::Op::Eq, {by, number(ir::Scalar::I32, 0)});
    ir::Operand minus_one = emit(out, t, ir::Op::Eq, {by, number(ir::Scalar::I32, -1)});
    ir::Operand unsafe = emit(out, t, ir::Op::Or, {zero, minus_one});
    ir::Operand safe = emit(out, t, ir::Op::Cond, {unsafe, number(ir::Scalar::I32, 1), by});
    ir::Operand result = emit(out, t, a.op, {x, safe});
    if (a.op == ir::Op::Div) {
      // x / -1 is -x, which wraps for INT_MIN.
      ir::Operand negated = emit(out, t, ir::Op::Neg, {x});
      result = emit(out, t, ir::Op::Cond, {minus_one, negated, result});
      a.args = {zero, number(ir::Scalar::I32, 0), result};
    } else {
      a.args = {unsafe, number(ir::Scalar::I32, 0), result};
    }
    a.op = ir::Op::Cond;
    out.push_back(ir::Stmt{std::move(a)});
  }

  bool count_in_range(const ir::Operand& count) const {
    const ir::Var& v = p_.var(count.var);
    if (v.kind != ir::VarKind::Const) return false;
    for (int i = 0; i < count.width(); ++i) {
      double c = v.value[count.swizzle[i]];
      if (c < 0 || c > 31) return false;
    }
    return true;
  }

  // A count outside [0, 31] shifts every bit out: shl gives 0, and shr by
  // 31 gives what shifting further would (0 or -1 by the sign).
  void shift(ir::Assign a, ir::Block& out) {
    ir::Type t{ir::Scalar::I32, a.mask.size};
    const ir::Operand x = a.args[0], count = a.args[1];
    ir::Operand below = emit(out, t, ir::Op::Lt, {count, number(ir::Scalar::I32, 0)});
    ir::Operand above = emit(out, t, ir::Op::Gt, {count, number(ir::Scalar::I32, 31)});
    ir::Operand outside = emit(out, t, ir::Op::Or, {below, above});
    if (a.op == ir::Op::Shr) {
      a.args = {x, emit(out, t, ir::Op::Cond, {outside, number(ir::Scalar::I32, 31), count})};
      out.push_back(ir::Stmt{std::move(a)});
      return;
    }
    ir::Operand safe = emit(out, t, ir::Op::Cond, {outside, number(ir::Scalar::I32, 0), count});
    ir::Operand shifted = emit(out, t, ir::Op::Shl, {x, safe});
    a.op = ir::Op::Cond;
    a.args = {outside, number(ir::Scalar::I32, 0), shifted};
    out.push_back(ir::Stmt{std::move(a)});
  }

  ir::Program& p_;
};

}  // namespace

ir::Program legalize(ir::Program p) {
  Legalizer l(p);
  p.body = l.mutate(std::move(p.body));
  return p;
}

}  // namespace sh::passes
