#pragma once
// Between the BVH's build and its layout: the tree as nodes that own their
// children, and the box arithmetic both use.
#include <array>
#include <limits>
#include <memory>
#include <vector>

#include "sh/raytracer/bvh.hpp"

namespace sh::rt::bvh {

inline Box empty_box() {
  constexpr float inf = std::numeric_limits<float>::infinity();
  return {{inf, inf, inf}, {-inf, -inf, -inf}};
}
inline Box merge(const Box& a, const Box& b) { return {min(a.lo, b.lo), max(a.hi, b.hi)}; }
inline Box grow(const Box& a, Vec3 p) { return {min(a.lo, p), max(a.hi, p)}; }
inline Vec3 centre(const Box& b) { return (b.lo + b.hi) * 0.5f; }

// 0 for an empty box.  In double: coordinates up to the tracer's 1e18
// square beyond float.
inline double area(const Box& b) {
  if (!(b.lo.x <= b.hi.x)) return 0;
  double x = static_cast<double>(b.hi.x) - b.lo.x, y = static_cast<double>(b.hi.y) - b.lo.y,
         z = static_cast<double>(b.hi.z) - b.lo.z;
  return 2 * (x * y + y * z + z * x);
}

struct Node {
  Box box = empty_box();
  std::array<std::unique_ptr<Node>, 2> child;  // none: a leaf
  std::vector<std::int32_t> triangles;         // a leaf's, in increasing order
  bool leaf() const { return !child[0]; }
};

// `limits.node_cost` as sah_node_cost resolved it (build_bvh does).
std::unique_ptr<Node> build_tree(const Scene& scene, BvhSettings limits);
// Boxes widened by a hair relative to each box; nodes depth-first with
// links for every order (threaded), or inner nodes depth-first with their
// children's boxes (stack).
Bvh lay_out(const Node& root, BvhWalk walk);

}  // namespace sh::rt::bvh
