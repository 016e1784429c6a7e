#include "sh/waves.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <map>
#include <mutex>

#include "running.hpp"
#include "sh/error.hpp"

namespace sh {
namespace {

struct Refiners {
  std::mutex mutex;
  std::map<std::string, RefinerFactory> factories;
};

Refiners& refiners() {
  static Refiners r;
  return r;
}

// The elements of a run still waiting: where each one's results belong in
// the caller's streams, and the gathered inputs they run on next.
class Stopped {
 public:
  // Elements whose request (output `request` of `args`) is >= 0; `at`
  // maps them back to the caller's positions.
  void collect(const RunArgs& args, int request, const std::vector<std::size_t>& at) {
    const BufferView& out = args.outputs[request];
    const auto* r = static_cast<const std::int32_t*>(out.data);
    width_ = out.type.width;
    positions_.clear();
    requests_.clear();
    for (std::size_t i = 0; i < args.count; ++i)
      if (r[i * width_] >= 0) {
        positions_.push_back(at.empty() ? i : at[i]);
        requests_.emplace_back();
        std::copy(r + i * width_, r + (i + 1) * width_, requests_.back().begin());
      }
  }
  bool empty() const { return positions_.empty(); }
  int width() const { return width_; }
  const std::vector<std::size_t>& positions() const { return positions_; }
  std::vector<std::int32_t> requests() const {
    std::vector<std::int32_t> flat;
    flat.reserve(requests_.size() * static_cast<std::size_t>(width_));
    for (const auto& r : requests_) flat.insert(flat.end(), r.begin(), r.begin() + width_);
    return flat;
  }

 private:
  int width_ = 1;
  std::vector<std::size_t> positions_;
  std::vector<std::array<std::int32_t, 4>> requests_;  // unused components zero
};

// Space for the stopped elements' streams, one buffer per input and
// output, kept from wave to wave: the stopped set only shrinks, so after
// the first wave no page is touched for the first time.
class Scratch {
 public:
  char* take(std::size_t slot, std::size_t bytes) {
    if (buffers_.size() <= slot) buffers_.resize(slot + 1);
    if (buffers_[slot].size() < bytes) buffers_[slot].resize(bytes);
    return buffers_[slot].data();
  }
  std::vector<std::size_t> places;  // the gathered elements' places in the whole stream

