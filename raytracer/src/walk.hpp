#pragma once
// Inside the intersector: the walks of each accelerator's cells, and what
// they share (the ray's reciprocal direction, the triangle test).
#include "sh/raytracer/kernels.hpp"
#include "sh/raytracer/walk_bounds.hpp"

namespace sh::rt::walk {

struct Ray {
  Ray(const Point3f& origin, const Vector3f& direction);
  const Point3f& o;
  const Vector3f& d;
  Attrib3f nonzero, inv, step;  // step: the sign of each usable component
  // Ray space of the watertight test: axes turned so that the direction's
  // largest component comes last, then sheared so the direction becomes
  // +z.  Where that component is negative the projection is seen from
  // behind: every edge function changes sign, which a test that takes
  // triangles facing either way does not see (t and the barycentrics are
  // ratios of them).
  Attrib1f last_is_x, last_is_y;
  Attrib3f shear;  // (-dx / dz, -dy / dz, 1 / dz) in turned axes
  Attrib3f turn(const Attrib3f& v) const;
};

// The ray's parameters where it enters and leaves the box [lo, hi] (t_enter
// > t_leave: it misses), clipped to [0, t_limit].
void clip(const Ray& r, const Attrib3f& lo, const Attrib3f& hi, const Attrib1f& t_limit, Attrib1f& t_enter,
          Attrib1f& t_leave);

// The watertight test (Woop, Benthin and Wald, JCGT 2013) against triangle
// `tri`, whose corners are v0, v1 and v2; keeps the nearest hit in
// (0, best).
void test_triangle(const Ray& r, const Attrib3f& v0, const Attrib3f& v1, const Attrib3f& v2, const Attrib1i& tri,
                   Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv);

// Tests the triangles listed in `list` from k on (k moves along), `tri`
// being list[k] (-1 where the list is empty), up to the -1 that ends it,
// their corners from the scene's tables: a grid cell's or an octree leaf's.
void test_listed(const SceneTables& s, const Ray& r, const Table1D<Attrib1i>& list, Attrib1i& k, Attrib1i tri,
                 Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv);

// Tests a BVH leaf's triangles, listed from k on to the entry that ends the
// list, with the corners beside it (bvh.hpp).
void test_leaf(const BvhTables& b, const Ray& r, Attrib1i k, Attrib1f& best, Attrib1i& best_tri, Attrib2f& best_uv);

// 1 along the axis of the nearest of the three exit distances, 0 elsewhere.
Attrib3f nearest_axis(const Attrib3f& t_exits);

// Each walk keeps the nearest hit in (0, best), best at most t_limit; with
// any_hit it may stop at the first hit nearer than t_limit instead.
void grid(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& tri, Attrib2f& uv,
          bool any_hit);
// Stops at an unbuilt node, leaving it and the cell in *request (a lazy
// octree only).
void octree(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, WalkState& state, Attrib4i* request,
            bool any_hit);
// The BVH's walk its tables were laid out for.  With `lanes` (the walks of
// lanes together: threaded and wide), counts into it as
// Intersector::lanes() says.
void bvh(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& tri, Attrib2f& uv,
         bool any_hit, Attrib4i* lanes = nullptr);
void bvh_threaded(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& tri,
                  Attrib2f& uv, bool any_hit, Attrib4i* lanes);
void bvh_stack(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& tri,
               Attrib2f& uv, bool any_hit);
void bvh_wide(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& tri,
              Attrib2f& uv, bool any_hit, Attrib4i* lanes);

// The order the lanes walk together take: 2 * axis + (downwards) of the
// direction's largest component, the lowest among the lanes.
Attrib1f walk_order(const Ray& r);

}  // namespace sh::rt::walk
