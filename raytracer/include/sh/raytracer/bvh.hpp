#pragma once
// A bounding volume hierarchy over the scene's triangles, built on the host
// with the surface area heuristic and walked by the kernels without a
// stack.
//
// The build bins triangle centroids (kBvhBins per axis) and takes the split
// of least SAH cost, or makes a leaf where no split pays; its subtrees are
// built in parallel, and the result never depends on which thread built
// what.  Bounded on degenerate input: triangles whose centroids coincide
// (no plane separates them) are halved by count, and below depth
// kBvhSahDepth every split halves by count, so the depth stays below
// kBvhSahDepth + log2(triangles) and a leaf never holds more than
// `max_leaf` triangles.
//
// Layout: nodes in depth-first order, the root first.  Each node has a box
// (widened by a hair, so rounding at a face never loses a triangle) and,
// for each of six walking orders, two links: where a ray goes next when
// it meets the box and when it misses it (the tree "threaded", after
// multiple-threaded BVHs).  Order k = 2 * axis + (direction < 0 along it)
// visits the children nearer the ray's start first for rays whose largest
// direction component is along that axis with that sign.  Per node and
// order:
//   hit  >= 0   an inner node: its first child in this order
//   hit  <= -2  a leaf: its triangles are listed in `triangles` from -hit-2, ended by -1
//   miss        the node after this one's subtree in this order; -1 after the last
// A leaf's walk goes on at `miss` whether the ray met it or not.
#include <cstdint>
#include <string>
#include <vector>

#include "sh/raytracer/accelerator.hpp"

namespace sh::rt {

struct BvhLimits {
  int max_leaf = 8;  // 1 .. kBvhMaxLeaf triangles in a leaf
};
inline constexpr int kBvhMaxLeaf = 64;
inline constexpr int kBvhBins = 16;
inline constexpr int kBvhSahDepth = 48;
inline constexpr int kBvhOrders = 6;

struct Bvh {
  std::vector<float> lo, hi;               // 3 per node
  std::vector<std::int32_t> links;         // per order, per node: (hit, miss); see above
  std::vector<std::int32_t> triangles;     // the leaves' lists, each ended by -1
  int depth = 0;                           // of the deepest leaf; the root is at 0
  double build_ms = 0;

  std::size_t nodes() const { return lo.size() / 3; }
  std::size_t bytes() const {
    return (lo.size() + hi.size()) * sizeof(float) + (links.size() + triangles.size()) * sizeof(std::int32_t);
  }
  // hit and miss of `node` in `order`.
  std::int32_t hit(int order, std::size_t node) const { return links[2 * (order * nodes() + node)]; }
  std::int32_t miss(int order, std::size_t node) const { return links[2 * (order * nodes() + node) + 1]; }
};

// Throws sh::Error on a scene without triangles or limits out of range.
Bvh build_bvh(const Scene& scene, BvhLimits limits = {});

}  // namespace sh::rt
