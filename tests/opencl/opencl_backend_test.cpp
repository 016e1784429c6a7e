// What the OpenCL backend adds beyond the conformance suite: readable
// source, build errors with log and line, devices, the kernel cache.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>

#include <sh/opencl.hpp>
#include <sh/sh.hpp>

#include "../../backends/opencl/src/runtime.hpp"
#include "../../backends/opencl/src/stream_buffers.hpp"
#include "../common/expect_error.hpp"
#include "../common/fresh.hpp"

namespace {

using namespace sh;

Program shader() {
  return SH_BEGIN_PROGRAM("shader") {
    InputAttrib3f n;
    OutputAttrib1f r;
    Attrib1f d = dot(n, n);
    SH_IF(d > 1.0f) { r = sqrt(d); } SH_ELSE { r = d; } SH_ENDIF;
  } SH_END;
}

TEST(OpenClBackend, ListingIsReadableOpenClC) {
  std::string src = kernel_for(shader(), backend("opencl"))->listing();
  EXPECT_NE(src.find("__kernel void sh_kernel("), std::string::npos) << src;
  EXPECT_NE(src.find("get_global_id(0)"), std::string::npos) << src;
  EXPECT_NE(src.find("if ("), std::string::npos) << src;
  EXPECT_NE(src.find("sqrt("), std::string::npos) << src;
  EXPECT_NE(src.find("#pragma OPENCL FP_CONTRACT OFF"), std::string::npos) << src;
  Options f64;
  f64.precision = Precision::F64;
  EXPECT_NE(kernel_for(shader(), backend("opencl", f64))->listing().find("cl_khr_fp64"), std::string::npos);
}

TEST(OpenClBackend, BuildErrorCarriesLogAndSourceLine) {
  auto device = opencl::open_device("");
  std::string source = "__kernel void broken(__global float* x) {\n  x[0] = 1.0f;\n  x[1] = undefined_name;\n}\n";
  try {
    opencl::build(*device, "broken_program", source, "");
    FAIL() << "the build must fail";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("broken_program"), std::string::npos) << m;
    EXPECT_NE(m.find("build log"), std::string::npos) << m;
    EXPECT_NE(m.find("undefined_name"), std::string::npos) << m;
    EXPECT_NE(m.find("line 3:   x[1] = undefined_name;"), std::string::npos) << m;
  }
}

TEST(OpenClBackend, DevicesAreListedAndChosenByIndexOrName) {
  std::vector<std::string> devices = opencl::devices();
  ASSERT_FALSE(devices.empty());
  EXPECT_EQ(devices[0].rfind("0:0 ", 0), 0u) << devices[0];
  // What each supports, from the device (PoCL's runs on this CPU).
  for (const char* what : {"compute units", "groups up to", "f64 ", "host memory ", "largest buffer "})
    EXPECT_NE(devices[0].find(what), std::string::npos) << what << " in " << devices[0];
  Channel<Attrib3f> n(std::vector<float>{1, 1, 1});
  Channel<Attrib1f> r;
  Options o;
  o.set(opencl::Options{.device = "0:0"});
  run(shader(), {n}, {r}, backend("opencl", o));
  EXPECT_EQ(o.get<opencl::Options>().device, "0:0");
  EXPECT_FLOAT_EQ(r[0], std::sqrt(3.f));
  o.set("opencl.device", "no such device");
  try {
    run(shader(), {n}, {r}, backend("opencl", o));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenCL device matches 'no such device'"), std::string::npos) << e.what();
  }
  // An index too long for an int names no device (it threw a bare "stoi").
  o.set("opencl.device", "99999999999:0");
  try {
    run(shader(), {n}, {r}, backend("opencl", o));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenCL device matches '99999999999:0'"), std::string::npos) << e.what();
  }
}

TEST(OpenClBackend, BuildsOncePerProgramAndOptions) {
  Channel<Attrib3f> n(std::vector<float>{1, 2, 3});
  Channel<Attrib1f> r;
  run(shader(), {n}, {r}, backend("opencl"));
  RunStats again = run(shader(), {n}, {r}, backend("opencl"));
  EXPECT_FALSE(again.compiled);
  EXPECT_FLOAT_EQ(r[0], std::sqrt(14.f));
}

