#pragma once
// What every accelerator shares: the box it covers (the scene's bounds,
// padded so that a flat scene still has thickness and a triangle on the
// boundary is inside), the exact triangle-box test, and the hair by which
// a cell's box is widened so that rounding at a face never loses a
// triangle.
#include <string>

#include "sh/raytracer/scene.hpp"

namespace sh::rt {

enum class Accel { Grid, Octree, LazyOctree, Bvh, Auto };
Accel parse_accel(const std::string& name);  // grid, octree, lazy-octree, bvh or auto; throws sh::Error
const char* accel_name(Accel a);

// What `auto` builds for a scene and a backend running `lanes` elements
// side by side (Backend::lanes): the BVH where lanes walk it together;
// where each element runs alone, the grid where the triangles fill the
// scene's box evenly, the BVH elsewhere.  Evenly: their centres lie in at
// least half of the cells of a kFillLattice^3 lattice over the box that
// they could fill (as many cells as triangles, at most all).  It picks
// whichever renders faster (BENCHMARKS.md, issue 24): in lanes the BVH on
// every scene measured, the soup of procedural's triangles and the engine
// model included; alone, the grid on that soup (0.77 of the cells) and the
// BVH on spheres, cornell and the seeds' scenes (0.03-0.21), whose
// triangles leave most of the box empty, as models' surfaces do.
inline constexpr int kFillLattice = 16;
double filled_share(const Scene& scene);
Accel choose_accel(double filled_share, int lanes);  // never Auto

struct Box {
  Vec3 lo, hi;
};
Box accelerator_bounds(const Scene& scene);  // throws sh::Error on a scene without triangles or with a vertex out of range

// Does the triangle overlap the axis-aligned box?  (Separating axes: the
// box's three, the triangle's normal, and the nine edge cross products.)
bool triangle_overlaps_box(Vec3 a, Vec3 b, Vec3 c, Vec3 box_lo, Vec3 box_hi);

// The widening of a cell of size `cell` inside `bounds`: relative to the
// cell and to the coordinates' magnitude.
Vec3 overlap_hair(const Box& bounds, Vec3 cell);

}  // namespace sh::rt
