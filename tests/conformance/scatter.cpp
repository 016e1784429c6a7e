// Accumulators: the language's scatter-add.  Every running element adds,
// lanes that a branch, a break or the stream's end left out do not; indices
// clamp to the edge; runs add to what the accumulator holds.  Sums of values
// exact in binary32 are compared exactly, whatever order the backend added
// in; other float sums to rounding.
#include <string>
#include <thread>
#include <vector>

#include "harness.hpp"

namespace conformance {
namespace {

using sh::Attrib1f;
using sh::Attrib1i;
using sh::Attrib2f;

TEST_P(Conformance, ScatterCountsEveryRunningElementAtEveryStreamLength) {
  sh::Accumulator<Attrib1i> counts(7, "counts");
  sh::Accumulator<Attrib2f> sums(5, "sums");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_counts") {
    sh::Input<Attrib1i> e;
    counts.add(e % 7, 1);
    Attrib1f x = e.cast<float>();
    sums.add((e * 3) % 5, join(x * 0.25f, -x));
  } SH_END;
  for (std::size_t length : {1, 2, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 33, 35, 1031, 2048}) {
    counts.clear();
    sums.clear();
    std::vector<std::int32_t> es(length);
    for (std::size_t k = 0; k < length; ++k) es[k] = static_cast<std::int32_t>(k);
    sh::Channel<Attrib1i> ce(es);
    run(p, {ce}, {});
    std::vector<std::int32_t> want_counts(7, 0);
    std::vector<float> want_sums(10, 0.f);
    for (std::int32_t k : es) {
      ++want_counts[k % 7];
      want_sums[2 * ((k * 3) % 5)] += 0.25f * static_cast<float>(k);
      want_sums[2 * ((k * 3) % 5) + 1] -= static_cast<float>(k);
    }
    EXPECT_EQ(counts.values(), want_counts) << "length " << length;
    EXPECT_EQ(sums.values(), want_sums) << "length " << length;
  }
}

// Elements add from inside divergent branches and loops with breaks and
// continues: element e adds 1 to buckets 0..e%6 except 2, stopping after
// bucket 4, and only where e is odd adds its number to bucket 5.
TEST_P(Conformance, ScatterUnderDivergentControlFlow) {
  sh::Accumulator<Attrib1f> buckets(6, "buckets");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_divergent") {
    sh::Input<Attrib1f> e;
    SH_FOR(Attrib1f j = 0.0f, j <= e % 6.0f, j += 1.0f) {
      SH_CONTINUE(j == 2.0f);
      buckets.add(j.cast<int>(), 1.0f);
      SH_BREAK(j >= 4.0f);
    } SH_ENDFOR;
    SH_IF(e % 2.0f == 1.0f) { buckets.add(5, e); } SH_ENDIF;
  } SH_END;
  for (std::size_t length : {1, 6, 17, 33, 1031}) {
    buckets.clear();
    std::vector<float> es(length);
    std::vector<float> want(6, 0.f);
    for (std::size_t k = 0; k < length; ++k) {
      es[k] = static_cast<float>(k);
      for (std::size_t j = 0; j <= k % 6; ++j) {
        if (j == 2) continue;
        want[j] += 1;
        if (j >= 4) break;
      }
      if (k % 2 == 1) want[5] += static_cast<float>(k);
    }
    sh::Channel<Attrib1f> ce(es);
    run(p, {ce}, {});
    EXPECT_EQ(buckets.values(), want) << "length " << length;
  }
}

TEST_P(Conformance, ScatterIndicesClampToTheEdgeAndRunsAccumulate) {
  sh::Accumulator<Attrib1i> hits(4, "hits");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_clamp") {
    sh::Input<Attrib1i> i;
    sh::Output<Attrib1i> same;
    hits.add(i, 1);
    same = i;
  } SH_END;
  std::vector<std::int32_t> is = {-5, 0, 3, 4, 1000000, std::numeric_limits<std::int32_t>::min(), 2,
                                  std::numeric_limits<std::int32_t>::max()};
  sh::Channel<Attrib1i> ci(is);
  sh::Channel<Attrib1i> out;
  run(p, {ci}, {out});
  EXPECT_EQ(hits.values(), (std::vector<std::int32_t>{3, 0, 1, 4}));
  EXPECT_EQ(out[3], 4);  // the element's own outputs are untouched by its scatter
  run(p, {ci}, {out});
  EXPECT_EQ(hits.values(), (std::vector<std::int32_t>{6, 0, 2, 8}));
  hits.clear();
  EXPECT_EQ(hits.values(), (std::vector<std::int32_t>(4, 0)));
  // Sums moved into memory (a table viewing them) are cleared there too.
  run(p, {ci}, {out});
  sh::MemoryPtr sums = hits.storage()->buffer.memory();
  ASSERT_TRUE(sums);
  hits.clear();
  EXPECT_EQ(hits.values(), (std::vector<std::int32_t>(4, 0)));
  run(p, {ci}, {out});
  EXPECT_EQ(hits.values(), (std::vector<std::int32_t>{3, 0, 1, 4}));
}

