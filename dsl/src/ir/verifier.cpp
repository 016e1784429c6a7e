#include "sh/ir/verifier.hpp"

#include <climits>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "sh/error.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::ir {
namespace {

class Verifier {
 public:
  explicit Verifier(const Program& p) : p_(p) {}

  void run() {
    for (VarId id : p_.inputs) expect_kind(id, {VarKind::Input, VarKind::InOut}, "input list");
    for (VarId id : p_.outputs) expect_kind(id, {VarKind::Output, VarKind::InOut}, "output list");
    for (VarId id : p_.uniforms) expect_kind(id, {VarKind::Uniform}, "uniform list");
    // Which list holds each variable, marked once: a search of the lists
    // for each variable took time in the square of their length.
    in_list_.assign(p_.vars.size(), 0);
    for (VarId id : p_.inputs) in_list_[id] |= kInInputs;
    for (VarId id : p_.outputs) in_list_[id] |= kInOutputs;
    for (VarId id : p_.uniforms) in_list_[id] |= kInUniforms;
    long array_values = 0;
    for (VarId id = 0; id < static_cast<VarId>(p_.vars.size()); ++id) {
      const Var& v = p_.var(id);
      if (v.type.width < 1 || v.type.width > 4) fail("a variable has width " + std::to_string(v.type.width));
      listed(id);
      if (v.kind == VarKind::Const) constant(id);
      if (v.kind == VarKind::Array) array_values += static_cast<long>(v.length) * v.type.width;
      bool array = v.kind == VarKind::Array;
      if (array ? v.length < 1 || v.length > kMaxArrayLength : v.length != 0)
        fail("a variable of kind " + std::string(var_kind_name(v.kind)) + " has length " + std::to_string(v.length) +
             (array ? " (an array holds 1 to " + std::to_string(kMaxArrayLength) + " elements)" : ""));
    }
    if (array_values > kMaxArrayValues)
      fail("local arrays of " + std::to_string(array_values) + " values in all; a program's hold at most " +
           std::to_string(kMaxArrayValues) + " (a CPU thread's stack holds them for 16 elements at once)");
    block(p_.body, 0);
  }

 private:
  [[noreturn]] void fail(const std::string& what, const Stmt* s = nullptr) const {
    std::string msg = "program '" + p_.name + "': invalid IR: " + what;
    if (s) {
      try {
        msg += " in `" + print(p_, *s) + "`";
      } catch (const std::out_of_range&) {
        // The statement names a variable that does not exist: say so only.
      }
    }
    throw Error(msg);
  }

  // A stream or uniform variable is bound through its list: one left out
  // would have no value to read, and no place to write.
  void listed(VarId id) {
    auto in = [&](unsigned list) { return (in_list_[id] & list) != 0; };
    VarKind k = p_.var(id).kind;
    bool missing = ((k == VarKind::Input || k == VarKind::InOut) && !in(kInInputs)) ||
                   ((k == VarKind::Output || k == VarKind::InOut) && !in(kInOutputs)) ||
                   (k == VarKind::Uniform && !in(kInUniforms));
    if (missing)
      fail("variable %" + std::to_string(id) + " of kind " + var_kind_name(k) + " is in none of the program's lists");
  }

  // An integer constant holds int32 values and a truth value 0 or 1, which
  // every backend and the constant folder read alike (a float constant
  // may hold any double: each backend rounds it to its precision).
  void constant(VarId id) {
    const Var& v = p_.var(id);
    for (int c = 0; c < v.type.width; ++c) {
      double x = v.value[static_cast<std::size_t>(c)];
      bool fits = true;
      switch (v.type.scalar) {
        case Scalar::I32: fits = x >= INT32_MIN && x <= INT32_MAX && x == std::trunc(x); break;
        case Scalar::Bool: fits = x == 0 || x == 1; break;
        case Scalar::F32:
        case Scalar::F64: break;
      }
      if (!fits)
        fail("constant %" + std::to_string(id) + " of type " + type_name(v.type) + " holds " + std::to_string(x) +
             ", which that type cannot");
    }
  }

  void expect_kind(VarId id, std::initializer_list<VarKind> kinds, const char* where) {
    if (id < 0 || id >= static_cast<VarId>(p_.vars.size())) fail(std::string("bad variable in ") + where);
    for (VarKind k : kinds)
      if (p_.var(id).kind == k) return;
    fail(std::string("variable %") + std::to_string(id) + " has the wrong kind for the " + where);
  }

