#pragma once
// An accumulator's sums take the adds of runs on several threads, and of
// several backends, at once: each addition is atomic, in the accumulator's
// type (f32 added as a float, i32 wrapping), as the cpu backend's are.
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "sh/ir/type.hpp"

namespace sh::detail {

inline void add_to_sum(ir::Scalar element, void* sums, std::size_t at, double value) {
  if (element == ir::Scalar::F32) {
    std::atomic_ref<float>(static_cast<float*>(sums)[at]).fetch_add(static_cast<float>(value));
  } else {
    auto add = static_cast<std::uint32_t>(static_cast<std::int32_t>(value));
    std::atomic_ref<std::uint32_t>(static_cast<std::uint32_t*>(sums)[at]).fetch_add(add);
  }
}

}  // namespace sh::detail
