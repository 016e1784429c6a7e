#include "codegen.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <climits>
#include <cmath>
#include <set>
#include <sstream>

#include "sh/analysis.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/verifier.hpp"
#include "sh/ir/visitor.hpp"

namespace sh::opencl {
namespace {

const char kComponent[] = "xyzw";
const char kLaneDigit[] = "0123456789abcdef";

const char kAtomicAddFloat[] =
    "\nvoid sh_atomic_add_float(volatile __global float* p, float v) {\n"
    "  union { float f; unsigned int u; } old, sum;\n"
    "  do {\n"
    "    old.f = *p;\n"
    "    sum.f = old.f + v;\n"
    "  } while (atomic_cmpxchg((volatile __global unsigned int*)p, old.u, sum.u) != old.u);\n"
    "}\n";

// What the kernels of one source share: the helper functions written once
// before them, and whether the source needs double precision.
struct Prelude {
  std::set<std::string> names;
  std::string text;
  bool needs_fp64 = false;
};

// One kernel of the source: the scalar form (lanes 1: a work-item runs one
// element, with C's control flow) or the SPMD form (a work-item runs
// `lanes` consecutive elements in vector registers, the control flow as
// masks: an assignment under a mask selects, a branch side runs when any
// lane takes it, a loop runs while any lane loops).  The two differ only
// in the text of types, choices and the statements that steer lanes.
class Generator {
 public:
  Generator(const ir::Program& p, const sh::Options& o, int lanes, std::uint64_t largest_buffer, Prelude& prelude)
      : p_(p),
        o_(o),
        lanes_(lanes),
        index_type_(largest_buffer / 4 <= INT_MAX ? "int" : "long"),
        prelude_(prelude),
        access_(analysis::table_access(p)),
        facts_(spmd() ? analysis::analyse_spmd(p) : analysis::SpmdFacts{}),
        truth_(spmd() ? truth_registers() : analysis::VarSet(p.vars.size(), false)) {}

  std::string run(const char* name) {
    std::ostringstream kernel;
    kernel << "\n__kernel void " << name << "(\n    const long base, const long first, const long row, const long rows";
    signature(kernel);
    // No test of e against the stream's end: every launch covers elements
    // that exist (backend.cpp), and a test would make a vectorising
    // compiler mask every load and store.
    kernel << ")\n{\n  const long e = base + (long)get_global_id(0) * " << lanes_ << ";\n";
    if (spmd()) kernel << "  " << vec("int") << " exec = (" << vec("int") << ")(-1);\n";
    if (ir::uses(p_, ir::Op::Position)) kernel << position();
    registers();
    load_inputs();
    stencil_or_body();
    store_outputs();
    body_ << "}\n";
    return kernel.str() + hidden_constants() + body_.str();
  }

 private:
  bool spmd() const { return lanes_ > 1; }
  // SPMD: whether lanes may hold different values of v (otherwise every
  // lane holds lane 0's), and whether an if or loop needs masks.
  bool varying(ir::VarId v) const { return !spmd() || facts_.varying[v]; }
  // SPMD: a variable every lane agrees on is one scalar, not a vector of
  // copies, so that the device's compiler sees uniform loops' counters
  // (their trip counts) and computes uniform values once.
  bool scalar_register(ir::VarId v) const {
    ir::VarKind k = p_.var(v).kind;
    return spmd() && k != ir::VarKind::Const && k != ir::VarKind::Uniform && !facts_.varying[v];
  }
  bool divergent(const ir::Stmt& s) const { return spmd() && facts_.divergent.at(&s); }

  // SPMD: a register that only ever holds 0 or 1 (a comparison, Sh's && and
  // || as min and max of such, a vote across lanes, a conversion of such)
  // is held as a mask, -1 or 0 a lane, the form a vector comparison gives.  A test such as
  // `i < n && dot(z, z) < 4` is then two comparisons and an and of masks,
  // where 0/1 floats took a conversion to float after each comparison and
  // one back for the loop's mask.  Where a mask is read as a number it
  // becomes 0 or 1 again (read()).
  analysis::VarSet truth_registers() const {
    struct Accesses : ir::Visitor {
      std::vector<std::vector<const ir::Assign*>> writes, reads;
      std::vector<bool> scattered;
      void visit(const ir::Assign& a) override {
        writes[a.dest].push_back(&a);
        for (const ir::Operand& o : a.args) reads[o.var].push_back(&a);
      }
      void visit(const ir::Scatter& s) override { scattered[s.index.var] = scattered[s.value.var] = true; }
    } access;
    access.writes.resize(p_.vars.size());
    access.reads.resize(p_.vars.size());
    access.scattered.resize(p_.vars.size());
    access.ir::Visitor::visit(p_.body);
    analysis::VarSet truth(p_.vars.size(), false);
    for (std::size_t v = 0; v < truth.size(); ++v) {
      const ir::Var& var = p_.vars[v];
      truth[v] = var.kind == ir::VarKind::Temp && facts_.varying[v] && !access.writes[v].empty() && !access.scattered[v];
    }
    auto keeps = [&](std::size_t v) {
      bool numbers = !ir::is_float(p_.vars[v].type.scalar);
      return std::all_of(access.writes[v].begin(), access.writes[v].end(), [&](const ir::Assign* a) { return gives_truth(*a, truth); }) &&
             (!numbers || std::all_of(access.reads[v].begin(), access.reads[v].end(),
                                      [&](const ir::Assign* a) { return reads_truth(*a, static_cast<ir::VarId>(v), truth); }));
    };
    for (bool changed = true; changed;) {
      changed = false;
      for (std::size_t v = 0; v < truth.size(); ++v)
        if (truth[v] && !keeps(v)) truth[v] = false, changed = true;
    }
    return truth;
  }
  // Whether `a` reads `v` only as a truth value.  Integer registers are held
  // as masks only where nothing reads them as numbers: a grid walk's steps,
  // computed from comparisons, would each take a conversion back.
  bool reads_truth(const ir::Assign& a, ir::VarId v, const analysis::VarSet& truth) const {
    using ir::Op;
    if (a.op == Op::And || a.op == Op::Or || a.op == Op::Not || a.op == Op::AnyLane) return true;
    if (a.op == Op::Cond) return a.args[1].var != v && a.args[2].var != v;
    return truth[a.dest] && (a.op == Op::Mov || a.op == Op::Min || a.op == Op::Max || a.op == Op::Cast);
  }
  // Whether `a` writes only 0 or 1, given the registers that hold only those.
  bool gives_truth(const ir::Assign& a, const analysis::VarSet& truth) const {
    using ir::Op;
    constexpr std::array kTests = {Op::Lt, Op::Le, Op::Gt, Op::Ge, Op::Eq, Op::Ne, Op::And, Op::Or, Op::Not, Op::AnyLane};
    if (std::find(kTests.begin(), kTests.end(), a.op) != kTests.end()) return true;
    if (a.op != Op::Mov && a.op != Op::Min && a.op != Op::Max && a.op != Op::Cast) return false;
    return std::all_of(a.args.begin(), a.args.end(), [&](const ir::Operand& o) { return truth_operand(o, truth); });
  }
  bool truth_operand(const ir::Operand& o, const analysis::VarSet& truth) const {
    const ir::Var& v = p_.var(o.var);
    if (v.kind != ir::VarKind::Const) return truth[o.var];
    for (int i = 0; i < o.width(); ++i)
      if (v.value[o.swizzle[i]] != 0 && v.value[o.swizzle[i]] != 1) return false;
    return true;
  }