  void operand(const Operand& o, const Stmt& s, bool array = false) {
    if (o.var < 0 || o.var >= static_cast<VarId>(p_.vars.size())) fail("operand names no variable", &s);
    if ((p_.var(o.var).kind == VarKind::Array) != array)
      fail(array ? "element reads an array, not a variable of another kind" : "an array is read only by element", &s);
    if (o.swizzle.size < 1 || o.swizzle.size > 4) fail("operand swizzle has no components", &s);
    int width = p_.type_of(o.var).width;
    for (int i = 0; i < o.swizzle.size; ++i)
      if (o.swizzle[i] >= width) fail("swizzle reads a component the variable lacks", &s);
  }

  void condition(const Operand& o, const Stmt& s) {
    operand(o, s);
    if (o.width() != 1) fail("a condition must be one component", &s);
  }

  void assign(const Assign& a, const Stmt& s) {
    if (a.dest < 0 || a.dest >= static_cast<VarId>(p_.vars.size())) fail("destination names no variable", &s);
    const Var& dest = p_.var(a.dest);
    if (dest.kind == VarKind::Input || dest.kind == VarKind::Const || dest.kind == VarKind::Uniform)
      fail(std::string("writes a variable of kind ") + var_kind_name(dest.kind), &s);
    if (a.mask.size < 1 || a.mask.has_repeats()) fail("bad write mask", &s);
    for (int i = 0; i < a.mask.size; ++i)
      if (a.mask[i] >= dest.type.width) fail("write mask names a component the destination lacks", &s);
    if (static_cast<int>(a.args.size()) != op_arity(a.op)) fail("wrong number of operands", &s);
    bool writes_array = a.op == Op::Store || a.op == Op::Fill;
    if ((dest.kind == VarKind::Array) != writes_array)
      fail(writes_array ? std::string(op_name(a.op)) + " into a variable that is not an array"
                        : "writes an array other than by store or fill",
           &s);
    if (is_array_access(a.op)) return array_access(a, s);
    for (const Operand& o : a.args) operand(o, s);
    if (is_table_read(a.op)) return table_read(a, s);
    if (a.table >= 0) fail("only table reads name a table", &s);
    if (op_info(a.op).result == ResultRule::ElementPosition) {
      if (a.mask.size > 3 || dest.type.scalar != Scalar::I32) fail("a position is i32, at most one per dimension (3)", &s);
      return;
    }
    Scalar operand_scalar = p_.type_of(a.args[0].var).scalar;
    for (const Operand& o : a.args) {
      if (o.width() != 1 && o.width() != a.mask.size) fail("operand width differs from the result width", &s);
      if (p_.type_of(o.var).scalar != operand_scalar) fail("operands differ in type", &s);
    }
    if (!accepts(a.op, operand_scalar))
      fail(std::string(op_name(a.op)) + " takes " + domain_name(op_info(a.op).domain) + ", not " + scalar_name(operand_scalar), &s);
    if (op_info(a.op).result == ResultRule::SameAsOperands && operand_scalar != dest.type.scalar)
      fail("operand type differs from the destination type", &s);
  }

  // element: dest = array[index]; store: array[index] = value, written
  // whole; fill: every element = value.  The index is one i32.
  void array_access(const Assign& a, const Stmt& s) {
    if (a.table >= 0) fail("only table reads name a table", &s);
    if (a.op == Op::Fill) {
      operand(a.args[0], s);
      Type element = p_.type_of(a.dest);
      if (!a.mask.is_identity(element.width)) fail("a fill writes every component of the elements", &s);
      if (Type{p_.type_of(a.args[0].var).scalar, a.args[0].width()} != element)
        fail("the value's type differs from the array's element type " + type_name(element), &s);
      return;
    }
    bool store = a.op == Op::Store;
    const Operand& index = a.args[store ? 0 : 1];
    if (!store) operand(a.args[0], s, true);
    operand(index, s);
    if (store) operand(a.args[1], s);
    if (index.width() != 1 || p_.type_of(index.var).scalar != Scalar::I32) fail("an array index is one i32", &s);
    VarId array = store ? a.dest : a.args[0].var;
    Type element = p_.type_of(array);
    if (!store && !a.args[0].swizzle.is_identity(element.width)) fail("element reads the whole array, unswizzled", &s);
    if (store && !a.mask.is_identity(element.width)) fail("a store writes every component of the element", &s);
    Type value = store ? Type{p_.type_of(a.args[1].var).scalar, a.args[1].width()} : Type{p_.type_of(a.dest).scalar, a.mask.size};
    if (value != element) fail("the value's type differs from the array's element type " + type_name(element), &s);
  }

