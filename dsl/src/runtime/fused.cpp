#include "sh/fused.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "running.hpp"
#include "sh/analysis.hpp"
#include "sh/detail/words.hpp"
#include "sh/error.hpp"

namespace sh::detail {
namespace {

// About what a core's second-level cache holds with room to spare: a
// strip's buffer of this many bytes or fewer stays there between the
// producer's writes and the consumer's reads.
constexpr std::size_t kStripBytes = 512 * 1024;

// A thread keeps a strip buffer up to this size for its next run.
constexpr std::size_t kKeptStripBytes = 4 * kStripBytes;

// The rows above (low, negative) and below (high) an element's own that a
// consumer reads of a table.
struct Reach {
  int low = 0, high = 0;
};

// None where one of the reads of table `t` is not a tap at a constant
// offset from position().
std::optional<Reach> row_reach(const ir::Program& consumer, int t) {
  std::optional<Reach> reach;
  for (const auto& [read, access] : analysis::table_access(consumer)) {
    if (read->table != t) continue;
    if (!access.offset) return std::nullopt;
    int dy = (*access.offset)[1];
    reach = reach ? Reach{std::min(reach->low, dy), std::max(reach->high, dy)} : Reach{dy, dy};
  }
  return reach;
}

// The consumer's reach into table `t` in the program its backend gets (the
// analysis proves offsets of values written once, as the passes leave
// them): found once per program and options.
std::optional<Reach> reach_of(const Program& consumer, int t, const Options& options) {
  static std::mutex mutex;
  static std::map<std::string, std::optional<Reach>> known;
  std::string key = std::to_string(consumer.hash()) + "|" + std::to_string(t) + "|" + options.key();
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto found = known.find(key); found != known.end()) return found->second;
  }
  std::optional<Reach> reach = row_reach(legal_program(consumer, options), t);
  std::lock_guard<std::mutex> lock(mutex);
  return known.emplace(key, reach).first->second;
}

bool has_accumulator(const Program& p) {
  return std::any_of(p.ir().tables.begin(), p.ir().tables.end(), [](const ir::TableDecl& t) { return t.accumulator; });
}

int table_index(const Program& p, const std::shared_ptr<TableStorage>& table) {
  auto found = std::find(p.tables().begin(), p.tables().end(), table);
  return found == p.tables().end() ? -1 : static_cast<int>(found - p.tables().begin());
}

std::string describe(const TableStorage& t) { return "table" + (t.decl.name.empty() ? "" : " '" + t.decl.name + "'"); }

// The producer gives the table the consumer reads without reading it, and
// neither takes input streams.
void check_linked(const Program& producer, const TableStorage& through, int through_at, bool producer_reads_it,
                  const Program& consumer) {
  const ir::Program& p = producer.ir();
  const ir::Program& c = consumer.ir();
  if (!p.inputs.empty() || !c.inputs.empty())
    throw Error("program '" + (p.inputs.empty() ? c.name : p.name) +
                "': run_fused runs programs without input streams over their outputs' launch domain");
  if (p.outputs.size() != 1)
    throw Error("program '" + p.name + "': run_fused's producer gives one output, not " + std::to_string(p.outputs.size()));
  if (p.type_of(p.outputs[0]) != through.decl.element)
    throw Error("program '" + p.name + "': its output is " + ir::type_name(p.type_of(p.outputs[0])) + " but " +
                describe(through) + " holds " + ir::type_name(through.decl.element));
  if (through_at < 0)
    throw Error("program '" + c.name + "': run_fused's consumer does not read the " + describe(through));
  // Its reads would meet its own writes, in an order each backend picks.
  if (producer_reads_it)
    throw Error("program '" + p.name + "': run_fused's producer reads the " + describe(through) +
                " it fills; read the values it needs from another table");
}

// The domain is a grid of the table's dimensions.
void check_grid(const ir::Program& c, const TableStorage& through, const LaunchDomain& domain) {
  if (through.decl.rank != 2)
    throw Error("program '" + c.name + "': run_fused reads the " + describe(through) + " as rows of a grid, but it has " +
                std::to_string(through.decl.rank) + " dimension" + (through.decl.rank == 1 ? "" : "s"));
  auto dim = [&](std::size_t i) { return static_cast<std::size_t>(through.dims[i]); };
  if (domain.extent[2] != 1 || dim(0) != domain.extent[0] || dim(1) != domain.extent[1])
    throw Error("program '" + c.name + "': run_fused runs over a grid of the " + describe(through) + "'s dimensions, " +
                std::to_string(through.dims[0]) + " x " + std::to_string(through.dims[1]) +
                ", but its outputs are shaped " + std::to_string(domain.extent[0]) + " x " +
                std::to_string(domain.extent[1]) + " x " + std::to_string(domain.extent[2]));
}

