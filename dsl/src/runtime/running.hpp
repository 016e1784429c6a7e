#pragma once
// What the run calls share (run, run with waves, run_fused): the backend a
// choice names, the kernel of a program (compiled or from the caches), and
// a run's arguments bound from its channels and the program's tables.
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "sh/backend.hpp"

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

}  // namespace sh::detail
