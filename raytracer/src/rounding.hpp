#pragma once
// Bounds on float rounding for the tracer's error analysis (the
// intersection's distance bound, where a ray may leave a surface).
#include <limits>

namespace sh::rt {

// A result n operations deep is within gamma(n) of its size of the exact
// value: gamma(n) = n u / (1 - n u), u = 2^-24 in float, 2^-53 in double.
template <class T = float>
constexpr T gamma(int n) {
  constexpr T u = std::numeric_limits<T>::epsilon() / 2;
  return n * u / (1 - n * u);
}

}  // namespace sh::rt
