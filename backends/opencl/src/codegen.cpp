#include "codegen.hpp"

#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

#include "sh/ir/printer.hpp"
#include "sh/ir/verifier.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::opencl {
namespace {

const char kComponent[] = "xyzw";

const char kAtomicAddFloat[] =
    "\nvoid sh_atomic_add_float(volatile __global float* p, float v) {\n"
    "  union { float f; unsigned int u; } old, sum;\n"
    "  do {\n"
    "    old.f = *p;\n"
    "    sum.f = old.f + v;\n"
    "  } while (atomic_cmpxchg((volatile __global unsigned int*)p, old.u, sum.u) != old.u);\n"
    "}\n";

// Sh's mod and round, as ir/eval.cpp defines them (the reference says why
// they are exact), in the scalar type t: the remainder with the sign of b
// (C's, plus b where the signs differ), and halves toward +Inf.
std::string floor_remainder_function(const std::string& t) {
  bool fp = t != "int";
  return "\n" + t + " sh_mod_" + t + "(" + t + " a, " + t + " b) {\n  " + t + " r = " +
         (fp ? "fmod(a, b)" : "a % b") + ";\n  return r != 0 && " + (fp ? "(r < 0) != (b < 0)" : "(r ^ b) < 0") +
         " ? r + b : r;\n}\n";
}

std::string round_half_up_function(const std::string& t) {
  std::string half = t == "float" ? "0.5f" : "0.5";
  return "\n" + t + " sh_round_" + t + "(" + t + " a) {\n  " + t + " f = floor(a);\n  return a - f >= " + half +
         " ? f + 1 : f;\n}\n";
}

// The element's place in the launch domain (sh::LaunchDomain): the run's
// elements start at `first` of a grid of rows `row` long, `rows` a layer.
constexpr const char* kPosition =
    "  const long at = first + e;\n"
    "  const int position_x = (int)(at % row), position_y = (int)(at / row % rows), position_z = (int)(at / row / rows);\n";

class Generator {
 public:
  Generator(const ir::Program& p, const sh::Options& o) : p_(p), o_(o) {}

  Source run() {
    needs_fp64_ = o_.precision == Precision::F64;
    for (const ir::Var& v : p_.vars) needs_fp64_ = needs_fp64_ || v.type.scalar == ir::Scalar::F64;
    for (const ir::TableDecl& t : p_.tables) needs_fp64_ = needs_fp64_ || t.element.scalar == ir::Scalar::F64;
    std::ostringstream head;
    head << "// program " << p_.name << ", generated from its optimised IR\n";
    if (needs_fp64_) head << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n";
    if (o_.math == MathMode::Precise) head << "#pragma OPENCL FP_CONTRACT OFF\n";
    if (adds_floats()) head << kAtomicAddFloat;
    std::ostringstream kernel;
    kernel << "\n__kernel void " << kKernelName << "(\n    const long base, const long first, const long row, const long rows";
    signature(kernel);
    // No test of e against the stream's end: every launch covers elements
    // that exist (backend.cpp), and a test would make a vectorising
    // compiler mask every load and store.
    kernel << ")\n{\n  const long e = base + get_global_id(0);\n";
    if (ir::uses(p_, ir::Op::Position)) kernel << kPosition;
    registers();
    load_inputs();
    block(p_.body, 1);
    store_outputs();
    body_ << "}\n";
    return Source{head.str() + helpers_ + kernel.str() + nan_constants() + body_.str(), needs_fp64_};
  }

 private:
  // A NaN constant is read from a volatile, so that PoCL's compiler never
  // sees it: given a NaN it knows, some of its built-ins (convert_int_sat,
  // exp10) give an undefined value and the store of it disappears.
  std::string nan_constants() const {
    std::string decls;
    if (uses_nan_float_) decls += "  volatile float sh_nan_f = NAN;\n";
    if (uses_nan_double_) decls += "  volatile double sh_nan_d = (double)NAN;\n";
    return decls;
  }

  // The name of a helper function of the kernel's source, written once,
  // before the kernel, the first time an operation needs it.
  std::string helper(const char* op, const std::string& t, std::string (*define)(const std::string&)) const {
    std::string name = std::string("sh_") + op + "_" + t;
    if (helper_names_.insert(name).second) helpers_ += define(t);
    return name;
  }

  bool adds_floats() const {
    for (const ir::TableDecl& t : p_.tables)
      if (t.accumulator && ir::is_float(t.element.scalar)) return true;
    return false;
  }

  // ---- types and names -------------------------------------------------------

