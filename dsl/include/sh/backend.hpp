#pragma once
// The one interface every backend implements, the registry that finds them
// by name, and the run() call users make.  A kernel is a pure function of
// the optimised IR and the options: uniform values and tables are handed to
// it at every run, so a new uniform value never recompiles anything.
//
// dsl names no backend but its own interpreter: a backend's library
// registers it as the library loads, and the umbrella target sh::sh keeps
// every backend built linked into the program (see the top CMakeLists.txt).
// sh::backends() lists what is there.  A backend's header (sh/cpu.hpp,
// sh/mpi.hpp, ...) holds only its own API: its options, its statistics.
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sh/error.hpp"
#include "sh/ir/eval.hpp"
#include "sh/ir/program.hpp"
#include "sh/options.hpp"
#include "sh/program.hpp"

namespace sh {

struct BufferView {
  ir::Type type;
  std::size_t count = 0;
  void* data = nullptr;
  // The bytes of the memory the view is a part of (0: its own count's),
  // as a strip of a channel is: whether what a run writes there can stay
  // in the cache (cpu::Options::stores).
  std::size_t memory_bytes = 0;
  // The caller reads what the run writes here at once (run_fused's strip
  // buffer): it stays in the cache whatever the stores setting asks.
  bool read_back = false;

  // Elements [first, first + n) of the view (a run's part of a stream): a
  // view of them alone, whose memory is still the whole view's.
  BufferView part(std::size_t first, std::size_t n) const {
    BufferView p = *this;
    p.memory_bytes = std::max(memory_bytes, count * ir::element_bytes(type));
    p.data = static_cast<char*>(data) + first * ir::element_bytes(type);
    p.count = n;
    return p;
  }
};

// A table read on demand instead of from memory: whoever calls Kernel::run
// may hand a kernel a table it does not hold whole (TableView::data null,
// ::source set).  The kernel asks the source for the span of elements held
// together with the one it reads (a block), and reads that span's other
// elements without asking again until it needs one outside.  A span stays
// valid until the next call; a source is called from one thread at a time.
// A part of the kernel interface, not of one backend: the mpi backend's
// tables split across ranks are sources, and so are a test's; kernels that
// can call back into the host read through them (interp always, cpu when
// compiled for it: Backend::read_through_sources); OpenCL kernels cannot.
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
  // Expires with the table: a copy a backend keeps between runs (on a
  // device) can go then.  Empty where the caller gives none.
  std::weak_ptr<const void> owner{};
  std::size_t bytes() const {
    return static_cast<std::size_t>(dims[0]) * dims[1] * dims[2] * element.width * ir::storage_bytes(element.scalar);
  }
};

// Where a run's elements lie in its launch domain, a row-major grid of
// extent[0] x extent[1] x extent[2] elements: element i of the run is
// element first + i of the grid, at x = g % extent[0], y = g / extent[0] %
// extent[1], z = g / (extent[0] * extent[1]) for g = first + i (what
// position() reads).  A run cut into parts (mpi ranks, waves) keeps the
// whole grid and moves `first`.  An extent[0] of 0 stands for one row as
// long as the stream.
struct LaunchDomain {
  std::array<std::size_t, 3> extent{0, 1, 1};
  std::size_t first = 0;
  std::size_t row() const { return extent[0] ? extent[0] : std::numeric_limits<std::size_t>::max(); }
  std::array<std::int32_t, 3> position(std::size_t i) const {
    std::size_t g = first + i, rows = g / row();
    return {static_cast<std::int32_t>(g % row()), static_cast<std::int32_t>(rows % extent[1]),
            static_cast<std::int32_t>(rows / extent[1])};
  }
};

struct RunArgs {
  std::size_t count = 0;  // stream elements
  LaunchDomain domain;
  std::vector<BufferView> inputs, outputs;
  std::vector<std::array<double, 4>> uniforms;  // parallel to ir.uniforms
  std::vector<TableView> tables;                // parallel to ir.tables
  // Run on the calling thread alone: its caller spreads runs over threads
  // itself (run_fused's strips).  A backend that runs in place honours it.
  bool on_this_thread = false;
  // Where the run's elements lie in the whole stream, where they are not
  // domain.first on (a wave's gathered elements): what messages name.
  const std::vector<std::size_t>* places = nullptr;
  std::size_t element(std::size_t i) const { return places && i < places->size() ? (*places)[i] : domain.first + i; }
};

