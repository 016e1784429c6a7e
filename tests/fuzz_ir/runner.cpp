#include "runner.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <sh/detail/buffer.hpp>
#include <sh/ir/printer.hpp>
#include <sh/passes.hpp>

namespace fuzz_ir {
namespace {

using sh::detail::Buffer;
using sh::ir::Scalar;

Buffer to_buffer(const Data& d) {
  std::size_t count = d.values.size() / static_cast<std::size_t>(d.type.width);
  Buffer b(d.type, count);
  for (std::size_t i = 0; i < count; ++i)
    for (int c = 0; c < d.type.width; ++c) b.set(i, c, d.values[i * d.type.width + c]);
  return b;
}

Data from_buffer(const Buffer& b) {
  Data d{b.type(), {}};
  for (std::size_t i = 0; i < b.size(); ++i)
    for (int c = 0; c < b.type().width; ++c) d.values.push_back(b.get(i, c));
  return d;
}

// Unwritten output bytes read as this pattern (an unlikely value of every
// type, not a NaN), so that a backend that skips a store disagrees.
void poison(Buffer& b) { std::memset(b.data(), 0xA5, b.bytes()); }

// Table identities unique in the process, so that no backend mistakes one
// case's table for another's.
std::uint64_t next_table_id() {
  static std::uint64_t id = std::uint64_t{1} << 48;
  return ++id;
}

template <class I, class F>
std::uint64_t ordered_distance(F a, F b) {
  auto ordered = [](F x) {
    I i;
    std::memcpy(&i, &x, sizeof x);
    return i < 0 ? static_cast<std::int64_t>(std::numeric_limits<I>::min()) - i : static_cast<std::int64_t>(i);
  };
  std::int64_t d = ordered(a) - ordered(b);
  return static_cast<std::uint64_t>(d < 0 ? -d : d);
}

const char kComponent[] = "xyzw";

std::string place(const std::string& name, std::size_t element, int component) {
  return name + "[" + std::to_string(element) + "]." + kComponent[component];
}

void compare_data(const Data& want, const Data& got, const Tolerance& tolerance, const std::string& name, int slot,
                  bool stream, std::vector<Mismatch>& out) {
  int width = want.type.width;
  if (got.values.size() != want.values.size()) {
    out.push_back({name, name, slot, true, 0, 0, 0, 0, 0, "holds " + std::to_string(got.values.size()) + " values, not " + std::to_string(want.values.size())});
    return;
  }
  for (std::size_t k = 0; k < want.values.size(); ++k) {
    int c = static_cast<int>(k % width);
    double a = want.values[k], b = got.values[k];
    bool same = sh::ir::is_float(want.type.scalar) ? ulp_distance(want.type.scalar, a, b) <= tolerance[c].ulps : a == b;
    if (!same) out.push_back({place(name, k / width, c), name, slot, stream, k / width, c, a, b, tolerance[c].ulps, {}});
  }
}

}  // namespace

std::string Mode::name() const {
  return backend + (variant.name.empty() ? "" : "_" + variant.name) + (precision == sh::Precision::F32 ? "_f32" : "_f64");
}

std::vector<Mode> all_modes(const std::vector<std::string>& only) {
  std::vector<Mode> modes;
  for (const std::string& b : only.empty() ? sh::backend_names() : only)
    for (const sh::Backend::Variant& v : sh::find_backend(b).variants())
      for (sh::Precision p : {sh::Precision::F32, sh::Precision::F64}) modes.push_back({b, v, p});
  return modes;
}

std::uint64_t ulp_distance(Scalar s, double a, double b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  if (std::isinf(a) || std::isinf(b)) return a == b ? 0 : UINT64_MAX;
  if (s == Scalar::F32) return ordered_distance<std::int32_t>(static_cast<float>(a), static_cast<float>(b));
  return ordered_distance<std::int64_t>(a, b);
}

namespace {

sh::Options options_for(const Mode& m, bool optimize) {
  sh::Options o;
  o.precision = m.precision;
  o.math = sh::MathMode::Precise;
  o.optimize = optimize;
  o.max_loop_iterations = kLoopCap;
  o.set(m.variant.options);
  return o;
}

sh::ir::Program prepared(const sh::ir::Program& p, const Mode& m, bool optimize) {
  return sh::passes::legalize(optimize ? sh::optimize(p, m.precision) : p);
}

}  // namespace

std::string listing(const Case& c, const Mode& m) {
  sh::ir::Program ir = prepared(c.program, m, true);
  try {
    return sh::ir::print(ir) + sh::find_backend(m.backend).compile(ir, options_for(m, true))->listing();
  } catch (const std::exception& e) {
    return sh::ir::print(ir) + e.what();
  }
}

Result run(const Case& c, const Mode& m, bool optimize) {
  const sh::ir::Program& p = c.program;
  Result r;
  std::vector<Buffer> inputs, outputs, tables;
  sh::RunArgs args;
  args.count = c.count;
  args.domain = c.domain;
  for (const Data& d : c.inputs) inputs.push_back(to_buffer(d));
  for (Buffer& b : inputs) args.inputs.push_back({b.type(), b.size(), b.data()});
  for (sh::ir::VarId id : p.outputs) {
    outputs.emplace_back(p.type_of(id), c.count);
    poison(outputs.back());
  }
  for (Buffer& b : outputs) args.outputs.push_back({b.type(), b.size(), b.data()});
  args.uniforms = c.uniforms;
  for (const TableData& t : c.tables) tables.push_back(to_buffer(t.data));
  for (std::size_t t = 0; t < tables.size(); ++t) {
    const sh::ir::TableDecl& d = p.tables[t];
    void* sums = d.accumulator ? tables[t].data() : nullptr;
    args.tables.push_back({d.element, d.rank, c.tables[t].dims, tables[t].data(), sums, next_table_id(), 1, nullptr});
  }
  try {
    sh::RunStats stats;
    sh::find_backend(m.backend).compile(prepared(p, m, optimize), options_for(m, optimize))->run(args, stats);
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  for (const Buffer& b : outputs) r.outputs.push_back(from_buffer(b));
  for (std::size_t t = 0; t < tables.size(); ++t)
    r.sums.push_back(p.tables[t].accumulator ? from_buffer(tables[t]) : Data{});
  return r;
}

std::vector<Mismatch> compare(const Case& c, const Result& reference, const Result& got) {
  std::vector<Mismatch> out;
  if (!reference.error.empty() || !got.error.empty()) {
    if (reference.error.empty() != got.error.empty())
      out.push_back({"error", "error", -1, false, 0, 0, 0, 0, 0, got.error.empty() ? "the interpreter threw: " + reference.error : got.error});
    return out;
  }
  const sh::ir::Program& p = c.program;
  std::vector<Tolerance> tolerance = tolerances(p);
  for (std::size_t k = 0; k < p.outputs.size(); ++k) {
    const std::string& name = p.var(p.outputs[k]).name;
    compare_data(reference.outputs[k], got.outputs[k], tolerance[p.outputs[k]], name.empty() ? "out" + std::to_string(k) : name,
                 static_cast<int>(k), true, out);
  }
  for (std::size_t t = 0; t < p.tables.size(); ++t)
    if (p.tables[t].accumulator)
      compare_data(reference.sums[t], got.sums[t], Tolerance{}, p.tables[t].name, static_cast<int>(p.outputs.size() + t), false,
                   out);
  return out;
}

}  // namespace fuzz_ir
