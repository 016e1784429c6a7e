#pragma once
// IR -> LLVM IR.  The whole stream loop, the kernel body, its control flow
// and its table reads become one LLVM function (signature.hpp).
#include <memory>
#include <vector>

#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

#include "sh/backend.hpp"

namespace sh::cpu {

struct Lowered {
  std::unique_ptr<llvm::Module> module;
  std::vector<const ir::Stmt*> loops;  // by loop number, for error messages
};

Lowered lower(const ir::Program& program, const Options& options, llvm::LLVMContext& context);

}  // namespace sh::cpu
