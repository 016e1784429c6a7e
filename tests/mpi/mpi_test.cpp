// The mpi backend under mpirun (-np 3 in CTest): per-rank statistics,
// tables sent once per version, uniforms, errors on one rank.
#include <gtest/gtest.h>

#include <sh/mpi.hpp>
#include <sh/sh.hpp>
#include <sh/waves.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

namespace {

using namespace sh;

// An mpi run's own figures, which every mpi run has.
const mpi::RunDetails& details(const RunStats& s) {
  const auto* d = s.details_as<mpi::RunDetails>();
  if (!d) throw std::runtime_error("an mpi run without mpi::RunDetails");
  return *d;
}

TEST(Mpi, EveryRankComputesAndResultsLandInOrder) {
  Program p = SH_BEGIN_PROGRAM("work") {
    InputAttrib1f x;
    OutputAttrib1f y;
    Attrib1f acc = 0.0f;
    SH_FOR(Attrib1f i = 0.0f, i < 200.0f, i += 1.0f) { acc += sin(x + i); } SH_ENDFOR;
    y = acc;
  } SH_END;
  std::vector<float> xs(30000);
  for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = static_cast<float>(i) * 1e-3f;
  Channel<Attrib1f> in(xs), out, reference;
  RunStats s = run(p, {in}, {out}, backend("mpi"));
  run(p, {in}, {reference}, backend("cpu"));
  EXPECT_EQ(out.values(), reference.values());
  const std::vector<mpi::PartStats>& parts = details(s).parts;
  ASSERT_EQ(static_cast<int>(parts.size()), mpi::size());
  std::size_t elements = 0, chunks = 0;
  for (const mpi::PartStats& part : parts) {
    elements += part.elements;
    chunks += part.chunks;
    // Each serving rank gets a chunk before rank 0 computes one.
    if (part.part != 0) {
      EXPECT_GT(part.elements, 0u) << "rank " << part.part << " computed nothing";
    }
  }
  EXPECT_EQ(elements, xs.size());
  EXPECT_GE(chunks, 8u * parts.size()) << "many more chunks than ranks";
}

// A uniform changed from +0 to -0 is a change (they compare equal): every
// rank divides by the new one.
TEST(Mpi, AUniformsSignOfZeroReachesEveryRank) {
  Attrib1f u = 0.0f;
  Program p = SH_BEGIN_PROGRAM("by_zero") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x / u;
  } SH_END;
  Channel<Attrib1f> in(std::vector<float>(64, 1.0f)), out;
  run(p, {in}, {out}, backend("mpi"));
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(out[i], std::numeric_limits<float>::infinity()) << i;
  u = -0.0f;
  run(p, {in}, {out}, backend("mpi"));
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(out[i], -std::numeric_limits<float>::infinity()) << "element " << i;
}

TEST(Mpi, TablesAndUniformsGoOutOncePerVersion) {
  Table1D<Attrib1f> t(20000);
  std::vector<float> data(20000, 1.0f);
  t.assign(data);
  Attrib1f scale = 2.0f;
  Program p = SH_BEGIN_PROGRAM("lookup") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = t[i] * scale;
  } SH_END;
  std::vector<std::int32_t> is(1000);
  for (int k = 0; k < 1000; ++k) is[k] = k * 7;
  Channel<Attrib1i> in(is);
  Channel<Attrib1f> out;
  auto sent = [](const RunStats& s) { return details(s).parts.at(0).bytes_sent; };
  RunStats first = run(p, {in}, {out}, backend("mpi"));
  RunStats second = run(p, {in}, {out}, backend("mpi"));
  EXPECT_EQ(out[5], 2.f);
  if (mpi::size() > 1) {
    // The 80 000-byte table went out with the first run only (what else is
    // sent varies by a few hundred bytes with how chunks fall).
    EXPECT_GE(sent(first), sent(second) + 70000u) << "the unchanged table was sent again";
    scale = 3.0f;
    RunStats third = run(p, {in}, {out}, backend("mpi"));
    EXPECT_LT(sent(third), sent(first)) << "a new uniform value sends no table";
    EXPECT_EQ(out[999], 3.f);
    data[7 * 999] = 5.0f;
    t.assign(data);
    RunStats fourth = run(p, {in}, {out}, backend("mpi"));
    EXPECT_GE(sent(fourth), 80000u) << "a new table version is sent";
    EXPECT_EQ(out[999], 15.f);
  }
}

