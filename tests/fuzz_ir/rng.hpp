#pragma once
// A small deterministic random source (SplitMix64): the same seed gives the
// same program on every platform, which the standard library's
// distributions do not promise.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fuzz_ir {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // In [0, n); n > 0.
  int below(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
  // In [lo, hi].
  int between(int lo, int hi) { return lo + below(hi - lo + 1); }
  // True with probability percent / 100.
  bool chance(int percent) { return below(100) < percent; }
  template <class T>
  const T& pick(const std::vector<T>& items) {
    return items[static_cast<std::size_t>(below(static_cast<int>(items.size())))];
  }

 private:
  std::uint64_t state_;
};

// The seed of program `index` of a run started with `seed`: printed with
// every failure, so that `fuzz_ir --replay SEED` regenerates the program.
inline std::uint64_t program_seed(std::uint64_t seed, std::uint64_t index) {
  Rng r(seed * 0x100000001B3ull + index);
  return r.next();
}

}  // namespace fuzz_ir
