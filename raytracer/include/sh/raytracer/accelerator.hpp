#pragma once
// What every accelerator shares: the box it covers (the scene's bounds,
// padded so that a flat scene still has thickness and a triangle on the
// boundary is inside), the exact triangle-box test, and the hair by which
// a cell's box is widened so that rounding at a face never loses a
// triangle.
#include <string>

#include "sh/raytracer/scene.hpp"

namespace sh::rt {

enum class Accel { Grid, Octree, LazyOctree, Bvh };
Accel parse_accel(const std::string& name);  // grid, octree, lazy-octree or bvh; throws sh::Error
const char* accel_name(Accel a);

struct Box {
  Vec3 lo, hi;
};
Box accelerator_bounds(const Scene& scene);  // throws sh::Error on a scene without triangles

// Does the triangle overlap the axis-aligned box?  (Separating axes: the
// box's three, the triangle's normal, and the nine edge cross products.)
bool triangle_overlaps_box(Vec3 a, Vec3 b, Vec3 c, Vec3 box_lo, Vec3 box_hi);

// The widening of a cell of size `cell` inside `bounds`: relative to the
// cell and to the coordinates' magnitude.
Vec3 overlap_hair(const Box& bounds, Vec3 cell);

}  // namespace sh::rt
