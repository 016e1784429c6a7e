#pragma once
#include <memory>
#include <string>

#include "options.hpp"
#include "sh/backend.hpp"

namespace sh::mpi {

// Rank 0's kernel: compiles locally and on every rank, and runs a stream
// by handing chunks to whichever rank asks while computing chunks itself.
std::unique_ptr<Kernel> coordinator(const ir::Program& program, const sh::Options& options);

// The backend each rank runs the kernel on, and the options it gets: all
// but the mpi backend's own.
std::string local_backend_name(const Options& mpi_options);
sh::Options local_options(const sh::Options& options);

}  // namespace sh::mpi
