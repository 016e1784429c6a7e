#pragma once
// The CPU backend: the optimised IR is lowered to LLVM IR, compiled by
// LLVM 15's ORC LLJIT for the host CPU, and run over the stream in oneTBB
// parallel loops.  Including this header registers it as "cpu".
//
// Kernels are SPMD: each SIMD lane runs one stream element (16 lanes with
// AVX-512, 8 with AVX, else 4), values that cannot differ between lanes
// stay scalar, divergent ifs and loops run under lane masks, and table
// reads are gathers.  The setting "width" picks scalar, 4, 8 or 16 lanes
// ("auto" or absent: the host's); every width gives the same results.
//
// Options it honours: precision (f32 without FMA contraction, IEEE divide
// and sqrt; f64 computes every float as double), math (fast: LLVM fast-math
// flags), threads (a oneTBB arena; 0 = every core), max_loop_iterations,
// settings["width"], settings["tables"] ("fetched": each table read calls
// out to the run, so a table may be a TableSource, such as an mpi rank's
// cache of a table split across ranks; "memory", the default, loads).
// kernel_for(p, backend("cpu"))->listing() gives the optimised LLVM IR.
#include "sh/backend.hpp"

namespace sh::cpu {

void register_backend();

namespace detail {
inline const bool registered = (register_backend(), true);
}  // namespace detail

}  // namespace sh::cpu
