#include "codegen.hpp"

#include <sstream>

#include "generator.hpp"
#include "sh/ir/verifier.hpp"

namespace sh::opencl {
namespace {

const char kAtomicAddFloat[] =
    "\nvoid sh_atomic_add_float(volatile __global float* p, float v) {\n"
    "  union { float f; unsigned int u; } old, sum;\n"
    "  do {\n"
    "    old.f = *p;\n"
    "    sum.f = old.f + v;\n"
    "  } while (atomic_cmpxchg((volatile __global unsigned int*)p, old.u, sum.u) != old.u);\n"
    "}\n";

bool needs_fp64(const ir::Program& p, const sh::Options& o) {
  bool needs = o.precision == Precision::F64;
  for (const ir::Var& v : p.vars) needs = needs || v.type.scalar == ir::Scalar::F64;
  for (const ir::TableDecl& t : p.tables) needs = needs || t.element.scalar == ir::Scalar::F64;
  return needs;
}

bool adds_floats(const ir::Program& p) {
  for (const ir::TableDecl& t : p.tables)
    if (t.accumulator && ir::is_float(t.element.scalar)) return true;
  return false;
}

}  // namespace

Source generate(const ir::Program& program, const sh::Options& options, int lanes, std::uint64_t largest_buffer) {
  ir::verify_legal(program);
  Prelude prelude;
  std::string kernels = Generator(program, options, 1, largest_buffer, prelude).run(kKernelName);
  if (lanes > 1) kernels += Generator(program, options, lanes, largest_buffer, prelude).run(kLanesKernelName);
  bool fp64 = needs_fp64(program, options);
  std::ostringstream head;
  head << "// program " << comment_text(program.name) << ", generated from its optimised IR\n";
  if (fp64) head << "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n";
  if (options.math == MathMode::Precise) head << "#pragma OPENCL FP_CONTRACT OFF\n";
  if (adds_floats(program)) head << kAtomicAddFloat;
  return Source{head.str() + prelude.text + kernels, fp64};
}

}  // namespace sh::opencl