// Generated code is not the user's to warn about: a program whose source
// draws a compiler warning (a truth value or-ed with a constant) builds
// without a word on stderr.  Named after the process, so that its source
// is new to the OpenCL compiler's own cache and is compiled, and with a
// fresh constant, so that it is new to the process's kernels.
TEST(OpenClBackend, BuildsGeneratedCodeWithoutWarnings) {
  std::string name = "no_warnings_" + std::to_string(::getpid());
  const float c = fresh_constant();
  Program p = SH_BEGIN_PROGRAM(name.c_str()) {
    InputAttrib1f x;
    OutputAttrib2f r;
    Attrib1b positive = (x > 0.0f).cast<bool>();
    r(0) = (positive || Attrib1b(true)).cast<float>();
    r(1) = x * c;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{-1.0f, 2.0f});
  Channel<Attrib2f> out;
  testing::internal::CaptureStderr();
  RunStats stats = run(p, {in}, {out}, backend("opencl"));
  std::string said = testing::internal::GetCapturedStderr();
  EXPECT_TRUE(stats.compiled);
  EXPECT_EQ(said.find("warning"), std::string::npos) << said;
  EXPECT_EQ(out.values(), (std::vector<float>{1, -c, 1, 2 * c}));
}

TEST(OpenClBackend, AgreesWithInterpOnTableClampingAndIntegers) {
  Table2D<Attrib2i> t(3, 2);
  t.assign({1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12});
  Program p = SH_BEGIN_PROGRAM("clamp") {
    InputAttrib2f uv;
    InputAttrib2i ij;
    OutputAttrib2i a;
    OutputAttrib2i b;
    a = t(uv);
    b = t[ij] / (ij + 1) + t[ij] % ij;
  } SH_END;
  Channel<Attrib2f> uv(std::vector<float>{-1, 0.5f, 0.99f, 7, 0.4f, std::numeric_limits<float>::quiet_NaN()});
  Channel<Attrib2i> ij(std::vector<std::int32_t>{-5, 1, 2, 0, 1, -1}), a, b, ra, rb;
  run(p, {uv, ij}, {a, b}, backend("opencl"));
  run(p, {uv, ij}, {ra, rb}, backend("interp"));
  EXPECT_EQ(a.values(), ra.values());
  EXPECT_EQ(b.values(), rb.values());
}

}  // namespace

Options width(int lanes) {
  Options o;
  o.set(opencl::Options{.device = {}, .lanes = lanes});
  return o;
}

// The SPMD kernel beside the scalar one: lanes in vector registers, an
// if the lanes may disagree on as masks, one on a uniform as a branch on
// a scalar.
TEST(OpenClBackend, WidthAddsAKernelOfLanesWithMasksOnlyWhereLanesDisagree) {
  Attrib1f scale = 2.0f;
  Program p = SH_BEGIN_PROGRAM("lanes") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x;
    SH_IF(scale > 1.0f) { r = r * scale; } SH_ENDIF;
    SH_IF(x > 0.5f) { r = r + 1.0f; } SH_ENDIF;
  } SH_END;
  std::string scalar = kernel_for(p, backend("opencl", width(1)))->listing();
  EXPECT_EQ(scalar.find("sh_kernel_lanes"), std::string::npos) << scalar;
  std::string lanes = kernel_for(p, backend("opencl", width(8)))->listing();
  EXPECT_NE(lanes.find("__kernel void sh_kernel_lanes("), std::string::npos) << lanes;
  EXPECT_NE(lanes.find("sh_run_float8(in0 + e)"), std::string::npos) << lanes;
  EXPECT_NE(lanes.find("sh_store_run_float8("), std::string::npos) << lanes;
  std::size_t selects = 0;
  for (auto at = lanes.find("select(", lanes.find("sh_kernel_lanes(")); at != std::string::npos; at = lanes.find("select(", at + 1))
    ++selects;
  EXPECT_EQ(selects, 1u) << "only the varying if masks its write: " << lanes;
  std::string kernel = lanes.substr(lanes.find("sh_kernel_lanes("));
  EXPECT_NE(kernel.find("\n  float v"), std::string::npos) << "the uniform condition is one scalar: " << kernel;
  std::size_t uniform_if = kernel.find("\n  if (v");
  ASSERT_NE(uniform_if, std::string::npos) << "the uniform if branches: " << kernel;
  EXPECT_EQ(kernel.substr(uniform_if, kernel.find('\n', uniform_if + 1) - uniform_if).find(".s0"), std::string::npos) << kernel;
  std::vector<float> in;
  for (int i = 0; i < 37; ++i) in.push_back(static_cast<float>(i % 3) * 0.4f);
  for (int w : {1, 2, 4, 8, 16}) {
    Channel<Attrib1f> x(in), r;
    run(p, {x}, {r}, backend("opencl", width(w)));
    for (std::size_t i = 0; i < in.size(); ++i) ASSERT_EQ(r[i], in[i] * 2.0f + (in[i] > 0.5f ? 1.0f : 0.0f)) << w << " " << i;
  }
  EXPECT_THROW(Options().set("opencl.lanes", "3"), Error);
  // Set as a number, not a string: refused as the kernel is compiled.
  Options three;
  three.set(opencl::Options{.device = {}, .lanes = 3});
  try {
    kernel_for(p, backend("opencl", three));
    FAIL() << "3 lanes a work-item were accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("lanes is 3"), std::string::npos) << e.what();
  }
}

