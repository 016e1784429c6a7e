// sh::compare: a program on every backend, variant and math mode, measured
// against the interpreter in f64.  The table's text form is in
// compare_print.cpp.
#include "sh/compare.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "sh/error.hpp"

namespace sh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

using Buffers = std::vector<std::shared_ptr<detail::Buffer>>;

// Maps a float's bits onto unsigned integers in the order of the values,
// so that the distance between two maps is the count of floats between
// (-0 and +0 one place: one value, not two floats apart).
template <class Bits, class Float>
Bits ordered(Float x) {
  Bits bits;
  std::memcpy(&bits, &x, sizeof x);
  constexpr Bits sign = Bits{1} << (8 * sizeof(Bits) - 1);
  return (bits & sign) ? sign - (bits & ~sign) : bits | sign;
}

template <class Bits>
double distance(Bits a, Bits b) {
  return static_cast<double>(a > b ? a - b : b - a);
}

// Two different values that are not NaN, in ULPs of `scalar`: an infinity
// against anything else is infinitely far.
double ulps_between(double a, double b, ir::Scalar scalar) {
  if (std::isinf(a) || std::isinf(b)) return kInf;
  switch (scalar) {
    case ir::Scalar::F32:
      return distance(ordered<std::uint32_t>(static_cast<float>(a)), ordered<std::uint32_t>(static_cast<float>(b)));
    case ir::Scalar::F64: return distance(ordered<std::uint64_t>(a), ordered<std::uint64_t>(b));
    case ir::Scalar::I32:
    case ir::Scalar::Bool: return std::fabs(a - b);
  }
  return kInf;
}

// Adds one component's comparison into `d`.
void compare_component(double value, double reference, std::size_t element, OutputDifference& d) {
  bool value_nan = std::isnan(value), reference_nan = std::isnan(reference);
  if ((value_nan && reference_nan) || value == reference) return;
  ++d.differing;
  double abs = kInf, ulps = kInf;
  if (value_nan || reference_nan)
    ++d.nan_mismatches;
  else {
    abs = std::fabs(value - reference);
    ulps = ulps_between(value, reference, d.type.scalar);
  }
  if (ulps > d.max_ulps) d.worst_element = element;  // every difference is at least one ULP
  d.max_abs = std::max(d.max_abs, abs);
  d.max_ulps = std::max(d.max_ulps, ulps);
}

OutputDifference difference(std::string name, const detail::Buffer& value, const detail::Buffer& reference) {
  OutputDifference d;
  d.name = std::move(name);
  d.type = value.type();
  for (std::size_t i = 0; i < value.size(); ++i)
    for (int c = 0; c < d.type.width; ++c) compare_component(value.get(i, c), reference.get(i, c), i, d);
  return d;
}

std::string output_name(const ir::Program& p, std::size_t k) {
  const std::string& name = p.var(p.outputs[k]).name;
  return name.empty() ? "output " + std::to_string(k) : name;
}

// The program's accumulators, whose sums every run adds to: each run of a
// row starts from the sums they held when compare was called, the sums a
// row leaves are compared as its outputs are, and the caller's sums are put
// back at the end.  Their bytes are copied (a Buffer's copy shares memory
// the sums were moved into).
class Accumulators {
 public:
  explicit Accumulators(const Program& program) {
    for (const std::shared_ptr<detail::TableStorage>& t : program.tables())
      if (t->decl.accumulator) {
        const auto* bytes = static_cast<const char*>(t->buffer.data());
        held_.push_back({t, std::vector<char>(bytes, bytes + t->buffer.bytes())});
      }
  }
  ~Accumulators() { restore(); }
  Accumulators(const Accumulators&) = delete;
  Accumulators& operator=(const Accumulators&) = delete;

  void restore() const {
    for (const auto& [table, sums] : held_) {
      std::memcpy(table->buffer.data(), sums.data(), sums.size());
      table->buffer.written();
      table->touch();
    }
  }
  std::vector<detail::Buffer> sums() const {
    std::vector<detail::Buffer> out;
    for (const auto& held : held_) {
      const detail::Buffer& now = held.first->buffer;
      out.emplace_back(now.type(), now.size());
      std::memcpy(out.back().data(), now.data(), now.bytes());
    }
    return out;
  }
  std::string name(std::size_t k) const {
    const std::string& name = held_[k].first->decl.name;
    return "accumulator " + (name.empty() ? std::to_string(k) : "'" + name + "'");
  }

 private:
  std::vector<std::pair<std::shared_ptr<detail::TableStorage>, std::vector<char>>> held_;
};

// What a row left: its outputs, and its accumulators' sums.
struct RowResult {
  Buffers outputs;
  std::vector<detail::Buffer> sums;
};

Buffers fresh_outputs(const ir::Program& p, std::size_t count) {
  Buffers out;
  for (ir::VarId v : p.outputs) out.push_back(std::make_shared<detail::Buffer>(p.type_of(v), count));
  return out;
}

