#pragma once
// What the kernels' walks round, cap and widen by: the bounds a ray's hits
// depend on besides the scene.  Public so that a walk written elsewhere
// (`shtrace rays`' hand-written baseline) finds the kernels' hits.

namespace sh::rt {

// A result n float operations deep is within gamma(n) of its size of the
// exact value: gamma(n) = n u / (1 - n u), u = 2^-24.
constexpr float gamma(int n) {
  constexpr float u = 0x1p-24f;
  return n * u / (1 - n * u);
}

// A direction component this small is treated as zero: its reciprocal is
// capped, so no infinity or NaN enters the walk (fast math keeps working).
inline constexpr float kTinyDirection = 1e-30f;

// Of triangles at the same distance to within this share of it, the
// lowest numbered is the hit, whatever order they are tested in.
inline constexpr float kTieTolerance = 1e-6f;

// A BVH's boxes are clipped a little beyond the nearest hit so far: a
// triangle at the same distance to the tie tolerance may still win a tie.
inline constexpr float kBeyondBest = 1.0f + 4e-6f;

}  // namespace sh::rt