TEST(Mpi, ARankThatFailsIsNamedAndTheJobGoesOn) {
  Program p = SH_BEGIN_PROGRAM("faulty") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x;
    SH_WHILE(y > 0.0f) { y += 1.0f; } SH_ENDWHILE;  // endless where x > 0
  } SH_END;
  std::vector<float> xs(4000, -1.0f);
  xs[3999] = 1.0f;
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.max_loop_iterations = 1000;
  try {
    run(p, {in}, {out}, backend("mpi", o));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("mpi backend: rank "), std::string::npos) << m;
    EXPECT_NE(m.find("element 3999 "), std::string::npos) << "its place in the whole stream, not in a rank's share: " << m;
    EXPECT_NE(m.find("faulty"), std::string::npos) << m;
  }
  xs[3999] = -2.0f;
  Channel<Attrib1f> fine(xs);
  run(p, {fine}, {out}, backend("mpi", o));
  EXPECT_EQ(out[3999], -2.f);
}

// The most bytes of tables a serving rank keeps after a run.
std::size_t held_by_serving_ranks(const RunStats& s) {
  std::size_t most = 0;
  for (const mpi::PartStats& part : details(s).parts)
    if (part.part != 0) most = std::max(most, part.held_bytes);
  return most;
}

// x + t[x]: a program that reads one table.
Program adding(const Table1D<Attrib1f>& t) {
  return SH_BEGIN_PROGRAM("adding") {
    InputAttrib1f x;
    OutputAttrib1f r;
    r = x + t[x.cast<int>()];
  } SH_END;
}

// One kernel run over a new table each time (a new scene for the same
// tracer): the serving ranks keep one copy, not one per table ever sent.
TEST(Mpi, ServingRanksKeepOneCopyOfEachTableAKernelReads) {
  constexpr std::size_t kTableBytes = 4096 * sizeof(float);
  Channel<Attrib1f> x(std::vector<float>(3000, 7.0f)), r;
  // What the ranks hold besides (earlier tests' kernels' tables), and
  // this kernel's one table.
  std::size_t held = 0;
  for (int scene = 0; scene < 4; ++scene) {
    Table1D<Attrib1f> t(4096);
    t.assign(std::vector<float>(4096, static_cast<float>(scene)));
    RunStats s = run(adding(t), {x}, {r}, backend("mpi"));
    EXPECT_EQ(r[2999], 7.0f + static_cast<float>(scene));
    if (scene == 0) held = held_by_serving_ranks(s);
    EXPECT_EQ(held_by_serving_ranks(s), held) << "scene " << scene;
  }
  if (mpi::size() > 1) {
    EXPECT_GE(held, kTableBytes);
  }
  // A second kernel reading the same table: one copy still.
  Table1D<Attrib1f> t(4096);
  t.assign(std::vector<float>(4096, 1.0f));
  run(adding(t), {x}, {r}, backend("mpi"));
  Program twice = SH_BEGIN_PROGRAM("held_twice") {
    InputAttrib1f y;
    OutputAttrib1f q;
    q = y * t[y.cast<int>()];
  } SH_END;
  RunStats s = run(twice, {x}, {r}, backend("mpi"));
  EXPECT_EQ(r[0], 7.0f);
  EXPECT_EQ(held_by_serving_ranks(s), held);
}

