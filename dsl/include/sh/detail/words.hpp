#pragma once
// The owned storage of channels, tables and host memory: 64-bit words
// whose first lies at the start of a cache line.  A batch of 16 floats (or
// 8 doubles) that starts at a multiple of 16 elements then fills one line,
// so a kernel's vector loads and stores at its batch's own elements are
// never split across two; malloc alone puts large blocks 16 bytes past a
// page's start, which split every one of them.
//
// Large blocks also start at one of eight places in a page, 512 bytes
// apart, taken in turn.  A core treats a load as dependent on an earlier
// store whose address has the same low 12 bits, and waits for the store:
// a kernel that reads one large block while it writes another at the same
// place in a page, or a few lines ahead of it, waits at every batch.  Rows
// of a power-of-two width keep that place row after row: a 5 x 5 blur of
// a 2048-float-wide image took 1.3 ms with its output 512 bytes or more
// from its input's place, 1.6 ms at the same place, 2.0 ms 64-320 bytes
// ahead of it (BENCHMARKS.md, "Blocks apart in a page").
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace sh::detail {

inline constexpr std::size_t kCacheLine = 64;

// `bytes` bytes starting a cache line (and, for a large block, at the next
// place in a page); freed with free_storage and the same `bytes`.
void* allocate_storage(std::size_t bytes);
void free_storage(void* p, std::size_t bytes) noexcept;

template <class T>
struct CacheLineAllocator {
  using value_type = T;
  CacheLineAllocator() = default;
  template <class U>
  CacheLineAllocator(const CacheLineAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_storage(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { free_storage(p, n * sizeof(T)); }
  template <class U>
  bool operator==(const CacheLineAllocator<U>&) const noexcept {
    return true;
  }
};

using Words = std::vector<std::uint64_t, CacheLineAllocator<std::uint64_t>>;

}  // namespace sh::detail
