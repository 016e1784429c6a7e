// The host API from several threads at once: shared output channels,
// accumulators, kernels asked for before they are compiled, tables'
// memory, and tables read while others come and go.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <sh/sh.hpp>

#include "../common/fresh.hpp"

namespace {

using namespace sh;

// Threads released together, so that they meet in the code under test.
void together(int threads, const std::function<void(int)>& work) {
  std::atomic<int> waiting{threads};
  std::vector<std::thread> running;
  for (int t = 0; t < threads; ++t)
    running.emplace_back([&, t] {
      waiting.fetch_sub(1);
      while (waiting.load() > 0) std::this_thread::yield();
      work(t);
    });
  for (std::thread& t : running) t.join();
}

// A second resize of the empty channel freed the storage the first run
// was writing (a double free in most processes).
TEST(Threads, RunsSharingAnEmptyOutputChannelSizeItOnce) {
  Program p = SH_BEGIN_PROGRAM("doubled") {
    InputAttrib1f x;
    OutputAttrib1f y;
    y = x * 2.0f;
  } SH_END;
  Channel<Attrib1f> x(std::vector<float>(4096, 1.5f));
  for (int round = 0; round < 50; ++round) {
    Channel<Attrib1f> shared;
    together(4, [&](int) { run(p, {x}, {shared}, backend("interp")); });
    ASSERT_EQ(shared.size(), 4096u);
    EXPECT_EQ(shared.values(), std::vector<float>(4096, 3.0f)) << "round " << round;
  }
}

// Runs of different backends at once add into one accumulator: each adds
// atomically (the opencl backend's sums were added under a lock of its own,
// which the cpu backend's atomic adds did not take).
TEST(Threads, RunsOfEveryBackendAtOnceAddIntoOneAccumulator) {
  std::vector<std::string> local;
  for (const std::string& name : backend_names())
    if (name != "mpi") local.push_back(name);
  const int slots = 1 << 18, runs = 6;
  const std::size_t elements = std::size_t{1} << 20;
  Accumulator<Attrib1i> count(slots, "count");
  Program p = SH_BEGIN_PROGRAM("counted") {
    InputAttrib1i i;
    OutputAttrib1i same;
    count.add(i, 1);
    same = i;
  } SH_END;
  std::vector<std::int32_t> is(elements);
  for (std::size_t k = 0; k < elements; ++k) is[k] = static_cast<std::int32_t>(k % slots);
  Channel<Attrib1i> in(is);
  together(static_cast<int>(local.size()), [&](int k) {
    for (int r = 0; r < runs; ++r) {
      Channel<Attrib1i> out;
      run(p, {in}, {out}, backend(local[static_cast<std::size_t>(k)]));
    }
  });
  const auto each = static_cast<std::int32_t>(local.size() * runs * (elements / slots));
  EXPECT_EQ(count.values(), std::vector<std::int32_t>(slots, each));
}

// Threads asking at once for a kernel not compiled yet: one compiles it,
// the others wait for it (each compiled it before).
TEST(Threads, AKernelAskedForByThreadsAtOnceIsCompiledOnce) {
  for (const std::string& name : backend_names()) {
    if (name == "mpi") continue;
    const float c = fresh_constant();  // new to the process on every run of the test
    Program p = SH_BEGIN_PROGRAM("compiled_once_" + name) {
      InputAttrib1f x;
      OutputAttrib1f y;
      Attrib1f s = x;
      for (int k = 0; k < 200; ++k) s = s * 1.0001f + static_cast<float>(k);  // long enough to overlap
      y = s + c;
    } SH_END;
    Channel<Attrib1f> x(std::vector<float>(64, 1.0f));
    std::atomic<int> compiled{0};
    together(4, [&](int) {
      Channel<Attrib1f> y;
      compiled += run(p, {x}, {y}, backend(name)).compiled ? 1 : 0;
    });
    EXPECT_EQ(compiled.load(), 1) << name;
  }
}

// Two threads adopting one table's storage moved it twice: the second was
// handed memory without data.
TEST(Threads, ATablesMemoryAskedForByThreadsAtOnceIsOneMemory) {
  for (int round = 0; round < 500; ++round) {
    Table1D<Attrib1f> t(64);
    t.assign(std::vector<float>(64, 2.0f));
    std::vector<MemoryPtr> got(4);
    together(4, [&](int k) { got[static_cast<std::size_t>(k)] = t.memory(); });
    for (const MemoryPtr& m : got) {
      ASSERT_TRUE(m) << "round " << round;
      ASSERT_EQ(m.get(), got[0].get()) << "round " << round;
      ASSERT_NE(m->data(), nullptr) << "round " << round;
      EXPECT_EQ(static_cast<const float*>(m->data())[63], 2.0f);
    }
  }
}

// Kernels on several threads at once share copies of a table the process
// holds (the opencl backend keeps one set a device) while tables of their
// own come and go: each run reads its own tables, whatever the others do.
TEST(Threads, RunsOnThreadsReadTheirOwnTablesWhileOthersComeAndGo) {
  Table1D<Attrib1f> shared(16);
  shared.assign(std::vector<float>(16, 100.0f));
  for (const std::string& name : backend_names()) {
    if (name == "mpi") continue;
    together(4, [&](int k) {
      for (int round = 0; round < 20; ++round) {
        Table1D<Attrib1f> own(16);
        const float value = static_cast<float>(1000 * k + round);
        own.assign(std::vector<float>(16, value));
        Program p = SH_BEGIN_PROGRAM("own_and_shared") {
          InputAttrib1i i;
          OutputAttrib1f y;
          y = own[i] + shared[i];
        } SH_END;
        Channel<Attrib1i> at(std::vector<std::int32_t>{0, 15});
        Channel<Attrib1f> out;
        run(p, {at}, {out}, backend(name));
        ASSERT_EQ(out.values(), std::vector<float>(2, value + 100.0f)) << name << ", thread " << k << ", round " << round;
      }
    });
  }
}

}  // namespace