// The width "auto" takes the device's float vector width (at most 16).
// A walk's lanes that still run and agree on the next node read it once:
// lanes that left the walk hold other places and must not count, and
// lanes that disagree gather.
TEST(OpenClBackend, AutoWidthTakesTheDeviceWidthAndRunningLanesThatAgreeReadOnce) {
  Table1D<Attrib1f> next(4);
  next.assign(std::vector<float>{3, 0, 1, 2});
  Program walk = SH_BEGIN_PROGRAM("walk") {
    InputAttrib1f start;
    OutputAttrib1f steps;
    Attrib1f at = start;
    steps = 0.0f;
    SH_WHILE(at > 0.5f) {
      at = next[at.cast<int>()];
      steps += 1.0f;
    } SH_ENDWHILE;
  } SH_END;
  auto device = opencl::open_device("");
  std::string listing = kernel_for(walk, backend("opencl"))->listing();
  const std::string per_work_item = "get_global_id(0) * ";
  std::size_t at = listing.find(per_work_item, listing.find("sh_kernel_lanes("));
  int lanes = 1;
  while (device->cpu && lanes * 2 <= static_cast<int>(device->float_lanes) && lanes * 2 <= 16) lanes *= 2;
  EXPECT_EQ(at == std::string::npos ? 1 : std::stoi(listing.substr(at + per_work_item.size())), lanes);
  for (int w : {4, 8, 16}) {
    std::vector<float> starts;
    for (int i = 0; i < 37; ++i) starts.push_back(static_cast<float>(i % 4));
    for (int i = 0; i < 64; ++i) starts.push_back(i % 5 == 0 ? 0.0f : 3.0f);  // the lanes at 0 never run
    Channel<Attrib1f> s(starts), steps;
    run(walk, {s}, {steps}, backend("opencl", width(w)));
    for (std::size_t i = 0; i < starts.size(); ++i)
      EXPECT_EQ(steps[i], starts[i]) << w << " lanes: from " << starts[i] << " the walk takes as many steps";
  }
}

