// The BVH's walk without a stack (bvh.hpp): from the root, follow a node's
// hit link where the ray meets its box and its miss link where it does
// not, testing each leaf met, until the links run out.  The order is the
// one threaded for the ray's largest direction component and its sign, so
// nearer children tend to come first and boxes beyond the nearest hit so
// far are skipped.
#include <optional>

#include "walk.hpp"

namespace sh::rt::walk {

// The order threaded for the ray's largest direction component and its
// sign: 2 * axis + (downwards), the axis the watertight test's turn puts
// last.  Rays walked together take the lowest order among them, so they
// follow the same links.
Attrib1f walk_order(const Ray& r) {
  Attrib1f axis = 2.0f - 2.0f * r.last_is_x - r.last_is_y;
  Attrib1f own = 2.0f * axis + (r.turn(r.d)(2) < 0.0f);
  Attrib1f lowest = 0.0f;
  for (int k = 0; k + 1 < kBvhOrders; ++k) lowest += 1.0f - any_lane(own <= static_cast<float>(k));
  return lowest;
}

// Rays side by side in SIMD lanes walk together: a box is entered when any
// of them meets it (any_lane), so every lane is at the same node and reads
// it with one load instead of a gather.  A ray is tested against the
// triangles of leaves it alone would have skipped; its nearest hit is the
// same, as the test does not depend on the boxes.  Where elements run
// alone (scalar code, the interpreter, OpenCL) this is the single ray's
// walk.
void bvh_threaded(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle,
                  Attrib2f& uv, bool any_hit, Attrib4i* lanes) {
  const BvhTables& b = *s.bvh;
  Attrib1i base = walk_order(r).cast<std::int32_t>() * b.nodes;
  Attrib1i node = 0;
  // A ray that found any hit is done and leaves; the others walk on
  // together, still agreeing on the node.
  auto walking = [&]() -> Attrib1i {
    if (!any_hit) return node >= 0;
    return node >= 0 && (best >= t_limit).cast<std::int32_t>();
  };
  SH_WHILE(walking()) {
    // Boxes up to the next leaf to test, then its triangles: the box walk
    // stays a short loop of its own.
    Attrib1i leaf = -1;
    std::optional<Attrib1i> own_leaf;  // counting: whether the leaf's box met this lane's ray
    if (lanes) own_leaf = Attrib1i(0);
    SH_WHILE(node >= 0 && leaf < 0) {
      Attrib1f t_enter, t_leave;
      clip(r, b.lo[node], b.hi[node], best * kBeyondBest, t_enter, t_leave);
      Attrib2i link = b.links[base + node];
      Attrib1f own = t_enter <= t_leave;
      Attrib1i met = any_lane(own).cast<std::int32_t>();
      if (lanes) {
        *own_leaf = own.cast<std::int32_t>();
        *lanes += join(join(ConstAttrib1i(1), *own_leaf), ConstAttrib2i(0, 0));
      }
      leaf = cond(met && link(0) <= -2, -link(0) - 2, leaf);
      node = cond(met && link(0) >= 0, link(0), link(1));
    } SH_ENDWHILE;
    SH_IF(leaf >= 0) {
      if (lanes) *lanes += join(ConstAttrib2i(0, 0), join(ConstAttrib1i(1), *own_leaf));
      test_leaf(b, r, leaf, best, triangle, uv);
    } SH_ENDIF;
  } SH_ENDWHILE;
}

void bvh(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle, Attrib2f& uv,
         bool any_hit, Attrib4i* lanes) {
  if (s.bvh->walk == BvhWalk::Stack) return bvh_stack(s, r, t_limit, best, triangle, uv, any_hit);
  if (s.bvh->walk == BvhWalk::Wide) return bvh_wide(s, r, t_limit, best, triangle, uv, any_hit, lanes);
  bvh_threaded(s, r, t_limit, best, triangle, uv, any_hit, lanes);
}

}  // namespace sh::rt::walk
