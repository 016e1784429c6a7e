// Assignments: an operation per row of the op table, truth values as
// masks, and the workarounds for PoCL's built-ins.
#include "generator.hpp"

#include <algorithm>
#include <array>

#include "sh/error.hpp"

namespace sh::opencl {

// A scalar register's value is computed in the scalar form: its operands
// are scalar registers, uniforms and constants too (any varying operand
// makes it varying, but for a vote across lanes), and no lane that may
// read it keeps an older value, so a mask never guards its write.
void Generator::assign(const ir::Assign& a, int depth) {
  if (!scalar_register(a.dest)) return assign_in_form(a, depth);
  if (a.op == ir::Op::AnyLane) return vote_once(a, depth);
  int lanes = lanes_;
  lanes_ = 1;
  assign_in_form(a, depth);
  lanes_ = lanes;
}

// A vote into a scalar register: the lanes' tests, one answer.
void Generator::vote_once(const ir::Assign& a, int depth) {
  ir::Scalar to = scalar_of(a.dest);
  for (int i = 0; i < a.mask.size; ++i)
    line(depth, reg(a.dest, a.mask[i]) + " = " + voted(mask_of(a.args[0], i)) + " ? " + number(to, 1) + " : " +
                    number(to, 0) + ";");
}

void Generator::assign_in_form(const ir::Assign& a, int depth) {
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
std::string Generator::operation(ir::Op op, ir::Scalar from, ir::Scalar to, const std::string& a, const std::string& b,
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
    // In brackets: a negative constant's "-" + "-2.5" would read as "--".
    case Op::Neg: return fp ? "-(" + a + ")" : bits_as("int", "0u - " + uint(a));
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

// A truth register's component (truth_registers) as a mask.
std::string Generator::truth_test(const ir::Assign& a, int i) const {
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

std::string Generator::compare(ir::Op op, const std::string& a, const std::string& b) {
  using ir::Op;
  constexpr std::array<std::pair<Op, const char*>, 6> kSymbols = {
      {{Op::Lt, "<"}, {Op::Le, "<="}, {Op::Gt, ">"}, {Op::Ge, ">="}, {Op::Eq, "=="}, {Op::Ne, "!="}}};
  auto s = std::find_if(kSymbols.begin(), kSymbols.end(), [&](const auto& e) { return e.first == op; });
  return "(" + a + " " + s->second + " " + b + ")";
}

// PoCL's vector forms (3.1) of float sin, cos and tan and of double fmod
// and pow lose lanes when another lane is denormal or large; its scalar
// forms are right, so those vectors take them lane by lane.
std::string Generator::lane_by_lane(const std::string& f, const std::vector<std::string>& args, ir::Scalar s) const {
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
std::string Generator::is_nan(const std::string& a, ir::Scalar s) const {
  return std::string(reg_type(s)) == "double" ? "(" + bits_as("ulong", a) + " & 0x7fffffffffffffffUL) > 0x7ff0000000000000UL"
                                              : "(" + bits_as("uint", a) + " & 0x7fffffffU) > 0x7f800000U";
}

// NaN gives 0: PoCL's convert_int_sat of a NaN it can see at compile time
// is undefined, so the store of it vanished.
std::string Generator::float_to_int(const std::string& a, ir::Scalar from) const {
  return choose(is_nan(a, from), constant(ir::Scalar::I32, 0), "convert_" + vec("int") + "_sat(" + a + ")", ir::Scalar::I32);
}

// f(a), with a NaN passed through untouched: PoCL's exp, exp2, exp10 and
// tanh (3.1) turn a NaN they can see at compile time (one its compiler
// worked out from constants, such as the remainder of inf) into an
// undefined value, and the store of the result vanished.
std::string Generator::nan_through(const std::string& f, const std::string& a, ir::Scalar s) const {
  std::string t = vec(reg_type(s));
  return helper("sh_" + f + "_" + t, t, "(" + t + " a) {\n  return " + choose(is_nan("a", s), "a", f + "(a)", s) + ";\n}\n") +
         "(" + a + ")";
}

std::string Generator::cast(const std::string& a, ir::Scalar from, ir::Scalar to) const {
  if (to == ir::Scalar::Bool) return bit("(" + a + " > 0)", to);
  if (to == ir::Scalar::I32) return ir::is_float(from) ? float_to_int(a, from) : a;
  return convert(reg_type(to), a);
}

}  // namespace sh::opencl
