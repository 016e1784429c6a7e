// sh::compare: every backend, variant and math mode against interp in f64.
// Three toy backends registered here (running interp's kernels) give known
// differences: `nudged` moves every output by its variant's number of ULPs
// in fast math only, `broken` cannot compile, `nans` puts a NaN where the
// reference has a number and a number where the reference has NaN.  The
// backends linked into this program (sh::sh) run an exact program too.
#include <gtest/gtest.h>

#include <sh/sh.hpp>

#include <cmath>
#include <limits>
#include <sstream>

#include "../common/expect_error.hpp"

namespace {

using namespace sh;

struct NudgeOptions {
  static constexpr const char* backend_name = "nudged";
  int ulps = 0;
  Settings settings() const { return ulps ? Settings{{"ulps", std::to_string(ulps)}} : Settings{}; }
  void set(const std::string& name, const std::string& value) {
    if (name != "ulps") throw Error("the nudged backend has no setting '" + name + "'");
    ulps = std::stoi(value);
  }
};

// Runs interp's kernel, then changes what it wrote.
class Altered : public Kernel {
 public:
  Altered(std::unique_ptr<Kernel> inner, std::function<void(const RunArgs&)> change)
      : inner_(std::move(inner)), change_(std::move(change)) {}
  void run(const RunArgs& args, RunStats& stats) override {
    inner_->run(args, stats);
    change_(args);
  }

