// The octree's walk, front to back without a stack: find the leaf holding
// the current cell by descending from the root (in integer cell
// coordinates, so the answer is exact), test its triangles, and go on to
// the cell just beyond the face where the ray leaves the leaf.
#include "walk.hpp"

namespace sh::rt::walk {
namespace {

struct Leaf {
  Attrib1i node, value;  // the node and its table entry (see octree.hpp)
  Attrib3f corner;       // finest-level coordinates
  Attrib1f size;         // finest cells per side
};

Leaf descend(const OctreeTables& q, const Attrib3f& cell) {
  Leaf l;
  l.node = 0;
  l.value = q.nodes[l.node];
  l.corner = ConstAttrib3f(0.0f, 0.0f, 0.0f);
  l.size = q.resolution;
  SH_WHILE(l.value >= 1) {
    l.size *= 0.5f;
    Attrib3f upper = cell >= l.corner + l.size;
    l.corner += upper * l.size;
    l.node = l.value + (upper(0) + 2.0f * upper(1) + 4.0f * upper(2)).cast<std::int32_t>();
    l.value = q.nodes[l.node];
  } SH_ENDWHILE;
  return l;
}

void test_leaf(const SceneTables& s, const OctreeTables& q, const Ray& r, const Leaf& leaf, WalkState& w) {
  Attrib1i k = -leaf.value - 2;
  test_listed(s, r, q.triangles, k, cond(leaf.value <= -2, q.triangles[k], ConstAttrib1i(-1)), w.best, w.triangle, w.uv);
}

}  // namespace

void octree(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, WalkState& w, Attrib4i* request,
            bool any_hit) {
  const OctreeTables& q = *s.octree;
  Attrib1f t_enter, t_leave;
  clip(r, q.lo, q.lo + q.finest_cell * q.resolution, t_limit, t_enter, t_leave);
  SH_IF(t_enter <= t_leave) {
    SH_IF(w.cell(0) < 0.0f) {
      w.cell = clamp(floor((r.o + r.d * t_enter - q.lo) / q.finest_cell), 0.0f, q.resolution - 1.0f);
    } SH_ENDIF;
    SH_DO {
      Leaf leaf = descend(q, w.cell);
      if (request) {
        *request = cond(leaf.value == 0, join(leaf.node, w.cell.cast<std::int32_t>()), *request);
        SH_BREAK(leaf.value == 0);
      }
      test_leaf(s, q, r, leaf, w);
      Attrib3f leaf_lo = q.lo + leaf.corner * q.finest_cell, leaf_hi = q.lo + (leaf.corner + leaf.size) * q.finest_cell;
      Attrib3f t_exits = cond(r.nonzero, (cond(r.step > 0.0f, leaf_hi, leaf_lo) - r.o) * r.inv, Attrib3f(kFar));
      Attrib1f t_exit = min_component(t_exits);
      SH_BREAK(w.best <= t_exit || t_exit >= t_leave);
      if (any_hit) SH_BREAK(w.best < t_limit);
      // Across the exit face: the next cell along the exit axis; along the
      // others, where the ray leaves, kept on this leaf's side of them.
      Attrib3f axis = nearest_axis(t_exits);
      Attrib3f beyond = cond(r.step > 0.0f, leaf.corner + leaf.size, leaf.corner - 1.0f);
      Attrib3f across = clamp(floor((r.o + r.d * t_exit - q.lo) / q.finest_cell), leaf.corner, leaf.corner + leaf.size - 1.0f);
      w.cell = axis * beyond + (1.0f - axis) * across;
    } SH_UNTIL(any(w.cell < 0.0f) || any(w.cell >= q.resolution));
  } SH_ENDIF;
}

}  // namespace sh::rt::walk
