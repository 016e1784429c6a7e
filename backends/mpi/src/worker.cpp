// A serving rank: compiles what rank 0 sends, keeps the tables and
// uniforms it was sent, and computes the chunks it is handed.
#include <mpi.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <new>
#include <optional>

#include "sh/error.hpp"
#include "sh/ir/serialize.hpp"
#include "sh/waves.hpp"
#include "held_tables.hpp"
#include "split_table.hpp"
#include "wire.hpp"
#include "world.hpp"

namespace sh::mpi {
namespace {

using Clock = std::chrono::steady_clock;

struct LocalKernel {
  ir::Program program;
  std::unique_ptr<Kernel> kernel;
  std::vector<std::array<double, 4>> uniforms;
  TableSlots slots;  // the tables its last run read (held_tables.hpp)
};

struct Table {
  std::uint64_t version = 0;
  TableView view;
  std::string bytes;
};

class Worker {
 public:
  Worker() { MPI_Comm_rank(MPI_COMM_WORLD, &rank_); }

  // A compile or a chunk that fails is reported to rank 0, which goes on.
  // What fails outside them (memory for rank 0's message, its tables or a
  // chunk's result on its way back) leaves this rank out of step with the
  // others: it says why and ends the job, rather than leave the runtime's
  // abort unexplained.
  [[noreturn]] void serve() {
    for (;;) {
      try {
        Traffic t;
        std::string message = broadcast({}, t);
        Unpacker u(message);
        switch (u.get<Command>()) {
          case Command::Compile: compile(u); break;
          case Command::Run: run(u, t); break;
          case Command::Forget: forget(u.get<std::uint64_t>()); break;
          case Command::Shutdown:
            release_split_tables();
            MPI_Finalize();
            std::exit(0);
        }
      } catch (const std::bad_alloc&) {
        end_job("out of memory for rank 0's command, its tables or a chunk's result");
      } catch (const std::exception& e) {
        end_job(e.what());
      }
    }
  }

 private:
  [[noreturn]] void end_job(const std::string& why) const {
    std::fprintf(stderr, "sh: rank %d: mpi backend: %s; ending the job\n", rank_, why.c_str());
    MPI_Abort(MPI_COMM_WORLD, 3);
    std::abort();  // MPI_Abort does not return
  }

  void compile(Unpacker& u) {
    auto id = u.get<std::uint64_t>();
    std::string local = u.text();
    Traffic t;
    try {
      sh::Options o = unpack_options(u);
      std::string ir = u.text();
      LocalKernel k;
      k.program = ir::deserialize(ir);
      k.kernel = find_backend(local).compile(k.program, o);
      k.slots = no_tables(k.program.tables.size());
      kernels_[id] = std::move(k);
      send({}, 0, kDone, t);
    } catch (const std::exception& e) {
      send(e.what(), 0, kFailed, t);
    }
  }

  void forget(std::uint64_t id) {
    auto it = kernels_.find(id);
    if (it == kernels_.end()) return;  // its compile failed here
    tables_.clear_all(it->second.slots);
    kernels_.erase(it);
  }

  void run(Unpacker& u, Traffic& t) {
    PartStats stats;
    stats.part = rank_;
    auto id = u.get<std::uint64_t>();
    LocalKernel& k = kernels_.at(id);
    RunArgs args;
    std::vector<SplitTable*> split;
    std::deque<Table> sums;
    receive_tables(u, k, args, split, sums, t);
    if (u.get<bool>()) {  // new uniform values; otherwise the last ones hold
      k.uniforms.resize(k.program.uniforms.size());
      for (auto& value : k.uniforms) value = u.get<std::array<double, 4>>();
    }
    args.uniforms = k.uniforms;
    args.domain = u.get<LaunchDomain>();
    std::optional<Waves> waves;
    std::string refusal;  // a refiner this process cannot make: each chunk fails with it
    if (u.get<bool>()) waves = receive_waves(u, refusal);
    send({}, 0, kReady, t);
    for (;;) {
      auto idle = Clock::now();
      int tag = 0;
      std::string message = receive(0, MPI_ANY_TAG, t, nullptr, &tag);
      stats.idle_s += std::chrono::duration<double>(Clock::now() - idle).count();
      if (tag == kDone) break;
      if (!refusal.empty())
        send(refusal, 0, kFailed, t);
      else
        compute(k, args, waves ? &*waves : nullptr, message, stats, t);
    }
    stats.bytes_sent = t.sent;
    stats.bytes_received = t.received;
    tables_.for_each([&](const Table& table) { stats.held_bytes += table.bytes.size(); });
    Packer p;
    bool refined = waves && refusal.empty() && waves->refiner;
    p.put(stats).put(refined);
    if (refined) p.put(waves->refiner->summary());
    for (const TableView& table : args.tables)
      if (table.sums) p.raw(table.sums, table.bytes());
    for (SplitTable* table : split) p.put(table->take_counts());
    send(p.bytes(), 0, kStats, t);
  }

