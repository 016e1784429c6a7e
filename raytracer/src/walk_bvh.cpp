// The BVH's walk without a stack (bvh.hpp): from the root, follow a node's
// hit link where the ray meets its box and its miss link where it does
// not, testing each leaf met, until the links run out.  The order is the
// one threaded for the ray's largest direction component and its sign, so
// nearer children tend to come first and boxes beyond the nearest hit so
// far are skipped.
#include "walk.hpp"

namespace sh::rt::walk {
namespace {

// Boxes are clipped a little beyond the nearest hit so far: a triangle at
// the same distance to the intersector's tie tolerance may still win a tie.
constexpr float kBeyondBest = 1.0f + 4e-6f;

// Where the ray's links start in bvh_links: order 2 * axis + (downwards),
// axis that of the largest direction component (the watertight test's
// turn puts it last).
Attrib1i links_base(const BvhTables& b, const Ray& r) {
  Attrib1f axis = 2.0f - 2.0f * r.last_is_x - r.last_is_y;
  Attrib1f downwards = r.turn(r.d)(2) < 0.0f;
  return (2.0f * axis + downwards).cast<std::int32_t>() * b.nodes;
}

void test_leaf(const SceneTables& s, const Ray& r, const Attrib1i& start, Attrib1f& best, Attrib1i& triangle,
               Attrib2f& uv) {
  const BvhTables& b = *s.bvh;
  Attrib1i k = start;
  Attrib1i tri = b.triangles[k];
  SH_WHILE(tri >= 0) {
    test_triangle(s, r, tri, best, triangle, uv);
    k += 1;
    tri = b.triangles[k];
  } SH_ENDWHILE;
}

}  // namespace

void bvh(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle, Attrib2f& uv,
         bool any_hit) {
  const BvhTables& b = *s.bvh;
  Attrib1i base = links_base(b, r);
  Attrib1i node = 0;
  SH_WHILE(node >= 0) {
    Attrib1f t_enter, t_leave;
    clip(r, b.lo[node], b.hi[node], best * kBeyondBest, t_enter, t_leave);
    Attrib2i link = b.links[base + node];
    Attrib1f meets = t_enter <= t_leave;
    SH_IF(meets && (link(0) <= -2).cast<float>()) { test_leaf(s, r, -link(0) - 2, best, triangle, uv); } SH_ENDIF;
    node = cond(meets && (link(0) >= 0).cast<float>(), link(0), link(1));
    if (any_hit) node = cond(best < t_limit, ConstAttrib1i(-1), node);
  } SH_ENDWHILE;
}

}  // namespace sh::rt::walk