 private:
  std::unique_ptr<Kernel> inner_;
  std::function<void(const RunArgs&)> change_;
};

// f32 outputs move up by n ULPs, i32 outputs by n.
void nudge(const RunArgs& args, int n) {
  for (const BufferView& out : args.outputs)
    for (std::size_t k = 0; k < out.count * out.type.width; ++k) {
      if (out.type.scalar == ir::Scalar::F32) {
        float& v = static_cast<float*>(out.data)[k];
        for (int i = 0; i < n; ++i) v = std::nextafter(v, std::numeric_limits<float>::infinity());
      } else if (out.type.scalar == ir::Scalar::I32) {
        static_cast<std::int32_t*>(out.data)[k] += n;
      }
    }
}

class Nudged : public Backend {
 public:
  std::string name() const override { return "nudged"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    int n = o.math == MathMode::Fast ? o.get<NudgeOptions>().ulps : 0;
    return std::make_unique<Altered>(find_backend("interp").compile(p, o), [n](const RunArgs& a) { nudge(a, n); });
  }
  BackendOptions default_options() const override { return NudgeOptions{}; }
  std::vector<Variant> variants() const override { return {{"one", NudgeOptions{.ulps = 1}}, {"three", NudgeOptions{.ulps = 3}}}; }
};

class Broken : public Backend {
 public:
  std::string name() const override { return "broken"; }
  std::unique_ptr<Kernel> compile(const ir::Program&, const Options&) override {
    throw Error("broken: no code generator here");
  }
};

// Element 5 of the first output becomes NaN; every NaN there becomes 0.
void swap_nans(const RunArgs& args) {
  float* v = static_cast<float*>(args.outputs[0].data);
  for (std::size_t k = 0; k < args.outputs[0].count; ++k) v[k] = std::isnan(v[k]) ? 0.0f : v[k];
  v[5] = std::numeric_limits<float>::quiet_NaN();
}

class Nans : public Backend {
 public:
  std::string name() const override { return "nans"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    return std::make_unique<Altered>(find_backend("interp").compile(p, o), swap_nans);
  }
};

const bool registered = (register_backend("nudged", [] { return std::make_unique<Nudged>(); }),
                         register_backend("broken", [] { return std::make_unique<Broken>(); }),
                         register_backend("nans", [] { return std::make_unique<Nans>(); }), true);

const std::vector<std::string> kToys = {"broken", "nans", "nudged"};

// r = 2x + y and its integer part: exact in f32, so every correct backend
// gives the reference's bits.
Program exact_program() {
  return SH_BEGIN_PROGRAM("exact") {
    InputAttrib1f x, y;
    OutputAttrib1f r;
    OutputAttrib1i whole;
    r.name("r");
    r = 2.0f * x + y;
    whole = floor(r).cast<int>();
  } SH_END;
}

std::vector<float> ramp(std::size_t n, float step) {
  std::vector<float> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = step * static_cast<float>(i);
  return v;
}

CompareOptions only(std::vector<std::string> backends) {
  CompareOptions o;
  o.backends = std::move(backends);
  return o;
}

TEST(Compare, FastVariantsShowTheirDifferenceInUlpsAndPreciseOnesNone) {
  Channel<Attrib1f> x(ramp(64, 0.25f)), y(ramp(64, 1.0f));
  Comparison c = compare(exact_program(), {x, y}, only({"nudged"}));
  ASSERT_EQ(c.rows.size(), 4u);  // two variants, two math modes
  ASSERT_FALSE(c.reference.failed()) << c.reference.error;
  EXPECT_EQ(c.reference.precision, Precision::F64);
  EXPECT_EQ(c.elements, 64u);
  for (const char* variant : {"one", "three"}) {
    const CompareRow* precise = c.find("nudged", variant, MathMode::Precise);
    ASSERT_NE(precise, nullptr) << variant;
    ASSERT_EQ(precise->outputs.size(), 2u);
    EXPECT_EQ(precise->outputs[0].differing, 0u);
    EXPECT_EQ(precise->outputs[1].differing, 0u);
    EXPECT_EQ(precise->max_ulps(), 0);
  }
  const CompareRow* three = c.find("nudged", "three", MathMode::Fast);
  ASSERT_NE(three, nullptr);
  const OutputDifference& r = three->outputs[0];
  EXPECT_EQ(r.name, "r");
  EXPECT_EQ(three->outputs[1].name, "output 1");  // unnamed
  EXPECT_EQ(r.type, (ir::Type{ir::Scalar::F32, 1}));
  EXPECT_EQ(r.max_ulps, 3);
  EXPECT_EQ(r.differing, 64u);
  EXPECT_EQ(r.nan_mismatches, 0u);
  // The largest value, 2 * 15.75 + 63 = 94.5, moves farthest: 3 ULPs of 2^-17.
  EXPECT_DOUBLE_EQ(r.max_abs, 3 * std::ldexp(1.0, -17));
  EXPECT_EQ(three->outputs[1].max_ulps, 3);  // an integer output: the difference itself
  EXPECT_EQ(three->outputs[1].max_abs, 3);
  EXPECT_EQ(c.find("nudged", "one", MathMode::Fast)->max_ulps(), 1);
}

// ULPs across zero: -0 and +0 are one value, so -0 against the smallest
// float above it is one ULP (it was counted two).
TEST(Compare, UlpsAcrossZeroCountMinusAndPlusZeroAsOne) {
  Program negate = SH_BEGIN_PROGRAM("negate") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = -x;
  } SH_END;
  Channel<Attrib1f> zeros(std::vector<float>(8, 0.0f));
  Comparison c = compare(negate, {zeros}, only({"nudged"}));
  ASSERT_FALSE(c.reference.failed()) << c.reference.error;
  EXPECT_EQ(c.find("nudged", "one", MathMode::Fast)->max_ulps(), 1);
  EXPECT_EQ(c.find("nudged", "three", MathMode::Fast)->max_ulps(), 3);
}

TEST(Compare, ABackendThatThrowsIsItsRowsErrorAndTheOthersStillRun) {
  Channel<Attrib1f> x(ramp(16, 1.0f)), y(ramp(16, 2.0f));
  Comparison c = compare(exact_program(), {x, y}, only({"broken", "interp"}));
  ASSERT_EQ(c.rows.size(), 4u);
  const CompareRow* broken = c.find("broken", "", MathMode::Precise);
  ASSERT_NE(broken, nullptr);
  EXPECT_TRUE(broken->failed());
  EXPECT_NE(broken->error.find("broken: no code generator here"), std::string::npos) << broken->error;
  EXPECT_TRUE(broken->outputs.empty());
  const CompareRow* interp = c.find("interp", "", MathMode::Precise);
  ASSERT_NE(interp, nullptr);
  EXPECT_FALSE(interp->failed()) << interp->error;
  EXPECT_EQ(interp->outputs.size(), 2u);
  std::string table = to_string(c);
  EXPECT_NE(table.find("error: broken: no code generator here"), std::string::npos) << table;
}

