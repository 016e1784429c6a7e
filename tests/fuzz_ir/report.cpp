#include "report.hpp"

#include <bit>
#include <cstdio>
#include <set>
#include <sstream>

#include <sh/ir/printer.hpp>
#include <sh/ir/visitor.hpp>

namespace fuzz_ir {
namespace {

using namespace sh::ir;

// The value and, for floats, its bits: two NaNs or ±0 print apart.
std::string value(Scalar s, double v) {
  std::string out = format_number(v, s);
  char bits[32];
  if (s == Scalar::F32) {
    std::snprintf(bits, sizeof bits, " (0x%08x)", std::bit_cast<std::uint32_t>(static_cast<float>(v)));
    out += bits;
  } else if (s == Scalar::F64) {
    std::snprintf(bits, sizeof bits, " (0x%016llx)", static_cast<unsigned long long>(std::bit_cast<std::uint64_t>(v)));
    out += bits;
  }
  return out;
}

std::string values(Scalar s, const double* v, std::size_t n) {
  std::string out = n == 1 ? "" : "(";
  for (std::size_t i = 0; i < n; ++i) out += (i ? ", " : "") + value(s, v[i]);
  return out + (n == 1 ? "" : ")");
}

class Used : public Visitor {
 public:
  using Visitor::visit;
  std::set<std::string> names;
  void visit(const Assign& a) override { names.insert(op_name(a.op)); }
  void visit(const If& s) override {
    names.insert("if");
    Visitor::visit(s);
  }
  void visit(const Loop& s) override {
    names.insert("loop");
    Visitor::visit(s);
  }
  void visit(const Break&) override { names.insert("break"); }
  void visit(const Continue&) override { names.insert("continue"); }
  void visit(const Scatter&) override { names.insert("scatter"); }
  void visit(const Prefetch&) override { names.insert("prefetch"); }
};

}  // namespace

std::string describe_data(const Case& c, std::size_t element) {
  std::ostringstream out;
  const Program& p = c.program;
  for (std::size_t k = 0; k < p.inputs.size(); ++k) {
    const Data& d = c.inputs[k];
    std::size_t w = static_cast<std::size_t>(d.type.width);
    out << "  input " << p.var(p.inputs[k]).name << "[" << element << "] = " << values(d.type.scalar, &d.values[element * w], w)
        << "\n";
  }
  for (std::size_t k = 0; k < p.uniforms.size(); ++k) {
    Type t = p.type_of(p.uniforms[k]);
    out << "  uniform " << p.var(p.uniforms[k]).name << " = " << values(t.scalar, c.uniforms[k].data(), static_cast<std::size_t>(t.width))
        << "\n";
  }
  for (std::size_t t = 0; t < p.tables.size(); ++t) {
    const TableData& d = c.tables[t];
    out << "  " << (p.tables[t].accumulator ? "accumulator " : "table ") << p.tables[t].name << " " << type_name(d.data.type) << " "
        << d.dims[0] << "x" << d.dims[1] << "x" << d.dims[2] << " (x fastest):";
    std::size_t w = static_cast<std::size_t>(d.data.type.width);
    for (std::size_t e = 0; e * w < d.data.values.size(); ++e) out << " " << values(d.data.type.scalar, &d.data.values[e * w], w);
    out << "\n";
  }
  return out.str();
}

Scalar slot_scalar(const Case& c, int slot) {
  const Program& p = c.program;
  if (slot < 0) return Scalar::I32;
  if (static_cast<std::size_t>(slot) < p.outputs.size()) return p.type_of(p.outputs[slot]).scalar;
  return p.tables[slot - p.outputs.size()].element.scalar;
}

std::string describe(const Mismatch& m, Scalar s, const std::string& mode) {
  if (m.slot < 0) return "  " + mode + ": " + m.detail;
  if (!m.detail.empty()) return "  " + mode + ": " + m.where + " " + m.detail;
  return "  " + m.where + ": interp " + value(s, m.expected) + ", " + mode + " " + value(s, m.got) + " (tolerance " +
         std::to_string(m.tolerance) + " ulp)";
}

std::string operations_used(const Case& c) {
  Used used;
  used.visit(Block(c.program.body.begin() + c.prologue, c.program.body.end()));
  std::string out;
  for (const std::string& n : used.names) out += (out.empty() ? "" : "+") + n;
  return out.empty() ? "(prologue only)" : out;
}

}  // namespace fuzz_ir
