#include "coordinator.hpp"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <set>

#include "sh/detail/sums.hpp"
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

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Whole tables the serving ranks hold, at the version they hold.
struct Sent {
  std::uint64_t version = 0;
  bool sent = false;
};
HeldTables<Sent>& tables_sent() {
  static HeldTables<Sent> sent;
  return sent;
}

// Kernels destroyed since rank 0 last spoke to the serving ranks, with the
// tables they held there.  A kernel may die on any thread, at any time; the
// message that the ranks may let go of it waits for rank 0's next command,
// sent from the thread that runs kernels.
struct Forgotten {
  std::mutex mutex;
  std::vector<std::pair<std::uint64_t, TableSlots>> kernels;
};
Forgotten& forgotten() {
  static Forgotten* f = new Forgotten;  // never destroyed: kernels die in static destructors too
  return *f;
}

// Tells the serving ranks of every kernel destroyed since the last call.
void send_forgotten() {
  std::vector<std::pair<std::uint64_t, TableSlots>> gone;
  {
    std::lock_guard<std::mutex> lock(forgotten().mutex);
    gone.swap(forgotten().kernels);
  }
  for (auto& [id, slots] : gone) {
    tables_sent().clear_all(slots);
    Packer p;
    p.put(Command::Forget).put(id);
    Traffic t;
    broadcast(p.bytes(), t);
  }
}

// Refiners whose seed the serving ranks have (each rank then builds its own).
std::set<std::uint64_t>& refiners_sent() {
  static std::set<std::uint64_t> sent;
  return sent;
}

class Coordinator : public Kernel {
 public:
  // The local backend gets `o` without the mpi backend's own options.
  Coordinator(const ir::Program& p, const sh::Options& o)
      : program_(p), mine_(o.get<Options>()), split_(split_settings(mine_)), local_name_(local_backend_name(mine_)) {
    static std::uint64_t next_id = 1;
    id_ = next_id++;
    MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
    sh::Options local = local_options(o);
    Backend& backend = find_backend(local_name_);
    if (split_.enabled) ask_to_read_split_tables(backend, local);
    local_ = backend.compile(p, local);
    if (ranks_ <= 1) return;
    try {
      compile_everywhere(local);
    } catch (...) {
      forget();  // the ranks where it compiled hold it
      throw;
    }
  }

  // The serving ranks let go of the kernel and of the tables only it held,
  // told before rank 0's next command.
  ~Coordinator() override {
    if (ranks_ > 1) forget();
  }

  void run(const RunArgs& args, RunStats& stats) override { spread(args, nullptr, stats); }

  // Each rank runs its chunks in waves with a refiner of its own: rank 0
  // with the caller's, the others with one started from its seed.
  void run_waves(const RunArgs& args, const Waves& waves, RunStats& stats) override { spread(args, &waves, stats); }

  std::string listing() const override { return local_->listing(); }

 private:
  // Dynamic: chunks in stream order to whichever rank asks.  Static
  // (fixed): share r - 1 to rank r and the last to rank 0, whatever order
  // the ranks ask in, so a rank gets the same share in every run.
  struct Schedule {
    const RunArgs& args;
    std::size_t chunk;
    std::size_t next;  // dynamic: the first element not handed out
    std::string error;
    const Waves* waves;
    bool fixed;
    std::vector<bool> share_taken;  // static: per rank
    std::vector<std::pair<std::size_t, std::string>> findings;  // checked mode's, each with its chunk's first element

    struct Range {
      std::size_t begin, count;
    };
    Range share_of(int rank, int ranks) const {
      std::size_t index = rank == 0 ? static_cast<std::size_t>(ranks - 1) : static_cast<std::size_t>(rank - 1);
      std::size_t begin = std::min(index * chunk, args.count);
      return {begin, std::min(chunk, args.count - begin)};
    }
    bool left_here() const { return error.empty() && (fixed ? !share_taken[0] : next < args.count); }
    // What `rank` computes next: its share, once (static), or the next
    // `piece` elements (dynamic); nothing when no work is left for it.
    Range take(int rank, int ranks, std::size_t piece) {
      if (!error.empty()) return {0, 0};
      if (fixed) {
        if (share_taken[static_cast<std::size_t>(rank)]) return {0, 0};
        share_taken[static_cast<std::size_t>(rank)] = true;
        return share_of(rank, ranks);
      }
      std::size_t begin = std::min(next, args.count), n = std::min(piece, args.count - begin);
      next = begin + n;
      return {begin, n};
    }
  };

