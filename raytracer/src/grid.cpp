#include <chrono>
#include <cmath>
#include <cstdio>
#include <utility>

#include <tbb/parallel_for.h>

#include "sh/raytracer/grid.hpp"
#include "sh/error.hpp"

namespace sh::rt {
namespace {

struct CellRange {
  int from[3], to[3];
  std::size_t cells() const {
    std::size_t n = 1;
    for (int k = 0; k < 3; ++k) n *= static_cast<std::size_t>(to[k] - from[k] + 1);
    return n;
  }
};

// The cells the triangle's bounds (widened by the hair) touch.
CellRange cells_under(const Grid& g, Vec3 hair, Vec3 a, Vec3 b, Vec3 c) {
  Vec3 tlo = min(min(a, b), c), thi = max(max(a, b), c);
  CellRange r;
  for (int k = 0; k < 3; ++k) {
    r.from[k] = std::clamp(static_cast<int>(std::floor((tlo[k] - hair[k] - g.lo[k]) / g.cell[k])), 0, g.dims[k] - 1);
    r.to[k] = std::clamp(static_cast<int>(std::floor((thi[k] + hair[k] - g.lo[k]) / g.cell[k])), 0, g.dims[k] - 1);
  }
  return r;
}

// About `cells_per_triangle` cells per triangle, as cubic as the bounds allow.
void set_resolution(Grid& g, const Box& bounds, std::size_t triangles, double cells_per_triangle) {
  Vec3 extent = bounds.hi - bounds.lo;
  double volume = static_cast<double>(extent.x) * extent.y * extent.z;
  double side = std::cbrt(volume / (cells_per_triangle * static_cast<double>(triangles)));
  for (int a = 0; a < 3; ++a) g.dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / side)), 1, kMaxGridCells);
  g.lo = bounds.lo;
  g.hi = bounds.hi;
  g.cell = {extent.x / g.dims[0], extent.y / g.dims[1], extent.z / g.dims[2]};
}

// Cells the build would test against triangles: under each one's bounds.
std::size_t cells_to_test(const Grid& g, const Box& bounds, const std::vector<Vec3>& positions) {
  Vec3 hair = overlap_hair(bounds, g.cell);
  std::size_t total = 0;
  for (std::size_t v = 0; v + 2 < positions.size(); v += 3)
    total += cells_under(g, hair, positions[v], positions[v + 1], positions[v + 2]).cells();
  return total;
}

// Which cells each triangle overlaps, in blocks of triangles on every
// core; then each cell's list, ended by -1, triangles in increasing order
// (the blocks are laid out in order, so the result never depends on
// which thread did what).
void fill_cells(Grid& g, Vec3 hair, const std::vector<Vec3>& positions) {
  constexpr std::size_t kBlock = 4096;
  std::size_t n = positions.size() / 3, blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<std::pair<std::uint32_t, std::int32_t>>> found(blocks);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
    for (std::size_t t = b * kBlock; t < std::min(n, (b + 1) * kBlock); ++t) {
      Vec3 a = positions[3 * t], p = positions[3 * t + 1], c = positions[3 * t + 2];
      CellRange r = cells_under(g, hair, a, p, c);
      for (int z = r.from[2]; z <= r.to[2]; ++z)
        for (int y = r.from[1]; y <= r.to[1]; ++y)
          for (int x = r.from[0]; x <= r.to[0]; ++x) {
            Vec3 box_lo = g.lo + Vec3{x * g.cell.x, y * g.cell.y, z * g.cell.z};
            if (triangle_overlaps_box(a, p, c, box_lo - hair, box_lo + g.cell + hair))
              found[b].emplace_back((static_cast<std::uint32_t>(z) * g.dims[1] + y) * g.dims[0] + x,
                                    static_cast<std::int32_t>(t));
          }
    }
  });
  std::vector<std::int32_t> count(g.cells(), 0);
  for (const auto& block : found)
    for (const auto& [cell, t] : block) ++count[cell];
  g.cell_start.assign(g.cells(), -1);
  std::vector<std::size_t> next(g.cells());
  std::size_t at = 0;
  for (std::size_t c = 0; c < g.cells(); ++c) {
    if (count[c] == 0) continue;
    g.cell_start[c] = static_cast<std::int32_t>(at);
    next[c] = at;
    at += static_cast<std::size_t>(count[c]) + 1;
  }
  g.cell_triangles.assign(at, -1);
  for (const auto& block : found)
    for (const auto& [cell, t] : block) g.cell_triangles[next[cell]++] = t;
}

std::string dims_text(const Grid& g) {
  return std::to_string(g.dims[0]) + "x" + std::to_string(g.dims[1]) + "x" + std::to_string(g.dims[2]);
}

}  // namespace

Grid build_grid(const Scene& scene, double cells_per_triangle, double tests_per_triangle) {
  // Out of range (a NaN, 1e30) the resolution overflowed to one cell.
  if (!(cells_per_triangle >= 0.01 && cells_per_triangle <= 64))
    throw Error("grid: cells per triangle must be 0.01 .. 64, got " + std::to_string(cells_per_triangle));
  if (!(tests_per_triangle >= 1))
    throw Error("grid: tests per triangle must be at least 1, got " + std::to_string(tests_per_triangle));
  auto t0 = std::chrono::steady_clock::now();
  Grid g;
  std::size_t n = scene.mesh.triangles();
  Box bounds = accelerator_bounds(scene);
  const std::vector<Vec3>& positions = scene.mesh.positions;
  // The work (and at most the references) is the cells under the
  // triangles' bounds: large triangles over fine cells make it grow with
  // the square of the resolution or faster.  Coarser until within budget.
  auto budget = std::max(kMinGridTests, static_cast<std::size_t>(tests_per_triangle * static_cast<double>(n)));
  set_resolution(g, bounds, n, cells_per_triangle);
  std::string asked = dims_text(g);
  std::size_t tests = cells_to_test(g, bounds, positions), first_estimate = tests;
  for (double density = cells_per_triangle; tests > budget && g.cells() > 1;) {
    density /= 2;
    set_resolution(g, bounds, n, density);
    tests = cells_to_test(g, bounds, positions);
  }
  if (tests != first_estimate)
    g.warning = "grid: " + dims_text(g) + " cells instead of " + asked + ": the triangles' bounds cover " +
                std::to_string(first_estimate) + " cells at " + asked + ", more than the budget of " + std::to_string(budget) +
                " (large or overlapping triangles)";

  fill_cells(g, overlap_hair(bounds, g.cell), positions);
  if (g.cell_triangles.empty()) g.cell_triangles.push_back(-1);
  g.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

}  // namespace sh::rt
