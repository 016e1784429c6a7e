// The kernel's frame: its signature, registers, input loads and output
// stores; which registers are uniform (scalars) or truth values (masks); and
// a stencil's body written twice, for taps inside their tables and not.
#include "generator.hpp"

#include <algorithm>
#include <array>
#include <climits>
#include <optional>

#include "sh/ir/visitor.hpp"

namespace sh::opencl {

Generator::Generator(const ir::Program& p, const sh::Options& o, int lanes, std::uint64_t largest_buffer, Prelude& prelude)
    : p_(p),
      o_(o),
      lanes_(lanes),
      index_type_(largest_buffer / 4 <= INT_MAX ? "int" : "long"),
      prelude_(prelude),
      access_(analysis::table_access(p)),
      facts_(spmd() ? analysis::analyse_spmd(p) : analysis::SpmdFacts{}),
      truth_(spmd() ? truth_registers() : analysis::VarSet(p.vars.size(), false)) {}

std::string Generator::run(const char* name) {
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

// SPMD: a variable every lane agrees on is one scalar, not a vector of
// copies, so that the device's compiler sees uniform loops' counters
// (their trip counts) and computes uniform values once.
bool Generator::scalar_register(ir::VarId v) const {
  ir::VarKind k = p_.var(v).kind;
  return spmd() && k != ir::VarKind::Const && k != ir::VarKind::Uniform && !facts_.varying[v];
}

// SPMD: a register that only ever holds 0 or 1 (a comparison, Sh's && and
// || as min and max of such, a vote across lanes, a conversion of such)
// is held as a mask, -1 or 0 a lane, the form a vector comparison gives.  A test such as
// `i < n && dot(z, z) < 4` is then two comparisons and an and of masks,
// where 0/1 floats took a conversion to float after each comparison and
// one back for the loop's mask.  Where a mask is read as a number it
// becomes 0 or 1 again (read()).
analysis::VarSet Generator::truth_registers() const {
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
bool Generator::reads_truth(const ir::Assign& a, ir::VarId v, const analysis::VarSet& truth) const {
  using ir::Op;
  if (a.op == Op::And || a.op == Op::Or || a.op == Op::Not || a.op == Op::AnyLane) return true;
  if (a.op == Op::Cond) return a.args[1].var != v && a.args[2].var != v;
  return truth[a.dest] && (a.op == Op::Mov || a.op == Op::Min || a.op == Op::Max || a.op == Op::Cast);
}

// Whether `a` writes only 0 or 1, given the registers that hold only those.
bool Generator::gives_truth(const ir::Assign& a, const analysis::VarSet& truth) const {
  using ir::Op;
  constexpr std::array kTests = {Op::Lt, Op::Le, Op::Gt, Op::Ge, Op::Eq, Op::Ne, Op::And, Op::Or, Op::Not, Op::AnyLane};
  if (std::find(kTests.begin(), kTests.end(), a.op) != kTests.end()) return true;
  if (a.op != Op::Mov && a.op != Op::Min && a.op != Op::Max && a.op != Op::Cast) return false;
  return std::all_of(a.args.begin(), a.args.end(), [&](const ir::Operand& o) { return truth_operand(o, truth); });
}

bool Generator::truth_operand(const ir::Operand& o, const analysis::VarSet& truth) const {
  const ir::Var& v = p_.var(o.var);
  if (v.kind != ir::VarKind::Const) return truth[o.var];
  for (int i = 0; i < o.width(); ++i)
    if (v.value[o.swizzle[i]] != 0 && v.value[o.swizzle[i]] != 1) return false;
  return true;
}

// The element's place in the launch domain (sh::LaunchDomain): the run's
// elements start at `first` of a grid of rows `row` long, `rows` a layer.
// A work-item's lanes usually share a row: then one division serves all.
std::string Generator::position() const {
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
void Generator::stencil_or_body() {
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
std::string Generator::taps_inside() const {
  if (!spmd()) return "";
  std::vector<std::optional<analysis::TapSpan>> spans = analysis::tap_spans(p_, access_);
  std::string inside;
  for (std::size_t t = 0; t < spans.size(); ++t) {
    if (!spans[t]) continue;
    for (int d = 0; d < p_.tables[t].rank; ++d) {
      std::string at = std::string("(long)position_") + kComponent[d] + ".s0";
      // In 64 bits: an offset may be INT_MAX.
      long long last = static_cast<long long>(spans[t]->high[d]) + (d == 0 ? lanes_ - 1 : 0);
      inside += " && " + at + " + " + std::to_string(spans[t]->low[d]) + " >= 0 && " + at + " + " + std::to_string(last) +
                " < table" + std::to_string(t) + "_" + kComponent[d];
    }
  }
  return inside.empty() ? "" : "same_row" + inside;
}

// A tap inside its table: its lanes' elements from the first lane's on.
std::string Generator::tap(const ir::Assign& a, int c) const {
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

// Streams are restrict: no two of a run's buffers overlap (an in-out
// channel is copied, backend.cpp; channels over partly overlapping host
// memory are outside what buffers over host memory allow anyway), so the
// compiler may keep an input's loads ahead of an output's stores.  Tables
// may share a channel's memory, and are only const.
void Generator::signature(std::ostringstream& out) {
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

void Generator::registers() {
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
    if (!var.name.empty()) body_ << "  // " << comment_text(var.name);
    body_ << "\n";
  }
}

// A local array: one private array per component, of vectors where its
// lanes may differ (lane k's value in lane k), zero at the start.
void Generator::array_registers(ir::VarId v) {
  const ir::Var& var = p_.var(v);
  std::string type = scalar_register(v) ? reg_type(var.type.scalar) : vec(reg_type(var.type.scalar));
  std::string n = std::to_string(var.length);
  for (int c = 0; c < var.type.width; ++c) {
    body_ << "  " << type << " " << reg(v, c) << "[" << n << "];";
    if (c == 0 && !var.name.empty()) body_ << "  // " << comment_text(var.name);
    body_ << "\n  for (int k = 0; k < " << n << "; ++k) " << reg(v, c) << "[k] = (" << type << ")(0);\n";
  }
}

// Element k's component c of a stream `w` components wide: in the SPMD
// form a one-component stream is a vector load or store, a wider one a
// load or store per lane.
std::string Generator::at(const std::string& stream, int w, int c, int k) const {
  return stream + "[(e + " + std::to_string(k) + ") * " + std::to_string(w) + " + " + std::to_string(c) + "]";
}

void Generator::load_inputs() {
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

void Generator::store_outputs() {
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

}  // namespace sh::opencl
