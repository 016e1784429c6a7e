// Which components of which variables a read may find as the element
// began: a forward walk that carries the components written on every path
// so far.  A branch keeps what both of its sides write; a loop keeps
// nothing of its own (it may not run, or leave early).  Within a loop the
// update sees only what its test wrote, where the test comes first (a
// continue skips the rest of the body), and a test at the bottom sees only
// what came before the loop.  Arrays are written whole by a fill alone: a
// store leaves the other elements.  Outputs are read when the element ends.
#include "sh/analysis.hpp"

namespace sh::analysis {
namespace {

class UnwrittenReads {
 public:
  explicit UnwrittenReads(const ir::Program& p) : p_(p), found_(p.vars.size(), 0) {}

  std::vector<std::uint8_t> run() {
    Written written(p_.vars.size(), 0);
    for (ir::VarId v : p_.inputs) written[static_cast<std::size_t>(v)] = all(v);
    block(p_.body, written);
    for (ir::VarId v : p_.outputs) note_read(v, all(v), written);
    return found_;
  }

 private:
  using Written = std::vector<std::uint8_t>;  // by VarId: bit c, component c

  std::uint8_t all(ir::VarId v) const { return ir::Swizzle::identity(p_.type_of(v).width).bits(); }

  void note_read(ir::VarId v, std::uint8_t components, const Written& written) {
    auto at = static_cast<std::size_t>(v);
    found_[at] = static_cast<std::uint8_t>(found_[at] | (components & ~written[at]));
  }

  void read(const ir::Operand& o, const Written& written) {
    note_read(o.var, p_.var(o.var).kind == ir::VarKind::Array ? all(o.var) : o.swizzle.bits(), written);
  }

  void assign(const ir::Assign& a, Written& written) {
    for (const ir::Operand& o : a.args) read(o, written);
    auto at = static_cast<std::size_t>(a.dest);
    if (p_.var(a.dest).kind == ir::VarKind::Array) {
      if (a.op == ir::Op::Fill) written[at] = all(a.dest);
      return;
    }
    if (ir::overwrites(a)) written[at] = static_cast<std::uint8_t>(written[at] | a.mask.bits());
  }

  void block(const ir::Block& b, Written& written) {
    for (const ir::Stmt& s : b) statement(s, written);
  }

  void statement(const ir::Stmt& s, Written& written) {
    if (const auto* a = std::get_if<ir::Assign>(&s.node)) return assign(*a, written);
    if (const auto* sc = std::get_if<ir::Scatter>(&s.node)) {
      read(sc->index, written);
      return read(sc->value, written);
    }
    if (const auto* pf = std::get_if<ir::Prefetch>(&s.node)) return read(pf->index, written);
    if (const auto* i = std::get_if<ir::If>(&s.node)) {
      read(i->cond, written);
      Written then_side = written, else_side = written;
      block(i->then_body, then_side);
      block(i->else_body, else_side);
      for (std::size_t v = 0; v < written.size(); ++v) written[v] = then_side[v] & else_side[v];
      return;
    }
    if (const auto* l = std::get_if<ir::Loop>(&s.node)) {
      Written first = written;
      if (l->test_at_top) test(*l, first);
      Written body = first, update = first;
      block(l->body, body);
      block(l->update, update);
      if (!l->test_at_top) {
        Written header = written;
        test(*l, header);
      }
    }
  }

  void test(const ir::Loop& l, Written& written) {
    block(l.header, written);
    read(l.cond, written);
  }

  const ir::Program& p_;
  std::vector<std::uint8_t> found_;
};

}  // namespace

std::vector<std::uint8_t> unwritten_reads(const ir::Program& p) { return UnwrittenReads(p).run(); }

}  // namespace sh::analysis