TEST(Compare, AnUnknownBackendIsARowNotAnAbort) {
  Channel<Attrib1f> x(ramp(4, 1.0f)), y(ramp(4, 1.0f));
  Comparison c = compare(exact_program(), {x, y}, only({"no-such", "interp"}));
  ASSERT_EQ(c.rows.size(), 3u);
  EXPECT_TRUE(c.rows[0].failed());
  EXPECT_NE(c.rows[0].error.find("unknown backend 'no-such'"), std::string::npos) << c.rows[0].error;
  EXPECT_FALSE(c.rows[1].failed());
}

// The table's header gives the rows' precision whatever the first row did,
// and a long output name is printed whole.
TEST(Compare, TheTableSaysThePrecisionAndKeepsLongNamesWhole) {
  std::string long_name(150, 'n');
  Program p = SH_BEGIN_PROGRAM("long_names") {
    Input<Attrib1f> x;
    Output<Attrib1f> y;
    y.name(long_name);
    y = x + 1.0f;
  } SH_END;
  Channel<Attrib1f> x(ramp(4, 1.0f));
  CompareOptions o = only({"no-such", "interp"});
  o.precision = Precision::F64;
  std::string table = to_string(compare(p, {x}, o));
  EXPECT_NE(table.find("4 elements in f64 against interp in f64"), std::string::npos) << table;
  EXPECT_NE(table.find(long_name + " f32"), std::string::npos) << table;
}

TEST(Compare, NanAgainstANumberCountsAsADifferenceEitherWay) {
  // x / y with x = y = 0 at element 7: the reference gives NaN there.
  Program divide = SH_BEGIN_PROGRAM("divide") {
    InputAttrib1f x, y;
    OutputAttrib1f q;
    q = x / y;
  } SH_END;
  std::vector<float> xs = ramp(10, 1.0f), ys(10, 2.0f);
  xs[7] = 0;
  ys[7] = 0;
  Channel<Attrib1f> x(xs), y(ys);
  CompareOptions o = only({"nans", "interp"});
  o.math = {MathMode::Precise};
  Comparison c = compare(divide, {x, y}, o);
  const CompareRow* nans = c.find("nans", "", MathMode::Precise);
  ASSERT_NE(nans, nullptr);
  ASSERT_EQ(nans->outputs.size(), 1u);
  const OutputDifference& q = nans->outputs[0];
  EXPECT_EQ(q.differing, 2u);
  EXPECT_EQ(q.nan_mismatches, 2u);
  EXPECT_TRUE(std::isinf(q.max_abs));
  EXPECT_TRUE(std::isinf(q.max_ulps));
  EXPECT_EQ(q.worst_element, 5u);
  // NaN where the reference has NaN too is no difference.
  EXPECT_EQ(c.find("interp", "", MathMode::Precise)->outputs[0].differing, 0u);
  std::string table = to_string(c);
  EXPECT_NE(table.find("2 (2 NaN)"), std::string::npos) << table;
}

// A row whose kernel was loaded from the disk cache says so beside its
// time; a compiled one gives the time alone, one this process had, cached.
TEST(Compare, TheTableSaysWhichCompileWasALoadFromTheDisk) {
  Comparison c;
  c.program = "p";
  c.reference.backend = "interp";
  c.reference.compiled = true;
  auto row = [](const std::string& variant, bool compiled, bool from_disk, double ms) {
    CompareRow r;
    r.backend = "cpu";
    r.variant = variant;
    r.compiled = compiled;
    r.from_disk = from_disk;
    r.compile_ms = ms;
    return r;
  };
  c.rows = {row("w4", true, true, 4.5), row("w8", true, false, 120.0), row("w16", false, false, 0)};
  std::string table = to_string(c);
  EXPECT_NE(table.find("4.5 disk"), std::string::npos) << table;
  EXPECT_NE(table.find("120.0 "), std::string::npos) << table;
  EXPECT_EQ(table.find("120.0 disk"), std::string::npos) << table;
  EXPECT_NE(table.find("cached"), std::string::npos) << table;
}