// A kernel made by the backend itself and destroyed: the serving ranks let
// go of it and of the table only it read.
TEST(Mpi, ADestroyedKernelsTableIsLetGo) {
  Table1D<Attrib1f> t(4096);
  t.assign(std::vector<float>(4096, 1.0f));
  Program p = adding(t);
  Channel<Attrib1f> x(std::vector<float>(3000, 7.0f)), r;
  std::size_t before = held_by_serving_ranks(run(p, {x}, {r}, backend("mpi")));
  std::vector<float> table(2 * 4096, 2.0f), in(3000, 7.0f), out(3000);
  {
    std::unique_ptr<Kernel> own = find_backend("mpi").compile(passes::legalize(p.ir()), Options{});
    RunArgs args;
    args.count = in.size();
    args.domain.extent = {in.size(), 1, 1};
    args.inputs.push_back({ir::Type{ir::Scalar::F32, 1}, in.size(), in.data()});
    args.outputs.push_back({ir::Type{ir::Scalar::F32, 1}, out.size(), out.data()});
    TableView view;
    view.element = ir::Type{ir::Scalar::F32, 1};
    view.dims = {2 * 4096, 1, 1};
    view.data = table.data();
    view.id = std::uint64_t{1} << 60;  // no table of the runtime's
    view.version = 1;
    args.tables.push_back(view);
    RunStats s;
    own->run(args, s);
    EXPECT_EQ(out[2999], 9.0f);
    if (mpi::size() > 1) {
      EXPECT_EQ(held_by_serving_ranks(s), before + table.size() * sizeof(float));
    }
  }
  EXPECT_EQ(held_by_serving_ranks(run(p, {x}, {r}, backend("mpi"))), before) << "the destroyed kernel's table let go";
  EXPECT_EQ(r[0], 8.0f);
}

// Chunks of ten floats: each result is 16 bytes of place, 40 of floats and
// 8 of findings, 64 bytes, which the suite's run with SH_MPI_MESSAGE_BYTES=64
// sends as one whole piece and an empty one.
TEST(Mpi, ResultsOfAWholeNumberOfMessagePiecesLand) {
  Program p = SH_BEGIN_PROGRAM("pieces") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f + 1.0f;
  } SH_END;
  std::vector<float> xs(1000);
  for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = static_cast<float>(i);
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.set(mpi::Options{.chunk = 10});
  run(p, {in}, {out}, backend("mpi", o));
  for (std::size_t i = 0; i < xs.size(); ++i) ASSERT_EQ(out[i], 2.0f * xs[i] + 1.0f) << "element " << i;
}

// Checked mode on the ranks (interp as the local backend): each kind of
// finding comes back from whichever rank computed it, from the element
// first in the stream, numbered in the whole stream.
TEST(Mpi, CheckedModeFindingsComeBackFromEveryRank) {
  Table1D<Attrib1f> t(3);
  t.assign({1, 2, 3});
  Program p = SH_BEGIN_PROGRAM("checked_ranks") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = sqrt(x) + t[x];
  } SH_END;
  std::vector<float> xs(6000, 1.0f);
  xs[5100] = 7.0f;   // out of range
  xs[3000] = -4.0f;  // NaN and out of range
  xs[4500] = -1.0f;  // a later NaN
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.checked = true;
  o.set(mpi::Options{.local = "interp", .chunk = 100});
  RunStats s = run(p, {in}, {out}, backend("mpi", o));
  std::string all;
  for (const std::string& d : s.diagnostics) all += d + "\n";
  ASSERT_EQ(s.diagnostics.size(), 2u) << all;
  EXPECT_NE(all.find("first NaN: element 3000,"), std::string::npos) << all;
  EXPECT_NE(all.find("first out-of-range table read: element 3000,"), std::string::npos) << all;
}

}  // namespace

