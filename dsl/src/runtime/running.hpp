#pragma once
// What the run calls share (run, run with waves, run_fused): the backend a
// choice names, the kernel of a program (compiled or from the caches), and
// a run's arguments bound from its channels and the program's tables.
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sh/backend.hpp"

namespace sh {
struct Waves;
}

namespace sh::detail {

std::string resolve(const BackendChoice& choice);
// The program as backends get it: optimised (where the options ask) and
// legalised, from the disk cache where an earlier process made it.
ir::Program legal_program(const Program& program, const Options& options);
std::shared_ptr<Kernel> cached_kernel(const Program& program, const std::string& name, const Options& options,
                                      RunStats& stats);
RunArgs bind_arguments(const Program& program, const std::vector<std::shared_ptr<Buffer>>& inputs,
                       const std::vector<std::shared_ptr<Buffer>>& outputs);
double ms_since(std::chrono::steady_clock::time_point t0);

// Waves' outputs and carried pairs as the program has them.
void check_waves(const ir::Program& p, const Waves& w);
// What is wrong with a table's view for a program's table of `element` and
// `rank` ("" where nothing is): the phrase after "table k".
std::string table_problem(ir::Type element, int rank, const TableView& view);
// The kernel, checking each run's arguments against `program` first.
std::shared_ptr<Kernel> checked(const Program& program, std::shared_ptr<Kernel> kernel);

// The bytes [first, second) of a block of memory, and whether two blocks
// share any.
using Bytes = std::pair<std::uintptr_t, std::uintptr_t>;
inline Bytes byte_range(const void* p, std::size_t bytes) {
  auto at = reinterpret_cast<std::uintptr_t>(p);
  return {at, at + bytes};
}
inline bool overlap(Bytes a, Bytes b) { return a.first < b.second && b.first < a.second; }

}  // namespace sh::detail
