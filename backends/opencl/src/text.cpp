// The text that differs between the scalar and SPMD forms, the helper
// functions the source's prelude holds, and the types, names and operands
// the statements are written with.
#include "generator.hpp"

#include <charconv>
#include <cmath>

namespace sh::opencl {

std::string Generator::iota(const std::string& scalar) const {
  std::string list;
  for (int k = 0; k < lanes_; ++k) list += (k ? ", " : "") + std::to_string(k);
  return "(" + vec(scalar) + ")(" + list + ")";
}

// A 1 or 0 in the type of `s` from a C comparison (1/0 for scalars, -1/0
// for vectors).  One element a work-item: a choice of constants, not a
// conversion of the truth, which NVIDIA's OpenCL compiler (driver 580,
// an H100) got wrong: `(double)(a <= b)` gave 0 for a = b = -1 among the
// conformance suite's comparisons, right without its optimiser.
std::string Generator::bit(const std::string& comparison, ir::Scalar s) const {
  if (!spmd()) {
    std::string type = reg_type(s);
    return "((" + comparison + ") ? (" + type + ")1 : (" + type + ")0)";
  }
  return "convert_" + vec(reg_type(s)) + "(-(" + comparison + "))";
}

// yes where `comparison` holds, otherwise no, in the type of `s`.
std::string Generator::choose(const std::string& comparison, const std::string& yes, const std::string& no, ir::Scalar s) const {
  if (!spmd()) return "(" + comparison + " ? " + yes + " : " + no + ")";
  return "select(" + no + ", " + yes + ", convert_" + vec(mask_type(s)) + "(" + comparison + "))";
}

std::string Generator::convert(const char* type, const std::string& x) const {
  return spmd() ? "convert_" + vec(type) + "(" + x + ")" : std::string("(") + type + ")(" + x + ")";
}

std::string Generator::constant(ir::Scalar s, double v) const {
  std::string n = number(s, v);
  return spmd() ? "((" + vec(reg_type(s)) + ")(" + n + "))" : n;
}

// The constants read from volatiles, so that PoCL's compiler never sees
// them: NaN (given a NaN it knows, some of its built-ins, convert_int_sat
// and exp10, give an undefined value and the store of it disappears), and
// the zeros moves write (written()).
std::string Generator::hidden_constants() const {
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
std::string Generator::run_load(const std::string& element) const {
  std::string v = vec(element);
  return helper("sh_run_" + v, v, "(const __global " + element + "* p) {\n" + unaligned(element) +
                                      "  return *(const __global unaligned*)p;\n}\n");
}

std::string Generator::run_store(const std::string& element) const {
  std::string v = vec(element);
  return helper("sh_store_run_" + v, "void", "(" + v + " x, __global " + element + "* p) {\n" + unaligned(element) +
                                                 "  *(__global unaligned*)p = x;\n}\n");
}

std::string Generator::unaligned(const std::string& element) const {
  return "  typedef " + vec(element) + " unaligned __attribute__((aligned(sizeof(" + element + "))));\n";
}

// A helper function of the source, written once, before the kernels,
// the first time an operation needs it; returns its name.
std::string Generator::helper(const std::string& name, const std::string& returns, const std::string& rest) const {
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
std::string Generator::floor_remainder(ir::Scalar s) const {
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

std::string Generator::round_half_up(ir::Scalar s) const {
  std::string t = vec(reg_type(s));
  return helper("sh_round_" + t, t,
                "(" + t + " a) {\n  " + t + " f = floor(a);\n  return " + choose("a - f >= " + number(s, 0.5), "f + 1", "f", s) +
                    ";\n}\n");
}

// The bits of every lane or-ed together, halving the vector each step:
// PoCL's any() and all() take the lanes out one at a time.
std::string Generator::bits_or(const std::string& scalar) const {
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
std::string Generator::same_index() const {
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

// The first lane set in a mask (the last lane where none is).
std::string Generator::first_lane() const {
  std::string n = std::to_string(lanes_);
  return helper("sh_first_lane" + n, "int",
                "(" + vec("int") + " m) {\n  int l[" + n + "];\n  vstore" + n + "(m, 0, l);\n  int k = 0;\n  while (k < " +
                    std::to_string(lanes_ - 1) + " && !l[k]) ++k;\n  return k;\n}\n");
}

const char* Generator::reg_type(ir::Scalar s) const {
  switch (s) {
    case ir::Scalar::F32: return o_.precision == Precision::F32 ? "float" : "double";
    case ir::Scalar::F64: return "double";
    case ir::Scalar::I32: case ir::Scalar::Bool: return "int";
  }
  return "int";
}

const char* Generator::storage_type(ir::Scalar s) {
  switch (s) {
    case ir::Scalar::F32: return "float";
    case ir::Scalar::F64: return "double";
    case ir::Scalar::I32: case ir::Scalar::Bool: return "int";
  }
  return "int";
}

std::string Generator::number(ir::Scalar s, double v) const {
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
std::string Generator::read(const ir::Operand& o, int i) const {
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
std::string Generator::written(const ir::Operand& o, int i) const {
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
std::string Generator::mask_of(const ir::Operand& o, int i) const {
  if (truth_[o.var]) return reg(o.var, o.component(i));
  return "(" + read(o, i) + " > " + constant(p_.type_of(o.var).scalar, 0) + ")";
}

std::string comment_text(const std::string& name) {
  std::string text = name;
  for (char& c : text)
    if (c == '\\' || c == '?' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '_';
  return text;
}

}  // namespace sh::opencl