// streams=copied (what a device without shared memory always does) copies
// streams in pieces overlapped with the kernel: the same results as streams
// used in place, at lengths of one piece, of several with a ragged end, and
// for an in-out channel and an accumulator; every stream byte moves once.
TEST(OpenClBackend, CopiedStreamsInPiecesGiveTheResultsOfStreamsInPlace) {
  Accumulator<Attrib1i> counts(4);
  Program p = SH_BEGIN_PROGRAM("pieces") {
    InputAttrib3f v;
    InputAttrib1f k;
    OutputAttrib1f sum;
    Output<Attrib2f> steps;
    Attrib1f n = 0.0f;
    SH_WHILE(n < k) { n += 1.0f; } SH_ENDWHILE;
    sum = v(0) + v(1) * v(2) + n;
    steps = join(n, -k);
    counts.add(k.cast<int>(), Attrib1i(1));
  } SH_END;
  Program twice = SH_BEGIN_PROGRAM("twice") {
    InOut<Attrib1f> x;
    x = x * 2.0f;
  } SH_END;
  Options copied;
  copied.set("opencl.streams", "copied");
  EXPECT_THROW(Options().set("opencl.streams", "sometimes"), Error);
  for (std::size_t length : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, (std::size_t{1} << 18) * 3 + 17}) {
    std::vector<float> v(3 * length), k(length);
    for (std::size_t i = 0; i < length; ++i) {
      v[3 * i] = static_cast<float>(i % 97), v[3 * i + 1] = 0.5f, v[3 * i + 2] = static_cast<float>(i % 5);
      k[i] = static_cast<float>(i % 4);
    }
    Channel<Attrib3f> vs(v);
    Channel<Attrib1f> ks(k), in_place_sum, copied_sum;
    Channel<Attrib2f> in_place_steps, copied_steps;
    counts.clear();
    run(p, {vs, ks}, {in_place_sum, in_place_steps}, backend("opencl"));
    std::vector<int> in_place_counts = counts.values();
    counts.clear();
    RunStats stats = run(p, {vs, ks}, {copied_sum, copied_steps}, backend("opencl", copied));
    ASSERT_EQ(copied_sum.size(), length);
    for (std::size_t i = 0; i < length; ++i) {
      ASSERT_EQ(copied_sum[i], in_place_sum[i]) << length << " elements, element " << i;
      ASSERT_EQ(copied_steps[2 * i], in_place_steps[2 * i]) << length << " elements, element " << i;
      ASSERT_EQ(copied_steps[2 * i + 1], -k[i]) << length << " elements, element " << i;
    }
    EXPECT_EQ(counts.values(), in_place_counts);
    if (length == 0) continue;  // an empty stream runs no kernel
    const auto* moved = stats.details_as<opencl::RunDetails>();
    ASSERT_NE(moved, nullptr);
    constexpr std::size_t kAccumulator = 4 * sizeof(int), kStatus = 3 * sizeof(cl_long);
    EXPECT_EQ(moved->to_device, 4 * length * sizeof(float) + kAccumulator + kStatus) << length;
    EXPECT_EQ(moved->from_device, 3 * length * sizeof(float) + kAccumulator + kStatus) << length;
    EXPECT_EQ(moved->in_place, 0u);
    Channel<Attrib1f> x(k);
    run(twice, {x}, {x}, backend("opencl", copied));
    for (std::size_t i = 0; i < length; ++i) ASSERT_EQ(x[i], 2.0f * k[i]) << length << " elements, element " << i;
  }
}

// A program that adds into an accumulator, with a local array of its
// own, over a long stream: its work-items run in groups the backend
// chooses for the array's size.  PoCL, left to choose, made groups of
// thousands, whose private memory overflowed a thread's stack (a crash).
TEST(OpenClBackend, AccumulatingProgramsWithLargeLocalArraysRunInGroupsThatFit) {
  Accumulator<Attrib1f> total(4, "total");
  Program p = SH_BEGIN_PROGRAM("big_private") {
    InputAttrib1i x;
    LocalArray<Attrib1f> scratch(1024, "scratch");
    SH_FOR(Attrib1i i = 0, i < 1024, i += 1) { scratch.store(i, (x + i).cast<float>()); } SH_ENDFOR;
    Attrib1i at = x % 1024;
    total.add(x % 4, 1.0f + scratch[at] - (x + at).cast<float>());  // 1 where the array held what was stored
  } SH_END;
  constexpr int kElements = 100003;
  std::vector<std::int32_t> xs(kElements);
  for (int k = 0; k < kElements; ++k) xs[k] = k;
  Channel<Attrib1i> in(xs);
  for (int lanes : {1, 8}) {
    Options o;
    o.set("lanes", std::to_string(lanes));
    total.clear();
    run(p, {in}, {}, backend("opencl", o));
    std::vector<float> got = total.values();
    EXPECT_EQ(got[0] + got[1] + got[2] + got[3], static_cast<float>(kElements)) << lanes << " lanes";
  }
}

