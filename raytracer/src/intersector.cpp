// The intersector of the seed: enter the grid's box, walk its cells with a
// 3D-DDA, test each cell's triangles, and accept a hit only inside the
// current cell (a nearer hit in a later cell cannot exist then).
#include "sh/raytracer/kernels.hpp"

namespace sh::rt {
namespace {

// A direction component this small is treated as zero: its reciprocal is
// capped, so no infinity or NaN enters the walk (fast math keeps working).
constexpr float kTinyDirection = 1e-30f;
constexpr float kFar = 1e30f;
// Barycentric tolerance: a ray through a shared edge or vertex hits both
// sides rather than slipping between them (watertight closed meshes).
constexpr float kEdgeTolerance = 1e-6f;

// Möller–Trumbore against triangle `tri`; keeps the nearest hit in (0, best).
void test_triangle(const SceneTables& s, const Point3f& o, const Vector3f& d, const Attrib1i& tri, Attrib1f& best,
                   Attrib1i& best_tri, Attrib2f& best_uv) {
  Attrib3f v0 = s.v0[tri], e1 = s.e1[tri], e2 = s.e2[tri];
  Attrib3f p = cross(d, e2);
  Attrib1f det = dot(e1, p);
  Attrib1f usable = det != 0.0f;
  Attrib1f inv = 1.0f / cond(usable, det, ConstAttrib1f(1.0f));
  Attrib3f sv = o - v0;
  Attrib1f u = dot(sv, p) * inv;
  Attrib3f q = cross(sv, e1);
  Attrib1f v = dot(d, q) * inv;
  Attrib1f t = dot(e2, q) * inv;
  Attrib1f hit = usable && u >= -kEdgeTolerance && v >= -kEdgeTolerance && u + v <= 1.0f + kEdgeTolerance &&
                 t > 0.0f && t < best;
  best = cond(hit, t, best);
  best_tri = cond(hit, tri, best_tri);
  best_uv = cond(hit, join(u, v), best_uv);
}

}  // namespace

Attrib1f intersect(const SceneTables& s, const Point3f& o, const Vector3f& d, const Attrib1f& t_limit, Attrib1f& t,
                   Attrib1i& triangle, Attrib2f& uv) {
  Attrib3f nonzero = abs(d) > kTinyDirection;
  Attrib3f inv = 1.0f / cond(nonzero, d, Attrib3f(kTinyDirection));
  // Slabs of the grid's box.
  Attrib3f grid_hi = s.grid_lo + s.grid_cell * s.grid_dims;
  Attrib3f ta = (s.grid_lo - o) * inv, tb = (grid_hi - o) * inv;
  Attrib1f t_enter = max(max_component(min(ta, tb)), 0.0f);
  Attrib1f t_leave = min(min_component(max(ta, tb)), t_limit);

  Attrib1f best = t_limit;
  triangle = -1;
  uv = ConstAttrib2f(0.0f, 0.0f);
  SH_IF(t_enter <= t_leave) {
    Point3f start = o + d * t_enter;
    Attrib3f voxel = clamp(floor((start - s.grid_lo) / s.grid_cell), 0.0f, s.grid_dims - 1.0f);
    Attrib3f step = sign(cond(nonzero, d, Attrib3f(0.0f)));
    Attrib3f t_max = cond(nonzero, (s.grid_lo + (voxel + (step > 0.0f)) * s.grid_cell - o) * inv, Attrib3f(kFar));
    Attrib3f t_delta = cond(nonzero, s.grid_cell * abs(inv), Attrib3f(kFar));
    SH_DO {
      // Every triangle listed in this cell.
      Attrib1i k = s.cell_start[voxel.cast<std::int32_t>()];
      Attrib1i tri = cond(k >= 0, s.cell_triangles[k], ConstAttrib1i(-1));
      SH_WHILE(tri >= 0) {
        test_triangle(s, o, d, tri, best, triangle, uv);
        k += 1;
        tri = s.cell_triangles[k];
      } SH_ENDWHILE;
      Attrib1f t_exit = min_component(t_max);
      SH_BREAK(best <= t_exit || t_exit >= t_leave);
      // Step into the neighbour across the nearest cell face.
      Attrib1f along_x = t_max(0) <= t_max(1) && t_max(0) <= t_max(2);
      Attrib1f along_y = (1.0f - along_x) * (t_max(1) <= t_max(2));
      Attrib3f axis = join(join(along_x, along_y), 1.0f - along_x - along_y);
      voxel += step * axis;
      t_max += t_delta * axis;
    } SH_UNTIL(any(voxel < 0.0f) || any(voxel >= s.grid_dims));
  } SH_ENDIF;
  t = best;
  return best < t_limit;
}

Program intersector_program(const SceneTables& s) {
  return SH_BEGIN_PROGRAM("intersector") {
    InputPoint3f o;
    InputVector3f d;
    OutputAttrib1f t;
    OutputAttrib1i triangle;
    Attrib1f hit_t;
    Attrib1i hit_triangle;
    Attrib2f uv;
    Attrib1f hit = intersect(s, o, d, ConstAttrib1f(kFar), hit_t, hit_triangle, uv);
    t = cond(hit, hit_t, ConstAttrib1f(-1.0f));
    triangle = hit_triangle;
  } SH_END;
}

}  // namespace sh::rt