  const char* reg_type(ir::Scalar s) const {
    switch (s) {
      case ir::Scalar::F32: return o_.precision == Precision::F32 ? "float" : "double";
      case ir::Scalar::F64: return "double";
      case ir::Scalar::I32: case ir::Scalar::Bool: return "int";
    }
    return "int";
  }
  static const char* storage_type(ir::Scalar s) {
    switch (s) {
      case ir::Scalar::F32: return "float";
      case ir::Scalar::F64: return "double";
      case ir::Scalar::I32: case ir::Scalar::Bool: return "int";
    }
    return "int";
  }
  const char* reg_type(ir::VarId v) const { return reg_type(p_.type_of(v).scalar); }

  std::string reg(ir::VarId v, int c) const { return "v" + std::to_string(v) + "_" + kComponent[c]; }

  std::string number(ir::Scalar s, double v) const {
    const char* t = reg_type(s);
    bool is_double = std::string(t) == "double";
    if (s == ir::Scalar::I32 || s == ir::Scalar::Bool) {
      auto i = static_cast<long long>(v);
      return i == -2147483648LL ? "(-2147483647 - 1)" : std::to_string(i);
    }
    if (std::isnan(v)) {
      (is_double ? uses_nan_double_ : uses_nan_float_) = true;
      return is_double ? "sh_nan_d" : "sh_nan_f";
    }
    if (std::isinf(v)) return std::string(v < 0 ? "-" : "") + (is_double ? "(double)INFINITY" : "INFINITY");
    char buf[64];
    auto r = is_double ? std::to_chars(buf, buf + sizeof buf, v) : std::to_chars(buf, buf + sizeof buf, static_cast<float>(v));
    std::string text(buf, r.ptr);
    if (text.find_first_of(".e") == std::string::npos) text += ".0";
    return is_double ? text : text + "f";
  }

  std::string read(const ir::Operand& o, int i) const {
    int c = o.swizzle[o.width() == 1 ? 0 : i];
    const ir::Var& v = p_.var(o.var);
    if (v.kind == ir::VarKind::Const) return number(v.type.scalar, v.value[c]);
    return reg(o.var, c);
  }

  void line(int depth, const std::string& text) { body_ << std::string(2 * depth, ' ') << text << "\n"; }

  // ---- signature, registers, inputs, outputs -----------------------------------

  void signature(std::ostringstream& out) {
    for (std::size_t i = 0; i < p_.inputs.size(); ++i)
      out << ",\n    __global const " << storage_type(p_.type_of(p_.inputs[i]).scalar) << "* in" << i;
    for (std::size_t o = 0; o < p_.outputs.size(); ++o)
      out << ",\n    __global " << storage_type(p_.type_of(p_.outputs[o]).scalar) << "* out" << o;
    for (ir::VarId u : p_.uniforms)
      for (int c = 0; c < p_.type_of(u).width; ++c) out << ",\n    const " << reg_type(u) << " " << reg(u, c);
    for (std::size_t t = 0; t < p_.tables.size(); ++t)
      out << ",\n    __global " << (p_.tables[t].accumulator ? "volatile " : "const ") << storage_type(p_.tables[t].element.scalar)
          << "* table" << t << ", const int table" << t << "_x, const int table" << t << "_y, const int table" << t << "_z";
    out << ",\n    __global long* status";
  }

  void registers() {
    for (std::size_t v = 0; v < p_.vars.size(); ++v) {
      const ir::Var& var = p_.vars[v];
      if (var.kind == ir::VarKind::Const || var.kind == ir::VarKind::Uniform) continue;
      std::string decl = std::string("  ") + reg_type(var.type.scalar);
      for (int c = 0; c < var.type.width; ++c) decl += (c ? ", " : " ") + reg(static_cast<ir::VarId>(v), c) + " = 0";
      body_ << decl << ";";
      if (!var.name.empty()) body_ << "  // " << var.name;
      body_ << "\n";
    }
  }

  void load_inputs() {
    for (std::size_t i = 0; i < p_.inputs.size(); ++i) {
      ir::VarId v = p_.inputs[i];
      int w = p_.type_of(v).width;
      for (int c = 0; c < w; ++c)
        line(1, reg(v, c) + " = in" + std::to_string(i) + "[e * " + std::to_string(w) + " + " + std::to_string(c) + "];");
    }
  }

