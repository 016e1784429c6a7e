#pragma once
// IR -> LLVM IR.  The whole stream loop, the kernel body, its control flow
// and its table reads become one LLVM function (signature.hpp), scalar
// (width 1) or SPMD with one SIMD lane per element (width 4, 8 or 16).
#include <cstddef>
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

Lowered lower(const ir::Program& program, const Options& options, int width, llvm::LLVMContext& context);

// The program's loops by number, as a kernel that stops early names them
// (signature.hpp): in program order, those after a break or continue in
// the same block left out, since they are never lowered.
std::vector<const ir::Stmt*> loop_statements(const ir::Program& program);

// The lanes a kernel runs with: cpu::Options::width, Auto being the host's
// widest vectors (16 with AVX-512, 8 with AVX, 4 otherwise).
int lane_count(const Options& options);

// cpu::Options::tables: Memory reads tables from the run's memory; Fetched
// reads each element through a call to the run's TableAccess
// (signature.hpp), so that a table may live elsewhere.
bool fetches_tables(const Options& options);

// cpu::Options::stores: whether a kernel may write outputs past the cache
// (signature.hpp's stream_outputs), and from how many bytes of the
// outputs' memory a run asks it to.
bool may_stream(const Options& options);
std::size_t streamed_from_bytes(const Options& options);

// The string form of cpu::Options, for Backend::settings().
std::vector<Backend::Setting> settings();

}  // namespace sh::cpu