// A run reports the bytes it moved: a table goes to the device once and
// again only when its contents change; streams are used in place on a
// device that shares host memory and copied both ways elsewhere.
TEST(OpenClBackend, RunsCountTheBytesTheyMoveAndTablesStayOnTheDevice) {
  constexpr std::size_t kElements = 256, kTableBytes = 1000 * sizeof(float);
  Table1D<Attrib1f> table(1000);
  table.assign(std::vector<float>(1000, 0.5f));
  auto adding = [](const Table1D<Attrib1f>& t) {
    return SH_BEGIN_PROGRAM("bytes") {
      InputAttrib1f x;
      OutputAttrib1f r;
      r = x + t[x.cast<int>()];
    } SH_END;
  };
  Program p = adding(table);
  Channel<Attrib1f> x(std::vector<float>(kElements, 3.0f)), r;
  auto moved = [&] {
    RunStats s = run(p, {x}, {r}, backend("opencl"));
    const auto* d = s.details_as<opencl::RunDetails>();
    EXPECT_NE(d, nullptr);
    return d ? *d : opencl::RunDetails{};
  };
  opencl::RunDetails first = moved(), second = moved();
  EXPECT_EQ(r[0], 3.5f);
  EXPECT_EQ(first.tables_kept, 0u);
  EXPECT_EQ(second.tables_kept, kTableBytes);
  EXPECT_EQ(first.to_device - second.to_device, kTableBytes);
  table.assign(std::vector<float>(1000, 1.5f));
  opencl::RunDetails third = moved();
  EXPECT_EQ(r[0], 4.5f);
  EXPECT_EQ(third.to_device, first.to_device);
  constexpr std::size_t kStreamBytes = kElements * sizeof(float);
  if (opencl::open_device("")->unified) {
    EXPECT_EQ(second.in_place, 2 * kStreamBytes);
  } else {
    EXPECT_GE(second.to_device, kStreamBytes);
    EXPECT_GE(second.from_device, kStreamBytes);
  }
  // The same kernel with another table in its place (another scene) holds
  // one copy: the first table goes to the device again after it.
  Table1D<Attrib1f> other(1000);
  other.assign(std::vector<float>(1000, 2.5f));
  RunStats with_other = run(adding(other), {x}, {r}, backend("opencl"));
  EXPECT_FALSE(with_other.compiled) << "the same kernel, another table";
  EXPECT_EQ(r[0], 5.5f);
  opencl::RunDetails fourth = moved();
  EXPECT_EQ(r[0], 4.5f);
  EXPECT_EQ(fourth.to_device, first.to_device);
  second.add(third);
  EXPECT_EQ(second.runs, 2u);
  EXPECT_NE(second.describe().front().find("2 runs moved"), std::string::npos) << second.describe().front();
}

// Through the Kernel API: a run of no elements whose output has no memory
// is nothing to do (clEnqueueReadBuffer was asked to read 0 bytes into
// null: CL_INVALID_VALUE), and a table read through a TableSource, which
// an OpenCL kernel cannot call back into, is refused naming the table.
// The views' table ids are far from those of the process's own tables.
TEST(OpenClBackend, KernelRunsOfNothingAndTablesReadThroughSources) {
  Table1D<Attrib1f> table(4);
  table.name("lookup").assign(std::vector<float>{1, 2, 3, 4});
  const float added = fresh_constant();  // names no other test's kernel keeps
  Program p = SH_BEGIN_PROGRAM("api_edges") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = table[i] + added;
  } SH_END;
  for (const char* streams : {"auto", "copied"}) {
    Options o;
    o.set("opencl.streams", streams);
    std::shared_ptr<Kernel> kernel = kernel_for(p, backend("opencl", o));
    const ir::Program& ir = p.ir();
    RunArgs nothing;
    nothing.inputs.push_back({ir.type_of(ir.inputs[0]), 0, nullptr});
    nothing.outputs.push_back({ir.type_of(ir.outputs[0]), 0, nullptr});
    TableView view;
    view.element = ir.tables[0].element;
    view.dims = {4, 1, 1};
    std::vector<float> values{1, 2, 3, 4};
    view.data = values.data();
    view.id = std::uint64_t{1} << 62;
    nothing.tables.push_back(view);
    RunStats stats;
    EXPECT_NO_THROW(kernel->run(nothing, stats)) << streams;

    struct Spans : TableSource {
      std::vector<float> values{1, 2, 3, 4};
      Span span_of(std::size_t) override { return {values.data(), 0, values.size()}; }
      void count_reads(std::size_t) override {}
    } source;
    RunArgs through = nothing;
    std::vector<std::int32_t> at{2};
    std::vector<float> out(1);
    through.count = 1;
    through.inputs[0] = {ir.type_of(ir.inputs[0]), 1, at.data()};
    through.outputs[0] = {ir.type_of(ir.outputs[0]), 1, out.data()};
    through.tables[0].data = nullptr;
    through.tables[0].source = &source;
    through.tables[0].id = (std::uint64_t{1} << 62) + 1;
    expect_error([&] { kernel->run(through, stats); }, {"table 'lookup'", "TableSource"});
  }
}

