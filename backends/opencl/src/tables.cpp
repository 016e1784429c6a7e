// Table reads (one load for lanes that agree, a vector load for a run, a
// gather otherwise), local arrays, atomic scatters and prefetches.
#include "generator.hpp"

namespace sh::opencl {

// The element a read or scatter names (coordinates in range: legal IR),
// or a prefetch (coordinates as asked, brought inside with `clamp_inside`).
std::string Generator::flat_index(int table, const ir::Operand& coord, bool clamp_inside) const {
  std::string name = "table" + std::to_string(table);
  std::string index, stride = "1";
  for (int d = 0; d < p_.tables[table].rank; ++d) {
    std::string dim = name + "_" + kComponent[d];
    std::string i = convert(index_type_, read(coord, d));
    if (clamp_inside) i = "clamp(" + i + ", (" + index_type_ + ")0, (" + index_type_ + ")(" + dim + " - 1))";
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
void Generator::table_read(const ir::Assign& a, std::string* results, int depth) {
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

// An array index as C indexes with it: lane k's in the SPMD form where
// the lanes' indices may differ, else the one scalar.
std::string Generator::index_of(const ir::Operand& o, int k) const {
  const ir::Var& v = p_.var(o.var);
  if (v.kind == ir::VarKind::Const) return number(ir::Scalar::I32, v.value[o.component(0)]);
  std::string r = reg(o.var, o.component(0));
  return spmd() && varying(o.var) ? r + lane(k) : r;
}

// Legal IR indexes in range.  A uniform index reads one element (a
// vector of lanes in a varying array); indices that differ, each lane's
// own.
void Generator::array_element(const ir::Assign& a, std::string* results) {
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
void Generator::array_store(const ir::Assign& a, int depth) {
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
void Generator::array_fill(const ir::Assign& a, int depth) {
  ir::VarId array = a.dest;
  std::string n = std::to_string(p_.var(array).length);
  for (int c = 0; c < a.mask.size; ++c) {
    std::string place = reg(array, c) + "[k]", value = read(a.args[0], c);
    if (spmd() && masked()) value = "select(" + place + ", " + value + ", " + exec_for(scalar_of(array)) + ")";
    line(depth, "for (int k = 0; k < " + n + "; ++k) " + place + " = " + value + ";");
  }
}

// OpenCL's own prefetch.  Its coordinates are clamped here, as legal IR
// leaves them: OpenCL C's pointer arithmetic past a buffer is undefined,
// whatever the instruction would do with the address.  In the SPMD form
// every lane asks where lanes may differ, those not running too, and lane
// 0 alone where they agree.
void Generator::prefetch(const ir::Prefetch& pf, int depth) {
  std::string table = "table" + std::to_string(pf.table), count = std::to_string(p_.tables[pf.table].element.width);
  std::string at = flat_index(pf.table, pf.index, true);
  if (!spmd()) return line(depth, "prefetch(" + table + " + " + at + ", " + count + ");");
  line(depth, "{");
  line(depth + 1, "const " + vec(index_type_) + " at = " + at + ";");
  int asking = facts_.varying[pf.index.var] ? lanes_ : 1;
  for (int k = 0; k < asking; ++k) line(depth + 1, "prefetch(" + table + " + at" + lane(k) + ", " + count + ");");
  line(depth, "}");
}

// OpenCL 1.2 adds ints atomically; floats by compare-and-swap on their
// bits.  The SPMD form adds lane by lane, for the lanes running.
void Generator::scatter(const ir::Scatter& sc, int depth) {
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

}  // namespace sh::opencl