// Runs on several host threads at once, each into its own outputs, add
// into one accumulator: every add counts (the interpreter's additions and
// the opencl backend's copy of the sums lost some).  The mpi backend is
// started for one thread's calls and refuses another's by name.
TEST_P(Conformance, RunsOnSeveralThreadsAddIntoOneAccumulator) {
  sh::Accumulator<Attrib1i> count(2, "count");
  sh::Accumulator<Attrib1f> weight(1, "weight");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_threads") {
    sh::Input<Attrib1i> i;
    sh::Output<Attrib1i> same;
    count.add(i % 2, 1);
    weight.add(0, 0.5f);
    same = i;
  } SH_END;
  const int threads = 4, runs = 3, elements = 1000;
  std::vector<std::int32_t> is(elements);
  for (int k = 0; k < elements; ++k) is[static_cast<std::size_t>(k)] = k;
  sh::Channel<Attrib1i> in(is);
  {
    sh::Channel<Attrib1i> out;
    sh::run(p, {in}, {out}, choice());  // on this thread first: the one that starts MPI
  }
  std::vector<std::string> errors(threads);
  std::vector<std::thread> running;
  for (int t = 0; t < threads; ++t)
    running.emplace_back([&, t] {
      try {
        for (int r = 0; r < runs; ++r) {
          sh::Channel<Attrib1i> out;
          sh::run(p, {in}, {out}, choice());
        }
      } catch (const sh::Error& e) {
        errors[static_cast<std::size_t>(t)] = e.what();
      }
    });
  for (std::thread& t : running) t.join();
  if (mode().backend == "mpi") {
    for (const std::string& e : errors)
      EXPECT_NE(e.find("only on the thread that started MPI"), std::string::npos) << e;
    return;
  }
  for (const std::string& e : errors) EXPECT_EQ(e, "");
  const int adds = (1 + threads * runs) * elements;
  EXPECT_EQ(count.values(), (std::vector<std::int32_t>{adds / 2, adds / 2}));
  EXPECT_EQ(weight.values()[0], 0.5f * adds);  // halves sum exactly in any order
}

// Values that are not exact in binary32: every backend's sum is within the
// rounding of adding 4000 terms in some order.
TEST_P(Conformance, ScatterFloatSumsAgreeToRounding) {
  sh::Accumulator<Attrib1f> total(2, "total");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_float") {
    sh::Input<Attrib1f> x;
    total.add(0, x);
    total.add(1, x * x);
  } SH_END;
  const std::size_t n = 4000;
  std::vector<float> xs(n);
  double sum = 0, squares = 0;
  for (std::size_t k = 0; k < n; ++k) {
    xs[k] = 0.1f * static_cast<float>(k % 97) + 0.01f;
    sum += xs[k];
    squares += static_cast<double>(xs[k]) * xs[k];
  }
  sh::Channel<Attrib1f> cx(xs);
  run(p, {cx}, {});
  std::vector<float> got = total.values();
  EXPECT_NEAR(got[0], sum, sum * n * 6e-8);
  EXPECT_NEAR(got[1], squares, squares * n * 6e-8 * 2);
}

// A float accumulator takes each value as a float, then adds in float,
// at every precision: 2^-24 + 2^-50 (exact in double) is 2^-24 there, and
// 1 + 2^-24 ties to 1, in either order.  One rounding in double would
// give 1 + 2^-23.
TEST_P(Conformance, ScatterRoundsTheValueToTheAccumulatorsTypeFirst) {
  sh::Accumulator<Attrib1f> total(1, "total");
  sh::Program p = SH_BEGIN_PROGRAM("scatter_rounding") {
    sh::Input<sh::Attrib2f> x;
    total.add(0, x(0) + x(1));
  } SH_END;
  sh::Channel<sh::Attrib2f> cx(std::vector<float>{1.0f, 0.0f, 0x1p-24f, 0x1p-50f});
  run(p, {cx}, {});
  EXPECT_EQ(total.values()[0], 1.0f);
}

}  // namespace
}  // namespace conformance
