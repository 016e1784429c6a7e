// Sh's host-memory API (<sh/compat.hpp>: ShHostMemory, ShChannel(memory,
// count), memory(), count(), texture.memory(m)) on every backend and mode:
// channels on the user's memory are that memory, results are in it when the
// run returns, and a table on memory is sent again after dirty(), never
// served stale from a backend's copy (opencl's device buffers, mpi's ranks).
#include <sh/compat.hpp>

#include "harness.hpp"

namespace conformance {
namespace {

constexpr std::size_t kElements = 37;  // a multiple of no SIMD width or chunk

sh::Program twice_plus_one() {
  return SH_BEGIN_PROGRAM("host_memory") {
    ShInputAttrib3f x;
    ShOutputAttrib3f y;
    y = x * 2.0f + 1.0f;
  } SH_END;
}

float input_value(std::size_t k) { return static_cast<float>(k) * 0.5f - 20.f; }

TEST_P(Conformance, ChannelsOnUserMemoryAreReadAndWrittenInPlace) {
  // The arrays start one float in: 4-byte aligned but not 8 or 16, as data
  // a user hands over may be.  The output memory holds one element more
  // than the stream, and a float lies before each: neither may be written.
  const std::size_t n = kElements, scalars = 3 * kElements;
  std::vector<float> in_store(scalars + 1), out_store(scalars + 4, -7.f);
  float* in = in_store.data() + 1;
  float* out = out_store.data() + 1;
  for (std::size_t k = 0; k < scalars; ++k) in[k] = input_value(k);
  ShHostMemoryPtr in_memory = new ShHostMemory(scalars * sizeof(float), in, SH_FLOAT);
  ShHostMemoryPtr out_memory = new ShHostMemory((scalars + 3) * sizeof(float), out, SH_FLOAT);
  ShChannel<ShAttrib3f> xs(in_memory, n), ys(out_memory, n);
  ASSERT_EQ(xs.data(), in) << "the channel is the user's memory, not a copy";
  ASSERT_EQ(ys.data(), out);
  run(twice_plus_one(), {xs}, {ys});
  for (std::size_t k = 0; k < scalars; ++k) {
    EXPECT_EQ(out[k], 2.f * input_value(k) + 1.f) << "scalar " << k;
    EXPECT_EQ(in[k], input_value(k)) << "an input is never written";
  }
  EXPECT_EQ(out_store[0], -7.f) << "before the channel";
  for (std::size_t k = scalars; k < scalars + 3; ++k) EXPECT_EQ(out[k], -7.f) << "past the channel's count, scalar " << k;
}

TEST_P(Conformance, ShStyleAssignmentLeavesResultsInTheMemory) {
  // As Sh programs did: memory allocated by ShHostMemory, filled through its
  // host storage, results read back through the output channel's memory.
  const std::size_t n = kElements;
  ShHostMemoryPtr in_memory = new ShHostMemory(3 * n * sizeof(float), SH_FLOAT);
  float* in = static_cast<float*>(in_memory->hostStorage()->data());
  for (std::size_t k = 0; k < 3 * n; ++k) in[k] = input_value(k);
  ShChannel<ShAttrib3f> xs(in_memory, n);
  ShChannel<ShAttrib3f> ys(new ShHostMemory(3 * n * sizeof(float), SH_FLOAT), n);
  ShProgram p = twice_plus_one();
  const std::string before = sh::default_backend_name();
  shUseBackend(mode().backend);  // the assignment runs on the default backend
  ys = p << xs;
  shUseBackend(before);
  ShHostStoragePtr results = shref_dynamic_cast<ShHostStorage>(ys.memory()->findStorage("host"));
  results->sync();
  const float* out = static_cast<const float*>(results->data());
  for (std::size_t k = 0; k < 3 * n; ++k) EXPECT_EQ(out[k], 2.f * input_value(k) + 1.f) << "scalar " << k;
}

TEST_P(Conformance, IntDoubleAndBoolChannelsOnMemory) {
  sh::Program p = SH_BEGIN_PROGRAM("typed_memory") {
    sh::Input<sh::Attrib2i> i;
    sh::Input<sh::Attrib1d> d;
    sh::Output<sh::Attrib2i> i_out;
    sh::Output<sh::Attrib1d> d_out;
    sh::Output<sh::Attrib1b> positive;
    i_out = i * 3 - 1;
    d_out = d * 0.25;
    positive = d.cast<bool>();
  } SH_END;
  const std::size_t n = kElements;
  std::vector<std::int32_t> is(2 * n), is_out(2 * n), flags(n);
  std::vector<double> ds(n), ds_out(n);
  for (std::size_t k = 0; k < n; ++k) {
    is[2 * k] = static_cast<std::int32_t>(k);
    is[2 * k + 1] = -static_cast<std::int32_t>(k) * 1000;
    ds[k] = static_cast<double>(k) - 18.5;
  }
  auto wrap = [](auto& v, ShValueType type) { return ShMemoryPtr(new ShHostMemory(v.size() * sizeof v[0], v.data(), type)); };
  ShChannel<sh::Attrib2i> ci(wrap(is, SH_INT), n), ci_out(wrap(is_out, SH_INT), n);
  ShChannel<sh::Attrib1d> cd(wrap(ds, SH_DOUBLE), n), cd_out(wrap(ds_out, SH_DOUBLE), n);
  ShChannel<sh::Attrib1b> cflags(wrap(flags, SH_INT), n);  // bools are stored as int32 0/1
  run(p, {ci, cd}, {ci_out, cd_out, cflags});
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(is_out[2 * k], is[2 * k] * 3 - 1);
    EXPECT_EQ(is_out[2 * k + 1], is[2 * k + 1] * 3 - 1);
    EXPECT_EQ(ds_out[k], ds[k] * 0.25);
    EXPECT_EQ(flags[k], ds[k] > 0 ? 1 : 0) << "bool of " << ds[k];
  }
}

TEST_P(Conformance, ChannelCountAndMemoryRoundTrip) {
  // A channel that allocated its own storage hands it out as memory without
  // a copy; a channel on that memory reads the same elements.
  std::vector<float> values(3 * kElements);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = input_value(k);
  ShChannel<ShAttrib3f> owned(values);
  ShMemoryPtr memory = owned.memory();
  ASSERT_TRUE(memory);
  EXPECT_EQ(memory->data(), owned.data());
  EXPECT_EQ(memory->bytes(), values.size() * sizeof(float));
  EXPECT_EQ(owned.memory(), memory) << "the same memory every time";
  ShChannel<ShAttrib3f> again(memory, kElements), out;
  EXPECT_EQ(again.count(), kElements);
  EXPECT_EQ(again.memory(), memory);
  run(twice_plus_one(), {again}, {out});
  EXPECT_EQ(out.count(), kElements);
  for (std::size_t k = 0; k < values.size(); ++k) EXPECT_EQ(out[k], 2.f * values[k] + 1.f);

  // memory(m, count) moves a channel onto other memory, for every stream
  // already built from it, and may hold fewer elements than the memory.
  std::vector<float> other(3 * kElements + 6, 4.f);
  sh::Stream inputs(std::vector<std::shared_ptr<sh::detail::Buffer>>{owned});
  owned.memory(new ShHostMemory(other.size() * sizeof(float), other.data(), SH_FLOAT), kElements - 1);
  EXPECT_EQ(owned.count(), kElements - 1);
  ShChannel<ShAttrib3f> fewer;
  run(twice_plus_one(), inputs.channels(), {fewer});
  ASSERT_EQ(fewer.count(), kElements - 1);
  for (std::size_t k = 0; k < 3 * (kElements - 1); ++k) EXPECT_EQ(fewer[k], 9.f);
}

TEST_P(Conformance, MemoryAndChannelsShareOwnership) {
  ShMemoryPtr results = new ShHostMemory(3 * kElements * sizeof(float), SH_FLOAT);
  {
    std::vector<float> values(3 * kElements, 1.5f);
    ShChannel<ShAttrib3f> in(values), out(results, kElements);
    EXPECT_EQ(results.use_count(), 2) << "the channel holds the memory too";
    run(twice_plus_one(), {in}, {out});
  }
  EXPECT_EQ(results.use_count(), 1);
  const float* kept = static_cast<const float*>(results->data());
  for (std::size_t k = 0; k < 3 * kElements; ++k) ASSERT_EQ(kept[k], 4.f) << "the results outlive the channel";

  // And a channel keeps memory alive that no pointer of the user's holds.
  ShChannel<ShAttrib3f> in(new ShHostMemory(3 * kElements * sizeof(float), SH_FLOAT), kElements), out;
  std::fill_n(static_cast<float*>(in.memory()->data()), 3 * kElements, -1.f);
  run(twice_plus_one(), {in}, {out});
  for (std::size_t k = 0; k < 3 * kElements; ++k) ASSERT_EQ(out[k], -1.f);
}

// A run that reads table `t` at elements 0..3 and returns them.
sh::Program read_four(const ShArray1D<ShAttrib1f>& t) {
  return SH_BEGIN_PROGRAM("table_on_memory") {
    sh::Input<ShAttrib1i> i;
    ShOutputAttrib1f v;
    v = t[i];
  } SH_END;
}

// On mpi every rank takes a share (a static schedule), so a rank that kept
// a stale copy of the table shows in the results.
std::vector<float> run_reads(const Conformance& c, const sh::Program& p) {
  sh::Options o;
  if (c.mode().backend == "mpi") o.set("mpi.schedule", "static");
  ShChannel<ShAttrib1i> is(std::vector<int>{0, 1, 2, 3});
  ShChannel<ShAttrib1f> out;
  sh::run(p, {is}, {out}, c.choice(o));
  return out.values();
}

TEST_P(Conformance, TablesOnMemoryAreSentAgainAfterDirty) {
  std::vector<float> first = {1, 2, 3, 4}, second = {10, 20, 30, 40};
  ShHostMemoryPtr a = new ShHostMemory(4 * sizeof(float), first.data(), SH_FLOAT);
  ShHostMemoryPtr b = new ShHostMemory(4 * sizeof(float), second.data(), SH_FLOAT);
  // b's version is older than a's: moving the table onto b must still be news.
  b->dirty();
  a->dirty();
  a->dirty();
  ShArray1D<ShAttrib1f> t(4);
  t.name("lut");
  t.memory(a);
  EXPECT_EQ(t.memory(), a);
  sh::Program p = read_four(t);
  EXPECT_EQ(run_reads(*this, p), first);

  first[2] = 300;
  a->hostStorage()->dirty();
  EXPECT_EQ(run_reads(*this, p), (std::vector<float>{1, 2, 300, 4})) << "written, then dirty()";

  t.memory(b);
  EXPECT_EQ(run_reads(*this, p), second) << "the table moved to other memory";
  second[0] = -5;
  b->dirty();
  EXPECT_EQ(run_reads(*this, p), (std::vector<float>{-5, 20, 30, 40}));

  t.assign({7, 8, 9, 6});
  EXPECT_EQ(second, (std::vector<float>{7, 8, 9, 6})) << "assign() writes the memory the table is";
  EXPECT_EQ(run_reads(*this, p), second);
}

TEST_P(Conformance, TableMemoryReadBackAndWritten) {
  // A table that allocated its own storage hands it out as memory; written
  // through it and marked dirty, the next run reads the new elements.
  ShArray1D<ShAttrib1f> t(4);
  t.assign({1, 2, 3, 4});
  sh::Program p = read_four(t);
  EXPECT_EQ(run_reads(*this, p), (std::vector<float>{1, 2, 3, 4}));
  ShMemoryPtr memory = t.memory();
  ASSERT_EQ(memory->bytes(), 4 * sizeof(float));
  float* data = static_cast<float*>(memory->data());
  EXPECT_EQ(data[3], 4.f);
  data[1] = -2.f;
  memory->dirty();
  EXPECT_EQ(run_reads(*this, p), (std::vector<float>{1, -2, 3, 4}));
  // Filled through its memory alone, never by assign(): a table all the same.
  ShArray1D<ShAttrib1f> fresh(4);
  sh::Program q = read_four(fresh);
  float* bytes = static_cast<float*>(fresh.memory()->data());
  for (int i = 0; i < 4; ++i) bytes[i] = 10.f + static_cast<float>(i);
  fresh.memory()->dirty();
  EXPECT_EQ(run_reads(*this, q), (std::vector<float>{10, 11, 12, 13}));
}

// An output in the memory of a table its own program reads is refused: the
// run would read elements it had already written, in an order each backend
// chooses (the interpreter gave 1 2 3 ... 20, the cpu backend's batches of
// 16 lanes 1 1 11 21 ...).  The same memory read by one program and
// written by the next (run_fused's in-place blur, run apart) stays allowed.
TEST_P(Conformance, AnOutputInTheMemoryOfATableItsProgramReadsIsRefused) {
  const int n = 40;
  sh::Channel<sh::Attrib1f> out(n);
  sh::Table1D<sh::Attrib1f> t(n);
  t.name("previous");
  t.memory(out.memory());
  t.assign(std::vector<float>(n, 0.0f));
  sh::Program p = SH_BEGIN_PROGRAM("cascade") {
    sh::Output<sh::Attrib1f> y;
    y = t[sh::position() - 1] + 1.0f;
  } SH_END;
  try {
    run(p, {}, {out});
    ADD_FAILURE() << "an output over a table its program reads ran";
  } catch (const sh::Error& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("output channel 0 lies in the memory of table 0 'previous'"), std::string::npos) << what;
  }
  EXPECT_EQ(out.values(), std::vector<float>(n, 0.0f)) << "nothing written";
  sh::Channel<sh::Attrib1f> own(n);
  run(p, {}, {own});
  EXPECT_EQ(own[0], 1.0f);
  EXPECT_EQ(own[n - 1], 1.0f);
}

}  // namespace
}  // namespace conformance
