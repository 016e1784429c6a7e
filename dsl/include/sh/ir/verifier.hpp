#pragma once
#include "sh/ir/program.hpp"

namespace sh::ir {

// Checks that a program is well formed: every operand names a variable and
// reads components it has, widths and types agree with each operation, only
// writable variables are written, break/continue sit inside loops, table
// reads name a declared table.  Throws sh::Error naming the program and the
// offending statement.  Every pass's output goes through it in tests and
// debug builds.
void verify(const Program& p);

}  // namespace sh::ir