// Whether a table of either program, other than `besides`, lies in any
// of `bytes`.
bool a_table_in(Bytes bytes, const RunArgs& make, const RunArgs& use, const TableView* besides = nullptr) {
  for (const RunArgs* args : {&make, &use})
    for (const TableView& t : args->tables)
      if (&t != besides && t.data && overlap(bytes, byte_range(t.data, t.bytes()))) return true;
  return false;
}

// Whether a run's output lies in memory a table of either program holds
// (an in-place blur): strips write rows another strip's producer still
// reads, where one run after the other does not.
bool writes_a_table(const RunArgs& make, const RunArgs& use) {
  return std::any_of(use.outputs.begin(), use.outputs.end(), [&](const BufferView& out) {
    return a_table_in(byte_range(out.data, out.count * ir::element_bytes(out.type)), make, use);
  });
}

// Whether a table other than the consumer's `through_at` views memory of
// that table (a second Table2D on its memory): strips put the producer's
// rows in a buffer of their own, so such a view would read what the table
// held before the call, where one run after the other reads the rows.
bool views_the_table(const RunArgs& make, const RunArgs& use, int through_at) {
  const TableView& through = use.tables[static_cast<std::size_t>(through_at)];
  return a_table_in(byte_range(through.data, through.bytes()), make, use, &through);
}

// The producer's output in the table's own memory, shaped as the domain.
std::shared_ptr<Buffer> table_as_output(TableStorage& through, const LaunchDomain& domain) {
  auto view = std::make_shared<Buffer>(through.decl.element, 0);
  view->view(through.buffer.memory(), through.buffer.size(), describe(through));
  view->shape(domain.extent);
  return view;
}

void add_run(RunStats& total, const RunStats& one) {
  add_compiled(total.compiled, total.from_disk, one);
  total.compile_ms += one.compile_ms;
  total.compile_cpu_ms += one.compile_cpu_ms;
  add_phases(total.compile_phases, one.compile_phases);
  total.diagnostics.insert(total.diagnostics.end(), one.diagnostics.begin(), one.diagnostics.end());
  add_details(total.details, one.details);
}

// `bytes` bytes before `p`: where row 0 of a table lies whose row `first`
// is at p.  Only rows the strip holds are read through it.
const void* shifted_back(const void* p, std::size_t bytes) {
  return reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(p) - bytes);
}

// The strips of `rows` rows over the domain, spread over `threads`
// threads, each with a buffer of its own for the producer's rows.
class Strips {
 public:
  Strips(const RunArgs& producer, const RunArgs& consumer, int through_at, Reach reach, int rows, std::size_t row_bytes)
      : producer_(producer), consumer_(consumer), through_at_(through_at), reach_(reach), rows_(rows),
        width_(consumer.domain.extent[0]), row_bytes_(row_bytes), height_(static_cast<int>(consumer.domain.extent[1])) {}

  std::size_t count() const { return static_cast<std::size_t>((std::int64_t{height_} + rows_ - 1) / rows_); }

  // The runs' details (RunStats::details) totalled into `details`.
  void run(Kernel& make, Kernel& use, int threads, std::shared_ptr<RunDetails>& details) {
    std::mutex totalling;
    use.run_tasks(count(), threads, [&](std::size_t k) {
      // As a channel's storage, starting a cache line.  Kept by the thread
      // for its next strip, which then neither clears nor maps it again,
      // unless strips asked for far more than the default.
      thread_local Words buffer;
      RunStats made, used;
      strip(static_cast<int>(k), make, use, buffer, made, used);
      if (buffer.capacity() * sizeof(std::uint64_t) > kKeptStripBytes) Words().swap(buffer);
      std::lock_guard<std::mutex> lock(totalling);
      add_details(details, made.details);
      add_details(details, used.details);
    });
  }

 private:
  // Strip k: the producer's rows [low, high) into the buffer, then the
  // consumer's rows [first, end) reading them there: its taps reach rows
  // [first + reach.low, end - 1 + reach.high], clamped to the table's
  // (or, where it gives zero outside, those of them inside it).
  void strip(int k, Kernel& make, Kernel& use, Words& buffer, RunStats& made, RunStats& used) const {
    std::int64_t first = std::int64_t{k} * rows_, end = std::min<std::int64_t>(height_, first + rows_);
    std::int64_t low = std::clamp<std::int64_t>(first + reach_.low, 0, height_ - 1);
    std::int64_t high = std::clamp<std::int64_t>(end - 1 + reach_.high, 0, height_ - 1) + 1;
    std::size_t held = static_cast<std::size_t>(high - low);
    buffer.resize((held * row_bytes_ + 7) / 8);
    RunArgs p = producer_;
    p.on_this_thread = true;
    p.count = held * width_;
    p.domain.first = static_cast<std::size_t>(low) * width_;
    p.outputs[0].data = buffer.data();
    p.outputs[0].count = p.count;
    p.outputs[0].read_back = true;
    make.run(p, made);
    RunArgs c = consumer_;
    c.on_this_thread = true;
    c.count = static_cast<std::size_t>(end - first) * width_;
    c.domain.first = static_cast<std::size_t>(first) * width_;
    for (BufferView& out : c.outputs) out = out.part(c.domain.first, c.count);
    // Rows [low, high) lie in the buffer: the view ends at its end, so that
    // nothing the kernel asks for (a prefetch of the next row) lies past it.
    TableView& through = c.tables[through_at_];
    through.data = shifted_back(buffer.data(), static_cast<std::size_t>(low) * row_bytes_);
    through.dims[1] = static_cast<int>(high);
    use.run(c, used);
  }

