#pragma once
// What the mpi backend reads from its own options (sh::mpi::Options).
#include <vector>

#include "sh/mpi.hpp"

namespace sh::mpi {

// Throws sh::Error naming a setting out of its range.
void check(const Options& options);

// The string form of mpi::Options, for Backend::settings().
std::vector<Backend::Setting> settings();

}  // namespace sh::mpi
