#pragma once
// The owned storage of channels, tables and host memory: 64-bit words
// whose first lies at the start of a cache line.  A batch of 16 floats (or
// 8 doubles) that starts at a multiple of 16 elements then fills one line,
// so a kernel's vector loads and stores at its batch's own elements are
// never split across two; malloc alone puts large blocks 16 bytes past a
// page's start, which split every one of them.
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace sh::detail {

inline constexpr std::size_t kCacheLine = 64;

template <class T>
struct CacheLineAllocator {
  using value_type = T;
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{kCacheLine})); }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{kCacheLine}); }
  template <class U>
  bool operator==(const CacheLineAllocator<U>&) const noexcept {
    return true;
  }
};

using Words = std::vector<std::uint64_t, CacheLineAllocator<std::uint64_t>>;

}  // namespace sh::detail