 private:
  std::vector<std::vector<char>> buffers_;
};

// The stopped elements' arguments: inputs gathered from the caller's
// streams (carried ones from its outputs), outputs into scratch space.
RunArgs gather(const RunArgs& full, const Waves& w, const std::vector<std::size_t>& at, Scratch& scratch) {
  RunArgs c = full;
  c.count = at.size();
  scratch.places.resize(at.size());
  for (std::size_t k = 0; k < at.size(); ++k) scratch.places[k] = full.element(at[k]);
  c.places = &scratch.places;
  std::size_t slot = 0;
  auto gathered = [&](const BufferView& from) {
    std::size_t n = ir::element_bytes(from.type);
    char* to = scratch.take(slot++, at.size() * n);
    for (std::size_t k = 0; k < at.size(); ++k) std::memcpy(to + k * n, static_cast<const char*>(from.data) + at[k] * n, n);
    return BufferView{from.type, at.size(), to};
  };
  for (std::size_t i = 0; i < full.inputs.size(); ++i) {
    auto carried = std::find_if(w.carried.begin(), w.carried.end(), [&](const auto& p) { return p.second == static_cast<int>(i); });
    c.inputs[i] = gathered(carried == w.carried.end() ? full.inputs[i] : full.outputs[carried->first]);
  }
  for (BufferView& out : c.outputs) out = BufferView{out.type, at.size(), scratch.take(slot++, at.size() * ir::element_bytes(out.type))};
  return c;
}

void refine(Refiner& refiner, const Stopped& stopped, const RunArgs& all) {
  std::vector<std::int32_t> requests = stopped.requests();
  if (refiner.refine(requests, stopped.width()) == 0)
    throw Error("running in waves: the " + refiner.kind() + " refiner built nothing for request " +
                std::to_string(requests.front()) + " (element " + std::to_string(all.element(stopped.positions().front())) +
                "), which would stop it forever");
}

void scatter(const RunArgs& part, const RunArgs& full, const std::vector<std::size_t>& at) {
  for (std::size_t o = 0; o < full.outputs.size(); ++o) {
    std::size_t n = ir::element_bytes(full.outputs[o].type);
    for (std::size_t k = 0; k < at.size(); ++k)
      std::memcpy(static_cast<char*>(full.outputs[o].data) + at[k] * n, static_cast<const char*>(part.outputs[o].data) + k * n, n);
  }
}

}  // namespace

Refiner::Refiner() {
  static std::atomic<std::uint64_t> next{1};
  id_ = next++;
}

void register_refiner(const std::string& kind, RefinerFactory factory) {
  Refiners& r = refiners();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.factories[kind] = std::move(factory);
}

std::unique_ptr<Refiner> make_refiner(const std::string& kind, const std::string& seed) {
  Refiners& r = refiners();
  RefinerFactory f;
  {
    std::lock_guard<std::mutex> lock(r.mutex);
    auto it = r.factories.find(kind);
    if (it == r.factories.end()) throw Error("no refiner of kind '" + kind + "' is registered in this process");
    f = it->second;
  }
  return f(seed);
}

std::uint64_t refined_table_id() {
  static std::atomic<std::uint64_t> next{1};
  return (std::uint64_t{1} << 63) | next++;
}

// What a refiner's bind hands the kernel must be what the program reads:
// as many tables, of the same element types and ranks, each of at least
// one element a dimension with its elements somewhere.  A kernel trusts
// its tables (one left out crashed the cpu backend's code).
void check_bound(const std::vector<TableView>& declared, const std::vector<TableView>& bound) {
  auto fail = [](const std::string& what) { throw Error("running in waves: the refiner's bind " + what); };
  if (bound.size() != declared.size())
    fail("left " + std::to_string(bound.size()) + " tables where the program reads " + std::to_string(declared.size()));
  for (std::size_t i = 0; i < bound.size(); ++i) {
    if (std::string problem = detail::table_problem(declared[i].element, declared[i].rank, bound[i]); !problem.empty())
      fail("made table " + std::to_string(i) + " that " + problem);
  }
}

void run_in_waves(Kernel& kernel, const RunArgs& args, const Waves& w, RunStats& stats) {
  RunArgs all = args;
  auto bind = [&] {
    w.refiner->bind(all.tables);
    check_bound(args.tables, all.tables);
  };
  if (w.refiner) bind();
  kernel.run(all, stats);
  Stopped stopped;
  stopped.collect(all, w.request_output, {});
  Scratch scratch;
  // This run's waves after the first (stats may hold other runs' too),
  // counted before the refiner builds for one that will not run.
  int waves = 0;
  while (!stopped.empty()) {
    if (++waves > w.max_waves)
      throw Error("running in waves: still " + std::to_string(stopped.positions().size()) + " elements stopped after " +
                  std::to_string(w.max_waves) + " waves");
    ++stats.waves;
    if (w.refiner) {
      refine(*w.refiner, stopped, all);
      bind();
    }
    std::vector<std::size_t> at = stopped.positions();
    RunArgs part = gather(all, w, at, scratch);
    kernel.run(part, stats);
    scatter(part, all, at);
    stats.resumed += at.size();
    stopped.collect(part, w.request_output, at);
  }
}

void Kernel::run_waves(const RunArgs& args, const Waves& waves, RunStats& stats) {
  run_in_waves(*this, args, waves, stats);
  if (waves.refiner) stats.refined = {waves.refiner->summary()};
}

}  // namespace sh
