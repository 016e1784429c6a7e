#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <thread>

#include "jit.hpp"
#include "sh/cpu.hpp"
#include "sh/error.hpp"
#include "sh/ir/printer.hpp"

namespace sh::cpu {
namespace {

// Options in this file: sh::Options; cpu::Options are the backend's own.
class CpuKernel : public Kernel {
 public:
  CpuKernel(const ir::Program& p, const sh::Options& o)
      : program_(p), options_(o), fetched_(fetches_tables(o)),
        streamed_from_(kernel_streams(p, o) ? streamed_from_bytes(o) : SIZE_MAX), jitted_(program_, options_),
        arena_(o.threads > 0 ? o.threads : tbb::task_arena::automatic) {}

  void run(const RunArgs& args, RunStats& stats) override {
    std::vector<void*> inputs, outputs;
    for (const BufferView& b : args.inputs) inputs.push_back(b.data);
    for (const BufferView& b : args.outputs) outputs.push_back(b.data);
    std::vector<double> uniforms;
    for (const auto& u : args.uniforms) uniforms.insert(uniforms.end(), u.begin(), u.end());
    std::vector<TableAccess> accesses;
    std::vector<const void*> tables;
    std::vector<std::int32_t> dims;
    for (std::size_t i = 0; i < args.tables.size(); ++i) {
      const TableView& t = args.tables[i];
      check_gather_range(t, i);
      check_held(t, i);
      if (fetched_) accesses.push_back(access_of(t));
      tables.push_back(t.data);
      dims.insert(dims.end(), t.dims.begin(), t.dims.end());
    }
    std::vector<std::atomic<std::int64_t>> inline_reads(args.tables.size());
    std::array<std::int64_t, 3> domain = kernel_domain(args.domain);
    alignas(16) std::int64_t status[2] = {0, 0};
    std::uint64_t streamed = streams_outputs(args.outputs) ? 1 : 0;
    KernelFn fn = jitted_.entry();
    auto n = static_cast<std::int64_t>(args.count);
    // Threads take whole sets of lanes, so only the stream's last set is
    // partly masked.
    std::int64_t lanes = jitted_.lanes(), sets = (n + lanes - 1) / lanes;
    // Sets [begin, end) of lanes, on this thread; none once an element ran
    // a loop past its cap (the run fails: the rest need not wait for every
    // other set to reach the cap too).
    auto sets_of = [&](std::int64_t begin, std::int64_t end) {
      if (std::atomic_ref<std::int64_t>(status[0]).load(std::memory_order_relaxed) != 0) return;
      auto call = [&](const void* const* its_tables) {
        fn(begin * lanes, std::min(end * lanes, n), inputs.data(), outputs.data(), uniforms.data(), its_tables, dims.data(),
           domain.data(), status, streamed);
      };
      if (!fetched_) return call(tables.data());
      // Each task moves windows of its own.
      std::vector<TableAccess> mine = accesses;
      std::vector<const void*> its_tables = tables;
      for (std::size_t i = 0; i < mine.size(); ++i)
        if (!args.tables[i].sums) its_tables[i] = &mine[i];
      call(its_tables.data());
      for (std::size_t i = 0; i < mine.size(); ++i) inline_reads[i] += mine[i].inline_reads;
    };
    if (args.on_this_thread) {
      sets_of(0, sets);
    } else {
      arena_.execute([&] {
        // Many more chunks than threads, so divergent elements balance out.
        std::int64_t threads = arena_.max_concurrency();
        std::int64_t grain = std::clamp<std::int64_t>(sets / (threads * 16), 1, 4096 / lanes);
        tbb::parallel_for(tbb::blocked_range<std::int64_t>(0, sets, grain),
                          [&](const tbb::blocked_range<std::int64_t>& r) { sets_of(r.begin(), r.end()); });
      });
    }
    for (std::size_t i = 0; i < args.tables.size(); ++i)
      if (!args.tables[i].data) args.tables[i].source->count_reads(static_cast<std::size_t>(inline_reads[i].load()));
    if (status[0] != 0) {
      const ir::Stmt* loop = jitted_.loops().at(static_cast<std::size_t>(status[0] - 1));
      throw runaway_loop(program_, *loop, args.element(static_cast<std::size_t>(status[1])),
                         options_.max_loop_iterations);
    }
    auto details = std::make_shared<RunDetails>();
    details->runs = 1;
    details->streamed = streamed;
    stats.details = std::move(details);
  }

