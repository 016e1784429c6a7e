#pragma once
// Compiles a program for the host CPU: lowered, LLVM's O3 pipeline (a
// short one for the largest kernels, jit.cpp) with the host's features,
// object files (a large kernel's in parts on several threads, codegen.hpp)
// linked by ORC LLJIT; or, where an earlier process compiled the same
// program, its objects from the object cache, linked without lowering or
// LLVM.  The result owns the machine code.
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "lower.hpp"
#include "object_cache.hpp"
#include "signature.hpp"

namespace llvm {
namespace orc {
class LLJIT;
class JITTargetMachineBuilder;
}  // namespace orc
}  // namespace llvm

namespace sh::cpu {

class Jitted {
 public:
  Jitted(const ir::Program& program, const sh::Options& options);
  ~Jitted();
  KernelFn entry() const { return entry_; }
  int lanes() const { return lanes_; }  // elements per trip of the stream loop
  const std::string& llvm_ir() const;  // after optimisation
  const std::vector<const ir::Stmt*>& loops() const { return loops_; }
  bool from_cache() const { return cache_ && cache_->hit(); }
  const std::vector<CompilePhase>& phases() const { return phases_; }
  double cpu_ms_elsewhere() const { return cpu_ms_elsewhere_; }  // code generation on other threads

 private:
  void build(const ir::Program& program, const sh::Options& options, bool read_cache);
  void start_jit(const ir::Program& program, const llvm::orc::JITTargetMachineBuilder& builder);
  void link(const ir::Program& program);

  std::optional<ObjectCache> cache_;  // outlives the JIT that uses it
  std::unique_ptr<llvm::orc::LLJIT> jit_;
  KernelFn entry_ = nullptr;
  int lanes_ = 1;
  // The listing is printed from the module's bitcode (kept, or on a cache
  // hit read from the cache) when first asked for: a 16-lane tracer's is a
  // few hundred kilobytes of text.
  std::string compiled_module_;
  mutable std::once_flag listing_read_;
  mutable std::string llvm_ir_;
  std::vector<const ir::Stmt*> loops_;
  std::vector<CompilePhase> phases_;
  double cpu_ms_elsewhere_ = 0;
};

}  // namespace sh::cpu