// Figures a backend reports beyond RunStats' own (the mpi backend's per
// rank and per split table: sh::mpi::RunDetails in sh/mpi.hpp).
class RunDetails {
 public:
  virtual ~RunDetails() = default;
  virtual std::unique_ptr<RunDetails> clone() const = 0;
  // Adds the figures of another run of the same backend, for a caller
  // that totals several runs (a render); another backend's are ignored.
  virtual void add(const RunDetails& more) = 0;
  // One line each, for reports (shtrace prints them).
  virtual std::vector<std::string> describe() const = 0;
};

// Where a compile's time went (RunStats::compile_phases): "passes" (the
// IR optimiser and legalisation) and the backend's own phases, in order.
struct CompilePhase {
  std::string name;
  double ms = 0;
};

struct RunStats {
  std::string backend;
  bool compiled = false;   // this run compiled the kernel (not cached)
  // Where compiled: its machine code came from the kernel cache on disk
  // (Kernel::loaded_from_disk), so compile_ms is a load, not a compile.
  bool from_disk = false;
  double compile_ms = 0;
  double compile_cpu_ms = 0;  // CPU time: the compiling thread's and what it had other threads do
  std::vector<CompilePhase> compile_phases;  // where compile_ms went, where compiled
  double run_ms = 0;
  std::size_t elements = 0;
  std::vector<std::string> diagnostics;  // checked mode findings
  // Runs in waves (waves.hpp): waves after the first (the most any part
  // took, where a run is split into parts: mpi chunks, a render's bands),
  // element runs they took, and per part the refiner's summary of what it
  // has built.
  std::size_t waves = 0, resumed = 0;
  // run_fused: the strips of rows its two programs ran in together; 0
  // where they ran one after the other (sh/fused.hpp).
  std::size_t strips = 0;
  std::vector<std::string> refined;
  std::shared_ptr<RunDetails> details;  // the backend's own figures, where it has some
  template <class T>
  const T* details_as() const {
    return dynamic_cast<const T*>(details.get());
  }
};

// Adds compile phases into `total`, phase by phase (by name, in order).
void add_phases(std::vector<CompilePhase>& total, const std::vector<CompilePhase>& more);

// Adds a run's details into `total` (a copy of them where total is empty).
void add_details(std::shared_ptr<RunDetails>& total, const std::shared_ptr<RunDetails>& more);

// Counts a run's compile into a total of runs (run_fused's two programs, a
// render's bands): `compiled` where any made its kernel, `from_disk` where
// every kernel made was loaded from the disk cache.
void add_compiled(bool& compiled, bool& from_disk, const RunStats& one);

struct Waves;