  void table_read(const Assign& a, const Stmt& s) {
    if (a.table < 0 || a.table >= static_cast<int>(p_.tables.size())) fail("reads an undeclared table", &s);
    const TableDecl& t = p_.tables[a.table];
    if (op_info(a.op).result == ResultRule::TableShape) {
      if (a.mask.size != t.rank || p_.type_of(a.dest).scalar != Scalar::I32) fail("a table's extent is i32, one per dimension", &s);
      return;
    }
    for (const Operand& coords : a.args) {
      if (coords.width() != t.rank) fail("table coordinates do not match the table's rank", &s);
      Scalar coord = p_.type_of(coords.var).scalar;
      if (!accepts(a.op, coord)) fail(std::string(op_name(a.op)) + " coordinates must be " + domain_name(op_info(a.op).domain), &s);
    }
    if (t.accumulator) fail("reads an accumulator (its sums are defined only after the run)", &s);
    if (a.mask.size != t.element.width) fail("table read result width differs from the element width", &s);
    if (p_.type_of(a.dest).scalar != t.element.scalar) fail("table read result type differs from the element type", &s);
  }

  void scatter(const Scatter& sc, const Stmt& s) {
    if (sc.table < 0 || sc.table >= static_cast<int>(p_.tables.size())) fail("adds into an undeclared table", &s);
    const TableDecl& t = p_.tables[sc.table];
    if (!t.accumulator) fail("adds into a read-only table", &s);
    if (t.element.scalar != Scalar::F32 && t.element.scalar != Scalar::I32) fail("accumulators hold f32 or i32", &s);
    operand(sc.index, s);
    operand(sc.value, s);
    if (sc.index.width() != t.rank || p_.type_of(sc.index.var).scalar != Scalar::I32)
      fail("scatter coordinates must be i32, one per dimension", &s);
    if (sc.value.width() != t.element.width || p_.type_of(sc.value.var).scalar != t.element.scalar)
      fail("scatter value differs from the accumulator's element type", &s);
  }

  void prefetch(const Prefetch& pf, const Stmt& s) {
    if (pf.table < 0 || pf.table >= static_cast<int>(p_.tables.size())) fail("prefetches from an undeclared table", &s);
    const TableDecl& t = p_.tables[pf.table];
    if (t.accumulator) fail("prefetches from an accumulator (the program never reads it)", &s);
    operand(pf.index, s);
    if (pf.index.width() != t.rank || p_.type_of(pf.index.var).scalar != Scalar::I32)
      fail("prefetch coordinates must be i32, one per dimension", &s);
  }

  void block(const Block& b, int loop_depth, int nesting = 0) {
    for (const Stmt& s : b) {
      if (nesting >= kMaxNesting && (std::holds_alternative<If>(s.node) || std::holds_alternative<Loop>(s.node)))
        fail("nested deeper than " + std::to_string(kMaxNesting) + " levels of control flow", &s);
      if (auto* a = std::get_if<Assign>(&s.node)) {
        assign(*a, s);
      } else if (auto* i = std::get_if<If>(&s.node)) {
        condition(i->cond, s);
        block(i->then_body, loop_depth, nesting + 1);
        block(i->else_body, loop_depth, nesting + 1);
      } else if (auto* l = std::get_if<Loop>(&s.node)) {
        // A break or continue in a loop's header or update would belong to
        // no loop in particular (the recorder refuses them there).
        block(l->header, 0, nesting + 1);
        condition(l->cond, s);
        block(l->body, loop_depth + 1, nesting + 1);
        block(l->update, 0, nesting + 1);
      } else if (auto* sc = std::get_if<Scatter>(&s.node)) {
        scatter(*sc, s);
      } else if (auto* pf = std::get_if<Prefetch>(&s.node)) {
        prefetch(*pf, s);
      } else if (loop_depth == 0) {
        fail("break or continue outside a loop body (or in a loop's header or update)", &s);
      }
    }
  }

  const Program& p_;
  static constexpr unsigned char kInInputs = 1, kInOutputs = 2, kInUniforms = 4;
  std::vector<unsigned char> in_list_;  // by variable: the lists that hold it
};

}  // namespace

void verify(const Program& p) { Verifier(p).run(); }

void verify_legal(const Program& p) {
  struct Legality : Visitor {
    using Visitor::visit;
    const Program* p;
    void visit(const Assign& a) override {
      if (!is_legal(a.op))
        throw Error("program '" + p->name + "': `" + print(*p, Stmt{a}) +
                    "` is not legal IR; backends are given sh::passes::legalize's output");
    }
  } check;
  check.p = &p;
  check.visit(p.body);
}

}  // namespace sh::ir