  // The element's place in the launch domain (sh::LaunchDomain): the run's
  // elements start at `first` of a grid of rows `row` long, `rows` a layer.
  // A work-item's lanes usually share a row: then one division serves all.
  std::string position() const {
    if (!spmd())
      return "  const long at = first + e;\n"
             "  const int position_x = (int)(at % row), position_y = (int)(at / row % rows), position_z = (int)(at / row / "
             "rows);\n";
    std::string i = vec("int"), l = vec("long");
    return "  const long at = first + e;\n  const int same_row = at % row + " + std::to_string(lanes_) + " <= row;\n  " + i +
           " position_x, position_y, position_z;\n  if (same_row) {\n    position_x = (int)(at % row) + " + iota("int") +
           ";\n    position_y = (" + i + ")((int)(at / row % rows));\n    position_z = (" + i +
           ")((int)(at / row / rows));\n  } else {\n    const " + l + " lane_at = at + " + iota("long") +
           ";\n    position_x = convert_" + i + "(lane_at % row);\n    position_y = convert_" + i +
           "(lane_at / row % rows);\n    position_z = convert_" + i + "(lane_at / row / rows);\n  }\n";
  }

  // Where the SPMD form reads tables at position() plus constants (a
  // stencil's taps), the body is written twice: once for a work-item whose
  // lanes share a row and whose taps all lie inside their tables, each tap
  // one vector load with no test, and once with each read tested.  One test
  // chooses; rows are long and taps short, so nearly every work-item takes
  // the first.
  void stencil_or_body() {
    std::string inside = taps_inside();
    if (inside.empty()) return block(p_.body, 1);
    line(1, "if (" + inside + ") {");
    int loops = loops_;
    taps_inside_ = true;
    block(p_.body, 2);
    taps_inside_ = false;
    loops_ = loops;  // the loops are numbered as they appear in the program
    line(1, "} else {");
    block(p_.body, 2);
    line(1, "}");
  }

  // Whether the work-item's lanes share a row and its taps lie inside
  // their tables, from their smallest and largest offsets (empty where the
  // program has no tap).
  std::string taps_inside() const {
    if (!spmd()) return "";
    std::vector<std::optional<analysis::TapSpan>> spans = analysis::tap_spans(p_, access_);
    std::string inside;
    for (std::size_t t = 0; t < spans.size(); ++t) {
      if (!spans[t]) continue;
      for (int d = 0; d < p_.tables[t].rank; ++d) {
        std::string at = std::string("(long)position_") + kComponent[d] + ".s0";
        int last = spans[t]->high[d] + (d == 0 ? lanes_ - 1 : 0);
        inside += " && " + at + " + " + std::to_string(spans[t]->low[d]) + " >= 0 && " + at + " + " + std::to_string(last) +
                  " < table" + std::to_string(t) + "_" + kComponent[d];
      }
    }
    return inside.empty() ? "" : "same_row" + inside;
  }

  // A tap inside its table: its lanes' elements from the first lane's on.
  std::string tap(const ir::Assign& a, int c) const {
    const ir::TableDecl& t = p_.tables[a.table];
    const std::array<int, 3>& offset = *access_.at(&a).offset;
    std::string name = "table" + std::to_string(a.table), start, stride = "1";
    for (int d = 0; d < t.rank; ++d) {
      std::string at = std::string("((long)position_") + kComponent[d] + ".s0 + " + std::to_string(offset[d]) + ")";
      start += (d ? " + " : "") + at + (d ? " * " + stride : "");
      stride = d ? stride + " * " + name + "_" + kComponent[d] : "(long)" + name + "_" + kComponent[d];
    }
    int w = t.element.width;
    if (w == 1) return run_load(storage_type(t.element.scalar)) + "(" + name + " + " + start + ")";
    std::string lanes;
    for (int k = 0; k < lanes_; ++k)
      lanes += (k ? ", " : "") + name + "[(" + start + " + " + std::to_string(k) + ") * " + std::to_string(w) + " + " +
               std::to_string(c) + "]";
    return "(" + vec(storage_type(t.element.scalar)) + ")(" + lanes + ")";
  }

  // ---- text that differs between the forms -----------------------------------------

  std::string vec(const std::string& scalar) const { return spmd() ? scalar + std::to_string(lanes_) : scalar; }
  std::string iota(const std::string& scalar) const {
    std::string list;
    for (int k = 0; k < lanes_; ++k) list += (k ? ", " : "") + std::to_string(k);
    return "(" + vec(scalar) + ")(" + list + ")";
  }
  static std::string lane(int k) { return std::string(".s") + kLaneDigit[k]; }

  // A 1 or 0 in the type of `s` from a C comparison (1/0 for scalars, -1/0
  // for vectors).  One element a work-item: a choice of constants, not a
  // conversion of the truth, which NVIDIA's OpenCL compiler (driver 580,
  // an H100) got wrong: `(double)(a <= b)` gave 0 for a = b = -1 among the
  // conformance suite's comparisons, right without its optimiser.
  std::string bit(const std::string& comparison, ir::Scalar s) const {
    if (!spmd()) {
      std::string type = reg_type(s);
      return "((" + comparison + ") ? (" + type + ")1 : (" + type + ")0)";
    }
    return "convert_" + vec(reg_type(s)) + "(-(" + comparison + "))";
  }
  // yes where `comparison` holds, otherwise no, in the type of `s`.
  std::string choose(const std::string& comparison, const std::string& yes, const std::string& no, ir::Scalar s) const {
    if (!spmd()) return "(" + comparison + " ? " + yes + " : " + no + ")";
    return "select(" + no + ", " + yes + ", convert_" + vec(mask_type(s)) + "(" + comparison + "))";
  }
  // The integer type whose lanes select values of type `s`.
  const char* mask_type(ir::Scalar s) const { return std::string(reg_type(s)) == "double" ? "long" : "int"; }
  std::string bits_as(const char* type, const std::string& x) const { return "as_" + vec(type) + "(" + x + ")"; }
  std::string convert(const char* type, const std::string& x) const {
    return spmd() ? "convert_" + vec(type) + "(" + x + ")" : std::string("(") + type + ")(" + x + ")";
  }
  std::string constant(ir::Scalar s, double v) const {
    std::string n = number(s, v);
    return spmd() ? "((" + vec(reg_type(s)) + ")(" + n + "))" : n;
  }

  // ---- the source's prelude ------------------------------------------------------

  // The constants read from volatiles, so that PoCL's compiler never sees
  // them: NaN (given a NaN it knows, some of its built-ins, convert_int_sat
  // and exp10, give an undefined value and the store of it disappears), and
  // the zeros moves write (written()).
  std::string hidden_constants() const {
    std::string decls;
    if (uses_nan_float_) decls += "  volatile float sh_nan_f = NAN;\n";
    if (uses_nan_double_) decls += "  volatile double sh_nan_d = (double)NAN;\n";
    if (uses_zero_float_) decls += "  volatile float sh_zero_fv = 0.0f;\n  const float sh_zero_f = sh_zero_fv;\n";
    if (uses_zero_double_) decls += "  volatile double sh_zero_dv = 0.0;\n  const double sh_zero_d = sh_zero_dv;\n";
    return decls;
  }