TEST(Compare, EveryLinkedBackendAndVariantGivesTheExactProgramsBits) {
  std::vector<std::string> linked;
  for (const std::string& name : backend_names())
    if (std::find(kToys.begin(), kToys.end(), name) == kToys.end()) linked.push_back(name);
  Channel<Attrib1f> x(ramp(1000, 0.5f)), y(ramp(1000, -0.25f));
  Comparison c = compare(exact_program(), {x, y}, only(linked));
  std::size_t expected_rows = 0;
  for (const std::string& name : linked) expected_rows += 2 * find_backend(name).variants().size();
  EXPECT_EQ(c.rows.size(), expected_rows);
  for (const CompareRow& row : c.rows) {
    ASSERT_FALSE(row.failed()) << row.label() << ": " << row.error;
    ASSERT_EQ(row.outputs.size(), 2u) << row.label();
    EXPECT_EQ(row.outputs[0].differing + row.outputs[1].differing, 0u) << row.label() << "\n" << to_string(c);
  }
  std::ostringstream printed;
  printed << c;
  EXPECT_EQ(printed.str(), to_string(c));
  EXPECT_NE(printed.str().find("compare 'exact': 1000 elements in f32 against interp in f64"), std::string::npos)
      << printed.str();
}

// Accumulators are outputs too: every row's sums are compared, each run
// starts from what the accumulator held (three runs a row would otherwise
// add three times), and compare leaves the caller's sums as they were.
TEST(Compare, AccumulatorsAreComparedAndLeftAsTheyWere) {
  std::vector<std::string> linked;
  for (const std::string& name : backend_names())
    if (std::find(kToys.begin(), kToys.end(), name) == kToys.end()) linked.push_back(name);
  Accumulator<Attrib1i> counts(4, "counts");
  Program p = SH_BEGIN_PROGRAM("histogram") {
    Input<Attrib1i> k;
    Output<Attrib1i> same;
    same = k;
    counts.add(k, 1);
  } SH_END;
  Channel<Attrib1i> keys(std::vector<std::int32_t>{0, 1, 1, 3, 3, 3}), out;
  run(p, {keys}, {out}, backend("interp"));
  std::vector<std::int32_t> before = counts.values();
  ASSERT_EQ(before, (std::vector<std::int32_t>{1, 2, 0, 3}));
  Comparison c = compare(p, {keys}, only(linked));
  for (const CompareRow& row : c.rows) {
    ASSERT_FALSE(row.failed()) << row.label() << ": " << row.error;
    ASSERT_EQ(row.outputs.size(), 2u) << row.label();
    EXPECT_EQ(row.outputs[1].name, "accumulator 'counts'");
    EXPECT_EQ(row.outputs[1].differing, 0u) << row.label() << "\n" << to_string(c);
  }
  EXPECT_EQ(counts.values(), before);
  // Sums moved into memory: copied, not shared, by compare's own copies.
  ASSERT_TRUE(counts.storage()->buffer.memory());
  Comparison in_memory = compare(p, {keys}, only(linked));
  for (const CompareRow& row : in_memory.rows) EXPECT_EQ(row.outputs[1].differing, 0u) << row.label();
  EXPECT_EQ(counts.values(), before);
}

TEST(Compare, InputsThatDoNotFitTheProgramAreTheCallersError) {
  Channel<Attrib1f> x(ramp(4, 1.0f));
  Channel<Attrib2f> pairs(ramp(8, 1.0f));
  expect_error([&] { compare(exact_program(), {x}); }, {"compare: program 'exact' takes 2 input channels; 1 were given"});
  expect_error([&] { compare(exact_program(), {x, pairs}); }, {"input channel 1 holds f32x2 but the input is f32"});
  CompareOptions none = only({"interp"});
  none.runs = 0;
  expect_error([&] { compare(exact_program(), {x, x}, none); }, {"runs must be at least 1"});
}

}  // namespace
