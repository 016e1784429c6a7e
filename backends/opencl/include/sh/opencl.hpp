#pragma once
// The OpenCL backend: the optimised IR becomes readable OpenCL C 1.2, one
// work-item per stream element, built and run through the ICD loader on
// any OpenCL device; PoCL on the CPU is the default.  Including this header
// registers it as "opencl".
//
// Device choice: Options::device or the environment variable
// SH_OPENCL_DEVICE, as "P:D" (platform and device indices) or a piece of
// the device's name; otherwise the first device of the first platform.
// kernel_for(p, backend("opencl"))->listing() gives the OpenCL C.
#include <string>
#include <vector>

#include "sh/backend.hpp"

namespace sh::opencl {

void register_backend();

// Every platform and device found, one line each ("P:D name (platform)").
std::vector<std::string> devices();

namespace detail {
inline const bool registered = (register_backend(), true);
}  // namespace detail

}  // namespace sh::opencl
