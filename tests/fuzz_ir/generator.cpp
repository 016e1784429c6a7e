#include "generator.hpp"

#include <algorithm>
#include <climits>
#include <optional>
#include <string>

#include "exactness.hpp"
#include "values.hpp"

namespace fuzz_ir {
namespace {

using namespace sh::ir;

const std::vector<Scalar> kScalars = {Scalar::F32, Scalar::F64, Scalar::I32, Scalar::Bool};

std::vector<Scalar> accepted(Domain d) {
  std::vector<Scalar> out;
  for (Scalar s : kScalars)
    if (accepts(d, s)) out.push_back(s);
  return out;
}

struct Reg {
  VarId id;
  bool exact;     // its class (exactness.hpp)
  bool writable;  // the body may assign it: not inputs, constants or loop counters
};

struct Context {
  int depth = 0;       // ifs and loops around
  int loops = 0;       // loops around
  bool jumps = false;  // inside a loop body, where break and continue may go
};

class Generator {
 public:
  Generator(std::uint64_t seed, const GeneratorOptions& options) : rng_(seed), options_(options) { c_.seed = seed; }

  Case run() {
    p().name = "fuzz_" + std::to_string(c_.seed);
    c_.count = static_cast<std::size_t>(rng_.between(1, 40));
    launch_domain();
    signature();
    budget_ = rng_.between(4, 48);
    Block body;
    block(body, Context{}, INT_MAX);
    epilogue(body);
    Block all = prologue();
    c_.prologue = static_cast<int>(all.size());
    for (Stmt& s : body) all.push_back(std::move(s));
    p().body = std::move(all);
    return std::move(c_);
  }

 private:
  Program& p() { return c_.program; }
  Type type_of(const Reg& r) { return p().type_of(r.id); }
  Type random_type() { return {rng_.pick(kScalars), rng_.between(1, 4)}; }

  VarId add(VarKind kind, Type t, std::string name, bool exact, bool writable) {
    VarId id = add_unwritten(kind, t, std::move(name), exact, writable);
    // Observers (outputs the body never writes) are written at the end.
    if (kind == VarKind::Temp || (kind == VarKind::Output && writable)) needs_init_.push_back(id);
    return id;
  }

  // A register the prologue leaves as the element begins it.
  VarId add_unwritten(VarKind kind, Type t, std::string name, bool exact, bool writable) {
    Var v;
    v.kind = kind;
    v.type = t;
    v.name = std::move(name);
    VarId id = p().add_var(std::move(v));
    regs_.push_back({id, exact, writable});
    return id;
  }

  std::vector<double> values(Type t, std::size_t count) {
    std::vector<double> v(count * static_cast<std::size_t>(t.width));
    for (double& x : v) x = random_value(rng_, t.scalar);
    return v;
  }

  void signature() {
    for (int i = rng_.between(1, 4); i > 0; --i) {
      Type t = random_type();
      p().inputs.push_back(add(VarKind::Input, t, "in" + std::to_string(p().inputs.size()), true, false));
      c_.inputs.push_back({t, values(t, c_.count)});
    }
    if (rng_.chance(20)) {  // starts as its input, compared as an output
      Type t = random_type();
      VarId id = add(VarKind::InOut, t, "io", false, true);
      p().inputs.push_back(id);
      p().outputs.push_back(id);
      c_.inputs.push_back({t, values(t, c_.count)});
    }
    for (int i = rng_.between(0, 2); i > 0; --i) {
      Type t = random_type();
      p().uniforms.push_back(add(VarKind::Uniform, t, "u" + std::to_string(p().uniforms.size()), true, false));
      std::array<double, 4> u{};
      std::vector<double> v = values(t, 1);
      std::copy(v.begin(), v.end(), u.begin());
      c_.uniforms.push_back(u);
    }
    for (int i = rng_.between(0, 2); i > 0; --i) table(false);
    if (rng_.chance(25) && options_.accumulators) table(true);
    for (int i = rng_.between(1, 3); i > 0; --i)
      p().outputs.push_back(add(VarKind::Output, random_type(), "out" + std::to_string(p().outputs.size()), false, true));
    for (Scalar s : kScalars) {
      add(VarKind::Temp, {s, 4}, "t" + std::to_string(regs_.size()), true, true);
      if (rng_.chance(50)) add(VarKind::Temp, {s, rng_.between(1, 3)}, "t" + std::to_string(regs_.size()), true, true);
    }
    for (Scalar s : {Scalar::F32, Scalar::F64})
      add(VarKind::Temp, {s, 4}, "x" + std::to_string(regs_.size()), false, true);
    for (int i = rng_.chance(50) ? rng_.between(1, 2) : 0; i > 0; --i) {
      Var v{VarKind::Array, random_type(), "arr" + std::to_string(arrays_.size()), {}, rng_.between(1, 6)};
      arrays_.push_back(p().add_var(std::move(v)));
    }
  }