  // The lanes' elements from p on, one load or store of the vector type
  // with the element's alignment: PoCL's vloadN assembles an unaligned
  // vector from pieces (six instructions for a float16 where one would do),
  // its vstoreN stores it in three.  A typedef that lowers a type's
  // alignment is Clang's reading of `aligned` (the OpenCL C compilers of
  // PoCL and the GPU vendors are Clang's); the kernel of lanes runs on CPU
  // devices unless the lanes setting asks for it elsewhere.
  std::string run_load(const std::string& element) const {
    std::string v = vec(element);
    return helper("sh_run_" + v, v, "(const __global " + element + "* p) {\n" + unaligned(element) +
                                        "  return *(const __global unaligned*)p;\n}\n");
  }
  std::string run_store(const std::string& element) const {
    std::string v = vec(element);
    return helper("sh_store_run_" + v, "void", "(" + v + " x, __global " + element + "* p) {\n" + unaligned(element) +
                                                   "  *(__global unaligned*)p = x;\n}\n");
  }
  std::string unaligned(const std::string& element) const {
    return "  typedef " + vec(element) + " unaligned __attribute__((aligned(sizeof(" + element + "))));\n";
  }

  // A helper function of the source, written once, before the kernels,
  // the first time an operation needs it; returns its name.
  std::string helper(const std::string& name, const std::string& returns, const std::string& rest) const {
    if (prelude_.names.insert(name).second) prelude_.text += "\n" + returns + " " + name + rest;
    return name;
  }

