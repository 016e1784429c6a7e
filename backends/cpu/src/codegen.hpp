#pragma once
// Machine code for an optimised module, as object files.  Code generation
// is most of a large kernel's compile, and LLVM generates one function on
// one core: so a large kernel's loops are outlined into functions until its
// module splits into parts of about equal size, and each part is compiled on
// a thread of its own.  The parts call one another through the JIT's
// linker, which resolves their symbols as it resolves the C library's.
#include <string>
#include <vector>

#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/IR/Module.h>

namespace sh::cpu {

struct Objects {
  std::vector<std::string> parts;  // object files
  std::string module;              // the module as compiled (its loops outlined), as bitcode
  double cpu_ms_elsewhere = 0;     // CPU time spent on threads other than the caller's
};

// Which of LLVM's machine passes run.  Lean leaves out the machine
// instruction scheduler, the early loop-invariant code motion and the
// common subexpressions of machine instructions: on the tracer (loops
// that run until rays finish, whose IR the short pipeline has already
// cleaned) they took about a sixth of its machine code's time and did not
// make its rays faster.
enum class MachinePasses { Full, Lean };

// A module of more LLVM instructions than `split_above` is cut into as many
// parts as `threads`, at most 4; others stay whole.  The module is spent:
// its loops outlined, other parts' bodies deleted, code generation's own
// changes made.  Throws sh::Error naming `program` where LLVM fails.
Objects compile_objects(llvm::Module& module, const llvm::orc::JITTargetMachineBuilder& builder, MachinePasses passes,
                        unsigned split_above, unsigned threads, const std::string& program);

}  // namespace sh::cpu
