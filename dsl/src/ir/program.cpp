#include "sh/ir/program.hpp"

namespace sh::ir {

const char* edge_name(Edge e) {
  switch (e) {
    case Edge::Clamp: return "clamp";
    case Edge::Repeat: return "repeat";
    case Edge::Zero: return "zero";
  }
  return "?";
}

const char* var_kind_name(VarKind k) {
  switch (k) {
    case VarKind::Input: return "input";
    case VarKind::Output: return "output";
    case VarKind::InOut: return "inout";
    case VarKind::Uniform: return "uniform";
    case VarKind::Const: return "const";
    case VarKind::Temp: return "temp";
    case VarKind::Array: return "array";
  }
  return "?";
}

VarId Program::add_const(Type t, const std::array<double, 4>& value) {
  Var v;
  v.kind = VarKind::Const;
  v.type = t;
  v.value = value;
  return add_var(std::move(v));
}

}  // namespace sh::ir
