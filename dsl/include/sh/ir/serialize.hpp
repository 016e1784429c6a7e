#pragma once
// Programs as bytes: the one serialized form, which the MPI backend sends
// to its ranks, `shtrace --dump-ir` writes and `shtrace ir` reads, and whose
// bytes without names are the kernel cache's key (structural_hash).
//
// Layout (integers little-endian, doubles as their IEEE-754 bits): "SHIR",
// a version byte, the program's name, its variables (kind, scalar, width,
// name, and a constant's components), its input, output and uniform lists,
// its tables, then its body, statement by statement.  A name is a length
// and its bytes; a count is a u32.
#include <cstdint>
#include <string>

#include "sh/ir/program.hpp"

namespace sh::ir {

struct SerializeOptions {
  // The names people gave the program, its variables and its tables.  Off,
  // each is written empty: the bytes then say only what the program does.
  bool names = true;
};

std::string serialize(const Program& p, const SerializeOptions& options = {});
// Throws sh::Error on bytes that do not make a well-formed program: every
// value read is range-checked, then the program verified.
Program deserialize(const std::string& bytes);

// A hash of the serialized bytes without names: programs that differ only
// in names or in uniform values (which the IR does not hold) hash alike.
std::uint64_t structural_hash(const Program& p);

}  // namespace sh::ir
