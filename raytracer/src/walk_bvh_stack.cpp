// The BVH's walk with a stack (bvh.hpp): a visit to an inner node tests
// both children's boxes; the ray goes on to the nearer child it meets and
// pushes the other, and where it meets neither it pops.  Inner nodes are
// walked in a loop of their own until the ray stands at a leaf (or has
// nothing left), then the leaf's triangles are tested and the walk pops:
// rays side by side in SIMD lanes each walk their own path, and those at
// a leaf wait for the others to reach one, so that the triangle tests run
// with as many lanes as can (a while-while walk, after Aila and Laine's on
// GPUs).  Every lane reads its own nodes and keeps its own stack.
#include "walk.hpp"

namespace sh::rt::walk {

void bvh_stack(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle,
               Attrib2f& uv, bool any_hit) {
  const BvhTables& b = *s.bvh;
  // A push goes one level down the tree, so the stack is as deep as it.
  LocalArray<Attrib1i> stack(b.depth + 1, "bvh_stack");
  Attrib1i depth = 0;
  Attrib1i node = b.root;  // >= 0 an inner node, <= -2 a leaf, -1 done
  // The node below the stack's top, or -1 where it is empty.
  auto popped = [&](const Attrib1i& popping) {
    depth -= popping;
    return cond(popping, stack[depth], ConstAttrib1i(-1));
  };
  auto walking = [&]() -> Attrib1i {
    if (!any_hit) return node != -1;
    return node != -1 && (best >= t_limit).cast<std::int32_t>();
  };
  SH_WHILE(walking()) {
    SH_WHILE(node >= 0) {
      Attrib1i first = node * 2, second = node * 2 + 1;
      Attrib1f clip_at = best * kBeyondBest;
      Attrib1f enter0, leave0, enter1, leave1;
      clip(r, b.pair_lo[first], b.pair_hi[first], clip_at, enter0, leave0);
      clip(r, b.pair_lo[second], b.pair_hi[second], clip_at, enter1, leave1);
      Attrib1i met0 = (enter0 <= leave0).cast<std::int32_t>(), met1 = (enter1 <= leave1).cast<std::int32_t>();
      Attrib1i second_first = met1 && (met0 == 0 || (enter1 < enter0).cast<std::int32_t>());
      Attrib1i kid0 = b.children[first], kid1 = b.children[second];
      Attrib1i near = cond(second_first, kid1, kid0), far = cond(second_first, kid0, kid1);
      // The far child is stored whether or not it is pushed: a slot at the
      // top is read only after a push has written it.
      stack.store(depth, far);
      depth += met0 && met1;
      Attrib1i met = met0 || met1;
      node = cond(met, near, popped((met == 0) && depth > 0));
    } SH_ENDWHILE;
    SH_IF(node <= -2) {
      test_leaf(b, r, -node - 2, best, triangle, uv);
      node = popped(depth > 0);
    } SH_ENDIF;
  } SH_ENDWHILE;
}

}  // namespace sh::rt::walk