// A table's copy on the device goes with the table, whatever kernel read
// it last: programs made, run and dropped one after another (each a kernel
// of its own, kept for the process) each left their table's copy behind.
TEST(OpenClBackend, ATablesCopyOnTheDeviceGoesWithTheTable) {
  constexpr std::size_t kFloats = std::size_t{1} << 18;
  constexpr std::size_t kBytes = kFloats * sizeof(float);
  Table1D<Attrib1f> kept(4);
  kept.assign(std::vector<float>(4, 1.0f));
  const float added = fresh_constant();  // a kernel of its own, shared with no other test's program
  Program probe = SH_BEGIN_PROGRAM("probe") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = kept[i] + added;
  } SH_END;
  Channel<Attrib1i> at(std::vector<std::int32_t>{0, 3});
  auto held = [&] {
    Channel<Attrib1f> out;
    RunStats s = run(probe, {at}, {out}, backend("opencl"));
    return s.details_as<opencl::RunDetails>()->tables_held;
  };
  const std::size_t before = held();
  for (int k = 0; k < 4; ++k) {
    Table1D<Attrib1f> table(kFloats);
    table.assign(std::vector<float>(kFloats, static_cast<float>(k)));
    const float c = fresh_constant();  // a kernel of its own
    Program p = SH_BEGIN_PROGRAM("reads_its_own") {
      InputAttrib1i i;
      OutputAttrib1f y;
      y = table[i] + c;
    } SH_END;
    Channel<Attrib1f> out;
    run(p, {at}, {out}, backend("opencl"));
    EXPECT_EQ(out[1], static_cast<float>(k) + c);
    EXPECT_EQ(held(), before + kBytes) << "held while its table lives, round " << k;
  }
  EXPECT_EQ(held(), before) << "the copies of the tables gone went with them";
}

// Copied streams' buffers are lent to runs and given back to the device's
// pool, where any kernel reuses one of its size and flags; idle ones are
// kept under the pool's budget, those idle longest let go first (each
// kernel kept its own for the process).
TEST(OpenClBackend, IdleStreamBuffersAreReusedAndKeptUnderABudget) {
  std::shared_ptr<opencl::Device> device = opencl::open_device("");
  int made = 0;
  auto maker = [&](std::size_t size) {
    return [&made, &device, size] {
      ++made;
      opencl::Buffer b;
      cl_int err = CL_SUCCESS;
      b.mem = clCreateBuffer(device->context, CL_MEM_READ_ONLY, size, nullptr, &err);
      EXPECT_EQ(err, CL_SUCCESS);
      return b;
    };
  };
  opencl::StreamBuffers pool(3 << 10);
  {
    opencl::Borrowed run(pool);
    cl_mem a = run.take(1 << 10, CL_MEM_READ_ONLY, maker(1 << 10));
    cl_mem b = run.take(1 << 10, CL_MEM_READ_ONLY, maker(1 << 10));
    EXPECT_NE(a, b);
  }
  EXPECT_EQ(made, 2);
  EXPECT_EQ(pool.idle_bytes(), 2u << 10) << "given back when the run ends";
  {
    opencl::Borrowed run(pool);
    run.take(1 << 10, CL_MEM_READ_ONLY, maker(1 << 10));
    EXPECT_EQ(made, 2) << "an idle buffer of the size lent again";
    run.take(1 << 10, CL_MEM_WRITE_ONLY, maker(1 << 10));
    EXPECT_EQ(made, 3) << "not one made with other flags";
    run.take(2 << 10, CL_MEM_READ_ONLY, maker(2 << 10));
    EXPECT_EQ(made, 4);
  }
  EXPECT_EQ(pool.idle_bytes(), 3u << 10) << "5 KiB given back, the longest idle let go down to the budget";
}

