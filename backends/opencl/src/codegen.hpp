#pragma once
// IR -> OpenCL C 1.2 source: a kernel of one work-item per element and,
// for `lanes` above 1, beside it a kernel of `lanes` consecutive elements per
// work-item in vector registers (what a CPU device's compiler vectorises).
#include <cstdint>
#include <string>

#include "sh/backend.hpp"

namespace sh::opencl {

inline constexpr const char* kKernelName = "sh_kernel";
inline constexpr const char* kLanesKernelName = "sh_kernel_lanes";

struct Source {
  std::string text;
  bool needs_fp64 = false;
};

// Each kernel's arguments, in order: long base (the first element that
// work-item 0 runs), long first, row and rows (the launch domain); one __global buffer per
// input, then per output; one scalar per uniform component; per table a
// __global buffer (an accumulator's is read and added into) and three int
// dimensions; __global long* status.  `largest_buffer`: the device's
// largest buffer in bytes (what bounds a table's element numbers).
Source generate(const ir::Program& program, const sh::Options& options, int lanes, std::uint64_t largest_buffer);

}  // namespace sh::opencl
