#pragma once
// Optimisation passes over the IR, each in its own file under src/passes.
// None changes a result beyond what the chosen precision allows: constants
// fold under the precision the kernel will run in.
#include "sh/ir/eval.hpp"
#include "sh/ir/program.hpp"
#include "sh/program.hpp"

namespace sh::passes {

ir::Program fold_constants(ir::Program p, ir::Precision precision);
ir::Program propagate_copies(ir::Program p);
ir::Program eliminate_common_subexpressions(ir::Program p);
ir::Program eliminate_dead_code(ir::Program p);
ir::Program coalesce_moves(ir::Program p);
ir::Program compact_variables(ir::Program p);
// What every backend is given: table reads as in-range loads, integer
// division that cannot trap (legalize.cpp says how).  Not an optimisation:
// the runtime runs it after the pipeline, always.
ir::Program legalize(ir::Program p);

}  // namespace sh::passes

namespace sh {

// The pipeline, run to a fixed point (specialisation happens here too: a
// frozen uniform is a constant, and the branches it decides fold away).
ir::Program optimize(ir::Program p, ir::Precision precision = ir::Precision::F32);
Program optimize(const Program& p, ir::Precision precision = ir::Precision::F32);

}  // namespace sh