class Kernel {
 public:
  virtual ~Kernel() = default;
  virtual void run(const RunArgs& args, RunStats& stats) = 0;
  // Runs in waves (waves.hpp), by default all on this process.
  virtual void run_waves(const RunArgs& args, const Waves& waves, RunStats& stats);
  // Runs task(0) .. task(count - 1), each once, on at most `threads`
  // threads, the caller's among them: for a caller that spreads its runs
  // itself (run_fused's strips, each run on_this_thread).  After every
  // task has stopped it rethrows the first exception one threw, and runs
  // no task not yet started once one has thrown.  By default on threads
  // started for the call; a backend with threads of its own uses them,
  // which keep what they hold between calls.
  virtual void run_tasks(std::size_t count, int threads, const std::function<void(std::size_t)>& task);
  // What the kernel became (LLVM IR, OpenCL C, ...), for --dump options.
  virtual std::string listing() const { return {}; }
  // Where its compile's time went, for backends that time their phases.
  virtual std::vector<CompilePhase> compile_phases() const { return {}; }
  // CPU time its compile spent on threads other than the caller's.
  virtual double compile_cpu_ms_elsewhere() const { return 0; }
  // Whether its machine code was loaded from a cache on disk that this
  // backend keeps (cpu: ~/.cache/sh) rather than compiled.
  virtual bool loaded_from_disk() const { return false; }
};

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string name() const = 0;
  virtual std::unique_ptr<Kernel> compile(const ir::Program& program, const Options& options) = 0;
  // Devices or platform in one line each, for `info`.
  virtual std::vector<std::string> describe() const { return {}; }

  // The settings of this backend's own options in their string form (see
  // Options::set): each name and the values it takes.
  struct Setting {
    std::string name, values;
  };
  virtual std::vector<Setting> settings() const { return {}; }
  // This backend's own options at their defaults; empty where it has none.
  virtual BackendOptions default_options() const { return {}; }

  // The code-generation modes a user can pick by options, each a different
  // code path that the conformance suite runs (cpu: scalar and each SPMD
  // width).  One unnamed variant with no options by default.
  struct Variant {
    std::string name;
    BackendOptions options;
  };
  virtual std::vector<Variant> variants() const { return {{}}; }

  // How many elements a kernel compiled with `options` runs side by side
  // (SIMD lanes that step together); 1 where each element runs alone.  A
  // program may pick its data structure by it: lanes that walk a tree
  // together (any_lane) read each node once.
  virtual int lanes(const Options& options) const {
    (void)options;
    return 1;
  }

  // Makes `options` ask for kernels that read a table whose TableView::data
  // is null through its TableSource, from one thread at a time; false, and
  // `options` unchanged, where this backend's kernels cannot call back into
  // the host.  A backend that hands its local kernels such tables (mpi)
  // asks its local backend this.
  virtual bool read_through_sources(Options& options) const {
    (void)options;
    return false;
  }

  // What decides, beside the options, where a kernel compiled with them
  // runs (the opencl backend's device, named by SH_OPENCL_DEVICE where the
  // options name none): part of the process's key for the kernel, so that
  // a kernel made for one device is not run where the choice is another.
  virtual std::string environment_key(const Options& options) const {
    (void)options;
    return {};
  }

  // Whether its kernels read and write in place, where RunArgs point in
  // this process's memory (no copy of a table kept between runs), and may
  // run on several threads at once for outputs that do not overlap: then
  // run_fused hands them strips of buffers of its own.
  virtual bool runs_in_place() const { return false; }
};

// The error every backend gives when an element runs a loop past
// Options::max_loop_iterations: names the program, the element (by its
// place in the whole launch domain, LaunchDomain::first plus its index in
// the run, however the run was cut) and the loop.
Error runaway_loop(const ir::Program& p, const ir::Stmt& loop, std::uint64_t element, std::uint64_t cap);

using BackendFactory = std::function<std::unique_ptr<Backend>()>;
// Called by a backend's library as it loads (a static initializer).  Where
// no backend is named, programs run on the one with the highest
// `preference` (interp has 1).
void register_backend(const std::string& name, BackendFactory factory, int preference = 0);
std::vector<std::string> backend_names();
Backend& find_backend(const std::string& name);  // throws sh::Error naming the known ones

// What a linked backend offers: the variants a conformance run covers and
// the settings of its own options.  Backend::describe() adds its devices.
struct BackendInfo {
  std::string name;
  std::vector<Backend::Variant> variants;
  std::vector<Backend::Setting> settings;
  int preference = 0;
};
// Every backend in this process, by name: interp, and each one linked.
std::vector<BackendInfo> backends();

// The linked backend with the highest preference, `except` left out.
std::string preferred_backend_name(const std::string& except = "");
// use_backend()'s choice, else SH_BACKEND from the environment, else the
// preferred backend.
std::string default_backend_name();
void use_backend(const std::string& name);  // Sh's shUseBackend

struct BackendChoice {
  std::string name;  // empty: the default backend
  Options options;
};
BackendChoice backend(const std::string& name, Options options = {});
// Backend::lanes of the chosen backend (the default one where none is named).
int lanes_of(const BackendChoice& choice);

// Runs `program` over the streams: every input the same length, every
// output that length (an empty output channel is sized to it).
RunStats run(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
             const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const BackendChoice& choice = {});

// The kernel run() would use (compiled or from the cache), e.g. to dump it
// or to run it on RunArgs built by hand: each run's arguments are checked
// against the program first (counts, types, lengths, memory, tables' ranks
// and sizes, the launch domain), an sh::Error naming what is wrong.  A
// kernel from Backend::compile itself trusts its arguments.
std::shared_ptr<Kernel> kernel_for(const Program& program, const BackendChoice& choice = {});

}  // namespace sh
