#pragma once
// The machine-code kernel's C signature: one call runs elements [begin,
// end).  Uniforms arrive as four doubles each; tables as data pointers and
// three dimensions each; the launch domain (position()) as the run's first
// element in it, its row length and its rows per layer (KernelDomain).  A
// kernel that stops early (a loop past its iteration cap) writes
// status[0] = loop number + 1, status[1] = element.  A stream_outputs
// other than 0 asks for the outputs' full batches to be written past the
// cache (cpu::Options::stores); a kernel that may stream orders those
// stores before it returns.
#include <array>
#include <cstddef>
#include <cstdint>

#include "sh/backend.hpp"

namespace sh::cpu {

using KernelFn = void (*)(std::int64_t begin, std::int64_t end, void* const* inputs, void* const* outputs,
                          const double* uniforms, const void* const* tables, const std::int32_t* table_dims,
                          const std::int64_t* domain, std::int64_t* status, std::uint64_t stream_outputs);

// The launch domain as a kernel reads it: the run's first element in the
// grid, the row length (INT64_MAX for a domain of one row) and the rows.
inline std::array<std::int64_t, 3> kernel_domain(const LaunchDomain& d) {
  std::int64_t row = d.extent[0] ? static_cast<std::int64_t>(d.extent[0]) : INT64_MAX;
  return {static_cast<std::int64_t>(d.first), row, static_cast<std::int64_t>(d.extent[1])};
}

inline constexpr const char* kKernelSymbol = "sh_kernel";

// With the setting "tables": "fetched", a table that is read (not an
// accumulator) arrives as one of these in place of its data pointer.  The
// kernel reads elements inside the window inline and calls `element` for
// any other, which moves the window to the source's span holding it.  A
// whole table is one window that never moves.  Field order is the
// kernel's (lowering's access_type).
struct TableAccess {
  const char* window;
  std::int64_t window_first, window_end;  // the elements [first, end) lie from window on
  std::int64_t inline_reads;              // reads the kernel served from the window
  const char* (*element)(TableAccess* self, std::int64_t flat);
  std::int64_t element_bytes;
  TableSource* source;
};

}  // namespace sh::cpu
