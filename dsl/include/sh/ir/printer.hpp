#pragma once
// The stable text form of a program: what `sh::print`, `--dump-ir` and the
// golden tests show.  (The hash is taken over the serialized bytes:
// serialize.hpp.)
#include <string>

#include "sh/ir/program.hpp"

namespace sh::ir {

struct PrintOptions {
  bool names = true;          // show the names people gave variables
  bool declare_temps = false; // list temporaries and constants in the header
  bool inline_consts = true;  // print a constant operand as its value
};

std::string print(const Program& p, const PrintOptions& options = {});
std::string print(const Program& p, const Stmt& s);  // one statement, one line
std::string print_operand(const Program& p, const Operand& o);

std::string format_number(double v, Scalar s);

}  // namespace sh::ir