  // This rank's refiner persists across runs: what it built for earlier
  // chunks serves later ones.
  Waves receive_waves(Unpacker& u, std::string& refusal) {
    Waves w;
    auto id = u.get<std::uint64_t>();
    if (u.get<bool>()) {
      std::string kind = u.text(), seed = u.text();
      try {
        refiners_[id] = make_refiner(kind, seed);
      } catch (const std::exception& e) {
        refusal = e.what();
      }
    }
    auto it = refiners_.find(id);
    if (id != 0 && it == refiners_.end() && refusal.empty()) refusal = "no refiner for this run";
    w.refiner = it == refiners_.end() ? nullptr : it->second.get();
    w.request_output = u.get<int>();
    w.max_waves = u.get<int>();
    auto n = u.get<std::uint64_t>();
    for (std::uint64_t i = 0; i < n; ++i) {
      int out = u.get<int>();
      w.carried.emplace_back(out, u.get<int>());
    }
    return w;
  }

  // An accumulator's zeros are the run's own (`sums`, kept until its sums
  // go back to rank 0), not a held table: rank 0 holds none for them.
  void receive_tables(Unpacker& u, LocalKernel& k, RunArgs& args, std::vector<SplitTable*>& split,
                      std::deque<Table>& sums, Traffic& t) {
    for (std::size_t i = 0; i < k.program.tables.size(); ++i) {
      auto id = u.get<std::uint64_t>();
      if (k.program.tables[i].accumulator) {
        tables_.clear(k.slots, i);
        Table& table = sums.emplace_back();
        table.view = u.get<TableView>();
        table.bytes.assign(table.view.bytes(), '\0');
        table.view.data = table.view.sums = table.bytes.data();
        args.tables.push_back(table.view);
        continue;
      }
      if (u.get<bool>()) {
        tables_.clear(k.slots, i);
        split.push_back(&receive_split(u, id, t));
        TableView view = split_views_[id];
        view.source = split.back();
        args.tables.push_back(view);
        continue;
      }
      Table& table = tables_.hold(k.slots, i, id);
      if (u.get<bool>()) {
        table.version = u.get<std::uint64_t>();
        table.view = u.get<TableView>();
        auto n = u.get<std::uint64_t>();
        table.bytes.assign(u.take(n), n);
      }
      table.view.data = table.bytes.data();
      args.tables.push_back(table.view);
    }
  }

  // A split table: unchanged, or a new version whose share rank 0 sends
  // now, held collectively.
  SplitTable& receive_split(Unpacker& u, std::uint64_t id, Traffic& t) {
    if (u.get<bool>()) {
      TableView view = u.get<TableView>();
      auto settings = u.get<SplitSettings>();
      view.data = nullptr;
      split_views_[id] = view;
      hold_split(view, settings, receive(0, kBlocks, t));
    }
    return *split_tables().at(id).table;
  }

  void compute(const LocalKernel& k, RunArgs args, const Waves* waves, const std::string& message, PartStats& stats,
               Traffic& t) {
    Unpacker u(message);
    auto begin = u.get<std::uint64_t>();
    args.count = u.get<std::uint64_t>();
    args.domain.first += begin;
    std::vector<std::string> inputs, outputs;
    auto busy = Clock::now();
    RunStats run;
    try {
      // Reserved up front: the views below point into these strings.
      inputs.reserve(k.program.inputs.size());
      outputs.reserve(k.program.outputs.size());
      for (ir::VarId v : k.program.inputs) {
        std::size_t n = args.count * ir::element_bytes(k.program.type_of(v));
        inputs.emplace_back(u.take(n), n);
        args.inputs.push_back({k.program.type_of(v), args.count, inputs.back().data()});
      }
      for (ir::VarId v : k.program.outputs) {
        outputs.emplace_back(args.count * ir::element_bytes(k.program.type_of(v)), '\0');
        args.outputs.push_back({k.program.type_of(v), args.count, outputs.back().data()});
      }
      if (waves)
        run_in_waves(*k.kernel, args, *waves, run);
      else
        k.kernel->run(args, run);
      stats.waves = std::max(stats.waves, run.waves);
      stats.resumed += run.resumed;
    } catch (const std::bad_alloc&) {
      send("out of memory for a chunk of " + std::to_string(args.count) + " elements", 0, kFailed, t);
      return;
    } catch (const std::exception& e) {
      send(e.what(), 0, kFailed, t);
      return;
    }
    stats.busy_s += std::chrono::duration<double>(Clock::now() - busy).count();
    auto waiting = Clock::now();  // a large result waits for rank 0 to take it
    Packer p;
    p.put(begin).put(static_cast<std::uint64_t>(args.count));
    for (const std::string& o : outputs) p.raw(o.data(), o.size());
    p.put(static_cast<std::uint64_t>(run.diagnostics.size()));
    for (const std::string& finding : run.diagnostics) p.put(finding);
    send(p.bytes(), 0, kResult, t);
    stats.idle_s += std::chrono::duration<double>(Clock::now() - waiting).count();
    stats.elements += args.count;
    ++stats.chunks;
  }

  int rank_ = 0;
  std::map<std::uint64_t, LocalKernel> kernels_;
  HeldTables<Table> tables_;
  std::map<std::uint64_t, TableView> split_views_;
  std::map<std::uint64_t, std::unique_ptr<Refiner>> refiners_;
};

}  // namespace

void serve() { Worker().serve(); }

}  // namespace sh::mpi
