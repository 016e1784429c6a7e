#pragma once
// Where a table read lands: the one definition of clamping that every
// backend reproduces.  Fetch clamps each integer coordinate to
// [0, dim - 1]; Sample maps u in [0, 1] to floor(u * dim) (computed in the
// coordinate's precision; NaN gives 0) and clamps the same way.
#include <cmath>
#include <cstddef>

#include "sh/backend.hpp"
#include "sh/ir/eval.hpp"

namespace sh {

struct TableIndex {
  std::size_t element = 0;  // flat, x fastest
  bool clamped = false;     // some coordinate was out of range
};

template <class Coord>
TableIndex fetch_index(const TableView& t, Coord coord) {
  TableIndex out;
  std::size_t stride = 1;
  for (int d = 0; d < t.rank; ++d) {
    auto i = static_cast<long long>(coord(d));
    long long hi = t.dims[d] - 1;
    if (i < 0 || i > hi) out.clamped = true;
    i = i < 0 ? 0 : i > hi ? hi : i;
    out.element += static_cast<std::size_t>(i) * stride;
    stride *= static_cast<std::size_t>(t.dims[d]);
  }
  return out;
}

template <class Coord>
TableIndex sample_index(const TableView& t, Coord coord, ir::Scalar scalar, ir::Precision precision) {
  return fetch_index(t, [&](int d) {
    double scaled = ir::hold(scalar, precision, coord(d) * t.dims[d]);
    return static_cast<double>(ir::to_int32(std::floor(scaled)));
  });
}

}  // namespace sh