namespace {

// A local backend that runs interp's kernels after checking what each run
// hands it: every stream view holds the run's elements, as a backend that
// copies a view (opencl on a device of its own memory) takes it to.
class CheckedViews : public Kernel {
 public:
  explicit CheckedViews(std::unique_ptr<Kernel> inner) : inner_(std::move(inner)) {}
  void run(const RunArgs& args, RunStats& stats) override {
    for (const std::vector<BufferView>* views : {&args.inputs, &args.outputs})
      for (const BufferView& v : *views)
        if (v.count != args.count)
          throw Error("a view of " + std::to_string(v.count) + " elements for a run of " + std::to_string(args.count));
    inner_->run(args, stats);
  }

 private:
  std::unique_ptr<Kernel> inner_;
};

class ViewsChecked : public Backend {
 public:
  std::string name() const override { return "views_checked"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const Options& o) override {
    return std::make_unique<CheckedViews>(find_backend("interp").compile(p, o));
  }
};

const bool registered = (register_backend("views_checked", [] { return std::make_unique<ViewsChecked>(); }), true);

// Rank 0 computes its share of the stream itself (the last, under a
// static schedule), in pieces: each a view of its own elements, not of
// the channel from the piece on.
TEST(Mpi, RankZerosPiecesAreViewsOfTheirOwnElements) {
  ASSERT_TRUE(registered);
  Program p = SH_BEGIN_PROGRAM("pieces") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 3.0f;
  } SH_END;
  std::vector<float> xs(5000);
  for (std::size_t i = 0; i < xs.size(); ++i) xs[i] = static_cast<float>(i);
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.set(mpi::Options{.local = "views_checked", .schedule = mpi::Schedule::Static});
  RunStats s = run(p, {in}, {out}, backend("mpi", o));
  EXPECT_GT(details(s).parts.at(0).elements, 0u) << "rank 0 computed nothing";
  for (std::size_t i = 0; i < xs.size(); ++i) ASSERT_EQ(out[i], 3.0f * xs[i]) << i;
}

TEST(Mpi, StaticScheduleGivesEachRankOneShareAndBadSettingsAreErrors) {
  using namespace sh;
  Program p = SH_BEGIN_PROGRAM("share") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 3.0f;
  } SH_END;
  std::vector<float> xs(9001, 1.0f);
  Channel<Attrib1f> in(xs), out;
  Options o;
  o.set(mpi::Options{.schedule = mpi::Schedule::Static});
  RunStats s = run(p, {in}, {out}, backend("mpi", o));
  const std::vector<mpi::PartStats>& parts = details(s).parts;
  ASSERT_EQ(static_cast<int>(parts.size()), mpi::size());
  // Rank r at r, whatever order the ranks reported in; each has the share
  // that is its rank's (rank r the r-th, rank 0 the last): the sizes tell.
  std::size_t share = (xs.size() + parts.size() - 1) / parts.size();
  for (std::size_t r = 0; r < parts.size(); ++r) {
    const mpi::PartStats& part = parts[r];
    EXPECT_EQ(part.part, static_cast<int>(r));
    EXPECT_EQ(part.chunks, 1u) << "rank " << part.part;
    std::size_t index = r == 0 ? parts.size() - 1 : r - 1, begin = std::min(index * share, xs.size());
    EXPECT_EQ(part.elements, std::min(share, xs.size() - begin)) << "rank " << r;
  }
  EXPECT_EQ(out[9000], 3.f);
  EXPECT_THROW(o.set("schedule", "round-robin"), Error);
  EXPECT_THROW(o.set("chunk", "-5"), Error);
  o.set("schedule", "dynamic").set("chunk", "100");
  s = run(p, {in}, {out}, backend("mpi", o));
  std::size_t chunks = 0;
  for (const mpi::PartStats& part : details(s).parts) chunks += part.chunks;
  EXPECT_EQ(chunks, 91u);
}

}  // namespace