std::size_t stream_length(const ir::Program& p, const Buffers& inputs, const CompareOptions& o) {
  if (inputs.size() != p.inputs.size())
    throw Error("compare: program '" + p.name + "' takes " + std::to_string(p.inputs.size()) + " input channels; " +
                std::to_string(inputs.size()) + " were given");
  if (o.runs < 1) throw Error("compare: CompareOptions::runs must be at least 1, not " + std::to_string(o.runs));
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    std::string slot = "compare: program '" + p.name + "': input channel " + std::to_string(k);
    if (!inputs[k]) throw Error(slot + " is missing");
    if (inputs[k]->type() != p.type_of(p.inputs[k]))
      throw Error(slot + " holds " + ir::type_name(inputs[k]->type()) + " but the input is " +
                  ir::type_name(p.type_of(p.inputs[k])));
    if (inputs[k]->size() != inputs[0]->size())
      throw Error(slot + " holds " + std::to_string(inputs[k]->size()) + " elements but input channel 0 holds " +
                  std::to_string(inputs[0]->size()));
  }
  return inputs.empty() ? o.elements : inputs[0]->size();
}

// Runs one row, `runs` times, into fresh outputs; a throw becomes its error.
CompareRow run_row(const Program& program, const Buffers& inputs, CompareRow row, const Options& options, int runs,
                   std::size_t count, const Accumulators& accumulators, RowResult& result) {
  result.outputs = fresh_outputs(program.ir(), count);
  auto run_once = [&] {
    accumulators.restore();
    return run(program, inputs, result.outputs, backend(row.backend, options));
  };
  try {
    RunStats first = run_once();
    row.compiled = first.compiled;
    row.from_disk = first.from_disk;
    row.compile_ms = first.compile_ms;
    row.run_ms = first.run_ms;
    if (first.details) row.notes = first.details->describe();
    for (int r = 1; r < runs; ++r) row.run_ms = std::min(row.run_ms, run_once().run_ms);
    result.sums = accumulators.sums();
  } catch (const std::exception& e) {
    row.error = e.what();
    result = {};
  }
  return row;
}

CompareRow reference_row(const Program& program, const Buffers& inputs, const CompareOptions& o, std::size_t count,
                         const Accumulators& accumulators, RowResult& result) {
  CompareRow row;
  row.backend = "interp";
  row.precision = Precision::F64;
  Options options = o.options;
  options.precision = Precision::F64;
  options.math = MathMode::Precise;
  options.checked = false;
  return run_row(program, inputs, row, options, 1, count, accumulators, result);  // its time is not what is compared
}

}  // namespace

std::string CompareRow::label() const { return variant.empty() ? backend : backend + ":" + variant; }

double CompareRow::max_ulps() const {
  double most = 0;
  for (const OutputDifference& d : outputs) most = std::max(most, d.max_ulps);
  return most;
}

const CompareRow* Comparison::find(const std::string& backend, const std::string& variant, MathMode math) const {
  for (const CompareRow& r : rows)
    if (r.backend == backend && r.variant == variant && r.math == math) return &r;
  return nullptr;
}

Comparison compare(const Program& program, const Buffers& inputs, const CompareOptions& o) {
  const ir::Program& p = program.ir();
  Comparison c;
  c.program = p.name;
  c.elements = stream_length(p, inputs, o);
  c.precision = o.precision;
  Accumulators accumulators(program);
  RowResult expected, got;
  c.reference = reference_row(program, inputs, o, c.elements, accumulators, expected);
  for (const std::string& name : o.backends.empty() ? backend_names() : o.backends) {
    std::vector<Backend::Variant> variants;
    try {
      variants = find_backend(name).variants();
    } catch (const std::exception& e) {
      CompareRow row;
      row.backend = name;
      row.error = e.what();
      c.rows.push_back(std::move(row));
      continue;
    }
    for (const Backend::Variant& v : variants)
      for (MathMode math : o.math) {
        CompareRow row;
        row.backend = name;
        row.variant = v.name;
        row.math = math;
        row.precision = o.precision;
        Options options = o.options;
        options.precision = o.precision;
        options.math = math;
        options.set(v.options);
        row = run_row(program, inputs, std::move(row), options, o.runs, c.elements, accumulators, got);
        if (row.failed() || c.reference.failed()) {
          c.rows.push_back(std::move(row));
          continue;
        }
        for (std::size_t k = 0; k < got.outputs.size(); ++k)
          row.outputs.push_back(difference(output_name(p, k), *got.outputs[k], *expected.outputs[k]));
        for (std::size_t k = 0; k < got.sums.size(); ++k)
          row.outputs.push_back(difference(accumulators.name(k), got.sums[k], expected.sums[k]));
        c.rows.push_back(std::move(row));
      }
  }
  return c;
}

}  // namespace sh
