#pragma once
// Compiles a lowered module for the host CPU: the O3 pipeline with the
// host's features, then ORC LLJIT.  The result owns the machine code.
#include <memory>
#include <optional>
#include <string>

#include "lower.hpp"
#include "object_cache.hpp"
#include "signature.hpp"

namespace llvm::orc {
class LLJIT;
}

namespace sh::cpu {

class Jitted {
 public:
  Jitted(const ir::Program& program, const Options& options);
  ~Jitted();
  KernelFn entry() const { return entry_; }
  int lanes() const { return lanes_; }  // elements per trip of the stream loop
  const std::string& llvm_ir() const { return llvm_ir_; }  // after optimisation
  const std::vector<const ir::Stmt*>& loops() const { return loops_; }
  bool from_cache() const { return cache_ && cache_->hit(); }
  const std::vector<CompilePhase>& phases() const { return phases_; }

 private:
  void build(const ir::Program& program, const Options& options, bool use_cache);

  std::optional<ObjectCache> cache_;  // outlives the JIT that uses it
  std::unique_ptr<llvm::orc::LLJIT> jit_;
  KernelFn entry_ = nullptr;
  int lanes_ = 1;
  std::string llvm_ir_;
  std::vector<const ir::Stmt*> loops_;
  std::vector<CompilePhase> phases_;
};

}  // namespace sh::cpu
