#include <chrono>
#include <cmath>
#include <limits>

#include "sh/error.hpp"
#include "sh/raytracer/grid.hpp"

namespace sh::rt {
namespace {

// Projects the triangle and the box (centred at the origin, half-size h) on
// `axis`; true if the projections are apart.
bool separated(Vec3 axis, Vec3 a, Vec3 b, Vec3 c, Vec3 h) {
  float pa = dot(a, axis), pb = dot(b, axis), pc = dot(c, axis);
  float r = h.x * std::fabs(axis.x) + h.y * std::fabs(axis.y) + h.z * std::fabs(axis.z);
  return std::min({pa, pb, pc}) > r || std::max({pa, pb, pc}) < -r;
}

}  // namespace

bool triangle_overlaps_box(Vec3 a, Vec3 b, Vec3 c, Vec3 box_lo, Vec3 box_hi) {
  Vec3 centre = (box_lo + box_hi) * 0.5f, h = (box_hi - box_lo) * 0.5f;
  a = a - centre;
  b = b - centre;
  c = c - centre;
  const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const Vec3& axis : axes)
    if (separated(axis, a, b, c, h)) return false;
  Vec3 edges[3] = {b - a, c - b, a - c};
  if (separated(cross(edges[0], edges[1]), a, b, c, h)) return false;
  for (const Vec3& e : edges)
    for (const Vec3& axis : axes)
      if (separated(cross(e, axis), a, b, c, h)) return false;
  return true;
}

Grid build_grid(const Scene& scene, double cells_per_triangle) {
  auto t0 = std::chrono::steady_clock::now();
  Grid g;
  std::size_t n = scene.mesh.triangles();
  if (n == 0) throw Error("cannot build a grid over a scene without triangles");
  Vec3 lo = scene.bounds_min(), hi = scene.bounds_max();
  Vec3 extent = hi - lo;
  // A flat scene still gets cells of some thickness along its thin axis.
  float largest = std::max({extent.x, extent.y, extent.z});
  float pad = std::max(largest * 1e-3f, std::max({std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x),
                                                   std::fabs(hi.y), std::fabs(hi.z)}) * 1e-6f);
  pad = std::max(pad, std::numeric_limits<float>::min());
  lo = lo - Vec3{pad, pad, pad};
  hi = hi + Vec3{pad, pad, pad};
  extent = hi - lo;
  double volume = static_cast<double>(extent.x) * extent.y * extent.z;
  double side = std::cbrt(volume / (cells_per_triangle * static_cast<double>(n)));
  for (int a = 0; a < 3; ++a) g.dims[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / side)), 1, 512);
  g.lo = lo;
  g.hi = hi;
  g.cell = {extent.x / g.dims[0], extent.y / g.dims[1], extent.z / g.dims[2]};

  // The box of each cell is widened by a hair, relative to the cell and to
  // the coordinates' magnitude, so rounding at a face keeps the triangle.
  float magnitude = std::max({std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z), std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)});
  Vec3 hair = g.cell * 1e-4f + Vec3{1, 1, 1} * (magnitude * 4 * std::numeric_limits<float>::epsilon());
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
