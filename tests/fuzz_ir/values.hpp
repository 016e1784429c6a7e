#pragma once
// The values programs see in their inputs, uniforms, constants and tables:
// mostly the extremes (NaN, ±Inf, denormals, ±0, INT_MIN, INT_MAX, huge and
// tiny, halfway cases of round, the edges of float-to-int conversion),
// the rest ordinary or random bit patterns.  Each is held as a double that
// represents the scalar's value exactly (an f32 value is a float's).
#include <sh/ir/type.hpp>

#include "rng.hpp"

namespace fuzz_ir {

double random_value(Rng& rng, sh::ir::Scalar s);

// The value a channel, table or uniform of scalar `s` stores for `v`.
double representable(sh::ir::Scalar s, double v);

}  // namespace fuzz_ir
