#pragma once
// IR -> LLVM IR.  The whole stream loop, the kernel body, its control flow
// and its table reads become one LLVM function (signature.hpp), scalar
// (width 1) or SPMD with one SIMD lane per element (width 4, 8 or 16).
#include <cstddef>
#include <memory>
#include <vector>

#include <llvm/ADT/StringMap.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>

#include "sh/backend.hpp"
#include "sh/cpu.hpp"

namespace sh::cpu {

struct Lowered {
  std::unique_ptr<llvm::Module> module;
  std::vector<const ir::Stmt*> loops;  // by loop number, for error messages
};

Lowered lower(const ir::Program& program, const sh::Options& options, int width, llvm::LLVMContext& context);

// The program's loops by number, as a kernel that stops early names them
// (signature.hpp): in program order, those after a break or continue in
// the same block left out, since they are never lowered.
std::vector<const ir::Stmt*> loop_statements(const ir::Program& program);

// The lanes a kernel runs with: cpu::Options::width, Auto being the host's
// widest vectors (16 with AVX-512, 8 with AVX, 4 otherwise).
int lane_count(const sh::Options& options);

// cpu::Options::tables: Memory reads tables from the run's memory; Fetched
// reads each element through a call to the run's TableAccess
// (signature.hpp), so that a table may live elsewhere.
bool fetches_tables(const sh::Options& options);

// cpu::Options::stores: whether a kernel of `program` may write its
// outputs past the cache (signature.hpp's stream_outputs), and from how
// many bytes of the outputs' memory a run asks it to.
bool kernel_streams(const ir::Program& program, const sh::Options& options);
std::size_t streamed_from_bytes(const sh::Options& options);

// cpu::Options::isa: the features kernels are compiled for (the host's,
// or its level's), and the CPU LLVM targets ("" for the host's own); both
// throw sh::Error where the host lacks the level.
llvm::StringMap<bool> isa_features(const sh::Options& options);
std::string isa_cpu(const sh::Options& options);
bool host_has(Isa isa);

// The string form of cpu::Options, for Backend::settings().
std::vector<Backend::Setting> settings();

}  // namespace sh::cpu
