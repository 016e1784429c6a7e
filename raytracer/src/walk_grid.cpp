// The seed's walk of the uniform grid: a 3D-DDA from the cell where the ray
// enters, testing each cell's triangles.
#include "walk.hpp"

namespace sh::rt::walk {

void grid(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle, Attrib2f& uv,
          bool any_hit) {
  const GridTables& g = *s.grid;
  Attrib1f t_enter, t_leave;
  clip(r, g.lo, g.lo + g.cell * g.dims, t_limit, t_enter, t_leave);
  SH_IF(t_enter <= t_leave) {
    Point3f start = r.o + r.d * t_enter;
    Attrib3f voxel = clamp(floor((start - g.lo) / g.cell), 0.0f, g.dims - 1.0f);
    Attrib3f t_max = cond(r.nonzero, (g.lo + (voxel + (r.step > 0.0f)) * g.cell - r.o) * r.inv, Attrib3f(kFar));
    Attrib3f t_delta = cond(r.nonzero, g.cell * abs(r.inv), Attrib3f(kFar));
    SH_DO {
      // Every triangle listed in this cell.
      Attrib1i k = g.cell_start[voxel.cast<std::int32_t>()];
      test_listed(s, r, g.cell_triangles, k, cond(k >= 0, g.cell_triangles[k], ConstAttrib1i(-1)), best, triangle, uv);
      Attrib1f t_exit = min_component(t_max);
      SH_BREAK(best <= t_exit || t_exit >= t_leave);
      if (any_hit) SH_BREAK(best < t_limit);
      // Step into the neighbour across the nearest cell face.  A cell many
      // times wider than the ray's direction is long makes t_delta
      // infinite along that axis: a choice, where a product with the
      // other axes' zeros would make them NaN.
      Attrib3f axis = nearest_axis(t_max);
      voxel += r.step * axis;
      t_max = cond(axis > 0.0f, t_max + t_delta, t_max);
    } SH_UNTIL(any(voxel < 0.0f) || any(voxel >= g.dims));
  } SH_ENDIF;
}

}  // namespace sh::rt::walk
