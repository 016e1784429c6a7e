#include "sh/ir/printer.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "sh/ir/visitor.hpp"

namespace sh::ir {
namespace {

const char kComponent[] = "xyzw";

// Malformed IR gets printed too (in the verifier's messages): components
// past w print as '?'.
char component_name(int c) { return c >= 0 && c < 4 ? kComponent[c] : '?'; }

std::string swizzle_suffix(const Swizzle& s, int width) {
  if (s.is_identity(width)) return "";
  std::string out = ".";
  for (int i = 0; i < s.size; ++i) out += component_name(s.index[i]);
  return out;
}

class Printer {
 public:
  Printer(const Program& p, const PrintOptions& o) : p_(p), o_(o) {}

  std::string program() {
    out_ << "program " << (o_.names ? p_.name : std::string()) << "\n";
    for (std::size_t i = 0; i < p_.vars.size(); ++i) declare(static_cast<VarId>(i));
    for (std::size_t t = 0; t < p_.tables.size(); ++t) {
      const TableDecl& d = p_.tables[t];
      out_ << (d.accumulator ? "  accumulator #" : "  table #") << t;
      if (o_.names && !d.name.empty()) out_ << " " << d.name;
      out_ << ": " << type_name(d.element) << " rank " << d.rank;
      if (d.edge != Edge::Clamp) out_ << " edge " << edge_name(d.edge);
      out_ << "\n";
    }
    out_ << "body\n";
    block(p_.body, 1);
    return out_.str();
  }

  std::string statement(const Stmt& s) {
    if (auto* a = std::get_if<Assign>(&s.node)) return assign(*a);
    if (auto* i = std::get_if<If>(&s.node)) return "if " + operand(i->cond);
    if (auto* l = std::get_if<Loop>(&s.node)) return loop_head(*l);
    if (auto* sc = std::get_if<Scatter>(&s.node))
      return "scatter-add #" + std::to_string(sc->table) + " " + operand(sc->index) + ", " + operand(sc->value);
    if (auto* pf = std::get_if<Prefetch>(&s.node)) return "prefetch #" + std::to_string(pf->table) + " " + operand(pf->index);
    if (std::holds_alternative<Break>(s.node)) return "break";
    return "continue";
  }

  std::string operand(const Operand& o) {
    const Var& v = p_.var(o.var);
    auto constant = [&](int c) { return c < 4 ? format_number(v.value[c], v.type.scalar) : std::string("?"); };
    if (v.kind == VarKind::Const && o_.inline_consts) {
      if (o.swizzle.size == 1) return constant(o.swizzle[0]);
      std::string s = "(";
      for (int i = 0; i < o.swizzle.size; ++i) s += (i ? ", " : "") + constant(o.swizzle[i]);
      return s + ")";
    }
    return "%" + std::to_string(o.var) + swizzle_suffix(o.swizzle, v.type.width);
  }

 private:
  void declare(VarId id) {
    const Var& v = p_.var(id);
    bool named_temp = v.kind == VarKind::Temp && o_.names && !v.name.empty();
    bool listed = (v.kind != VarKind::Temp && v.kind != VarKind::Const) || named_temp;
    if (!listed && !o_.declare_temps) return;
    out_ << "  " << var_kind_name(v.kind) << " %" << id;
    if (o_.names && !v.name.empty()) out_ << " " << v.name;
    out_ << ": " << type_name(v.type);
    if (v.kind == VarKind::Array) out_ << "[" << v.length << "]";
    if (v.kind == VarKind::Const) {
      out_ << " =";
      for (int i = 0; i < v.type.width && i < 4; ++i) out_ << " " << format_number(v.value[i], v.type.scalar);
    }
    out_ << "\n";
  }

  // %5 = element %2[%3]; %2[%3] = store %4
  std::string assign(const Assign& a) {
    if (a.op == Op::Element && a.args.size() == 2)
      return "%" + std::to_string(a.dest) + swizzle_suffix(a.mask, p_.type_of(a.dest).width) + " = element %" +
             std::to_string(a.args[0].var) + "[" + operand(a.args[1]) + "]";
    if (a.op == Op::Store && a.args.size() == 2)
      return "%" + std::to_string(a.dest) + "[" + operand(a.args[0]) + "] = store " + operand(a.args[1]);
    std::string s = "%" + std::to_string(a.dest) + swizzle_suffix(a.mask, p_.type_of(a.dest).width);
    s += " = ";
    s += op_name(a.op);
    if (a.op == Op::Cast) s += std::string(" ") + scalar_name(p_.type_of(a.dest).scalar);
    if (a.table >= 0) s += " #" + std::to_string(a.table);
    for (std::size_t i = 0; i < a.args.size(); ++i) s += (i ? ", " : " ") + operand(a.args[i]);
    return s;
  }

  std::string loop_head(const Loop& l) {
    return std::string("loop ") + (l.test_at_top ? "test-first" : "test-last") + " while " +
           operand(l.cond);
  }

  void line(int depth, const std::string& text) { out_ << std::string(2 * depth, ' ') << text << "\n"; }

  void block(const Block& b, int depth) {
    for (const Stmt& s : b) stmt(s, depth);
  }

  void stmt(const Stmt& s, int depth) {
    if (auto* i = std::get_if<If>(&s.node)) {
      line(depth, "if " + operand(i->cond) + " {");
      block(i->then_body, depth + 1);
      if (!i->else_body.empty()) {
        line(depth, "} else {");
        block(i->else_body, depth + 1);
      }
      line(depth, "}");
    } else if (auto* l = std::get_if<Loop>(&s.node)) {
      line(depth, loop_head(*l) + " {");
      section(depth, "header", l->header);
      section(depth, "body", l->body);
      section(depth, "update", l->update);
      line(depth, "}");
    } else {
      line(depth, statement(s));
    }
  }

  void section(int depth, const char* name, const Block& b) {
    if (b.empty()) return;
    line(depth, std::string(name) + ":");
    block(b, depth + 1);
  }

  const Program& p_;
  PrintOptions o_;
  std::ostringstream out_;
};

}  // namespace

std::string format_number(double v, Scalar s) {
  if (s == Scalar::Bool) return v != 0 ? "true" : "false";
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  // A float register holds a double in f64 precision: print it exactly.
  bool as_float = s == Scalar::F32 && static_cast<double>(static_cast<float>(v)) == v;
  auto r = as_float ? std::to_chars(buf, buf + sizeof buf, static_cast<float>(v))
                    : std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string print(const Program& p, const PrintOptions& options) { return Printer(p, options).program(); }

std::string print(const Program& p, const Stmt& s) { return Printer(p, {}).statement(s); }

std::string print_operand(const Program& p, const Operand& o) { return Printer(p, {}).operand(o); }

}  // namespace sh::ir