// Views the Kernel API's caller made, without an owner, are their slot's
// alone, whatever ids they carry: two tables left at id 0 were one copy
// (every slot read the first), and a view given another table's id read
// that table.
TEST(OpenClBackend, ViewsWithoutAnOwnerAreTheirSlotsAlone) {
  Table1D<Attrib1f> a(4), b(4);
  a.name("a").assign(std::vector<float>{1, 2, 3, 4});
  b.name("b").assign(std::vector<float>{10, 20, 30, 40});
  const float added = fresh_constant();
  Program p = SH_BEGIN_PROGRAM("two_tables") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = a[i] + b[i] * 100.0f + added;
  } SH_END;
  Channel<Attrib1i> at(std::vector<std::int32_t>{0, 1, 2, 3});
  Channel<Attrib1f> through_run;
  run(p, {at}, {through_run}, backend("opencl"));  // the process's own tables, their ids, owned
  std::shared_ptr<Kernel> kernel = kernel_for(p, backend("opencl"));
  const ir::Program& ir = p.ir();
  std::vector<std::int32_t> is{0, 1, 2, 3};
  std::vector<float> first{1, 2, 3, 4}, second{10, 20, 30, 40}, out(4);
  RunArgs args;
  args.count = 4;
  args.inputs.push_back({ir.type_of(ir.inputs[0]), 4, is.data()});
  args.outputs.push_back({ir.type_of(ir.outputs[0]), 4, out.data()});
  for (const ir::TableDecl& table : ir.tables) {
    std::vector<float>* values = table.name == "a" ? &first : &second;
    TableView view;
    view.element = ir.tables[0].element;
    view.dims = {4, 1, 1};
    view.data = values->data();
    args.tables.push_back(view);  // id 0, version 0, no owner: both
  }
  RunStats stats;
  kernel->run(args, stats);
  EXPECT_EQ(std::vector<float>(out.begin(), out.end()), through_run.values()) << "two slots at id 0";
  second = {5, 6, 7, 8};
  for (TableView& view : args.tables) {
    view.id = 1;  // an id that may be one of the process's own tables'
    view.version = view.data == second.data();
  }
  kernel->run(args, stats);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(out[k], first[k] + second[k] * 100.0f + added) << "element " << k;
}

// The device SH_OPENCL_DEVICE names is part of the process's kernel key: a
// kernel made for one device was run after the variable named another (one
// that does not exist, here, which a kernel of its own then reports).
TEST(OpenClBackend, AKernelIsForTheDeviceTheEnvironmentNames) {
  const float added = fresh_constant();
  Program p = SH_BEGIN_PROGRAM("on_the_named_device") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x + added;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>{1.0f}), out;
  run(p, {in}, {out}, backend("opencl"));
  {
    // The caller's choice put back however the block ends: a bogus one
    // left set would fail every later OpenCL test in the process.
    struct Named {
      const char* before = std::getenv("SH_OPENCL_DEVICE");
      std::string kept = before ? before : "";
      Named() { setenv("SH_OPENCL_DEVICE", "no device is called this", 1); }
      ~Named() { before ? setenv("SH_OPENCL_DEVICE", kept.c_str(), 1) : unsetenv("SH_OPENCL_DEVICE"); }
    } named;
    expect_error([&] { run(p, {in}, {out}, backend("opencl")); }, {"no device is called this"});
  }
  EXPECT_FALSE(run(p, {in}, {out}, backend("opencl")).compiled) << "the first device's kernel again";
  EXPECT_EQ(out[0], 1 + added);
}
