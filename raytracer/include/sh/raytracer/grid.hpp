#pragma once
// The uniform grid of the seed: built on the host, handed to the kernels as
// tables.  Each cell lists the triangles that overlap it (an exact
// triangle-box test, on a box widened by a hair so that rounding at a cell
// face never loses a triangle), each list ended by -1.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sh/raytracer/accelerator.hpp"

namespace sh::rt {

struct Grid {
  Vec3 lo, hi, cell;          // bounds and cell size
  std::array<int, 3> dims{1, 1, 1};
  std::vector<std::int32_t> cell_start;  // per cell, x fastest: index into cell_triangles, or -1
  std::vector<std::int32_t> cell_triangles;
  double build_ms = 0;
  std::string warning;  // where the work budget made the cells coarser than asked; else empty

  std::size_t cells() const { return static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]; }
  std::size_t bytes() const { return (cell_start.size() + cell_triangles.size()) * sizeof(std::int32_t); }
};

// Resolution: about `cells_per_triangle` cells per triangle, cells as cubic
// as the bounds allow, at most kMaxGridCells along an axis.  The work is
// bounded: the cells under the triangles' bounding boxes (each tested
// against its triangle) may number `tests_per_triangle` per triangle (at
// least kMinGridTests in all); past that the grid is made coarser, which
// `warning` says.
inline constexpr int kMaxGridCells = 512;
inline constexpr std::size_t kMinGridTests = 1 << 16;
Grid build_grid(const Scene& scene, double cells_per_triangle = 2.0, double tests_per_triangle = 64);

}  // namespace sh::rt
