#pragma once
// Values no earlier call in this process gave.  A kernel is keyed by what
// its program computes (and its name, which a test names fixed), so a test
// that must miss the process's own kernels records a program with a fresh
// constant in it; a test that must meet a once-a-process message again
// uses a fresh name.
// Either still holds when the test runs again (--gtest_repeat) or after
// another test that recorded the same program.
#include <atomic>
#include <string>

namespace fresh_detail {
inline std::atomic<int> calls{0};
}

inline std::string fresh_name(const std::string& base) { return base + "_" + std::to_string(fresh_detail::calls++); }

// A whole number as a float, exact in arithmetic with other small whole
// numbers, and from 4097 on: not a constant other programs are likely to
// hold.
inline float fresh_constant() { return static_cast<float>(4097 + fresh_detail::calls++ % (1 << 20)); }
