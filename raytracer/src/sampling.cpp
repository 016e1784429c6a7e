#include <cmath>
#include <numbers>
#include <random>

#include "sh/error.hpp"
#include "sh/raytracer/sampling.hpp"

namespace sh::rt {

SamplePattern parse_pattern(const std::string& name) {
  if (name == "random") return SamplePattern::Random;
  if (name == "pseudo" || name == "pseudo-random") return SamplePattern::PseudoRandom;
  throw Error("unknown sample pattern '" + name + "' (known: random, pseudo)");
}

const char* pattern_name(SamplePattern p) { return p == SamplePattern::Random ? "random" : "pseudo"; }

std::vector<float> disk_samples(SamplePattern pattern, int n, unsigned seed) {
  if (n < 1 || n > kMaxShadowSamples)
    throw Error("shadow samples must be 1.." + std::to_string(kMaxShadowSamples) + ", got " + std::to_string(n));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  constexpr float two_pi = 2 * std::numbers::pi_v<float>;
  std::vector<float> xy;
  if (pattern == SamplePattern::Random) {
    for (int i = 0; i < n; ++i) {
      float r = std::sqrt(u(rng)), theta = two_pi * u(rng);
      xy.insert(xy.end(), {r * std::cos(theta), r * std::sin(theta)});
    }
    return xy;
  }
  xy.insert(xy.end(), {0.0f, 0.0f});
  for (int i = 1; i < n; ++i) {
    float theta = two_pi * static_cast<float>(i) / static_cast<float>(n - 1);
    float r = 0.3f + 0.7f * u(rng);
    xy.insert(xy.end(), {r * std::cos(theta), r * std::sin(theta)});
  }
  return xy;
}

}  // namespace sh::rt