  void table(bool accumulator) {
    TableDecl d;
    d.rank = rng_.between(1, 3);
    d.element = accumulator ? Type{Scalar::I32, rng_.between(1, 4)} : random_type();
    d.accumulator = accumulator;
    if (!accumulator) d.edge = static_cast<Edge>(rng_.below(3));
    d.name = (accumulator ? "acc" : "tab") + std::to_string(p().tables.size());
    TableData t;
    std::size_t elements = 1;
    for (int r = 0; r < d.rank; ++r) {
      t.dims[r] = rng_.between(1, d.rank == 1 ? 9 : d.rank == 2 ? 4 : 3);
      elements *= static_cast<std::size_t>(t.dims[r]);
    }
    t.data = {d.element, values(d.element, elements)};
    p().tables.push_back(d);
    c_.tables.push_back(std::move(t));
  }

  VarId constant(Type t) {
    std::array<double, 4> v{};
    for (int i = 0; i < t.width; ++i) v[i] = random_value(rng_, t.scalar);
    return p().add_const(t, v);
  }

  Swizzle swizzle(int size, int width) {
    if (size == width && rng_.chance(40)) return Swizzle::identity(width);
    Swizzle s;
    s.size = size;
    for (int i = 0; i < size; ++i) s.index[i] = static_cast<std::uint8_t>(rng_.below(width));
    return s;
  }

  // `size` distinct components of a register `width` wide.
  Swizzle mask(int size, int width) {
    Swizzle s = Swizzle::identity(width);
    if (!rng_.chance(40))
      for (int i = width - 1; i > 0; --i) std::swap(s.index[i], s.index[rng_.below(i + 1)]);
    s.size = size;
    return s;
  }

  // A read of `width` components of scalar `s` (or one, broadcast).  Only
  // operands that pass an error through may read inexact registers; the
  // prologue reads only the signature and constants.
  Operand operand(Scalar s, int width, bool inexact_ok, bool broadcast_ok, bool temps_ok = true) {
    int size = broadcast_ok && width > 1 && rng_.chance(20) ? 1 : width;
    std::vector<VarId> from;
    if (!rng_.chance(15))
      for (const Reg& r : regs_) {
        VarKind k = p().var(r.id).kind;
        bool temp = k == VarKind::Temp || k == VarKind::Output || k == VarKind::InOut;
        if (type_of(r).scalar == s && (r.exact || inexact_ok) && (temps_ok || !temp)) from.push_back(r.id);
      }
    VarId v = from.empty() ? constant({s, rng_.chance(70) ? size : rng_.between(1, 4)}) : rng_.pick(from);
    return Operand{v, swizzle(size, p().type_of(v).width)};
  }

  std::optional<VarId> dest(Scalar s, int min_width, bool inexact) {
    std::vector<VarId> from;
    for (const Reg& r : regs_)
      if (r.writable && type_of(r).scalar == s && type_of(r).width >= min_width && (!inexact || !r.exact))
        from.push_back(r.id);
    if (from.empty()) return std::nullopt;
    return rng_.pick(from);
  }

  bool exact_class(VarId id) {
    for (const Reg& r : regs_)
      if (r.id == id) return r.exact;
    return true;
  }

  // An operation on operands of one scalar (comparisons give 0/1 in it).
  std::optional<Assign> same_as_operands(Op op) {
    const OpInfo& info = op_info(op);
    Scalar s = rng_.pick(accepted(info.domain));
    std::optional<VarId> d = dest(s, 1, !exact_operation(op, s));
    if (!d) return std::nullopt;
    int width = p().type_of(*d).width, size = rng_.between(1, width);
    Assign a{*d, mask(size, width), op, {}, -1};
    bool pass_through = !exact_class(*d) && info.ulp_precise == 0;
    for (int k = 0; k < info.arity; ++k) a.args.push_back(operand(s, size, pass_through && passes_error_through(op, k), true));
    return a;
  }