  // Sh's mod and round, as ir/eval.cpp defines them (the reference says why
  // they are exact): the remainder with the sign of b (C's, plus b where
  // the signs differ), and halves toward +Inf.
  //
  // A float remainder by zero is NaN, read from a volatile: where PoCL can
  // see the zero (a constant folded into the divisor), its fmod gives a NaN
  // it treats as undefined, and the store of the result, or of what is
  // computed from it, vanished.
  std::string floor_remainder(ir::Scalar s) const {
    std::string t = vec(reg_type(s));
    bool fp = ir::is_float(s);
    std::string differ = fp ? "(r < 0) != (b < 0)" : "(r ^ b) < 0";
    std::string result = choose("r != 0 && " + differ, "r + b", "r", s);
    std::string nan;
    if (fp) {
      nan = std::string("  volatile ") + reg_type(s) + " sh_nan = NAN;\n";
      result = choose("b == 0", "(" + t + ")sh_nan", result, s);
    }
    return helper("sh_mod_" + t, t,
                  "(" + t + " a, " + t + " b) {\n" + nan + "  " + t + " r = " + (fp ? lane_by_lane("fmod", {"a", "b"}, s) : "a % b") +
                      ";\n  return " + result + ";\n}\n");
  }
  std::string round_half_up(ir::Scalar s) const {
    std::string t = vec(reg_type(s));
    return helper("sh_round_" + t, t,
                  "(" + t + " a) {\n  " + t + " f = floor(a);\n  return " + choose("a - f >= " + number(s, 0.5), "f + 1", "f", s) +
                      ";\n}\n");
  }
  // The bits of every lane or-ed together, halving the vector each step:
  // PoCL's any() and all() take the lanes out one at a time.
  std::string bits_or(const std::string& scalar) const {
    std::string body = "(" + vec(scalar) + " m) {\n";
    std::string from = "m";
    for (int n = lanes_ / 2; n >= 1; n /= 2) {
      std::string to = "m" + std::to_string(n);
      body += "  const " + (n > 1 ? scalar + std::to_string(n) : scalar) + " " + to + " = " + from + ".lo | " + from + ".hi;\n";
      from = to;
    }
    return helper("sh_or_" + vec(scalar), scalar, body + "  return " + from + ";\n}\n");
  }
  // The index every running lane holds, or -1 where they differ or none
  // runs (indices are never negative): lanes that walk a tree together
  // (any_lane) read one node, one load and a broadcast instead of a gather.
  std::string same_index() const {
    std::string t = index_type_, body = "(" + vec(t) + " at, " + vec("int") + " run) {\n";
    std::string mask = t == "int" ? "run" : "convert_" + vec(t) + "(run)";
    body += "  const " + vec(t) + " low" + std::to_string(lanes_) + " = select((" + vec(t) + ")(" + (t == "int" ? "INT_MAX" : "LONG_MAX") +
            "), at, " + mask + "), high" + std::to_string(lanes_) + " = select((" + vec(t) + ")(-1), at, " + mask + ");\n";
    for (int n = lanes_ / 2; n >= 1; n /= 2) {
      std::string type = n > 1 ? t + std::to_string(n) : t, from = std::to_string(n * 2), to = std::to_string(n);
      body += "  const " + type + " low" + to + " = min(low" + from + ".lo, low" + from + ".hi), high" + to + " = max(high" + from +
              ".lo, high" + from + ".hi);\n";
    }
    return helper("sh_same_" + vec(t), t, body + "  return low1 == high1 ? low1 : -1;\n}\n");
  }
  // Whether a mask has a lane set.
  std::string any(const std::string& mask) const { return "(" + bits_or("int") + "(" + mask + ") != 0)"; }
  // The first lane set in a mask (the last lane where none is).
  std::string first_lane() const {
    std::string n = std::to_string(lanes_);
    return helper("sh_first_lane" + n, "int",
                  "(" + vec("int") + " m) {\n  int l[" + n + "];\n  vstore" + n + "(m, 0, l);\n  int k = 0;\n  while (k < " +
                      std::to_string(lanes_ - 1) + " && !l[k]) ++k;\n  return k;\n}\n");
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
  ir::Scalar scalar_of(ir::VarId v) const { return p_.type_of(v).scalar; }

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

  // An operand's component; in the SPMD form constants, uniforms and
  // scalar registers are broadcast, so that every built-in sees vectors.
  std::string read(const ir::Operand& o, int i) const {
    int c = o.component(i);
    const ir::Var& v = p_.var(o.var);
    if (v.kind == ir::VarKind::Const) return constant(v.type.scalar, v.value[c]);
    if (truth_[o.var]) return "select(" + constant(v.type.scalar, 0) + ", " + constant(v.type.scalar, 1) + ", " + reg(o.var, c) + ")";
    if (spmd() && (v.kind == ir::VarKind::Uniform || scalar_register(o.var)))
      return "((" + vec(reg_type(v.type.scalar)) + ")" + reg(o.var, c) + ")";
    return reg(o.var, c);
  }

  // An operand's component as a move or a choice writes it.  PoCL's LLVM 15
  // rewrites `x > 0 ? 0 : x` as `x >= 0 ? 0 : x` (llvm-project issue
  // 57357), which gives +0 where x is -0; a float zero written is therefore
  // one the compiler cannot see, read once from a volatile, and the rewrite
  // never matches.  Arithmetic keeps the constant.
  std::string written(const ir::Operand& o, int i) const {
    const ir::Var& v = p_.var(o.var);
    double x = v.value[o.component(i)];
    if (v.kind != ir::VarKind::Const || !ir::is_float(v.type.scalar) || x != 0) return read(o, i);
    bool is_double = std::string(reg_type(v.type.scalar)) == "double";
    (is_double ? uses_zero_double_ : uses_zero_float_) = true;
    std::string zero = std::string(std::signbit(x) ? "-" : "") + (is_double ? "sh_zero_d" : "sh_zero_f");
    return spmd() ? "((" + vec(reg_type(v.type.scalar)) + ")(" + zero + "))" : "(" + zero + ")";
  }

  // An operand's component as a mask of its comparison's type: true where
  // it is > 0.
  std::string mask_of(const ir::Operand& o, int i) const {
    if (truth_[o.var]) return reg(o.var, o.component(i));
    return "(" + read(o, i) + " > " + constant(p_.type_of(o.var).scalar, 0) + ")";
  }

  void line(int depth, const std::string& text) { body_ << std::string(2 * depth, ' ') << text << "\n"; }

  // ---- signature, registers, inputs, outputs -----------------------------------

  // Streams are restrict: no two of a run's buffers overlap (an in-out
  // channel is copied, backend.cpp; channels over partly overlapping host
  // memory are outside what buffers over host memory allow anyway), so the
  // compiler may keep an input's loads ahead of an output's stores.  Tables
  // may share a channel's memory, and are only const.
  void signature(std::ostringstream& out) {
    for (std::size_t i = 0; i < p_.inputs.size(); ++i)
      out << ",\n    __global const " << storage_type(scalar_of(p_.inputs[i])) << "* restrict in" << i;
    for (std::size_t o = 0; o < p_.outputs.size(); ++o)
      out << ",\n    __global " << storage_type(scalar_of(p_.outputs[o])) << "* restrict out" << o;
    for (ir::VarId u : p_.uniforms)
      for (int c = 0; c < p_.type_of(u).width; ++c) out << ",\n    const " << reg_type(scalar_of(u)) << " " << reg(u, c);
    for (std::size_t t = 0; t < p_.tables.size(); ++t)
      out << ",\n    __global " << (p_.tables[t].accumulator ? "volatile " : "const ") << storage_type(p_.tables[t].element.scalar)
          << "* table" << t << ", const int table" << t << "_x, const int table" << t << "_y, const int table" << t << "_z";
    out << ",\n    __global long* status";
  }

  void registers() {
    for (std::size_t v = 0; v < p_.vars.size(); ++v) {
      const ir::Var& var = p_.vars[v];
      if (var.kind == ir::VarKind::Const || var.kind == ir::VarKind::Uniform) continue;
      if (var.kind == ir::VarKind::Array) {
        array_registers(static_cast<ir::VarId>(v));
        continue;
      }
      const char* type = truth_[v] ? mask_type(var.type.scalar) : reg_type(var.type.scalar);
      std::string decl = "  " + (scalar_register(static_cast<ir::VarId>(v)) ? std::string(type) : vec(type));
      for (int c = 0; c < var.type.width; ++c) decl += (c ? ", " : " ") + reg(static_cast<ir::VarId>(v), c) + " = 0";
      body_ << decl << ";";
      if (!var.name.empty()) body_ << "  // " << var.name;
      body_ << "\n";
    }
  }

  // A local array: one private array per component, of vectors where its
  // lanes may differ (lane k's value in lane k), zero at the start.
  void array_registers(ir::VarId v) {
    const ir::Var& var = p_.var(v);
    std::string type = scalar_register(v) ? reg_type(var.type.scalar) : vec(reg_type(var.type.scalar));
    std::string n = std::to_string(var.length);
    for (int c = 0; c < var.type.width; ++c) {
      body_ << "  " << type << " " << reg(v, c) << "[" << n << "];";
      if (c == 0 && !var.name.empty()) body_ << "  // " << var.name;
      body_ << "\n  for (int k = 0; k < " << n << "; ++k) " << reg(v, c) << "[k] = (" << type << ")(0);\n";
    }
  }

  // Element k's component c of a stream `w` components wide: in the SPMD
  // form a one-component stream is a vector load or store, a wider one a
  // load or store per lane.
  std::string at(const std::string& stream, int w, int c, int k) const {
    return stream + "[(e + " + std::to_string(k) + ") * " + std::to_string(w) + " + " + std::to_string(c) + "]";
  }

  void load_inputs() {
    for (std::size_t i = 0; i < p_.inputs.size(); ++i) {
      ir::VarId v = p_.inputs[i];
      ir::Type t = p_.type_of(v);
      std::string in = "in" + std::to_string(i);
      for (int c = 0; c < t.width; ++c) {
        std::string value;
        if (!spmd()) {
          value = at(in, t.width, c, 0);
        } else if (t.width == 1) {
          value = "convert_" + vec(reg_type(t.scalar)) + "(" + run_load(storage_type(t.scalar)) + "(" + in + " + e))";
        } else {
          for (int k = 0; k < lanes_; ++k) value += (k ? ", " : "") + at(in, t.width, c, k);
          value = "(" + vec(reg_type(t.scalar)) + ")(" + value + ")";
        }
        line(1, reg(v, c) + " = " + value + ";");
      }
    }
  }

  void store_outputs() {
    for (std::size_t o = 0; o < p_.outputs.size(); ++o) {
      ir::VarId v = p_.outputs[o];
      ir::Type t = p_.type_of(v);
      std::string out = "out" + std::to_string(o);
      const char* stored = storage_type(t.scalar);
      for (int c = 0; c < t.width; ++c) {
        if (!spmd()) {
          line(1, at(out, t.width, c, 0) + " = (" + stored + ")" + reg(v, c) + ";");
        } else if (t.width == 1) {
          line(1, run_store(stored) + "(" + convert(stored, reg(v, c)) + ", " + out + " + e);");
        } else {
          for (int k = 0; k < lanes_; ++k)
            line(1, at(out, t.width, c, k) + " = (" + stored + ")" + reg(v, c) + lane(k) + ";");
        }
      }
    }
  }

  // ---- statements -----------------------------------------------------------------

  // In the SPMD form the rest of a block after a break or continue runs for
  // no lane, so it is not written.
  void block(const ir::Block& b, int depth) {
    for (const ir::Stmt& s : b) {
      if (auto* a = std::get_if<ir::Assign>(&s.node)) {
        assign(*a, depth);
      } else if (auto* i = std::get_if<ir::If>(&s.node)) {
        divergent(s) ? masked_branch(*i, s, depth) : branch(*i, depth);
      } else if (auto* l = std::get_if<ir::Loop>(&s.node)) {
        divergent(s) ? masked_loop(*l, s, depth) : loop(*l, s, depth);
      } else if (auto* sc = std::get_if<ir::Scatter>(&s.node)) {
        scatter(*sc, depth);
      } else {
        leave(std::holds_alternative<ir::Break>(s.node), depth);
        return;
      }
    }
  }

  // A masked loop's breaking lanes leave it for good and its continuing
  // lanes come back at the update; a branching loop is left with C's jumps.
  void leave(bool is_break, int depth) {
    const LoopExit& l = exits_.back();
    if (!l.active.empty()) {
      if (is_break) line(depth, l.active + " &= ~exec;");
      line(depth, "exec = 0;");
    } else if (is_break) {
      line(depth, l.wrapped ? "{ " + l.flag + " = 1; break; }" : "break;");
    } else {
      line(depth, "continue;");
    }
  }

  // A branch's condition: the SPMD form branches only where the running
  // lanes agree, on a scalar register or a uniform.
  std::string truthy(const ir::Operand& o) const {
    const ir::Var& v = p_.var(o.var);
    int c = o.swizzle[0];
    if (v.kind == ir::VarKind::Const) return "(" + number(v.type.scalar, v.value[c]) + " > 0)";
    if (truth_[o.var]) return "(" + reg(o.var, c) + ".s0 != 0)";
    return "(" + reg(o.var, c) + (spmd() && v.kind != ir::VarKind::Uniform && !scalar_register(o.var) ? ".s0" : "") + " > 0)";
  }
  std::string lanes_where(const ir::Operand& o) const { return exec_mask(mask_of(o, 0)); }
  // The lanes where a comparison holds, as a mask of the exec mask's type.
  std::string exec_mask(const std::string& comparison) const { return "convert_" + vec("int") + "(" + comparison + ")"; }

  void branch(const ir::If& s, int depth) {
    line(depth, "if " + truthy(s.cond) + " {");
    block(s.then_body, depth + 1);
    if (!s.else_body.empty()) {
      line(depth, "} else {");
      block(s.else_body, depth + 1);
    }
    line(depth, "}");
  }

  // Each side runs under its share of the lanes, and only when that share
  // has one; afterwards the lanes that finished either side go on (those
  // that broke or continued inside it do not).
  void masked_branch(const ir::If& s, const ir::Stmt& at, int depth) {
    std::string n = std::to_string(branches_++), before = "before" + n, taken = "taken" + n, done = "done" + n;
    std::string mask = vec("int");
    line(depth, "{");
    line(depth + 1, "const " + mask + " " + before + " = exec, " + taken + " = " + lanes_where(s.cond) + ";");
    line(depth + 1, "exec = " + before + " & " + taken + ";");
    side(s.then_body, facts_.live_during_then.at(&at), depth + 1);
    line(depth + 1, "const " + mask + " " + done + " = exec;");
    line(depth + 1, "exec = " + before + " & ~" + taken + ";");
    side(s.else_body, facts_.live_at_rejoin.at(&at), depth + 1);
    line(depth + 1, "exec |= " + done + ";");
    line(depth, "}");
  }

  void side(const ir::Block& body, const analysis::VarSet& live, int depth) {
    if (body.empty()) return;
    line(depth, "if (" + any("exec") + ") {");
    enter_masked(live);
    block(body, depth + 1);
    keep_.pop_back();
    line(depth, "}");
  }

  // Under a mask, a write to a variable live where the waiting lanes
  // rejoin keeps their values; any other write is dead for them.
  void enter_masked(const analysis::VarSet& live) {
    analysis::VarSet keep = live;
    if (!keep_.empty())
      for (std::size_t v = 0; v < keep.size(); ++v) keep[v] = keep[v] || keep_.back()[v];
    keep_.push_back(std::move(keep));
  }
  bool masked() const { return !keep_.empty(); }

  // Past the iteration cap the kernel stops and reports the loop and the
  // element (in the SPMD form, the first lane still looping).
  void count_iteration(int number, const std::string& counter, const std::string& element, int depth) {
    line(depth, "if (++" + counter + " > " + std::to_string(o_.max_loop_iterations) + "L) { if (status[0] == 0) { status[0] = " +
                    std::to_string(number + 1) + "; status[1] = " + element + "; } return; }");
  }

  // for (;;) { count; [header; test]; body; update; [header; test] }.  A
  // body with `continue` runs inside do { } while (0), where `continue`
  // reaches the update and `break` needs a flag to leave the loop.
  // A branching loop inside masked code runs for the lanes running there,
  // which agree on its test; every one of them may have left already (a
  // break under a uniform if empties exec and goes on): then it is
  // skipped, as its test would be on values no lane holds.
  void loop(const ir::Loop& l, const ir::Stmt& s, int depth) {
    if (!masked()) return branching_loop(l, s, depth, "e");
    line(depth, "if " + any("exec") + " {");
    branching_loop(l, s, depth + 1, "e + " + first_lane() + "(exec)");
    line(depth, "}");
  }

  void branching_loop(const ir::Loop& l, const ir::Stmt& s, int depth, const std::string& element) {
    int number = loops_++;
    std::string n = std::to_string(number), counter = "iterations" + n, flag = "leave" + n;
    bool wrapped = analysis::continues(l.body);
    line(depth, "// " + ir::print(p_, s));
    line(depth, "long " + counter + " = 0;");
    if (wrapped) line(depth, "int " + flag + " = 0;");
    line(depth, "for (;;) {");
    count_iteration(number, counter, element, depth + 1);
    auto test = [&] {
      block(l.header, depth + 1);
      line(depth + 1, "if (!" + truthy(l.cond) + ") break;");
    };
    if (l.test_at_top) test();
    exits_.push_back({"", wrapped, flag});
    if (wrapped) {
      line(depth + 1, "do {");
      block(l.body, depth + 2);
      line(depth + 1, "} while (0);");
      line(depth + 1, "if (" + flag + ") break;");
    } else {
      block(l.body, depth + 1);
    }
    exits_.pop_back();
    block(l.update, depth + 1);
    if (!l.test_at_top) test();
    line(depth, "}");
  }

  // The same loop while any lane loops: the test retires the lanes whose
  // condition failed, every part runs for the lanes still looping, and
  // every lane that entered leaves at the end.
  void masked_loop(const ir::Loop& l, const ir::Stmt& s, int depth) {
    int number = loops_++;
    std::string n = std::to_string(number), counter = "iterations" + n, active = "active" + n, entered = "entered" + n;
    std::string mask = vec("int");
    line(depth, "// " + ir::print(p_, s));
    line(depth, "{");
    line(depth + 1, "const " + mask + " " + entered + " = exec;");
    line(depth + 1, mask + " " + active + " = exec;");
    line(depth + 1, "long " + counter + " = 0;");
    line(depth + 1, "for (;;) {");
    enter_masked(facts_.live_at_rejoin.at(&s));
    count_iteration(number, counter, "e + " + first_lane() + "(" + active + ")", depth + 2);
    auto test = [&] {
      line(depth + 2, "exec = " + active + ";");
      block(l.header, depth + 2);
      line(depth + 2, active + " &= " + lanes_where(l.cond) + ";");
      line(depth + 2, "if (!" + any(active) + ") break;");
    };
    if (l.test_at_top) test();
    line(depth + 2, "exec = " + active + ";");
    exits_.push_back({active, false, ""});
    block(l.body, depth + 2);
    exits_.pop_back();
    line(depth + 2, "exec = " + active + ";");
    block(l.update, depth + 2);
    if (!l.test_at_top) test();
    keep_.pop_back();
    line(depth + 1, "}");
    line(depth + 1, "exec = " + entered + ";");
    line(depth, "}");
  }

  // ---- assignments -------------------------------------------------------------------

  // A scalar register's value is computed in the scalar form: its operands
  // are scalar registers, uniforms and constants too (any varying operand
  // makes it varying, but for a vote across lanes), and no lane that may
  // read it keeps an older value, so a mask never guards its write.
  void assign(const ir::Assign& a, int depth) {
    if (!scalar_register(a.dest)) return assign_in_form(a, depth);
    if (a.op == ir::Op::AnyLane) return vote_once(a, depth);
    int lanes = lanes_;
    lanes_ = 1;
    assign_in_form(a, depth);
    lanes_ = lanes;
  }

  // A vote into a scalar register: the lanes' tests, one answer.
  void vote_once(const ir::Assign& a, int depth) {
    ir::Scalar to = scalar_of(a.dest);
    for (int i = 0; i < a.mask.size; ++i)
      line(depth, reg(a.dest, a.mask[i]) + " = " + voted(mask_of(a.args[0], i)) + " ? " + number(to, 1) + " : " +
                      number(to, 0) + ";");
  }

  void assign_in_form(const ir::Assign& a, int depth) {
    std::string results[4];
    ir::Scalar to = scalar_of(a.dest);
    if (a.op == ir::Op::Store) return array_store(a, depth);
    if (a.op == ir::Op::Fill) return array_fill(a, depth);
    if (a.op == ir::Op::Element) {
      array_element(a, results);
    } else if (ir::is_table_read(a.op)) {
      table_read(a, results, depth);
    } else if (truth_[a.dest]) {
      for (int i = 0; i < a.mask.size; ++i) results[i] = truth_test(a, i);
    } else if (a.op == ir::Op::Position) {
      for (int i = 0; i < a.mask.size; ++i) results[i] = std::string("position_") + kComponent[i];
    } else {
      ir::Scalar from = scalar_of(a.args[0].var);
      for (int i = 0; i < a.mask.size; ++i) {
        std::string x[3];
        for (std::size_t k = 0; k < a.args.size(); ++k)
          x[k] = a.op == ir::Op::Mov || (a.op == ir::Op::Cond && k > 0) ? written(a.args[k], i) : read(a.args[k], i);
        results[i] = operation(a.op, from, to, x[0], x[1], x[2]);
      }
    }
    // Under a mask, lanes that do not run the statement keep their values.
    auto write = [&](ir::VarId v, int c, const std::string& value) {
      std::string r = reg(v, c);
      if (!masked() || !varying(v) || !keep_.back()[v]) return r + " = " + value + ";";
      return r + " = select(" + r + ", " + value + ", " + exec_for(to) + ");";
    };
    // All components are computed before any is written (v.xy = v.yx).
    if (a.mask.size == 1) {
      line(depth, write(a.dest, a.mask[0], results[0]));
      return;
    }
    std::string t = vec(truth_[a.dest] ? mask_type(to) : reg_type(to));
    line(depth, "{");
    for (int i = 0; i < a.mask.size; ++i) line(depth + 1, t + " r" + std::to_string(i) + " = " + results[i] + ";");
    for (int i = 0; i < a.mask.size; ++i) line(depth + 1, write(a.dest, a.mask[i], "r" + std::to_string(i)));
    line(depth, "}");
  }

  // One case per row of the op table (ops.def), no default: a new
  // operation does not build until it is generated here.  Signed overflow
  // is undefined in OpenCL C, so wrapping integer arithmetic goes through
  // uint.
  std::string operation(ir::Op op, ir::Scalar from, ir::Scalar to, const std::string& a, const std::string& b,
                        const std::string& c) const {
    using ir::Op;
    const bool fp = ir::is_float(from);
    auto pos = [&](const std::string& x) { return "(" + x + " > 0)"; };
    auto call = [](const char* f, const std::string& x) { return std::string(f) + "(" + x + ")"; };
    auto call2 = [](const char* f, const std::string& x, const std::string& y) {
      return std::string(f) + "(" + x + ", " + y + ")";
    };
    auto uint = [&](const std::string& x) { return bits_as("uint", x); };
    auto wrap = [&](const char* sym) { return bits_as("int", uint(a) + " " + sym + " " + uint(b)); };
    std::string one = constant(from, 1.0);
    switch (op) {
      case Op::Mov: return a;
      case Op::Cast: return cast(a, from, to);
      case Op::Add: return fp ? a + " + " + b : wrap("+");
      case Op::Sub: return fp ? a + " - " + b : wrap("-");
      case Op::Mul: return fp ? a + " * " + b : wrap("*");
      // Legal IR divides integers only by divisors that cannot trap.
      case Op::Div: return a + " / " + b;
      case Op::Mod: return floor_remainder(from) + "(" + a + ", " + b + ")";
      case Op::Neg: return fp ? "-" + a : bits_as("int", "0u - " + uint(a));
      case Op::Min: return call2(fp ? "fmin" : "min", a, b);
      case Op::Max: return call2(fp ? "fmax" : "max", a, b);
      // In uint: abs(INT_MIN) wraps to INT_MIN, where PoCL's abs assumes a
      // result that is not negative.
      case Op::Abs: return fp ? call("fabs", a) : bits_as("int", choose(a + " < 0", "0u - " + uint(a), uint(a), from));
      case Op::Sign:
        if (fp) return choose(a + " > 0", one, choose(a + " < 0", "-" + one, a, from), from);
        return choose(a + " > 0", one, choose(a + " < 0", constant(from, -1), constant(from, 0), from), from);
      case Op::Floor: return call("floor", a);
      case Op::Ceil: return call("ceil", a);
      case Op::Round: return round_half_up(from) + "(" + a + ")";
      case Op::Sqrt: return call("sqrt", a);
      case Op::Rsqrt: return one + " / sqrt(" + a + ")";
      case Op::Rcp: return one + " / " + a;
      case Op::Pow: return lane_by_lane("pow", {a, b}, from);
      case Op::Exp: return nan_through("exp", a, from);
      case Op::Exp2: return nan_through("exp2", a, from);
      case Op::Log: return call("log", a);
      case Op::Log2: return call("log2", a);
      case Op::Sin: return lane_by_lane("sin", {a}, from);
      case Op::Cos: return lane_by_lane("cos", {a}, from);
      case Op::Tan: return lane_by_lane("tan", {a}, from);
      case Op::Asin: return call("asin", a);
      case Op::Acos: return call("acos", a);
      case Op::Atan: return call("atan", a);
      case Op::Atan2: return call2("atan2", a, b);
      case Op::Sinh: return call("sinh", a);
      case Op::Cosh: return call("cosh", a);
      case Op::Tanh: return nan_through("tanh", a, from);
      case Op::Asinh: return call("asinh", a);
      case Op::Acosh: return call("acosh", a);
      case Op::Atanh: return call("atanh", a);
      case Op::Exp10: return nan_through("exp10", a, from);
      case Op::Log10: return call("log10", a);
      case Op::Cbrt: return call("cbrt", a);
      case Op::BitAnd: return "(" + a + " & " + b + ")";
      case Op::BitOr: return "(" + a + " | " + b + ")";
      case Op::BitXor: return "(" + a + " ^ " + b + ")";
      case Op::BitNot: return "(~" + a + ")";
      // Legal IR shifts by counts in [0, 31] only; a left shift into the
      // sign bit is defined on uint.
      case Op::Shl: return bits_as("int", uint(a) + " << " + uint(b));
      case Op::Shr: return "(" + a + " >> " + b + ")";
      case Op::Lt: case Op::Le: case Op::Gt: case Op::Ge: case Op::Eq: case Op::Ne: return bit(compare(op, a, b), to);
      case Op::And: return bit(pos(a) + " && " + pos(b), to);
      case Op::Or: return bit(pos(a) + " || " + pos(b), to);
      case Op::Not: return bit("!" + pos(a), to);
      case Op::Cond: return choose(pos(a), b, c, to);
      // The scalar form's work-item is its own group: OpenCL 1.2 has no
      // vote across work-items outside a barrier, which divergent code
      // cannot take.  The SPMD form votes over the lanes running.
      case Op::AnyLane:
        if (!spmd()) return bit(pos(a), to);
        return "((" + vec(reg_type(to)) + ")(" + voted(pos(a)) + " ? " + number(to, 1) + " : " + number(to, 0) + "))";
      case Op::Extent: case Op::Load: break;   // table_read()
      case Op::Position: break;                 // assign()
      case Op::Element: case Op::Store: case Op::Fill: break;  // array_element(), array_store(), array_fill()
      case Op::Fetch: case Op::Sample: break;  // not legal IR: generate() refuses it
    }
    throw Error(std::string("opencl backend: ") + ir::op_name(op) + " reached the arithmetic generator");
  }

  // Whether `test` holds in a running lane: a vote across the lanes.
  std::string voted(const std::string& test) const { return any("(" + exec_mask(test) + " & exec)"); }

  // A truth register's component (truth_registers) as a mask.
  std::string truth_test(const ir::Assign& a, int i) const {
    using ir::Op;
    auto m = [&](int k) { return mask_of(a.args[k], i); };
    if (a.op == Op::And || a.op == Op::Min) return "(" + m(0) + " & " + m(1) + ")";
    if (a.op == Op::Or || a.op == Op::Max) return "(" + m(0) + " | " + m(1) + ")";
    if (a.op == Op::Not) return "(~" + m(0) + ")";
    if (a.op == Op::Mov) return m(0);
    std::string mask = vec(mask_type(scalar_of(a.dest)));
    if (a.op == Op::Cast) {
      ir::Scalar from = scalar_of(a.args[0].var);
      return std::string(mask_type(from)) == mask_type(scalar_of(a.dest)) ? m(0) : "convert_" + mask + "(" + m(0) + ")";
    }
    if (a.op == Op::AnyLane) return "((" + mask + ")(" + voted(m(0)) + " ? -1 : 0))";
    return compare(a.op, read(a.args[0], i), read(a.args[1], i));
  }

  static std::string compare(ir::Op op, const std::string& a, const std::string& b) {
    using ir::Op;
    constexpr std::array<std::pair<Op, const char*>, 6> kSymbols = {
        {{Op::Lt, "<"}, {Op::Le, "<="}, {Op::Gt, ">"}, {Op::Ge, ">="}, {Op::Eq, "=="}, {Op::Ne, "!="}}};
    auto s = std::find_if(kSymbols.begin(), kSymbols.end(), [&](const auto& e) { return e.first == op; });
    return "(" + a + " " + s->second + " " + b + ")";
  }

  // PoCL's vector forms (3.1) of float sin, cos and tan and of double fmod
  // and pow lose lanes when another lane is denormal or large; its scalar
  // forms are right, so those vectors take them lane by lane.
  std::string lane_by_lane(const std::string& f, const std::vector<std::string>& args, ir::Scalar s) const {
    std::string type = reg_type(s);
    bool trig = f == "sin" || f == "cos" || f == "tan";
    auto call = [&](const std::string& part) {
      std::string text = f + "(";
      for (std::size_t i = 0; i < args.size(); ++i) text += (i ? ", " : "") + args[i] + part;
      return text + ")";
    };
    if (!spmd() || type != (trig ? "float" : "double")) return call("");
    std::string lanes;
    for (int k = 0; k < lanes_; ++k) lanes += (k ? ", " : "") + call(lane(k));
    return "(" + vec(type) + ")(" + lanes + ")";
  }

  // Whether `a` is NaN, told by its bits: PoCL folds a float isnan() of a
  // NaN it can see at compile time wrongly, as it does the built-ins below.
  std::string is_nan(const std::string& a, ir::Scalar s) const {
    return std::string(reg_type(s)) == "double" ? "(" + bits_as("ulong", a) + " & 0x7fffffffffffffffUL) > 0x7ff0000000000000UL"
                                                : "(" + bits_as("uint", a) + " & 0x7fffffffU) > 0x7f800000U";
  }

  // NaN gives 0: PoCL's convert_int_sat of a NaN it can see at compile time
  // is undefined, so the store of it vanished.
  std::string float_to_int(const std::string& a, ir::Scalar from) const {
    return choose(is_nan(a, from), constant(ir::Scalar::I32, 0), "convert_" + vec("int") + "_sat(" + a + ")", ir::Scalar::I32);
  }

  // f(a), with a NaN passed through untouched: PoCL's exp, exp2, exp10 and
  // tanh (3.1) turn a NaN they can see at compile time (one its compiler
  // worked out from constants, such as the remainder of inf) into an
  // undefined value, and the store of the result vanished.
  std::string nan_through(const std::string& f, const std::string& a, ir::Scalar s) const {
    std::string t = vec(reg_type(s));
    return helper("sh_" + f + "_" + t, t, "(" + t + " a) {\n  return " + choose(is_nan("a", s), "a", f + "(a)", s) + ";\n}\n") +
           "(" + a + ")";
  }

  std::string cast(const std::string& a, ir::Scalar from, ir::Scalar to) const {
    if (to == ir::Scalar::Bool) return bit("(" + a + " > 0)", to);
    if (to == ir::Scalar::I32) return ir::is_float(from) ? float_to_int(a, from) : a;
    return convert(reg_type(to), a);
  }

  // The element a read or scatter names (coordinates in range: legal IR).
  std::string flat_index(int table, const ir::Operand& coord) const {
    std::string name = "table" + std::to_string(table);
    std::string index, stride = "1";
    for (int d = 0; d < p_.tables[table].rank; ++d) {
      std::string dim = name + "_" + kComponent[d];
      std::string i = convert(index_type_, read(coord, d));
      index += (d ? " + " : "") + i + (d ? " * " + stride : "");
      stride = d ? stride + " * " + dim : std::string("(") + index_type_ + ")" + dim;
    }
    return "(" + index + ") * " + std::to_string(p_.tables[table].element.width);
  }

  // In the SPMD form a read into a scalar register is the scalar form's one
  // load (assign); any other is one load per lane.  Where the table access
  // analysis hints that the lanes read one element, or consecutive elements
  // of a one-component table, a test of the lanes' places takes one load
  // and a broadcast, or a vector load, instead.
  void table_read(const ir::Assign& a, std::string* results, int depth) {
    const ir::TableDecl& t = p_.tables[a.table];
    std::string name = "table" + std::to_string(a.table);
    const char* element = reg_type(t.element.scalar);
    if (a.op == ir::Op::Extent) {
      for (int d = 0; d < t.rank; ++d) results[d] = spmd() ? "((" + vec("int") + ")" + name + "_" + kComponent[d] + ")" : name + "_" + kComponent[d];
      return;
    }
    if (taps_inside_ && access_.at(&a).offset) {
      for (int c = 0; c < t.element.width; ++c) results[c] = "convert_" + vec(element) + "(" + tap(a, c) + ")";
      return;
    }
    std::string index = flat_index(a.table, a.args[0]);
    if (!spmd()) {
      for (int c = 0; c < t.element.width; ++c)
        results[c] = std::string("(") + element + ")" + name + "[" + index + " + " + std::to_string(c) + "]";
      return;
    }
    std::string n = std::to_string(reads_++), at = "at" + n, stored = vec(storage_type(t.element.scalar));
    line(depth, "const " + vec(index_type_) + " " + at + " = " + index + ";");
    auto component = [&](int c) { return " + " + std::to_string(c); };
    // Every lane loads, those not running too: legal IR's coordinates lie
    // inside the table in every lane (each a clamp or wrap computed in all
    // lanes, or the 0 a register starts at, and a table has at least one
    // element a dimension), and a load per lane without a test is cheaper
    // than one behind it.
    auto gather = [&](int c) {
      std::string lanes;
      for (int k = 0; k < lanes_; ++k) lanes += (k ? ", " : "") + name + "[" + at + lane(k) + component(c) + "]";
      return "(" + stored + ")(" + lanes + ")";
    };
    bool consecutive = access_.at(&a).hint == analysis::Access::Consecutive;
    std::string test, read = "read" + n + "_", lead = "lead" + n;
    if (consecutive && t.element.width == 1) {
      test = "!" + bits_or(index_type_) + "(" + at + " ^ (" + at + ".s0 + " + iota(index_type_) + "))";
    } else if (!consecutive) {
      line(depth, std::string("const ") + index_type_ + " " + lead + " = " + same_index() + "(" + at + ", exec);");
      test = lead + " >= 0";
    }
    auto fast = [&](int c) {
      if (!consecutive) return "(" + stored + ")(" + name + "[" + lead + component(c) + "])";
      return run_load(storage_type(t.element.scalar)) + "(" + name + " + " + at + ".s0)";
    };
    for (int c = 0; c < t.element.width; ++c) {
      line(depth, stored + " " + read + std::to_string(c) + ";");
      results[c] = "convert_" + vec(element) + "(" + read + std::to_string(c) + ")";
    }
    // A branch, not a choice: both sides of a choice would run.
    if (!test.empty()) line(depth, "if (" + test + ") {");
    for (int c = 0; !test.empty() && c < t.element.width; ++c) line(depth + 1, read + std::to_string(c) + " = " + fast(c) + ";");
    if (!test.empty()) line(depth, "} else {");
    for (int c = 0; c < t.element.width; ++c) line(depth + !test.empty(), read + std::to_string(c) + " = " + gather(c) + ";");
    if (!test.empty()) line(depth, "}");
  }

  // ---- local arrays ------------------------------------------------------------

  // An array index as C indexes with it: lane k's in the SPMD form where
  // the lanes' indices may differ, else the one scalar.
  std::string index_of(const ir::Operand& o, int k) const {
    const ir::Var& v = p_.var(o.var);
    if (v.kind == ir::VarKind::Const) return number(ir::Scalar::I32, v.value[o.component(0)]);
    std::string r = reg(o.var, o.component(0));
    return spmd() && varying(o.var) ? r + lane(k) : r;
  }

  // Legal IR indexes in range.  A uniform index reads one element (a
  // vector of lanes in a varying array); indices that differ, each lane's
  // own.
  void array_element(const ir::Assign& a, std::string* results) {
    ir::VarId array = a.args[0].var;
    bool by_lane = spmd() && varying(a.args[1].var);
    for (int c = 0; c < a.mask.size; ++c) {
      std::string name = reg(array, c);
      if (!by_lane) {
        std::string one = name + "[" + index_of(a.args[1], 0) + "]";
        results[c] = spmd() && scalar_register(array) ? "((" + vec(reg_type(scalar_of(array))) + ")" + one + ")" : one;
        continue;
      }
      std::string list;
      for (int k = 0; k < lanes_; ++k)
        list += (k ? ", " : "") + name + "[" + index_of(a.args[1], k) + "]" + (scalar_register(array) ? "" : lane(k));
      results[c] = "((" + vec(reg_type(scalar_of(array))) + ")(" + list + "))";
    }
  }

  // Under a mask only the running lanes store.  A uniform array (a scalar
  // register's form) is stored where the lanes running agree.
  void array_store(const ir::Assign& a, int depth) {
    ir::VarId array = a.dest;
    bool by_lane = spmd() && varying(a.args[0].var);
    for (int c = 0; c < a.mask.size; ++c) {
      std::string name = reg(array, c), value = read(a.args[1], c);
      if (!by_lane) {
        std::string place = name + "[" + index_of(a.args[0], 0) + "]";
        if (spmd() && masked()) value = "select(" + place + ", " + value + ", " + exec_for(scalar_of(array)) + ")";
        line(depth, place + " = " + value + ";");
        continue;
      }
      line(depth, "{");
      line(depth + 1, "const " + vec(reg_type(scalar_of(array))) + " value = " + value + ";");
      for (int k = 0; k < lanes_; ++k)
        line(depth + 1, std::string(masked() ? "if (exec" + lane(k) + ") " : "") + name + "[" + index_of(a.args[0], k) +
                            "]" + lane(k) + " = value" + lane(k) + ";");
      line(depth, "}");
    }
  }

  // Every element; under a mask only the running lanes'.
  void array_fill(const ir::Assign& a, int depth) {
    ir::VarId array = a.dest;
    std::string n = std::to_string(p_.var(array).length);
    for (int c = 0; c < a.mask.size; ++c) {
      std::string place = reg(array, c) + "[k]", value = read(a.args[0], c);
      if (spmd() && masked()) value = "select(" + place + ", " + value + ", " + exec_for(scalar_of(array)) + ")";
      line(depth, "for (int k = 0; k < " + n + "; ++k) " + place + " = " + value + ";");
    }
  }

  // The exec mask as a select between values of scalar `s` takes it.
  std::string exec_for(ir::Scalar s) const { return std::string(mask_type(s)) == "int" ? "exec" : convert("long", "exec"); }

  // OpenCL 1.2 adds ints atomically; floats by compare-and-swap on their
  // bits.  The SPMD form adds lane by lane, for the lanes running.
  void scatter(const ir::Scatter& sc, int depth) {
    const ir::TableDecl& t = p_.tables[sc.table];
    bool is_float = ir::is_float(t.element.scalar);
    const char* add = is_float ? "sh_atomic_add_float(" : "atomic_add(";
    std::string stored = storage_type(t.element.scalar), table = "table" + std::to_string(sc.table);
    line(depth, "{");
    line(depth + 1, "const " + vec(index_type_) + " at = " + flat_index(sc.table, sc.index) + ";");
    for (int c = 0; c < t.element.width; ++c) {
      std::string value = "value" + std::to_string(c);
      line(depth + 1, "const " + vec(reg_type(t.element.scalar)) + " " + value + " = " + read(sc.value, c) + ";");
      if (!spmd()) {
        line(depth + 1, add + table + " + at + " + std::to_string(c) + ", (" + stored + ")" + value + ");");
        continue;
      }
      for (int k = 0; k < lanes_; ++k)
        line(depth + 1, "if (exec" + lane(k) + ") " + add + table + " + at" + lane(k) + " + " + std::to_string(c) + ", (" +
                            stored + ")" + value + lane(k) + ");");
    }
    line(depth, "}");
  }

  // A masked loop's active mask, or how a branching loop is left.
  struct LoopExit {
    std::string active;
    bool wrapped;
    std::string flag;
  };

  const ir::Program& p_;
  const sh::Options& o_;
  int lanes_;  // 1 while a scalar register's value is written (assign)
  // Table elements are numbered in int where no buffer the device allows
  // holds more than INT_MAX of them (every element is 4 bytes or more): a
  // CPU device's gathers then take 32-bit indices, twice the lanes of
  // 64-bit ones a gather instruction.
  const char* index_type_;
  Prelude& prelude_;
  std::unordered_map<const ir::Assign*, analysis::ReadAccess> access_;
  std::ostringstream body_;
  mutable bool uses_nan_float_ = false, uses_nan_double_ = false, uses_zero_float_ = false, uses_zero_double_ = false;
  int loops_ = 0, branches_ = 0, reads_ = 0;
  analysis::SpmdFacts facts_;
  analysis::VarSet truth_;              // SPMD: registers held as masks (truth_registers)
  std::vector<analysis::VarSet> keep_;  // SPMD: per masked statement around, what a write keeps
  std::vector<LoopExit> exits_;         // how each loop around is left
  bool taps_inside_ = false;            // SPMD: writing the body for taps inside their tables
};

bool needs_fp64(const ir::Program& p, const sh::Options& o) {
  bool needs = o.precision == Precision::F64;
  for (const ir::Var& v : p.vars) needs = needs || v.type.scalar == ir::Scalar::F64;
  for (const ir::TableDecl& t : p.tables) needs = needs || t.element.scalar == ir::Scalar::F64;
  return needs;
}

bool adds_floats(const ir::Program& p) {
  for (const ir::TableDecl& t : p.tables)
    if (t.accumulator && ir::is_float(t.element.scalar)) return true;
  return false;
}

}  // namespace

Source generate(const ir::Program& program, const sh::Options& options, int lanes, std::uint64_t largest_buffer) {
  ir::verify_legal(program);
  Prelude prelude;
  std::string kernels = Generator(program, options, 1, largest_buffer, prelude).run(kKernelName);
  if (lanes > 1) kernels += Generator(program, options, lanes, largest_buffer, prelude).run(kLanesKernelName);
  bool fp64 = needs_fp64(program, options);
  std::ostringstream head;
  head << "// program " << program.name << ", generated from its optimised IR\n";
  if (fp64) head << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n";
  if (options.math == MathMode::Precise) head << "#pragma OPENCL FP_CONTRACT OFF\n";
  if (adds_floats(program)) head << kAtomicAddFloat;
  return Source{head.str() + prelude.text + kernels, fp64};
}

}  // namespace sh::opencl
