#pragma once
// The accuracy every backend promises, in one place: the largest error in
// units in the last place against the correctly rounded result of C++'s
// <cmath> computed in double.  Precise bounds are those of OpenCL 1.2's full
// profile (so that a conforming OpenCL device passes), tighter where every
// target is exact.  Fast math gives up special values (NaN, infinities,
// denormals, signed zero): those inputs are skipped in fast mode, and the
// bounds below are looser.
#include <cstdint>
#include <string_view>

namespace conformance {

struct UlpBound {
  std::string_view function;
  std::uint64_t precise;
  std::uint64_t fast;
};

inline constexpr UlpBound kUlpBounds[] = {
    {"add", 0, 0},      {"sub", 0, 0},      {"mul", 0, 0},      {"div", 0, 3},     {"mod", 0, 4},
    {"neg", 0, 0},      {"abs", 0, 0},      {"min", 0, 0},      {"max", 0, 0},     {"sign", 0, 0},
    {"floor", 0, 0},    {"ceil", 0, 0},     {"round", 0, 0},    {"frac", 0, 4},    {"sqrt", 0, 4},
    {"rsqrt", 2, 4},    {"rcp", 0, 3},      {"pow", 16, 8192},  {"exp", 3, 8192},  {"exp2", 3, 8192},
    {"log", 3, 8192},   {"log2", 3, 8192},  {"sin", 4, 8192},   {"cos", 4, 8192},  {"tan", 5, 8192},
    {"asin", 4, 8192},  {"acos", 4, 8192},  {"atan", 5, 8192},  {"atan2", 6, 8192},
};

constexpr UlpBound ulp_bound(std::string_view function) {
  for (const UlpBound& b : kUlpBounds)
    if (b.function == function) return b;
  return {function, 0, 0};
}

}  // namespace conformance
