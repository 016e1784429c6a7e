#pragma once
// Running in waves: for tables the host extends while a stream runs (an
// accelerator built lazily, only where elements go).  Kernels cannot
// allocate, so an element that needs a part of a table not built yet stops
// and writes a request to the program's request output (an int, or up to
// four: the first >= 0 says the element stopped, the others say more about
// what it needs); after the run, a Refiner builds what the requests ask
// for, and the stopped elements run again.  Outputs named as carried are fed back into inputs, so an
// element resumes where it stopped; without them it starts over.  An
// element that finished writes a first request component of -1.
//
// Without a refiner, waves are a wavefront: an element that is not done
// (a path with bounces to go) writes a request >= 0, and the next wave runs
// only such elements, gathered side by side, so that SIMD lanes are not
// left idle beside elements that finished early.
//
// Every backend runs waves: run() drives them on one process; the mpi
// backend gives each rank its own refiner (made from the first one's seed)
// so that each rank builds only what its own chunks need.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sh/backend.hpp"

namespace sh {

class Refiner {
 public:
  Refiner();
  virtual ~Refiner() = default;
  // Unique in the process: says whether another process already has it.
  std::uint64_t id() const { return id_; }
  // The name its factory is registered under (register_refiner).
  virtual std::string kind() const = 0;
  // What another process needs to start its own refiner in the state this
  // one started from (not what this one has built since).
  virtual std::string seed() const = 0;
  // Points the views of the tables this refiner extends at what it has
  // built so far (each table it owns keeps an id of its own, and a version
  // bumped whenever it grows).
  virtual void bind(std::vector<TableView>& tables) const = 0;
  // Builds what the requests ask for (`width` ints each, one per stopped
  // element, in the order of the stream: many elements may ask for the
  // same thing); returns how many things it built.
  virtual std::size_t refine(const std::vector<std::int32_t>& requests, int width) = 0;
  // What it has built, in bytes a caller of that kind can read (per rank
  // in RunStats::refined).
  virtual std::string summary() const = 0;

 private:
  std::uint64_t id_;
};

using RefinerFactory = std::function<std::unique_ptr<Refiner>(const std::string& seed)>;
// Every process of a job registers the same kinds (static registration in
// the program that uses them does this).
void register_refiner(const std::string& kind, RefinerFactory factory);
std::unique_ptr<Refiner> make_refiner(const std::string& kind, const std::string& seed);

// A process-unique id for a table a refiner owns; never equal to the id of
// a Table made with sh::Table in any process.
std::uint64_t refined_table_id();

struct Waves {
  Refiner* refiner = nullptr;               // none: stopped elements run again as they are
  int request_output = 0;                    // an int output of 1 to 4 components
  std::vector<std::pair<int, int>> carried;  // (output, input) pairs of equal types
  int max_waves = 1 << 16;                   // a refiner that never satisfies a request ends here
};

// Runs the kernel over the stream in waves on this process.
void run_in_waves(Kernel& kernel, const RunArgs& args, const Waves& waves, RunStats& stats);

// run() in waves: the program's request output and carried pairs are
// checked against its types.
RunStats run(const Program& program, const std::vector<std::shared_ptr<detail::Buffer>>& inputs,
             const std::vector<std::shared_ptr<detail::Buffer>>& outputs, const Waves& waves,
             const BackendChoice& choice = {});

}  // namespace sh
