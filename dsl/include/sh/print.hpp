#pragma once
// Human-readable IR of a program, as recorded or after the passes.
#include <string>

#include "sh/ir/eval.hpp"
#include "sh/ir/printer.hpp"
#include "sh/ir/serialize.hpp"
#include "sh/ir/verifier.hpp"
#include "sh/program.hpp"

namespace sh {

std::string print(const Program& p);
std::string print_optimized(const Program& p, ir::Precision precision = ir::Precision::F32);

}  // namespace sh