namespace {

using namespace sh;

Options split(std::uint64_t cache_blocks, const std::string& local = "cpu") {
  Options o;
  o.set(mpi::Options{.local = local, .split_tables = 0, .block_bytes = 256, .cache_blocks = cache_blocks});
  return o;
}

const std::vector<mpi::TableCacheStats>& caches(const RunStats& s) { return details(s).caches; }

const mpi::TableCacheStats& cache_of(const RunStats& s, const std::string& table) {
  for (const mpi::TableCacheStats& c : caches(s))
    if (c.table == table) return c;
  throw std::runtime_error("no cache for table " + table);
}

// A composed program whose parts read one split table with two edge modes
// holds it in two entries: the table is split and sent once, and both
// read it (this hung every rank before).
TEST(MpiSplitTables, OneTableReadWithTwoEdgeModesIsSplitOnce) {
  Table1D<Attrib1f> t(1000);
  std::vector<float> values(1000);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = static_cast<float>(k);
  t.assign(values);
  auto shifted = [&](const char* name) {
    return SH_BEGIN_PROGRAM(name) {
      InputAttrib1i i;
      OutputAttrib1f r;
      r = t[i + 990];
    } SH_END;
  };
  t.edge(Edge::Clamp);
  Program clamped = shifted("clamped");
  t.edge(Edge::Repeat);
  Program both = clamped & shifted("wrapped");
  std::vector<std::int32_t> is(40);
  for (std::size_t k = 0; k < is.size(); ++k) is[k] = static_cast<std::int32_t>(k);
  Channel<Attrib1i> in(is);
  Channel<Attrib1f> c, w, c_cpu, w_cpu;
  run(both, {in, in}, {c, w}, backend("mpi", split(4)));
  run(both, {in, in}, {c_cpu, w_cpu}, backend("cpu"));
  EXPECT_EQ(c.values(), c_cpu.values());
  EXPECT_EQ(w.values(), w_cpu.values());
  EXPECT_EQ(c[20], 999.f);
  EXPECT_EQ(w[20], 10.f);
}

// Scattered reads through a cache of 4 blocks of 256 bytes, under divergent
// control flow, must give what the whole table gives, on every local
// backend that reads split tables.
TEST(MpiSplitTables, TheCacheReturnsWhatTheWholeTableHolds) {
  constexpr int n = 5000;
  std::vector<float> points(3 * n);
  for (std::size_t k = 0; k < points.size(); ++k) points[k] = std::sin(0.37f * static_cast<float>(k));
  Table1D<Attrib3f> table(n);
  table.assign(points);
  table.name("points");
  std::vector<std::int32_t> steps(64 * 16);
  for (std::size_t k = 0; k < steps.size(); ++k) steps[k] = static_cast<std::int32_t>(k % 7);
  Table2D<Attrib1i> step_table(64, 16);
  step_table.assign(steps);
  step_table.name("steps");
  Program p = SH_BEGIN_PROGRAM("gather") {
    InputAttrib1i i;
    OutputAttrib3f y;
    y = table[(i * 7919) % n];
    Attrib1i k = 0;
    Attrib2i at;
    at(0) = i % 64;
    at(1) = i % 16;
    SH_WHILE(k < step_table[at]) {  // 0 to 6 more reads per element
      y += table[(i * 31 + k * 977) % n];
      k += 1;
    } SH_ENDWHILE;
  } SH_END;
  std::vector<std::int32_t> is(20000);
  for (std::size_t k = 0; k < is.size(); ++k) is[k] = static_cast<std::int32_t>(k);
  Channel<Attrib1i> in(is);
  Channel<Attrib3f> whole;
  run(p, {in}, {whole}, backend("cpu"));
  for (std::string local : {"cpu", "interp"}) {
    Channel<Attrib3f> out;
    RunStats s = run(p, {in}, {out}, backend("mpi", split(4, local)));
    EXPECT_EQ(out.values(), whole.values()) << local;
    ASSERT_EQ(caches(s).size(), 2u) << local;
    const mpi::TableCacheStats& points_cache = cache_of(s, "points");
    EXPECT_EQ(points_cache.blocks, (n * 12 + 251) / 252u) << "21 float3 (252 bytes) in a 256-byte block";
    EXPECT_EQ(points_cache.cache_blocks, 4u);
    std::size_t loop_reads = 0;
    for (std::int32_t i : is) loop_reads += static_cast<std::size_t>(steps[(i % 16) * 64 + i % 64]);
    EXPECT_EQ(points_cache.counts.reads, is.size() + loop_reads) << local;
    EXPECT_EQ(cache_of(s, "steps").counts.reads, is.size() + loop_reads) << "the loop's test reads it each trip";
    EXPECT_GT(points_cache.counts.local_misses, 0u) << local;
    if (mpi::size() > 2) {
      EXPECT_GT(points_cache.counts.remote_misses, points_cache.counts.local_misses) << "most blocks live elsewhere";
    } else if (mpi::size() == 2) {
      EXPECT_GT(points_cache.counts.remote_misses, 0u) << "half the blocks live on the other rank";
    } else {
      EXPECT_EQ(points_cache.counts.remote_misses, 0u);
    }
    EXPECT_LT(points_cache.counts.hit_rate(), 0.5) << "scattered reads through 4 blocks mostly miss";
  }
}

// Least recently used: with 2 slots, a block read every other time stays
// (first in, first out would evict it), while 4 others take turns in the
// other slot; with 5 slots each block misses once.
TEST(MpiSplitTables, TheCacheReplacesTheLeastRecentlyUsedBlock) {
  std::vector<float> values(5 * 64);
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = static_cast<float>(k);
  Table1D<Attrib1f> table(5 * 64);
  table.assign(values);
  table.name("hot and cold");
  Program p = SH_BEGIN_PROGRAM("hot_and_cold") {
    InputAttrib1i i;
    OutputAttrib1f y;
    Attrib1i block = 0;
    SH_IF(i % 2 == 1) { block = 1 + (i / 2) % 4; } SH_ENDIF;
    y = table[block * 64];
  } SH_END;
  std::vector<std::int32_t> is(3000);
  for (std::size_t k = 0; k < is.size(); ++k) is[k] = static_cast<std::int32_t>(k);
  Channel<Attrib1i> in(is);
  for (std::size_t slots : {2, 5}) {
    Options o = split(slots);
    o.set("schedule", "static");  // each rank reads one contiguous share in order,
    o.set("width", "scalar");     // one element after another (the local cpu backend's setting)
    Channel<Attrib1f> out;
    RunStats s = run(p, {in}, {out}, backend("mpi", o));
    EXPECT_EQ(out[2999], 256.f);
    const mpi::CacheCounts& c = cache_of(s, "hot and cold").counts;
    EXPECT_EQ(c.reads, is.size());
    std::size_t shares = details(s).parts.size(), share = (is.size() + shares - 1) / shares, expected = 0;
    for (std::size_t begin = 0; begin < is.size(); begin += share) {
      std::size_t end = std::min(begin + share, is.size()), odd = end / 2 - begin / 2;
      expected += slots == 2 ? 1 + odd : 5;  // the hot block once, each cold read; or each block once
    }
    EXPECT_EQ(c.local_misses + c.remote_misses, expected) << slots << " slots";
  }
}

TEST(MpiSplitTables, BadSettingsAreErrorsAndOpenClKeepsTablesWhole) {
  Table1D<Attrib1f> table(100);
  table.assign(std::vector<float>(100, 2.0f));
  Program p = SH_BEGIN_PROGRAM("read") {
    InputAttrib1i i;
    OutputAttrib1f y;
    y = table[i];
  } SH_END;
  Channel<Attrib1i> in(std::vector<std::int32_t>(500, 3));
  Channel<Attrib1f> out;
  for (const char* bad : {"split_tables=-1", "cache_blocks=0", "block_bytes=2k", "colour=red"}) {
    Options o = split(4);
    std::string kv = bad, name = kv.substr(0, kv.find('='));
    try {
      o.set("mpi." + name, kv.substr(kv.find('=') + 1));
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("mpi"), std::string::npos) << e.what();
    }
  }
  Options typed;  // the typed form's ranges are checked when it compiles
  typed.set(mpi::Options{.split_tables = 0, .block_bytes = 1 << 25});
  EXPECT_THROW(run(p, {in}, {out}, backend("mpi", typed)), Error);
  Options o = split(4);
  o.set("split_tables", "1000");  // 400 bytes: below, so whole
  EXPECT_TRUE(caches(run(p, {in}, {out}, backend("mpi", o))).empty());
  std::vector<std::string> names = backend_names();
  if (std::find(names.begin(), names.end(), "opencl") != names.end()) {
    RunStats s = run(p, {in}, {out}, backend("mpi", split(4, "opencl")));
    EXPECT_TRUE(caches(s).empty()) << "OpenCL kernels cannot read through a TableSource: the table stays whole";
    EXPECT_EQ(out[499], 2.f);
  }
}

