#pragma once
// The machine-code kernel's C signature: one call runs elements [begin,
// end).  Uniforms arrive as four doubles each; tables as data pointers and
// three dimensions each.  A kernel that stops early (a loop past its
// iteration cap) writes status[0] = loop number + 1, status[1] = element.
#include <cstdint>

namespace sh::cpu {

using KernelFn = void (*)(std::int64_t begin, std::int64_t end, void* const* inputs, void* const* outputs,
                          const double* uniforms, const void* const* tables, const std::int32_t* table_dims,
                          std::int64_t* status);

inline constexpr const char* kKernelSymbol = "sh_kernel";

}  // namespace sh::cpu