  std::optional<Assign> converted(Op op) {
    const OpInfo& info = op_info(op);
    Scalar from = rng_.pick(accepted(info.domain)), to = rng_.pick(kScalars);
    std::optional<VarId> d = dest(to, 1, !exact_operation(op, to));
    if (!d) return std::nullopt;
    int width = p().type_of(*d).width, size = rng_.between(1, width);
    Assign a{*d, mask(size, width), op, {}, -1};
    for (int k = 0; k < info.arity; ++k) a.args.push_back(operand(from, size, false, true));
    return a;
  }

  std::optional<Assign> table_read(Op op) {
    const OpInfo& info = op_info(op);
    std::vector<int> readable;
    for (std::size_t t = 0; t < p().tables.size(); ++t)
      if (!p().tables[t].accumulator) readable.push_back(static_cast<int>(t));
    if (readable.empty() || info.arity != 1) return std::nullopt;
    int t = rng_.pick(readable);
    const TableDecl& decl = p().tables[t];
    std::optional<VarId> d = dest(decl.element.scalar, decl.element.width, !exact_operation(op, decl.element.scalar));
    if (!d) return std::nullopt;
    Assign a{*d, mask(decl.element.width, p().type_of(*d).width), op, {}, t};
    a.args.push_back(operand(rng_.pick(accepted(info.domain)), decl.rank, false, false));
    return a;
  }

  // A small grid, often with rows shorter than the SIMD lanes, and a run
  // that starts inside it (as an mpi rank's or a wave's part does).
  void launch_domain() {
    std::size_t row = static_cast<std::size_t>(rng_.between(1, 20)), rows = static_cast<std::size_t>(rng_.between(1, 4));
    c_.domain.first = static_cast<std::size_t>(rng_.between(0, 30));
    c_.domain.extent = {row, rows, (c_.domain.first + c_.count + row * rows - 1) / (row * rows)};
  }

  std::optional<Assign> position(Op op) {
    int n = rng_.between(1, 3);
    std::optional<VarId> d = dest(Scalar::I32, n, !exact_operation(op, Scalar::I32));
    if (!d) return std::nullopt;
    return Assign{*d, mask(n, p().type_of(*d).width), op, {}, -1};
  }

  std::optional<Assign> table_shape(Op op) {
    if (p().tables.empty() || op_info(op).arity != 0) return std::nullopt;
    int t = rng_.below(static_cast<int>(p().tables.size()));
    int rank = p().tables[t].rank;
    std::optional<VarId> d = dest(Scalar::I32, rank, !exact_operation(op, Scalar::I32));
    if (!d) return std::nullopt;
    return Assign{*d, mask(rank, p().type_of(*d).width), op, {}, t};
  }

  // A local array's element, a store into it or a fill.  Arrays hold only exact
  // values, so that what an element read gives needs no tolerance; the
  // index is any i32 (outside the array it clamps).
  std::optional<Assign> array_access(Op op) {
    if (arrays_.empty()) return std::nullopt;
    VarId array = rng_.pick(arrays_);
    Type t = p().type_of(array);
    if (op == Op::Fill) return Assign{array, Swizzle::identity(t.width), op, {operand(t.scalar, t.width, false, false)}, -1};
    Operand index = operand(Scalar::I32, 1, false, false);
    if (op == Op::Store) return Assign{array, Swizzle::identity(t.width), op, {index, operand(t.scalar, t.width, false, false)}, -1};
    std::optional<VarId> d = dest(t.scalar, t.width, false);
    if (!d) return std::nullopt;
    return Assign{*d, mask(t.width, p().type_of(*d).width), op, {Operand{array, Swizzle::identity(t.width)}, index}, -1};
  }

  // An operation drawn from the whole table, so that a new row is fuzzed
  // without a change here.
  void assign(Block& b) {
    static const std::vector<Op> ops = generated_ops();
    for (int attempt = 0; attempt < 50; ++attempt) {
      Op op = rng_.pick(ops);
      std::optional<Assign> a;
      switch (op_info(op).result) {
        case ResultRule::SameAsOperands: a = same_as_operands(op); break;
        case ResultRule::Converted: a = converted(op); break;
        case ResultRule::TableElement: a = table_read(op); break;
        case ResultRule::TableShape: a = table_shape(op); break;
        case ResultRule::ElementPosition: a = position(op); break;
        case ResultRule::ArrayElement: a = array_access(op); break;
      }
      if (a) return b.push_back(Stmt{std::move(*a)});
    }
  }

