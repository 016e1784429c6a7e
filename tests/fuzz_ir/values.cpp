#include "values.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace fuzz_ir {
namespace {

using sh::ir::Scalar;

template <class T>
std::vector<double> float_extremes() {
  using L = std::numeric_limits<T>;
  std::vector<T> v = {T(0),          -T(0),         T(1),        T(-1),           T(0.5),        T(-0.5),
                      T(2),          T(3),          T(0.25),     T(0.75),         T(1) / T(3),   T(0.1),
                      T(0.999),      T(1.001),      T(100),      T(-2.5),         T(2.5),        T(1.5),
                      T(0.49999997), T(8388607.5),  T(1e10),     T(-1e10),        T(7.5e7),      T(16777216),
                      T(2147483648.0), T(-2147483648.0), T(2147483520.0), T(-2147483904.0), T(4294967296.0),
                      T(1e-20),      T(1e30),       T(-1e30),    T(3.14159265358979), T(-1.5707963267948966),
                      L::max(),      L::lowest(),   L::min(),    -L::min(),       L::denorm_min(), -L::denorm_min(),
                      L::min() / 4,  L::infinity(), -L::infinity(), L::quiet_NaN(), -L::quiet_NaN()};
  if constexpr (sizeof(T) == 8) {
    for (double d : {1e300, -1e300, 1e-300, 9007199254740992.0, 9007199254740994.0, 1e20, 3.4028235677973366e38})
      v.push_back(d);
  }
  return {v.begin(), v.end()};
}

const std::vector<double>& extremes(Scalar s) {
  static const std::vector<double> f32 = float_extremes<float>(), f64 = float_extremes<double>();
  static const std::vector<double> i32 = {0,         1,         -1,         2,        -2,         3,
                                          7,         -7,        31,         32,       33,         100,
                                          -100,      65536,     16777217,   -16777217, 1 << 30,
                                          2147483647, -2147483647.0 - 1, 2147483646, -2147483647};
  static const std::vector<double> boolean = {0, 1};
  switch (s) {
    case Scalar::F32: return f32;
    case Scalar::F64: return f64;
    case Scalar::I32: return i32;
    case Scalar::Bool: return boolean;
  }
  return boolean;
}

double random_bits(Rng& rng, Scalar s) {
  std::uint64_t bits = rng.next();
  switch (s) {
    case Scalar::F32: return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
    case Scalar::F64: return std::bit_cast<double>(bits);
    case Scalar::I32: return static_cast<std::int32_t>(static_cast<std::uint32_t>(bits));
    case Scalar::Bool: return static_cast<double>(bits & 1);
  }
  return 0;
}

// Small numbers in quarter steps: where loops, table coordinates and
// comparisons do something other than saturate.
double ordinary(Rng& rng, Scalar s) {
  if (s == Scalar::Bool) return rng.below(2);
  if (s == Scalar::I32) return rng.between(-8, 8);
  return rng.between(-32, 32) / 4.0;
}

}  // namespace

double representable(Scalar s, double v) {
  switch (s) {
    case Scalar::F32: return static_cast<double>(static_cast<float>(v));
    case Scalar::F64: return v;
    case Scalar::I32: return std::isnan(v) ? 0 : static_cast<double>(static_cast<std::int32_t>(std::fmax(-2147483648.0, std::fmin(v, 2147483647.0))));
    case Scalar::Bool: return v > 0 ? 1 : 0;
  }
  return v;
}

double random_value(Rng& rng, Scalar s) {
  int kind = rng.below(10);
  if (kind < 5) return rng.pick(extremes(s));
  if (kind < 8) return ordinary(rng, s);
  return random_bits(rng, s);
}

}  // namespace fuzz_ir
