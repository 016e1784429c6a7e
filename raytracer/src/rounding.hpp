#pragma once
// Bounds on float rounding for the tracer's error analysis (the
// intersection's distance bound, where a ray may leave a surface).

namespace sh::rt {

// A result n float operations deep is within gamma(n) of its size of the
// exact value: gamma(n) = n u / (1 - n u), u = 2^-24.
constexpr float gamma(int n) {
  constexpr float u = 0x1p-24f;
  return n * u / (1 - n * u);
}

}  // namespace sh::rt
