#include "interp.hpp"

#include <chrono>
#include <cmath>

#include "sh/detail/sums.hpp"
#include "sh/error.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/verifier.hpp"

namespace sh::interp {
namespace {

using Reg = std::array<double, 4>;
enum class Flow { Next, Break, Continue };

class Machine {
 public:
  Machine(const ir::Program& p, const Options& o, const RunArgs& a, RunStats& s)
      : p_(p), o_(o), a_(a), stats_(s), regs_(p.vars.size()), arrays_(p.vars.size()), initial_(p.vars.size()) {
    // Constants as registers hold them: an f32 one rounded to float.
    for (std::size_t v = 0; v < p_.vars.size(); ++v)
      if (p_.vars[v].kind == ir::VarKind::Const) initial_[v] = held(static_cast<ir::VarId>(v), p_.vars[v].value);
  }

  void element(std::size_t e) {
    element_ = e;
    regs_ = initial_;
    for (std::size_t v = 0; v < p_.vars.size(); ++v) arrays_[v].assign(static_cast<std::size_t>(p_.vars[v].length), Reg{});
    for (std::size_t u = 0; u < p_.uniforms.size(); ++u) regs_[p_.uniforms[u]] = held(p_.uniforms[u], a_.uniforms[u]);
    for (std::size_t i = 0; i < p_.inputs.size(); ++i) load(p_.inputs[i], a_.inputs[i], e);
    block(p_.body);
    for (std::size_t o = 0; o < p_.outputs.size(); ++o) store(p_.outputs[o], a_.outputs[o], e);
  }

 private:
  // The element's place in the whole stream (RunArgs::element).
  std::size_t element_number() const { return a_.element(element_); }

  Reg held(ir::VarId id, Reg r) const {
    ir::Scalar s = p_.type_of(id).scalar;
    for (double& x : r) x = ir::hold(s, o_.precision, x);
    return r;
  }

  void load(ir::VarId id, const BufferView& b, std::size_t e) {
    Reg r{};
    for (int c = 0; c < b.type.width; ++c) r[c] = read_component(b.type.scalar, b.data, e * b.type.width + c);
    regs_[id] = held(id, r);
  }

  void store(ir::VarId id, const BufferView& b, std::size_t e) {
    for (int c = 0; c < b.type.width; ++c) write_component(b.type.scalar, b.data, e * b.type.width + c, regs_[id][c]);
  }

  static double read_component(ir::Scalar s, const void* data, std::size_t k) {
    switch (s) {
      case ir::Scalar::F32: return static_cast<const float*>(data)[k];
      case ir::Scalar::F64: return static_cast<const double*>(data)[k];
      default: return static_cast<const std::int32_t*>(data)[k];
    }
  }

  static void write_component(ir::Scalar s, void* data, std::size_t k, double v) {
    switch (s) {
      case ir::Scalar::F32: static_cast<float*>(data)[k] = static_cast<float>(v); break;
      case ir::Scalar::F64: static_cast<double*>(data)[k] = v; break;
      default: static_cast<std::int32_t*>(data)[k] = static_cast<std::int32_t>(v); break;
    }
  }

  double arg(const ir::Operand& o, int i) const { return regs_[o.var][o.component(i)]; }

  Flow block(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      Flow f = stmt(s);
      if (f != Flow::Next) return f;
    }
    return Flow::Next;
  }

  Flow stmt(const ir::Stmt& s) {
    if (auto* a = std::get_if<ir::Assign>(&s.node)) {
      assign(*a, s);
      return Flow::Next;
    }
    if (auto* i = std::get_if<ir::If>(&s.node)) return block(arg(i->cond, 0) > 0 ? i->then_body : i->else_body);
    if (auto* l = std::get_if<ir::Loop>(&s.node)) return loop(*l, s);
    if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
      scatter(*sc, s);
      return Flow::Next;
    }
    if (std::holds_alternative<ir::Prefetch>(s.node)) return Flow::Next;  // nothing to bring near
    return std::holds_alternative<ir::Break>(s.node) ? Flow::Break : Flow::Continue;
  }

  Flow loop(const ir::Loop& l, const ir::Stmt& s) {
    auto keep_going = [&] {
      block(l.header);
      return arg(l.cond, 0) > 0;
    };
    // A pass is counted once its test (at the top) lets it in: a loop of
    // exactly the cap's passes runs.
    for (std::uint64_t n = 0;; ++n) {
      if (l.test_at_top && !keep_going()) break;
      if (n >= o_.max_loop_iterations)
        throw runaway_loop(p_, s, element_number(), o_.max_loop_iterations);
      if (block(l.body) == Flow::Break) break;
      block(l.update);
      if (!l.test_at_top && !keep_going()) break;
    }
    return Flow::Next;
  }

  void assign(const ir::Assign& a, const ir::Stmt& s) {
    Reg result{};
    int n = a.mask.size;
    if (a.op == ir::Op::Fill) {
      for (Reg& slot : arrays_[a.dest])
        for (int i = 0; i < n; ++i) slot[i] = arg(a.args[0], i);
      return;
    }
    if (a.op == ir::Op::Store) {
      Reg& slot = arrays_[a.dest][array_index(a.dest, a.args[0], s)];
      for (int i = 0; i < n; ++i) slot[i] = arg(a.args[1], i);
      return;
    }
    if (a.op == ir::Op::Element) {
      result = arrays_[a.args[0].var][array_index(a.args[0].var, a.args[1], s)];
    } else if (ir::is_table_read(a.op)) {
      result = table_read(a, s);
    } else if (a.op == ir::Op::Position) {
      std::array<std::int32_t, 3> at = a_.domain.position(element_);
      for (int i = 0; i < n; ++i) result[i] = at[i];
    } else {
      ir::Scalar from = p_.type_of(a.args[0].var).scalar, to = p_.type_of(a.dest).scalar;
      for (int i = 0; i < n; ++i) {
        double x[3] = {0, 0, 0};
        for (std::size_t k = 0; k < a.args.size(); ++k) x[k] = arg(a.args[k], i);
        result[i] = ir::eval(a.op, from, to, o_.precision, x[0], x[1], x[2]);
      }
      if (o_.checked) check_nan(a, s, result);
    }
    for (int i = 0; i < n; ++i) regs_[a.dest][a.mask[i]] = result[i];
  }