  void forget() {
    std::lock_guard<std::mutex> lock(forgotten().mutex);
    forgotten().kernels.emplace_back(id_, std::move(slots_));
  }

  // What rank 0 takes the serving ranks to hold, as it was before a run's
  // command was made: put back where the command never goes out (memory, a
  // refiner's seed that throws), so that nothing is taken as sent that was
  // not (the ranks then read a table they never got, or lack a refiner).
  struct Sending {
    HeldTables<Sent> tables;
    TableSlots slots;
    std::vector<std::array<double, 4>> uniforms;
    std::set<std::uint64_t> refiners;
  };

  std::string command_for(const RunArgs& whole, const std::vector<bool>& split, const Waves* waves) {
    Sending before{tables_sent(), slots_, uniforms_sent_, refiners_sent()};
    try {
      return run_command(whole, split, waves);
    } catch (...) {
      tables_sent() = std::move(before.tables);
      slots_ = std::move(before.slots);
      uniforms_sent_ = std::move(before.uniforms);
      refiners_sent() = std::move(before.refiners);
      throw;
    }
  }

  void spread(const RunArgs& whole, const Waves* waves, RunStats& stats) {
    check_thread(program_.name);
    if (ranks_ > 1) send_forgotten();
    Traffic t;
    std::vector<bool> split = which_split(whole);
    std::string command = ranks_ > 1 ? command_for(whole, split, waves) : std::string();
    // From the command on until their stats are in, the serving ranks wait
    // on rank 0: a failure meanwhile would leave them waiting for ever.
    bool ranks_waiting = ranks_ > 1;
    std::string error;
    try {
      if (ranks_waiting) broadcast(command, t);
      error = coordinate(whole, split, waves, stats, t, ranks_waiting);
    } catch (const std::exception& e) {
      if (ranks_waiting) end_job(e.what());
      throw;
    }
    if (!error.empty()) throw Error("mpi backend: " + error);
  }

  [[noreturn]] void end_job(const char* why) const {
    std::fprintf(stderr,
                 "sh: rank 0: mpi backend: program '%s': %s, in the middle of a run that the other ranks wait on; "
                 "ending the job\n",
                 program_.name.c_str(), why);
    MPI_Abort(MPI_COMM_WORLD, 3);
    std::abort();  // MPI_Abort does not return
  }

