#pragma once
// An accumulator's sums take the adds of runs on several threads, and of
// several backends, at once: each addition is atomic, in the accumulator's
// type (f32 added as a float, i32 wrapping), as the cpu backend's are.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

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

// Adds sums computed elsewhere (a device's, another rank's), `bytes` of
// them in the accumulator's type, into `sums`, each atomically.
inline void add_sums_from(ir::Scalar element, void* sums, const char* theirs, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes / ir::storage_bytes(element); ++i) {
    double value = 0;
    if (element == ir::Scalar::F32) {
      float a;
      std::memcpy(&a, theirs + sizeof a * i, sizeof a);
      value = a;
    } else {
      std::int32_t a;
      std::memcpy(&a, theirs + sizeof a * i, sizeof a);
      value = a;
    }
    add_to_sum(element, sums, i, value);
  }
}

}  // namespace sh::detail
