#pragma once
// Points on the unit disk for sampling disk lights, precomputed on the host
// and handed to the kernel as a table, as the soft-shadow paper does.
//   random:        x = sqrt(a) cos(theta), y = sqrt(a) sin(theta), a and theta uniform
//   pseudo-random: the centre, then n-1 points at theta_i = 2 pi i / (n-1)
//                  with a random radius in [0.3, 1].  (The paper's printed
//                  formula adds 0.3 to x and y; its text means the radius,
//                  which is what this does.)
#include <string>
#include <vector>

namespace sh::rt {

enum class SamplePattern { Random, PseudoRandom };

SamplePattern parse_pattern(const std::string& name);  // "random" or "pseudo"; throws sh::Error
const char* pattern_name(SamplePattern p);

// n points (x, y interleaved) in the unit disk.
std::vector<float> disk_samples(SamplePattern pattern, int n, unsigned seed);

inline constexpr int kMaxShadowSamples = 1024;

}  // namespace sh::rt