  void scatter(Block& b) {
    std::vector<int> accumulators;
    for (std::size_t t = 0; t < p().tables.size(); ++t)
      if (p().tables[t].accumulator) accumulators.push_back(static_cast<int>(t));
    if (accumulators.empty()) return assign(b);
    int t = rng_.pick(accumulators);
    const TableDecl& d = p().tables[t];
    b.push_back(Stmt{Scatter{t, operand(Scalar::I32, d.rank, false, false), operand(d.element.scalar, d.element.width, false, false)}});
  }

  // Coordinates of any value, inexact or far outside the table: a
  // prefetch takes them as asked and changes no result.
  void prefetch(Block& b) {
    std::vector<int> readable;
    for (std::size_t t = 0; t < p().tables.size(); ++t)
      if (!p().tables[t].accumulator) readable.push_back(static_cast<int>(t));
    if (readable.empty()) return assign(b);
    int t = rng_.pick(readable);
    b.push_back(Stmt{Prefetch{t, operand(Scalar::I32, p().tables[t].rank, true, false)}});
  }

  Operand condition() { return operand(rng_.pick(kScalars), 1, false, false); }

  void if_statement(Block& b, Context ctx) {
    If s;
    s.cond = condition();
    ++ctx.depth;
    block(s.then_body, ctx, rng_.between(1, 5));
    if (rng_.chance(50)) block(s.else_body, ctx, rng_.between(1, 4));
    b.push_back(Stmt{std::move(s)});
  }

  void jump(Block& b, const Context& ctx) {
    Stmt j = rng_.chance(50) ? Stmt{Break{}} : Stmt{Continue{}};
    if (rng_.chance(20)) return b.push_back(std::move(j));
    If s;
    s.cond = condition();
    s.then_body.push_back(std::move(j));
    if (rng_.chance(30)) block(s.else_body, Context{ctx.depth + 1, ctx.loops, ctx.jumps}, rng_.between(1, 2));
    b.push_back(Stmt{std::move(s)});
  }

  static Operand whole(VarId v) { return Operand{v, Swizzle::identity(1)}; }

  static Stmt assign_stmt(VarId dest, Op op, std::vector<Operand> args) {
    return Stmt{Assign{dest, Swizzle::identity(1), op, std::move(args), -1}};
  }

  // A loop that ends: a counter no other statement writes goes up by one
  // every iteration (in the header or the update, which continue does not
  // skip) and the condition holds only while it is below a constant of at
  // most 4; a data-dependent condition may end it sooner.
  void loop(Block& b, const Context& ctx) {
    Scalar s = rng_.pick(accepted(Domain::Numeric));
    std::string n = std::to_string(regs_.size());
    VarId counter = add(VarKind::Temp, {s, 1}, "i" + n, true, false);
    VarId test = add(VarKind::Temp, {s, 1}, "c" + n, true, false);
    auto number = [&](double v) { return Operand{p().add_const({s, 1}, {v, 0, 0, 0}), Swizzle::identity(1)}; };
    int limit = rng_.between(0, 4), form = rng_.below(3);
    b.push_back(assign_stmt(counter, Op::Mov, {number(0)}));
    Loop l;
    Block counting;
    if (form != 1) counting.push_back(assign_stmt(counter, Op::Add, {whole(counter), number(1)}));
    counting.push_back(assign_stmt(test, form == 0 ? Op::Le : Op::Lt, {whole(counter), number(limit)}));
    if (rng_.chance(30)) counting.push_back(assign_stmt(test, Op::And, {whole(test), operand(s, 1, false, false)}));
    block_of_assignments(l.header, rng_.between(0, 1));
    for (Stmt& st : counting) l.header.push_back(std::move(st));
    l.cond = whole(test);
    l.test_at_top = form != 2;  // 0: while, 1: for, 2: do/until
    if (form == 2 && rng_.chance(50)) read_before_test(l, s, counter, number);
    block(l.body, Context{ctx.depth + 1, ctx.loops + 1, true}, rng_.between(1, 6));
    if (form == 1) l.update.push_back(assign_stmt(counter, Op::Add, {whole(counter), number(1)}));
    block_of_assignments(l.update, rng_.between(0, 1));
    b.push_back(Stmt{std::move(l)});
  }

