#pragma once
// Sh's truth values are numbers, 1 and 0, and the lowering writes each
// comparison's and logical operation's result as a select of 1 or 0, so
// that a variable holds it as the program says.  LLVM's instruction
// combiner then joins `a && b`'s two tests of such selects into one test
// of their minimum (`minnum`), which code generation cannot see through:
// each comparison becomes a mask, a select of 1.0 and a `vminps`, then a
// comparison again.  This pass tests the selects' conditions instead: a
// test `x > 0` of such a value, or of the minimum (maximum) of such values,
// becomes the conditions' and (or), and the numbers that only fed it go.
#include <llvm/IR/PassManager.h>

namespace sh::cpu {

struct TruthValuesPass : llvm::PassInfoMixin<TruthValuesPass> {
  llvm::PreservedAnalyses run(llvm::Function& f, llvm::FunctionAnalysisManager&);
};

}  // namespace sh::cpu