  // Legal IR reads tables at coordinates in range; one outside would be a
  // legaliser's fault, reported rather than read.
  std::size_t element_at(const TableView& t, const ir::Operand& coords, const ir::Stmt& s) {
    std::size_t flat = 0, stride = 1;
    for (int d = 0; d < t.rank; ++d) {
      double i = arg(coords, d);
      if (!(i >= 0 && i < t.dims[d]))
        throw Error("program '" + p_.name + "': element " + std::to_string(element_number()) + " reads outside a table in `" +
                    ir::print(p_, s) + "` (the IR is not legal)");
      flat += static_cast<std::size_t>(i) * stride;
      stride *= static_cast<std::size_t>(t.dims[d]);
    }
    return flat;
  }

  // Legal IR indexes arrays in range, as it reads tables.
  std::size_t array_index(ir::VarId array, const ir::Operand& index, const ir::Stmt& s) const {
    double i = arg(index, 0);
    if (!(i >= 0 && i < p_.var(array).length))
      throw Error("program '" + p_.name + "': element " + std::to_string(element_number()) + " indexes outside an array in `" +
                  ir::print(p_, s) + "` (the IR is not legal)");
    return static_cast<std::size_t>(i);
  }

  Reg table_read(const ir::Assign& a, const ir::Stmt& s) {
    const TableView& t = a_.tables[a.table];
    Reg r{};
    if (a.op == ir::Op::Extent) {
      for (int d = 0; d < t.rank; ++d) r[d] = t.dims[d];
      return r;
    }
    std::size_t element = element_at(t, a.args[0], s);
    if (o_.checked)
      for (int d = 0; d < t.rank; ++d)
        if (arg(a.args[0], d) != arg(a.args[1], d)) note("first out-of-range table read", s);
    if (t.source) {
      TableSource::Span span = t.source->span_of(element);
      std::size_t at = (element - span.first) * t.element.width;
      for (int k = 0; k < t.element.width; ++k) r[k] = read_component(t.element.scalar, span.data, at + k);
      return r;
    }
    for (int k = 0; k < t.element.width; ++k) r[k] = read_component(t.element.scalar, t.data, element * t.element.width + k);
    return r;
  }

  // In stream order, one atomic addition at a time (sh/detail/sums.hpp):
  // a float accumulator takes the value as a float first, at every
  // precision.
  void scatter(const ir::Scatter& sc, const ir::Stmt& s) {
    const TableView& t = a_.tables[sc.table];
    std::size_t element = element_at(t, sc.index, s);
    for (int k = 0; k < t.element.width; ++k)
      detail::add_to_sum(t.element.scalar, t.sums, element * t.element.width + k, arg(sc.value, k));
  }

  void check_nan(const ir::Assign& a, const ir::Stmt& s, const Reg& result) {
    if (!ir::is_float(p_.type_of(a.dest).scalar)) return;
    for (const ir::Operand& o : a.args)
      for (int i = 0; i < o.width(); ++i)
        if (std::isnan(regs_[o.var][o.swizzle[i]])) return;  // carried in, not made here
    for (int i = 0; i < a.mask.size; ++i)
      if (std::isnan(result[i])) return note("first NaN", s);
  }

  void note(const std::string& what, const ir::Stmt& s) {
    for (const std::string& d : stats_.diagnostics)
      if (d.rfind(what + ":", 0) == 0) return;
    stats_.diagnostics.push_back(what + ": element " + std::to_string(element_number()) + ", `" + ir::print(p_, s) + "`");
  }

  const ir::Program& p_;
  const Options& o_;
  const RunArgs& a_;
  RunStats& stats_;
  std::vector<Reg> regs_;
  std::vector<std::vector<Reg>> arrays_;  // by variable: an array's elements, empty for the others
  std::vector<Reg> initial_;              // by variable: what each register holds at an element's start
  std::size_t element_ = 0;
};

class InterpKernel : public Kernel {
 public:
  InterpKernel(ir::Program p, Options o) : p_(std::move(p)), o_(std::move(o)) {}

  void run(const RunArgs& args, RunStats& stats) override {
    Machine m(p_, o_, args, stats);
    for (std::size_t e = 0; e < args.count; ++e) m.element(e);
  }

  std::string listing() const override { return ir::print(p_); }

 private:
  ir::Program p_;
  Options o_;
};

class InterpBackend : public Backend {
 public:
  std::string name() const override { return "interp"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    ir::verify_legal(p);
    return std::make_unique<InterpKernel>(p, o);
  }
  std::vector<std::string> describe() const override {
    return {"interp: reference interpreter on the host (f32 and f64, checked mode)"};
  }
  // Every table read goes through the TableView; elements run one by one.
  bool read_through_sources(Options&) const override { return true; }
  // In place, and a run keeps nothing of its own between elements.
  bool runs_in_place() const override { return true; }
};

}  // namespace

std::unique_ptr<Backend> make_backend() { return std::make_unique<InterpBackend>(); }

}  // namespace sh::interp
