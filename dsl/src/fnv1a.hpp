#pragma once
// The 64-bit FNV-1a hash of a run of bytes: the kernel cache's names and
// checksums, and a program's structural hash.  Fast and well spread for
// keys; not a defence against anyone choosing the bytes.
#include <cstdint>
#include <string_view>

namespace sh::detail {

inline std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace sh::detail
