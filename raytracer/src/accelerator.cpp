#include "sh/raytracer/accelerator.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "sh/error.hpp"

namespace sh::rt {
namespace {

// Projects the triangle and the box (centred at the origin, half-size h) on
// `axis`; true if the projections are apart.
bool separated(Vec3 axis, Vec3 a, Vec3 b, Vec3 c, Vec3 h) {
  float pa = dot(a, axis), pb = dot(b, axis), pc = dot(c, axis);
  float r = h.x * std::fabs(axis.x) + h.y * std::fabs(axis.y) + h.z * std::fabs(axis.z);
  return std::min({pa, pb, pc}) > r || std::max({pa, pb, pc}) < -r;
}

float magnitude(const Box& b) {
  return std::max({std::fabs(b.lo.x), std::fabs(b.lo.y), std::fabs(b.lo.z), std::fabs(b.hi.x), std::fabs(b.hi.y),
                   std::fabs(b.hi.z)});
}

}  // namespace

Accel parse_accel(const std::string& name) {
  if (name == "grid") return Accel::Grid;
  if (name == "octree") return Accel::Octree;
  if (name == "lazy-octree") return Accel::LazyOctree;
  if (name == "bvh") return Accel::Bvh;
  if (name == "auto") return Accel::Auto;
  throw Error("unknown accelerator '" + name + "' (grid, octree, lazy-octree, bvh or auto)");
}

const char* accel_name(Accel a) {
  switch (a) {
    case Accel::Grid: return "grid";
    case Accel::Octree: return "octree";
    case Accel::LazyOctree: return "lazy-octree";
    case Accel::Bvh: return "bvh";
    case Accel::Auto: return "auto";
  }
  return "?";
}

// The renderer validates its scene first; a caller that builds an
// accelerator alone gets the check of what the builds assume of the
// vertices (a NaN would bin nowhere and index no cell).
Box accelerator_bounds(const Scene& scene) {
  if (scene.mesh.triangles() == 0) throw Error("cannot build an accelerator over a scene without triangles");
  for (std::size_t i = 0; i < scene.mesh.positions.size(); ++i)
    if (std::string problem = coordinate_problem(scene.mesh.positions[i]); !problem.empty())
      throw Error("cannot build an accelerator: triangle " + std::to_string(i / 3) + ", vertex " +
                  std::to_string(i % 3) + ": " + problem);
  Box b{scene.bounds_min(), scene.bounds_max()};
  Vec3 extent = b.hi - b.lo;
  // A flat scene still gets cells of some thickness along its thin axis.
  float largest = std::max({extent.x, extent.y, extent.z});
  float pad = std::max({largest * 1e-3f, magnitude(b) * 1e-6f, std::numeric_limits<float>::min()});
  return {b.lo - Vec3{pad, pad, pad}, b.hi + Vec3{pad, pad, pad}};
}

double filled_share(const Scene& scene) {
  Box b = accelerator_bounds(scene);
  constexpr int n = kFillLattice;
  std::vector<bool> filled(n * n * n, false);
  std::size_t count = 0;
  for (std::size_t t = 0; t < scene.mesh.triangles(); ++t) {
    const Vec3* v = &scene.mesh.positions[3 * t];
    Vec3 centre = (v[0] + v[1] + v[2]) * (1.0f / 3);
    int cell = 0;
    for (int a = 2; a >= 0; --a) {
      float at = (centre[a] - b.lo[a]) / (b.hi[a] - b.lo[a]) * n;
      cell = cell * n + std::clamp(static_cast<int>(at), 0, n - 1);
    }
    if (!filled[static_cast<std::size_t>(cell)]) filled[static_cast<std::size_t>(cell)] = true, ++count;
  }
  return static_cast<double>(count) / static_cast<double>(std::min<std::size_t>(filled.size(), scene.mesh.triangles()));
}

Accel choose_accel(double share, int lanes) { return lanes == 1 && share >= 0.5 ? Accel::Grid : Accel::Bvh; }

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

Vec3 overlap_hair(const Box& bounds, Vec3 cell) {
  return cell * 1e-4f + Vec3{1, 1, 1} * (magnitude(bounds) * 4 * std::numeric_limits<float>::epsilon());
}

}  // namespace sh::rt
