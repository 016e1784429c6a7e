#pragma once
// Mutations of valid seed files: the malformed input a model reader meets.
#include <cstdint>
#include <random>
#include <string>

#include "seeds.hpp"

namespace sh::fuzz {

struct Case {
  std::string format, extension, bytes;
  std::string mutations;   // what was done, for the report
  bool must_fail = false;  // the file is certainly invalid: rendering it is a silent accept
};

// A mutant of `seed`: either one targeted change that leaves the file
// certainly invalid (a poisoned vertex coordinate, a face index past the
// vertices, nesting past what a scene may hold), or one to three blind
// ones (truncation, byte and bit flips, spliced ranges, repeated lines,
// numbers swapped for huge counts, NaN, Inf or out-of-range values).
Case mutate(const Seed& seed, std::mt19937_64& rng);

}  // namespace sh::fuzz