  // A do/until loop whose test writes a register that the body reads
  // before it, on its first trip: there the register is as the element
  // began it, zero, whatever the previous element left in it.  The first
  // trip's read is kept in a register of its own, watched at the end.
  template <class Number>
  void read_before_test(Loop& l, Scalar s, VarId counter, const Number& number) {
    std::string n = std::to_string(regs_.size());
    VarId carried = add_unwritten(VarKind::Temp, {s, 1}, "d" + n, true, false);
    VarId first_trip = add(VarKind::Temp, {s, 1}, "e" + n, true, false);
    VarId seen = add_unwritten(VarKind::Temp, {s, 1}, "f" + n, true, false);
    watched_.push_back(seen);
    l.header.insert(l.header.begin(), assign_stmt(carried, Op::Mov, {operand(s, 1, false, false)}));
    l.body.push_back(assign_stmt(first_trip, Op::Eq, {whole(counter), number(0)}));
    If on_first;
    on_first.cond = whole(first_trip);
    on_first.then_body.push_back(assign_stmt(seen, Op::Mov, {whole(carried)}));
    l.body.push_back(Stmt{std::move(on_first)});
  }

  void block_of_assignments(Block& b, int n) {
    for (int i = 0; i < n; ++i) assign(b);
  }

  void statement(Block& b, const Context& ctx) {
    --budget_;
    int r = rng_.below(100);
    if (r < 10 && ctx.depth < 3) return if_statement(b, ctx);
    if (r < 17 && ctx.depth < 3 && ctx.loops < 2) return loop(b, ctx);
    if (r < 21 && ctx.jumps) return jump(b, ctx);
    if (r < 25) return scatter(b);
    if (r < 28) return prefetch(b);
    assign(b);
  }

  void block(Block& b, const Context& ctx, int n) {
    for (int i = 0; i < n && budget_ > 0; ++i) statement(b, ctx);
  }

  // Temporaries and outputs written whole before the body, from the
  // signature (converted where its scalar differs) or constants; a fifth
  // are left as the element begins them, at zero, so that reads of
  // unwritten registers (which a backend may skip zeroing where none can
  // happen) are tried too.
  Block prologue() {
    Block b;
    std::vector<VarId> sources = p().inputs;
    sources.insert(sources.end(), p().uniforms.begin(), p().uniforms.end());
    std::erase_if(sources, [&](VarId v) { return !exact_class(v); });
    for (VarId id : needs_init_) {
      if (rng_.chance(20)) continue;
      Type t = p().type_of(id);
      Assign a{id, Swizzle::identity(t.width), Op::Mov, {operand(t.scalar, t.width, false, true, false)}, -1};
      if (!sources.empty() && p().type_of(a.args[0].var).scalar == t.scalar && p().var(a.args[0].var).kind == VarKind::Const &&
          rng_.chance(70)) {
        VarId from = rng_.pick(sources);
        a.op = Op::Cast;
        a.args[0] = Operand{from, swizzle(rng_.chance(20) ? 1 : t.width, p().type_of(from).width)};
      }
      b.push_back(Stmt{std::move(a)});
    }
    return b;
  }

  // Every register the body may write, and every one watched, is observed
  // by an output of its own at the end, so that no computation is dead to
  // the optimiser.
  void epilogue(Block& b) {
    std::vector<Reg> observed;
    for (const Reg& r : regs_)
      if ((r.writable && p().var(r.id).kind == VarKind::Temp) || std::count(watched_.begin(), watched_.end(), r.id))
        observed.push_back(r);
    for (const Reg& r : observed) {
      Type t = type_of(r);
      VarId out = add(VarKind::Output, t, "see_" + p().var(r.id).name, false, false);
      p().outputs.push_back(out);
      b.push_back(Stmt{Assign{out, Swizzle::identity(t.width), Op::Mov, {Operand{r.id, Swizzle::identity(t.width)}}, -1}});
    }
  }

  Rng rng_;
  GeneratorOptions options_;
  Case c_;
  std::vector<Reg> regs_;
  std::vector<VarId> needs_init_;
  std::vector<VarId> watched_;  // observed at the end though the body does not write them
  std::vector<VarId> arrays_;
  int budget_ = 0;
};

}  // namespace

std::vector<Op> generated_ops() {
  std::vector<Op> ops;
  for (int i = 0; i < kOpCount; ++i)
    if ((op_info(op_at(i)).result != ResultRule::TableElement || op_arity(op_at(i)) == 1) && !is_lane_group(op_at(i)))
      ops.push_back(op_at(i));
  return ops;
}

Case generate(std::uint64_t seed, const GeneratorOptions& options) { return Generator(seed, options).run(); }

}  // namespace fuzz_ir
