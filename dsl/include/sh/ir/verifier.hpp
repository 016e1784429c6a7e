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

// Checks that a program is legal IR (sh::passes::legalize's output), what
// a backend is given: no fetch or sample.  Throws sh::Error naming the
// program and the statement.
void verify_legal(const Program& p);

}  // namespace sh::ir