  // Hands out the run's chunks, computes rank 0's, and gathers results and
  // stats (`ranks_waiting` false once the last are in); returns the first
  // chunk's error, if any.
  std::string coordinate(const RunArgs& whole, const std::vector<bool>& split, const Waves* waves, RunStats& stats,
                         Traffic& t, bool& ranks_waiting) {
    // Rank 0 reads split tables through its cache, as every rank does.
    RunArgs args = whole;
    auto details = std::make_shared<RunDetails>();
    hold_split_tables(args, split, *details, t);
    PartStats mine;
    mine.part = 0;
    // Dynamic: many more chunks than ranks (16 each unless a size is set);
    // static: one contiguous share per rank.  Runs in waves are static
    // unless the settings say otherwise: each rank's refiner keeps what it
    // built for its share, which the next run hands it again.
    bool fixed = mine_.schedule == mpi::Schedule::Static || (mine_.schedule == mpi::Schedule::Auto && waves);
    std::size_t shares = fixed ? ranks_ : 16 * ranks_;
    std::size_t chunk = mine_.chunk > 0 && !fixed ? mine_.chunk : std::max<std::size_t>(1, (args.count + shares - 1) / shares);
    Schedule s{args, chunk, 0, {}, waves, fixed, std::vector<bool>(static_cast<std::size_t>(ranks_), false), {}};
    std::size_t served = 0;  // serving ranks that have been told they are done
    // Per serving rank (rank r at r - 1), however their stats arrive.
    std::vector<PartStats> parts(static_cast<std::size_t>(ranks_ - 1));
    std::vector<std::string> summaries(parts.size());
    int waiting_stats = ranks_ - 1;
    // Every serving rank gets its first chunk before rank 0 computes any:
    // a rank busy computing does not see requests (MPI progresses only in
    // MPI calls), and a static split needs each rank to take its share.
    for (int i = 1; i < ranks_; ++i) {
      auto idle = Clock::now();
      int source = 0;
      receive(MPI_ANY_SOURCE, kReady, t, &source);
      mine.idle_s += seconds_since(idle);
      served += hand_out(s, source, t);
    }
    while (served < static_cast<std::size_t>(ranks_ - 1) || s.left_here()) {
      // Answer every rank that is asking, then compute a chunk here.
      int pending = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &pending, &status);
      // A static split keeps rank 0's share for rank 0.
      if ((!pending || fixed) && s.left_here()) {
        auto busy = Clock::now();
        compute_here(s, mine);
        mine.busy_s += seconds_since(busy);
        continue;
      }
      auto idle = Clock::now();
      int source = 0, tag = 0;
      std::string message = receive(MPI_ANY_SOURCE, MPI_ANY_TAG, t, &source, &tag);
      mine.idle_s += seconds_since(idle);
      if (tag == kStats) {
        take_stats(message, args, parts.at(source - 1), summaries.at(source - 1), *details);
        --waiting_stats;
        continue;
      }
      if (tag == kResult) land(s, message);
      if (tag == kFailed && s.error.empty()) s.error = "rank " + std::to_string(source) + ": " + message;
      served += hand_out(s, source, t);
    }
    for (; waiting_stats > 0; --waiting_stats) {
      int source = 0;
      std::string message = receive(MPI_ANY_SOURCE, kStats, t, &source);
      take_stats(message, args, parts.at(source - 1), summaries.at(source - 1), *details);
    }
    ranks_waiting = false;
    for (std::size_t i = 0, k = 0; i < args.tables.size(); ++i)
      if (split[i]) details->caches[k++].counts += static_cast<SplitTable*>(args.tables[i].source)->take_counts();
    mine.chunks = mine.elements / chunk + (mine.elements % chunk != 0);  // rank 0 computes in pieces: its chunks' worth
    mine.bytes_sent = t.sent;
    mine.bytes_received = t.received;
    parts.insert(parts.begin(), mine);
    if (waves && waves->refiner) {
      stats.refined = {waves->refiner->summary()};
      for (std::string& summary : summaries)
        if (!summary.empty()) stats.refined.push_back(std::move(summary));
    }
    for (const PartStats& p : parts) {
      stats.waves = std::max(stats.waves, p.waves);
      stats.resumed += p.resumed;
    }
    details->parts = std::move(parts);
    stats.details = std::move(details);
    stats.diagnostics = first_findings(std::move(s.findings));
    return s.error;
  }

  // A serving rank's stats, with waves its refiner's summary, its
  // accumulators' sums, added into ours, and its caches' counts.  Stats
  // arrive in any order; they are kept by rank.
  static void take_stats(const std::string& message, const RunArgs& args, PartStats& part, std::string& summary,
                         RunDetails& details) {
    Unpacker u(message);
    part = u.get<PartStats>();
    if (u.get<bool>()) summary = u.text();
    for (const TableView& table : args.tables)
      if (table.sums)  // each add atomic: runs on other threads may add into the same sums
        detail::add_sums_from(table.element.scalar, table.sums, u.take(table.bytes()), table.bytes());
    for (TableCacheStats& cache : details.caches) cache.counts += u.get<CacheCounts>();
  }

  // Split tables are read through sources, so only by local kernels that
  // can call back into the runtime (cpu, interp; MPI is then called from
  // the kernel); others (OpenCL) keep every table whole on every rank.
  void ask_to_read_split_tables(const Backend& backend, sh::Options& local) {
    if (backend.read_through_sources(local)) return;
    std::fprintf(stderr,
                 "sh: mpi backend: %s kernels cannot read tables through a TableSource; program '%s' keeps its tables "
                 "whole on every rank\n",
                 local_name_.c_str(), program_.name.c_str());
    split_.enabled = false;
  }

  std::vector<bool> which_split(const RunArgs& args) const {
    std::vector<bool> split;
    for (const TableView& table : args.tables)
      split.push_back(split_.enabled && !table.sums && table.bytes() >= split_.min_bytes);
    return split;
  }

  // Collective with the serving ranks: each new split table's shares go
  // out, then every rank holds its own; the run reads them through caches.
  void hold_split_tables(RunArgs& args, const std::vector<bool>& split, RunDetails& details, Traffic& t) {
    for (std::size_t i = 0; i < args.tables.size(); ++i) {
      if (!split[i]) continue;
      TableView& table = args.tables[i];
      BlockLayout layout(table, split_.block_bytes, ranks_);
      if (!holds_split(table, split_)) {
        for (int r = 1; r < ranks_; ++r) send(layout.share(table.data, r), r, kBlocks, t);
        hold_split(table, split_, layout.share(table.data, 0));
      }
      table.source = split_tables().at(table.id).table.get();
      table.data = nullptr;
      details.caches.push_back({program_.tables[i].name, layout.blocks(), split_.cache_blocks, {}});
    }
  }

  void compile_everywhere(const sh::Options& local) {
    send_forgotten();
    Packer p;
    p.put(Command::Compile).put(id_).put(local_name_);
    pack(p, local);
    p.put(ir::serialize(program_));
    Traffic t;
    broadcast(p.bytes(), t);
    std::string failures;
    for (int i = 1; i < ranks_; ++i) {
      int source = 0, tag = 0;
      std::string message = receive(MPI_ANY_SOURCE, MPI_ANY_TAG, t, &source, &tag);
      if (tag == kFailed) failures += "\n  rank " + std::to_string(source) + ": " + message;
    }
    if (!failures.empty()) throw Error("program '" + program_.name + "': mpi backend: compiling failed on" + failures);
  }

  // The command every serving rank receives: the kernel, and the tables
  // and uniforms that changed since they last got them.
  std::string run_command(const RunArgs& args, const std::vector<bool>& split, const Waves* waves) {
    Packer p;
    p.put(Command::Run).put(id_);
    // A table the program reads twice (a composed program's parts with two
    // edge modes) is split once: hold_split_tables sends its blocks for the
    // first of its entries.
    std::set<std::uint64_t> splitting;
    for (std::size_t i = 0; i < args.tables.size(); ++i) {
      const TableView& table = args.tables[i];
      p.put(table.id);
      if (table.sums) {  // each rank adds into zeros of its own; rank 0 sums them
        tables_sent().clear(slots_, i);
        p.put(table);
        continue;
      }
      p.put(static_cast<bool>(split[i]));
      if (split[i]) {  // its blocks follow, one share per rank
        tables_sent().clear(slots_, i);
        bool fresh = !holds_split(table, split_) && splitting.insert(table.id).second;
        p.put(fresh);
        if (fresh) p.put(table).put(split_);
        continue;
      }
      Sent& sent = tables_sent().hold(slots_, i, table.id);
      bool fresh = !sent.sent || sent.version != table.version;
      p.put(fresh);
      if (!fresh) continue;
      p.put(table.version).put(table).put(static_cast<std::uint64_t>(table.bytes())).raw(table.data, table.bytes());
      sent = {table.version, true};
    }
    // Compared bit for bit: -0.0 == +0.0, but x / -0.0 is not x / +0.0.
    bool changed = args.uniforms.size() != uniforms_sent_.size() ||
                   (!args.uniforms.empty() && std::memcmp(args.uniforms.data(), uniforms_sent_.data(),
                                                          args.uniforms.size() * sizeof(std::array<double, 4>)) != 0);
    p.put(changed);
    if (changed)
      for (const auto& u : args.uniforms) p.put(u);
    uniforms_sent_ = args.uniforms;
    p.put(args.domain);
    p.put(waves != nullptr);
    if (waves) pack_waves(p, *waves);
    return p.bytes();
  }

  static void pack_waves(Packer& p, const Waves& w) {
    // Refiners' ids start at 1: 0 says there is none (a wavefront).
    std::uint64_t id = w.refiner ? w.refiner->id() : 0;
    p.put(id);
    bool fresh = id != 0 && refiners_sent().insert(id).second;
    p.put(fresh);
    if (fresh) p.put(w.refiner->kind()).put(w.refiner->seed());
    p.put(w.request_output).put(w.max_waves).put(static_cast<std::uint64_t>(w.carried.size()));
    for (const auto& [out, in] : w.carried) p.put(out).put(in);
  }

  // Gives `rank` its next chunk (static: its share, once), or tells it the
  // run is over (returns 1).
  std::size_t hand_out(Schedule& s, int rank, Traffic& t) {
    auto [begin, n] = s.take(rank, ranks_, s.chunk);
    if (n == 0) {
      send({}, rank, kDone, t);
      return 1;
    }
    Packer p;
    p.put(static_cast<std::uint64_t>(begin)).put(static_cast<std::uint64_t>(n));
    for (const BufferView& in : s.args.inputs)
      p.raw(static_cast<const char*>(in.data) + begin * ir::element_bytes(in.type), n * ir::element_bytes(in.type));
    send(p.bytes(), rank, kAssign, t);
    return 0;
  }

  // Results land in order: each chunk is copied to where it belongs.
  void land(Schedule& s, const std::string& message) {
    Unpacker u(message);
    auto begin = u.get<std::uint64_t>();
    auto n = u.get<std::uint64_t>();
    for (const BufferView& out : s.args.outputs) {
      std::size_t bytes = n * ir::element_bytes(out.type);
      std::memcpy(static_cast<char*>(out.data) + begin * ir::element_bytes(out.type), u.take(bytes), bytes);
    }
    for (auto k = u.get<std::uint64_t>(); k > 0; --k) s.findings.emplace_back(begin, u.text());
  }

  // Each kind of finding ("first NaN: element ...") from the chunk that
  // comes first in the stream, as one run over the whole stream reports it.
  static std::vector<std::string> first_findings(std::vector<std::pair<std::size_t, std::string>> findings) {
    std::stable_sort(findings.begin(), findings.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> first;
    std::set<std::string> kinds;
    for (auto& [begin, finding] : findings)
      if (kinds.insert(finding.substr(0, finding.find(':'))).second) first.push_back(std::move(finding));
    return first;
  }

  // Rank 0 computes in pieces an eighth of a chunk (dynamic schedule), so
  // that it answers the other ranks often: MPI moves messages only while
  // rank 0 is in an MPI call, and a waiting rank is an idle rank.
  void compute_here(Schedule& s, PartStats& mine) {
    auto [begin, n] = s.take(0, ranks_, std::max<std::size_t>(1, s.chunk / 8));
    if (n == 0) return;
    RunArgs slice = s.args;
    slice.count = n;
    slice.domain.first += begin;
    for (BufferView& b : slice.inputs) b = b.part(begin, n);
    for (BufferView& b : slice.outputs) b = b.part(begin, n);
    try {
      RunStats run;
      if (s.waves)
        run_in_waves(*local_, slice, *s.waves, run);
      else
        local_->run(slice, run);
      mine.waves = std::max(mine.waves, run.waves);
      mine.resumed += run.resumed;
      mine.elements += n;
      for (std::string& finding : run.diagnostics) s.findings.emplace_back(begin, std::move(finding));
    } catch (const std::exception& e) {
      if (s.error.empty()) s.error = std::string("rank 0: ") + e.what();
    }
  }

  ir::Program program_;
  Options mine_;
  SplitSettings split_;
  std::string local_name_;
  std::uint64_t id_ = 0;
  int ranks_ = 1;
  std::unique_ptr<Kernel> local_;
  std::vector<std::array<double, 4>> uniforms_sent_;
  TableSlots slots_ = no_tables(program_.tables.size());  // what the serving ranks hold for this kernel
};

}  // namespace

std::string local_backend_name(const Options& o) {
  std::string name = o.local.empty() ? preferred_backend_name(Options::backend_name) : o.local;
  if (name == Options::backend_name) throw Error("mpi backend: the local backend cannot be mpi itself");
  return name;
}

sh::Options local_options(const sh::Options& o) {
  sh::Options local = o;
  local.backends.erase(Options::backend_name);
  return local;
}

std::unique_ptr<Kernel> coordinator(const ir::Program& program, const sh::Options& options) {
  return std::make_unique<Coordinator>(program, options);
}

}  // namespace sh::mpi
