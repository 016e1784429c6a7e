#include <chrono>
#include <cmath>

#include "sh/raytracer/grid.hpp"

namespace sh::rt {

Grid build_grid(const Scene& scene, double cells_per_triangle) {
  auto t0 = std::chrono::steady_clock::now();
  Grid g;
  std::size_t n = scene.mesh.triangles();
  Box bounds = accelerator_bounds(scene);
  Vec3 lo = bounds.lo, hi = bounds.hi, extent = hi - lo;
  double volume = static_cast<double>(extent.x) * extent.y * extent.z;
  double side = std::cbrt(volume / (cells_per_triangle * static_cast<double>(n)));
  for (int a = 0; a < 3; ++a) g.dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / side)), 1, 512);
  g.lo = lo;
  g.hi = hi;
  g.cell = {extent.x / g.dims[0], extent.y / g.dims[1], extent.z / g.dims[2]};

  Vec3 hair = overlap_hair(bounds, g.cell);
  std::vector<std::vector<std::int32_t>> lists(g.cells());
  for (std::size_t t = 0; t < n; ++t) {
    Vec3 a = scene.mesh.positions[3 * t], b = scene.mesh.positions[3 * t + 1], c = scene.mesh.positions[3 * t + 2];
    Vec3 tlo = min(min(a, b), c), thi = max(max(a, b), c);
    int from[3], to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = std::clamp(static_cast<int>(std::floor((tlo[k] - hair[k] - lo[k]) / g.cell[k])), 0, g.dims[k] - 1);
      to[k] = std::clamp(static_cast<int>(std::floor((thi[k] + hair[k] - lo[k]) / g.cell[k])), 0, g.dims[k] - 1);
    }
    for (int z = from[2]; z <= to[2]; ++z)
      for (int y = from[1]; y <= to[1]; ++y)
        for (int x = from[0]; x <= to[0]; ++x) {
          Vec3 box_lo = lo + Vec3{x * g.cell.x, y * g.cell.y, z * g.cell.z};
          if (triangle_overlaps_box(a, b, c, box_lo - hair, box_lo + g.cell + hair))
            lists[(static_cast<std::size_t>(z) * g.dims[1] + y) * g.dims[0] + x].push_back(static_cast<std::int32_t>(t));
        }
  }
  g.cell_start.assign(g.cells(), -1);
  for (std::size_t c = 0; c < lists.size(); ++c) {
    if (lists[c].empty()) continue;
    g.cell_start[c] = static_cast<std::int32_t>(g.cell_triangles.size());
    g.cell_triangles.insert(g.cell_triangles.end(), lists[c].begin(), lists[c].end());
    g.cell_triangles.push_back(-1);
  }
  if (g.cell_triangles.empty()) g.cell_triangles.push_back(-1);
  g.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return g;
}

}  // namespace sh::rt
