#pragma once
// The one interface every backend implements, the registry that finds them
// by name, and the run() call users make.  A kernel is a pure function of
// the optimised IR and the options: uniform values and tables are handed to
// it at every run, so a new uniform value never recompiles anything.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sh/error.hpp"
#include "sh/ir/eval.hpp"
#include "sh/ir/program.hpp"
#include "sh/program.hpp"

namespace sh {

using ir::Precision;
enum class MathMode : std::uint8_t { Precise, Fast };

struct Options {
  Precision precision = Precision::F32;
  MathMode math = MathMode::Precise;
  int threads = 0;                        // 0: every core
  std::uint64_t max_loop_iterations = 1u << 24;  // per loop, per element
  bool checked = false;                   // interp: report first NaN / bad table read
  bool optimize = true;                   // run the passes before compiling
  std::string device;                     // backend-specific device choice
  std::string local_backend;              // for backends that delegate (mpi): what each part runs; default cpu
  // Backend-specific knobs by name (cpu: "width", "tables"; mpi: "chunk"
  // elements per chunk, "schedule" dynamic or static, "split_tables",
  // "block_bytes", "cache_blocks").  Part of the kernel key.
  std::map<std::string, std::string> settings;

  std::string key() const;  // what a compiled kernel depends on
};

struct BufferView {
  ir::Type type;
  std::size_t count = 0;
  void* data = nullptr;
};

// A table this process does not hold whole (the mpi backend splits big
// tables across ranks): a kernel asks it for the span of elements held
// together with the one it reads (a block), and reads that span's other
// elements without asking again until it needs one outside.  A span stays
// valid until the next call; a source is called from one thread at a time
// (the kernels that read one run on one).  The interpreter reads through
// sources; the cpu backend does when compiled with the setting "tables":
// "fetched"; OpenCL kernels cannot call back.
class TableSource {
 public:
  struct Span {
    const void* data;          // element `first` lies here, the others after it
    std::size_t first, end;   // the elements [first, end)
  };
  virtual ~TableSource() = default;
  // The span holding element `flat`, counted as one read.
  virtual Span span_of(std::size_t flat) = 0;
  // Reads a kernel served from spans without asking.
  virtual void count_reads(std::size_t reads) = 0;
};

struct TableView {
  ir::Type element;
  int rank = 1;
  std::array<int, 3> dims{1, 1, 1};
  const void* data = nullptr;
  void* sums = nullptr;       // an accumulator's storage (then data is it too), which the run adds into
  std::uint64_t id = 0;       // the table, unique in the process: with version, says whether it changed
  std::uint64_t version = 0;
  TableSource* source = nullptr;  // where data is null: the elements are read through this
  std::size_t bytes() const {
    return static_cast<std::size_t>(dims[0]) * dims[1] * dims[2] * element.width * ir::storage_bytes(element.scalar);
  }
};

struct RunArgs {
  std::size_t count = 0;  // stream elements
  std::vector<BufferView> inputs, outputs;
  std::vector<std::array<double, 4>> uniforms;  // parallel to ir.uniforms
  std::vector<TableView> tables;                // parallel to ir.tables
};

// What one part of a run did: a rank of the mpi backend, for instance.
struct PartStats {
  int part = 0;
  std::size_t elements = 0, chunks = 0;
  double busy_s = 0, idle_s = 0;
  std::size_t bytes_sent = 0, bytes_received = 0;
  std::size_t waves = 0, resumed = 0;  // see RunStats
};

// Reads of a table through a cache of blocks (the mpi backend's split
// tables): a miss fills a block from this process (local) or another.
struct CacheCounts {
  std::size_t reads = 0, local_misses = 0, remote_misses = 0;
  double fill_s = 0;  // time spent filling blocks
  CacheCounts& operator+=(const CacheCounts& o) {
    reads += o.reads;
    local_misses += o.local_misses;
    remote_misses += o.remote_misses;
    fill_s += o.fill_s;
    return *this;
  }
  double hit_rate() const { return reads ? 1.0 - static_cast<double>(local_misses + remote_misses) / reads : 1.0; }
};

struct TableCacheStats {
  std::string table;
  std::size_t blocks = 0, cache_blocks = 0;  // the table's, and each part's cache's
  CacheCounts counts;                        // summed over parts
};

// Adds `more`'s counts into `total`'s, table by table (by name).
void add_cache_stats(std::vector<TableCacheStats>& total, const std::vector<TableCacheStats>& more);

struct RunStats {
  std::string backend;
  bool compiled = false;   // this run compiled the kernel (not cached)
  double compile_ms = 0;
  double run_ms = 0;
  std::size_t elements = 0;
  std::vector<std::string> diagnostics;  // checked mode findings
  std::vector<PartStats> parts;          // per rank (or device), where the backend has them
  // Runs in waves (waves.hpp): waves after the first, element runs they
  // took, and per part the refiner's summary of what it has built.
  std::size_t waves = 0, resumed = 0;
  std::vector<std::string> refined;
  std::vector<TableCacheStats> caches;  // tables read through caches
};

struct Waves;

class Kernel {
 public:
  virtual ~Kernel() = default;
  virtual void run(const RunArgs& args, RunStats& stats) = 0;
  // Runs in waves (waves.hpp), by default all on this process.
  virtual void run_waves(const RunArgs& args, const Waves& waves, RunStats& stats);
  // What the kernel became (LLVM IR, OpenCL C, ...), for --dump options.
  virtual std::string listing() const { return {}; }
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  virtual std::unique_ptr<Kernel> compile(const ir::Program& program, const Options& options) = 0;
  // Devices or platform in one line each, for `info`.
  virtual std::vector<std::string> describe() const { return {}; }
  // The code-generation modes a user can pick by settings, each a different
  // code path that the conformance suite runs (cpu: scalar and each SPMD
  // width).  One unnamed variant with no settings by default.
  struct Variant {
    std::string name;
    std::map<std::string, std::string> settings;
  };
  virtual std::vector<Variant> variants() const { return {{}}; }
};

// The error every backend gives when an element runs a loop past
// Options::max_loop_iterations: names the program, the element and the loop.
Error runaway_loop(const ir::Program& p, const ir::Stmt& loop, std::uint64_t element, std::uint64_t cap);

using BackendFactory = std::function<std::unique_ptr<Backend>()>;
void register_backend(const std::string& name, BackendFactory factory);
std::vector<std::string> backend_names();
Backend& find_backend(const std::string& name);  // throws sh::Error naming the known ones

// SH_BACKEND from the environment, else "cpu" where built, else "interp".
std::string default_backend_name();
void use_backend(const std::string& name);  // Sh's shUseBackend

struct BackendChoice {
  std::string name;  // empty: the default backend
  Options options;
};
BackendChoice backend(const std::string& name, Options options = {});

// Runs `program` over the streams: every input the same length, every
// output that length (an empty output channel is sized to it).
RunStats run(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
             const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const BackendChoice& choice = {});

// The kernel run() would use (compiled or from the cache), e.g. to dump it.
std::shared_ptr<Kernel> kernel_for(const Program& program, const BackendChoice& choice = {});

}  // namespace sh
