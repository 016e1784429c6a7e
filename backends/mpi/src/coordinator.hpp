#pragma once
#include <memory>

#include "sh/backend.hpp"

namespace sh::mpi {

// Rank 0's kernel: compiles locally and on every rank, and runs a stream
// by handing chunks to whichever rank asks while computing chunks itself.
std::unique_ptr<Kernel> coordinator(const ir::Program& program, const sh::Options& options);

}  // namespace sh::mpi
