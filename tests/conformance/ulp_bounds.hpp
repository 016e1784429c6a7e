#pragma once
// The accuracy every backend promises: the largest error in units in the
// last place against the correctly rounded result of C++'s <cmath> computed
// in double.  An operation's bounds are its row in the op table
// (dsl/include/sh/ir/ops.def); library functions composed of operations
// have theirs here.  Fast math gives up special values (NaN, infinities,
// denormals, signed zero): those inputs are skipped in fast mode, and the
// fast bounds are looser.
#include <cstdint>
#include <string>
#include <string_view>

#include <sh/ir/op.hpp>

namespace conformance {

struct UlpBound {
  std::string_view function;
  std::uint64_t precise;
  std::uint64_t fast;
};

// Library functions, not operations of the table.
inline constexpr UlpBound kLibraryUlpBounds[] = {
    {"frac", 0, 4},
};

inline UlpBound ulp_bound(std::string_view function) {
  sh::ir::Op op;
  if (sh::ir::op_named(std::string(function).c_str(), op))
    return {function, sh::ir::op_info(op).ulp_precise, sh::ir::op_info(op).ulp_fast};
  for (const UlpBound& b : kLibraryUlpBounds)
    if (b.function == function) return b;
  return {function, 0, 0};
}

}  // namespace conformance