  void store_outputs() {
    for (std::size_t o = 0; o < p_.outputs.size(); ++o) {
      ir::VarId v = p_.outputs[o];
      ir::Type t = p_.type_of(v);
      for (int c = 0; c < t.width; ++c)
        line(1, "out" + std::to_string(o) + "[e * " + std::to_string(t.width) + " + " + std::to_string(c) + "] = (" +
                    storage_type(t.scalar) + ")" + reg(v, c) + ";");
    }
  }

  // ---- statements -----------------------------------------------------------------

  void block(const ir::Block& b, int depth) {
    for (const ir::Stmt& s : b) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) assign(*a, depth);
      else if (auto* i = std::get_if<ir::If>(&s.node)) branch(*i, depth);
      else if (auto* l = std::get_if<ir::Loop>(&s.node)) loop(*l, s, depth);
      else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) scatter(*sc, depth);
      else if (std::holds_alternative<ir::Break>(s.node)) line(depth, jumps_.back().wrapped ? "{ " + jumps_.back().flag + " = 1; break; }" : "break;");
      else line(depth, "continue;");
    }
  }

  std::string truthy(const ir::Operand& o) const { return "(" + read(o, 0) + " > 0)"; }

  void branch(const ir::If& s, int depth) {
    line(depth, "if " + truthy(s.cond) + " {");
    block(s.then_body, depth + 1);
    if (!s.else_body.empty()) {
      line(depth, "} else {");
      block(s.else_body, depth + 1);
    }
    line(depth, "}");
  }

  static bool has_continue(const ir::Block& b) {
    for (const ir::Stmt& s : b) {
      if (std::holds_alternative<ir::Continue>(s.node)) return true;
      if (auto* i = std::get_if<ir::If>(&s.node))
        if (has_continue(i->then_body) || has_continue(i->else_body)) return true;
    }
    return false;
  }

  // for (;;) { count; [header; test]; body; update; [header; test] }.  A
  // body with `continue` runs inside do { } while (0), where `continue`
  // reaches the update and `break` needs a flag to leave the loop.
  void loop(const ir::Loop& l, const ir::Stmt& s, int depth) {
    int number = loops_++;
    std::string n = std::to_string(number), counter = "iterations" + n, flag = "leave" + n;
    bool wrapped = has_continue(l.body);
    line(depth, "// " + ir::print(p_, s));
    line(depth, "long " + counter + " = 0;");
    if (wrapped) line(depth, "int " + flag + " = 0;");
    line(depth, "for (;;) {");
    line(depth + 1, "if (++" + counter + " > " + std::to_string(o_.max_loop_iterations) + "L) { if (status[0] == 0) { status[0] = " +
                        std::to_string(number + 1) + "; status[1] = e; } return; }");
    auto test = [&] {
      block(l.header, depth + 1);
      line(depth + 1, "if (!" + truthy(l.cond) + ") break;");
    };
    if (l.test_at_top) test();
    jumps_.push_back({wrapped, flag});
    if (wrapped) {
      line(depth + 1, "do {");
      block(l.body, depth + 2);
      line(depth + 1, "} while (0);");
      line(depth + 1, "if (" + flag + ") break;");
    } else {
      block(l.body, depth + 1);
    }
    jumps_.pop_back();
    block(l.update, depth + 1);
    if (!l.test_at_top) test();
    line(depth, "}");
  }

  // ---- assignments -------------------------------------------------------------------

  void assign(const ir::Assign& a, int depth) {
    std::string results[4];
    if (ir::is_table_read(a.op)) {
      table_read(a, results);
    } else if (a.op == ir::Op::Position) {
      for (int i = 0; i < a.mask.size; ++i) results[i] = std::string("position_") + kComponent[i];
    } else {
      ir::Scalar from = p_.type_of(a.args[0].var).scalar, to = p_.type_of(a.dest).scalar;
      for (int i = 0; i < a.mask.size; ++i) {
        std::string x[3];
        for (std::size_t k = 0; k < a.args.size(); ++k) x[k] = read(a.args[k], i);
        results[i] = operation(a.op, from, to, x[0], x[1], x[2]);
      }
    }
    // All components are computed before any is written (v.xy = v.yx).
    if (a.mask.size == 1) {
      line(depth, reg(a.dest, a.mask[0]) + " = " + results[0] + ";");
      return;
    }
    std::string t = reg_type(a.dest);
    line(depth, "{");
    for (int i = 0; i < a.mask.size; ++i) line(depth + 1, t + " r" + std::to_string(i) + " = " + results[i] + ";");
    for (int i = 0; i < a.mask.size; ++i) line(depth + 1, reg(a.dest, a.mask[i]) + " = r" + std::to_string(i) + ";");
    line(depth, "}");
  }

  std::string one(ir::Scalar s) const { return number(s, 1.0); }

  // One case per row of the op table (ops.def), no default: a new
  // operation does not build until it is generated here.  Signed overflow
  // is undefined in OpenCL C, so wrapping integer arithmetic goes through
  // uint.
  std::string operation(ir::Op op, ir::Scalar from, ir::Scalar to, const std::string& a, const std::string& b,
                        const std::string& c) const {
    using ir::Op;
    const bool fp = ir::is_float(from);
    std::string t = reg_type(from);
    auto mask = [&](const std::string& bit) { return "(" + t + ")(" + bit + ")"; };
    auto pos = [&](const std::string& x) { return "(" + x + " > 0)"; };
    auto call = [](const char* f, const std::string& x) { return std::string(f) + "(" + x + ")"; };
    auto call2 = [](const char* f, const std::string& x, const std::string& y) {
      return std::string(f) + "(" + x + ", " + y + ")";
    };
    auto wrap = [&](const char* sym) { return "(int)((uint)" + a + " " + sym + " (uint)" + b + ")"; };
    switch (op) {
      case Op::Mov: return a;
      case Op::Cast: return cast(a, from, to);
      case Op::Add: return fp ? a + " + " + b : wrap("+");
      case Op::Sub: return fp ? a + " - " + b : wrap("-");
      case Op::Mul: return fp ? a + " * " + b : wrap("*");
      // Legal IR divides integers only by divisors that cannot trap.
      case Op::Div: return a + " / " + b;
      case Op::Mod: return helper("mod", t, floor_remainder_function) + "(" + a + ", " + b + ")";
      case Op::Neg: return fp ? "-" + a : "(int)(0u - (uint)" + a + ")";
      case Op::Min: return call2(fp ? "fmin" : "min", a, b);
      case Op::Max: return call2(fp ? "fmax" : "max", a, b);
      // In uint: abs(INT_MIN) wraps to INT_MIN, where PoCL's abs assumes a
      // result that is not negative.
      case Op::Abs: return fp ? call("fabs", a) : "(int)(" + a + " < 0 ? 0u - (uint)" + a + " : (uint)" + a + ")";
      case Op::Sign:
        if (fp) return "(" + a + " > 0 ? " + one(from) + " : (" + a + " < 0 ? -" + one(from) + " : " + a + "))";
        return "(" + a + " > 0 ? 1 : (" + a + " < 0 ? -1 : 0))";
      case Op::Floor: return call("floor", a);
      case Op::Ceil: return call("ceil", a);
      case Op::Round: return helper("round", t, round_half_up_function) + "(" + a + ")";
      case Op::Sqrt: return call("sqrt", a);
      case Op::Rsqrt: return one(from) + " / sqrt(" + a + ")";
      case Op::Rcp: return one(from) + " / " + a;
      case Op::Pow: return call2("pow", a, b);
      case Op::Exp: return call("exp", a);
      case Op::Exp2: return call("exp2", a);
      case Op::Log: return call("log", a);
      case Op::Log2: return call("log2", a);
      case Op::Sin: return call("sin", a);
      case Op::Cos: return call("cos", a);
      case Op::Tan: return call("tan", a);
      case Op::Asin: return call("asin", a);
      case Op::Acos: return call("acos", a);
      case Op::Atan: return call("atan", a);
      case Op::Atan2: return call2("atan2", a, b);
      case Op::Sinh: return call("sinh", a);
      case Op::Cosh: return call("cosh", a);
      case Op::Tanh: return call("tanh", a);
      case Op::Asinh: return call("asinh", a);
      case Op::Acosh: return call("acosh", a);
      case Op::Atanh: return call("atanh", a);
      case Op::Exp10: return call("exp10", a);
      case Op::Log10: return call("log10", a);
      case Op::Cbrt: return call("cbrt", a);
      case Op::BitAnd: return "(" + a + " & " + b + ")";
      case Op::BitOr: return "(" + a + " | " + b + ")";
      case Op::BitXor: return "(" + a + " ^ " + b + ")";
      case Op::BitNot: return "(~" + a + ")";
      // Legal IR shifts by counts in [0, 31] only; a left shift into the
      // sign bit is defined on uint.
      case Op::Shl: return "(int)((uint)" + a + " << " + b + ")";
      case Op::Shr: return "(" + a + " >> " + b + ")";
      case Op::Lt: return mask(a + " < " + b);
      case Op::Le: return mask(a + " <= " + b);
      case Op::Gt: return mask(a + " > " + b);
      case Op::Ge: return mask(a + " >= " + b);
      case Op::Eq: return mask(a + " == " + b);
      case Op::Ne: return mask(a + " != " + b);
      case Op::And: return mask(pos(a) + " && " + pos(b));
      case Op::Or: return mask(pos(a) + " || " + pos(b));
      case Op::Not: return mask("!" + pos(a));
      case Op::Cond: return pos(a) + " ? " + b + " : " + c;
      // Each work-item is its own group: OpenCL 1.2 has no vote across
      // work-items outside a barrier, which divergent code cannot take.
      case Op::AnyLane: return mask(pos(a));
      case Op::Extent: case Op::Load: break;   // table_read()
      case Op::Position: break;                 // assign()
      case Op::Fetch: case Op::Sample: break;  // not legal IR: generate() refuses it
    }
    throw Error(std::string("opencl backend: ") + ir::op_name(op) + " reached the arithmetic generator");
  }

  // NaN gives 0, told by its bits: PoCL's convert_int_sat of a NaN it can
  // see at compile time is undefined, so the store of it vanished, and a
  // float isnan() test was folded the same way.
  std::string float_to_int(const std::string& a, ir::Scalar from) const {
    bool is_double = std::string(reg_type(from)) == "double";
    std::string nan = is_double ? "(as_ulong(" + a + ") & 0x7fffffffffffffffUL) > 0x7ff0000000000000UL"
                                : "(as_uint(" + a + ") & 0x7fffffffU) > 0x7f800000U";
    return "(" + nan + " ? 0 : convert_int_sat(" + a + "))";
  }

  std::string cast(const std::string& a, ir::Scalar from, ir::Scalar to) const {
    if (to == ir::Scalar::Bool) return "(int)(" + a + " > 0)";
    if (to == ir::Scalar::I32) return ir::is_float(from) ? float_to_int(a, from) : a;
    return std::string("(") + reg_type(to) + ")(" + a + ")";
  }

  // The element a read or scatter names (coordinates in range: legal IR).
  std::string flat_index(int table, const ir::Operand& coord) const {
    std::string name = "table" + std::to_string(table);
    std::string index, stride = "1";
    for (int d = 0; d < p_.tables[table].rank; ++d) {
      std::string dim = name + "_" + kComponent[d];
      std::string i = "(long)" + read(coord, d);
      index += (d ? " + " : "") + i + (d ? " * " + stride : "");
      stride = d ? stride + " * " + dim : "(long)" + dim;
    }
    return "(" + index + ") * " + std::to_string(p_.tables[table].element.width);
  }

  void table_read(const ir::Assign& a, std::string* results) {
    const ir::TableDecl& t = p_.tables[a.table];
    std::string name = "table" + std::to_string(a.table);
    if (a.op == ir::Op::Extent) {
      for (int d = 0; d < t.rank; ++d) results[d] = name + "_" + kComponent[d];
      return;
    }
    std::string at = flat_index(a.table, a.args[0]);
    for (int c = 0; c < t.element.width; ++c)
      results[c] = std::string("(") + reg_type(t.element.scalar) + ")" + name + "[" + at + " + " + std::to_string(c) + "]";
  }

  // OpenCL 1.2 adds ints atomically; floats by compare-and-swap on their bits.
  void scatter(const ir::Scatter& sc, int depth) {
    const ir::TableDecl& t = p_.tables[sc.table];
    bool is_float = ir::is_float(t.element.scalar);
    line(depth, "{");
    line(depth + 1, "const long at = " + flat_index(sc.table, sc.index) + ";");
    for (int c = 0; c < t.element.width; ++c) {
      std::string place = "table" + std::to_string(sc.table) + " + at + " + std::to_string(c);
      std::string value = std::string("(") + storage_type(t.element.scalar) + ")" + read(sc.value, c);
      line(depth + 1, std::string(is_float ? "sh_atomic_add_float(" : "atomic_add(") + place + ", " + value + ");");
    }
    line(depth, "}");
  }

  struct Jump {
    bool wrapped;
    std::string flag;
  };

  const ir::Program& p_;
  const sh::Options& o_;
  std::ostringstream body_;
  bool needs_fp64_ = false;
  mutable bool uses_nan_float_ = false, uses_nan_double_ = false;
  mutable std::set<std::string> helper_names_;
  mutable std::string helpers_;
  int loops_ = 0;
  std::vector<Jump> jumps_;
};

}  // namespace

Source generate(const ir::Program& program, const sh::Options& options) {
  ir::verify_legal(program);
  return Generator(program, options).run();
}

}  // namespace sh::opencl
