#pragma once
// IR -> OpenCL C 1.2 source: one kernel, one work-item per element.
#include <string>

#include "sh/backend.hpp"

namespace sh::opencl {

inline constexpr const char* kKernelName = "sh_kernel";

struct Source {
  std::string text;
  bool needs_fp64 = false;
};

// The kernel's arguments, in order: long base (the element that work-item
// 0 runs), long first, row and rows (the launch domain); one __global buffer per
// input, then per output; one scalar per uniform component; per table a
// __global buffer (an accumulator's is read and added into) and three int
// dimensions; __global long* status.
Source generate(const ir::Program& program, const sh::Options& options);

}  // namespace sh::opencl