  // On the kernel's arena, whose threads stay between calls (and so keep
  // what a task leaves them, as run_fused's strip buffers).  The arena
  // has the threads the kernel was compiled for, which are the caller's.
  // Each task runs isolated: a thread waiting inside one (on parallel
  // work of a TableSource, say) takes up no other task of this call,
  // which would find the thread's state in use.
  void run_tasks(std::size_t count, int, const std::function<void(std::size_t)>& task) override {
    arena_.execute([&] {
      // One task a range, so that a task that throws cancels every one
      // not yet started.
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, count, 1),
          [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k < r.end(); ++k) tbb::this_task_arena::isolate([&] { task(k); });
          },
          tbb::simple_partitioner());
    });
  }

  std::string listing() const override { return jitted_.llvm_ir(); }
  std::vector<CompilePhase> compile_phases() const override { return jitted_.phases(); }
  double compile_cpu_ms_elsewhere() const override { return jitted_.cpu_ms_elsewhere(); }
  bool loaded_from_disk() const override { return jitted_.from_cache(); }

 private:
  // Whether the outputs' memory together is too large to stay in the
  // cache (cpu::Options::stores), and none is read back at once: the
  // kernel writes them past it.
  bool streams_outputs(const std::vector<BufferView>& outputs) const {
    std::size_t bytes = 0;
    for (const BufferView& out : outputs) {
      if (out.read_back) return false;
      bytes += std::max(out.memory_bytes, out.count * ir::element_bytes(out.type));
    }
    return bytes > 0 && bytes >= streamed_from_;
  }

  // SPMD gathers index tables in 32 bits.
  void check_gather_range(const TableView& t, std::size_t i) const {
    std::size_t values = t.bytes() / ir::storage_bytes(t.element.scalar);
    if (jitted_.lanes() > 1 && values > static_cast<std::size_t>(INT32_MAX))
      throw Error("program '" + program_.name + "': table '" + program_.tables[i].name + "' holds " + std::to_string(values) +
                  " values; the cpu backend's SPMD kernels index at most 2^31 - 1 of a table: run it with width=scalar");
  }

  // A table held elsewhere is read only by kernels that fetch.
  void check_held(const TableView& t, std::size_t i) const {
    if (t.data) return;
    if (!t.source) throw Error("program '" + program_.name + "': table '" + program_.tables[i].name + "' has no data");
    if (!fetched_)
      throw Error("program '" + program_.name + "': table '" + program_.tables[i].name +
                  "' is not held in this process; the cpu backend reads it only with cpu::Options::tables Fetched "
                  "(the setting tables=fetched)");
  }

  // A whole table is one window; a source's starts empty.
  static TableAccess access_of(const TableView& t) {
    std::int64_t bytes = t.element.width * ir::storage_bytes(t.element.scalar);
    std::int64_t elements = t.data ? static_cast<std::int64_t>(t.bytes()) / bytes : 0;
    return {static_cast<const char*>(t.data), 0, elements, 0, &move_window, bytes, t.source};
  }

  static const char* move_window(TableAccess* a, std::int64_t flat) {
    TableSource::Span span = a->source->span_of(static_cast<std::size_t>(flat));
    a->window = static_cast<const char*>(span.data);
    a->window_first = static_cast<std::int64_t>(span.first);
    a->window_end = static_cast<std::int64_t>(span.end);
    return a->window + (flat - a->window_first) * a->element_bytes;
  }

  ir::Program program_;  // the loops in error messages point into it
  sh::Options options_;
  bool fetched_;
  std::size_t streamed_from_;  // bytes of the outputs' memory
  Jitted jitted_;
  tbb::task_arena arena_;
};

class CpuBackend : public Backend {
 public:
  std::string name() const override { return "cpu"; }
  std::unique_ptr<Kernel> compile(const ir::Program& p, const sh::Options& o) override {
    return std::make_unique<CpuKernel>(p, o);
  }
  std::vector<Setting> settings() const override { return cpu::settings(); }
  BackendOptions default_options() const override { return Options{}; }
  // The levels' variants run the lowering an older host takes (masks in
  // vector lanes, gathers a lane at a time, no 16-lane permutes) on this
  // one.
  std::vector<Variant> variants() const override {
    std::vector<Variant> all{{"scalar", Options{.width = Width::Scalar}},
                             {"w4", Options{.width = Width::Lanes4}},
                             {"w8", Options{.width = Width::Lanes8}},
                             {"w16", Options{.width = Width::Lanes16}},
                             {"w16_streamed", Options{.width = Width::Lanes16, .stores = Stores::Streamed}},
                             {"scalar_fetched", Options{.width = Width::Scalar, .tables = Tables::Fetched}},
                             {"w16_fetched", Options{.width = Width::Lanes16, .tables = Tables::Fetched}}};
    if (host_has(Isa::Sse42)) all.push_back({"w4_sse42", Options{.width = Width::Lanes4, .isa = Isa::Sse42}});
    if (host_has(Isa::Avx2)) all.push_back({"w8_avx2", Options{.width = Width::Lanes8, .isa = Isa::Avx2}});
    return all;
  }
  int lanes(const sh::Options& o) const override { return lane_count(o); }
  // Tables and streams are read where they lie; a run's state is its own.
  bool runs_in_place() const override { return true; }
  // Fetched reads on one thread: a TableSource is called from one at a time.
  bool read_through_sources(sh::Options& o) const override {
    Options mine = o.get<Options>();
    mine.tables = Tables::Fetched;
    o.set(mine);
    o.threads = 1;
    return true;
  }
  std::vector<std::string> describe() const override {
    return {"cpu: LLVM 15 ORC JIT for the host CPU (setting \"isa\": an x86-64 level it has), SPMD with " +
            std::to_string(lane_count(sh::Options{})) +
            " lanes by default (setting \"width\": scalar, 4, 8, 16), oneTBB with " +
            std::to_string(tbb::this_task_arena::max_concurrency()) + " threads"};
  }
};

// Registered as the library loads: linking it is enough.  The fastest
// backend for any program on the host, so the default where it is linked.
const bool registered = (sh::register_backend("cpu", [] { return std::make_unique<CpuBackend>(); }, 10), true);

}  // namespace

}  // namespace sh::cpu