// A refiner whose seed cannot be given the first time it is asked for (its
// state was being written, say); each later time it can.
class SeedFailsOnce : public Refiner {
 public:
  static constexpr const char* kKind = "seed fails once";
  std::string kind() const override { return kKind; }
  std::string seed() const override {
    if (!asked_++) throw std::runtime_error("seed: not ready yet");
    return "";
  }
  void bind(std::vector<TableView>&) const override {}
  std::size_t refine(const std::vector<std::int32_t>&, int) override { return 0; }
  std::string summary() const override { return "nothing built"; }

 private:
  mutable int asked_ = 0;
};

const bool seed_fails_once_registered = [] {
  register_refiner(SeedFailsOnce::kKind, [](const std::string&) { return std::make_unique<SeedFailsOnce>(); });
  return true;
}();

// A run whose command could not be made (the refiner's seed threw) sent
// nothing, so nothing may be taken as sent: the ranks were told of the
// refiner in the next run (they answered "no refiner for this run" to
// every later run), and a table another kernel had sent, which that
// kernel then let go of, is sent again (the ranks read an empty table).
TEST(Mpi, ARunThatFailedBeforeItsCommandWentOutLeavesNothingTakenAsSent) {
  ASSERT_TRUE(seed_fails_once_registered);
  Table1D<Attrib1f> table(64), other(64);
  table.assign(std::vector<float>(64, 3.0f));
  other.assign(std::vector<float>(64, 5.0f));
  auto reader = [](const Table1D<Attrib1f>& t) {
    return SH_BEGIN_PROGRAM("reads_a_table") {  // one kernel, whichever table it reads
      InputAttrib1i i;
      OutputAttrib1f y;
      y = t[i];
    } SH_END;
  };
  Attrib1f scale = 2.0f;
  Program p = SH_BEGIN_PROGRAM("after_a_failed_command") {
    InputAttrib1i i;
    OutputAttrib1i request;
    OutputAttrib1f y;
    request = -1;
    y = table[i] * scale;
  } SH_END;
  Channel<Attrib1i> in(std::vector<std::int32_t>(3000, 5));
  SeedFailsOnce refiner;
  Waves waves{&refiner, 0, {}, 16};
  Channel<Attrib1i> requests;
  Channel<Attrib1f> out;
  run(reader(table), {in}, {out}, backend("mpi"));
  EXPECT_EQ(out.values(), std::vector<float>(3000, 3.0f));
  if (mpi::size() > 1) {  // one rank sends no seed
    try {
      run(p, {in}, {requests, out}, waves, backend("mpi"));
      ADD_FAILURE() << "the refiner's seed threw";
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("seed: not ready yet"), std::string::npos) << e.what();
    }
  }
  run(reader(other), {in}, {out}, backend("mpi"));  // the reader's kernel lets go of `table`
  EXPECT_EQ(out.values(), std::vector<float>(3000, 5.0f));
  for (int again = 0; again < 2; ++again) {
    run(p, {in}, {requests, out}, waves, backend("mpi"));
    EXPECT_EQ(out.values(), std::vector<float>(3000, 6.0f)) << "run " << again;
  }
}

}  // namespace
