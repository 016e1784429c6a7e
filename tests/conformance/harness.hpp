#pragma once
// The conformance suite's harness: every test runs once per registered
// backend and mode, with expectations written once.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <sh/sh.hpp>

#include "ulp_bounds.hpp"

namespace conformance {

struct Mode {
  std::string backend;
  sh::Backend::Variant variant;
  sh::Precision precision = sh::Precision::F32;
  sh::MathMode math = sh::MathMode::Precise;
};

std::vector<Mode> all_modes();
void PrintTo(const Mode& m, std::ostream* os);
std::string mode_name(const testing::TestParamInfo<Mode>& info);

class Conformance : public testing::TestWithParam<Mode> {
 public:
  const Mode& mode() const { return GetParam(); }
  bool fast() const { return mode().math == sh::MathMode::Fast; }
  bool f64() const { return mode().precision == sh::Precision::F64; }
  sh::BackendChoice choice(sh::Options o = {}) const {
    o.precision = mode().precision;
    o.math = mode().math;
    o.set(mode().variant.options);
    return sh::backend(mode().backend, o);
  }
  sh::RunStats run(const sh::Program& p, const std::vector<std::shared_ptr<sh::detail::Buffer>>& in,
                   const std::vector<std::shared_ptr<sh::detail::Buffer>>& out) const {
    return sh::run(p, in, out, choice());
  }
};

// Distance in units in the last place between two values of type T; NaN
// matches NaN, an infinity only itself, and ±0 are equal.
template <class T>
std::uint64_t ulp_distance(T a, T b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b) ? 0 : UINT64_MAX;
  if (std::isinf(a) || std::isinf(b)) return a == b ? 0 : UINT64_MAX;
  using I = std::conditional_t<sizeof(T) == 4, std::int32_t, std::int64_t>;
  auto ordered = [](T x) {
    I i;
    std::memcpy(&i, &x, sizeof x);
    return i < 0 ? static_cast<std::int64_t>(std::numeric_limits<I>::min()) - i : static_cast<std::int64_t>(i);
  };
  std::int64_t d = ordered(a) - ordered(b);
  return static_cast<std::uint64_t>(d < 0 ? -d : d);
}

// Special float inputs every numeric test sweeps.
template <class T>
std::vector<T> extreme_values() {
  using L = std::numeric_limits<T>;
  return {T(0),        -T(0),          T(1),          T(-1),       T(0.5),      T(2),        T(3.75),
          T(-2.5),     T(0.1),         T(1e-3),       T(100),      T(1e10),     T(-1e10),    T(3.14159265358979),
          L::max(),    L::lowest(),    L::min(),      -L::min(),   L::denorm_min(), L::min() / 4,
          L::infinity(), -L::infinity(), L::quiet_NaN(), T(1e-20), T(7.5e7), T(-0.75), T(0.999), T(1.001)};
}

// Component c of element i takes the values in a rotated order, so every
// component position sees every value.
template <class T>
std::vector<T> spread(const std::vector<T>& values, int width, std::size_t elements) {
  std::vector<T> out(elements * width);
  for (std::size_t i = 0; i < elements; ++i)
    for (int c = 0; c < width; ++c) out[i * width + c] = values[(i + 3 * c) % values.size()];
  return out;
}

}  // namespace conformance
