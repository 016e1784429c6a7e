#pragma once
// Programs as bytes, to send one to another process (the MPI backend
// compiles the same IR on every rank) without recording it again.
#include <string>

#include "sh/ir/program.hpp"

namespace sh::ir {

std::string serialize(const Program& p);
// Throws sh::Error on bytes that do not make a well-formed program.
Program deserialize(const std::string& bytes);

}  // namespace sh::ir