  RunArgs producer_, consumer_;
  int through_at_;
  Reach reach_;
  int rows_;
  std::size_t width_, row_bytes_;
  int height_;
};

// The producer fills the table, so the consumer's arguments take it as
// filled from the start; a call that fails before its run leaves the
// table as it found it (a table never filled stays an error to read).
class FilledByProducer {
 public:
  explicit FilledByProducer(TableStorage& table) : table_(table), was_filled_(table.filled) { table.touch(); }
  FilledByProducer(const FilledByProducer&) = delete;
  FilledByProducer& operator=(const FilledByProducer&) = delete;
  ~FilledByProducer() {
    if (!running_) table_.filled = was_filled_;
  }
  void running() { running_ = true; }

 private:
  TableStorage& table_;
  bool was_filled_;
  bool running_ = false;
};

}  // namespace

RunStats run_fused(const Program& producer, const std::shared_ptr<TableStorage>& through, const Program& consumer,
                   const std::vector<std::shared_ptr<Buffer>>& outputs, const BackendChoice& choice, int strip_rows) {
  RunStats stats;
  stats.backend = resolve(choice);
  int through_at = table_index(consumer, through);
  check_linked(producer, *through, through_at, table_index(producer, through) >= 0, consumer);
  FilledByProducer filled(*through);
  RunArgs use_args = bind_arguments(consumer, {}, outputs);
  check_grid(consumer.ir(), *through, use_args.domain);
  std::shared_ptr<Buffer> rows = table_as_output(*through, use_args.domain);
  RunArgs make_args = bind_arguments(producer, {}, {rows});
  RunStats compiled;
  std::shared_ptr<Kernel> make = cached_kernel(producer, stats.backend, choice.options, compiled);
  add_run(stats, compiled);
  compiled = {};
  std::shared_ptr<Kernel> use = cached_kernel(consumer, stats.backend, choice.options, compiled);
  add_run(stats, compiled);
  stats.elements = use_args.count;
  filled.running();
  if (use_args.count == 0) return stats;

  // Checked runs keep the two apart, so that their findings name elements
  // of the whole grid.
  bool may_strip = find_backend(stats.backend).runs_in_place() && !choice.options.checked &&
                   consumer.ir().tables[through_at].edge != ir::Edge::Repeat &&
                   !has_accumulator(producer) && !has_accumulator(consumer) && !writes_a_table(make_args, use_args) &&
                   !views_the_table(make_args, use_args, through_at);
  std::optional<Reach> reach = may_strip ? reach_of(consumer, through_at, choice.options) : std::nullopt;
  // A tap so far below the last row that row + offset passes what int32
  // holds wraps in the kernel's arithmetic to a row the strips do not hold.
  if (reach && static_cast<std::int64_t>(use_args.domain.extent[1]) - 1 + reach->high > INT32_MAX) reach.reset();
  auto t0 = std::chrono::steady_clock::now();
  if (reach) {
    std::size_t row_bytes = rows->bytes_for(use_args.domain.extent[0]);
    std::size_t height = use_args.domain.extent[1];
    std::size_t rows_per_strip = strip_rows > 0 ? static_cast<std::size_t>(strip_rows) : kStripBytes / row_bytes;
    rows_per_strip = std::clamp<std::size_t>(rows_per_strip, 1, height);
    Strips strips(make_args, use_args, through_at, *reach, static_cast<int>(rows_per_strip), row_bytes);
    int threads = choice.options.threads > 0 ? choice.options.threads
                                             : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    strips.run(*make, *use, threads, stats.details);
    stats.strips = strips.count();
  } else {
    RunStats made, used;
    make->run(make_args, made);
    rows->written();
    use_args = bind_arguments(consumer, {}, outputs);  // the table's new version
    use->run(use_args, used);
    add_run(stats, made);
    add_run(stats, used);
  }
  for (const auto& o : outputs) o->written();
  stats.run_ms = ms_since(t0);
  return stats;
}

}  // namespace sh::detail
