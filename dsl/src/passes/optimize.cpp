#include "sh/ir/serialize.hpp"
#include "sh/ir/verifier.hpp"
#include "sh/passes.hpp"

namespace sh {
namespace {

#ifdef NDEBUG
constexpr bool kVerifyEachPass = false;
#else
constexpr bool kVerifyEachPass = true;
#endif

ir::Program checked(ir::Program p) {
  if (kVerifyEachPass) ir::verify(p);
  return p;
}

}  // namespace

ir::Program optimize(ir::Program p, ir::Precision precision) {
  ir::verify(p);
  // Each round can expose work for the others (a folded branch frees a
  // copy, a propagated copy makes an expression common); a few rounds reach
  // the fixed point of every program we have seen.
  constexpr int kMaxRounds = 8;
  std::uint64_t before = ir::structural_hash(p);
  for (int round = 0; round < kMaxRounds; ++round) {
    p = checked(passes::fold_constants(std::move(p), precision));
    p = checked(passes::propagate_copies(std::move(p)));
    p = checked(passes::eliminate_common_subexpressions(std::move(p)));
    p = checked(passes::propagate_copies(std::move(p)));
    p = checked(passes::coalesce_moves(std::move(p)));
    p = checked(passes::eliminate_dead_code(std::move(p)));
    p = checked(passes::compact_variables(std::move(p)));
    std::uint64_t after = ir::structural_hash(p);
    if (after == before) break;
    before = after;
  }
  return p;
}

Program optimize(const Program& p, ir::Precision precision) { return p.with_ir(optimize(p.ir(), precision)); }

}  // namespace sh
