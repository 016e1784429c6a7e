#pragma once
// A bounding volume hierarchy over the scene's triangles, built on the host
// with the surface area heuristic and walked by the kernels in one of three
// ways (BvhWalk), each reading a layout of its own: wide nodes with a
// stack (the default), a binary tree threaded for walking without a
// stack, or a binary tree walked by each ray alone with a stack.
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
// The threaded walk's layout: nodes in depth-first order, the root first.
// Each node has a box (widened by a hair, so rounding at a face never
// loses a triangle; every layout's boxes are) and, for each of six walking
// orders, two links: where a ray goes next when it meets the box and when
// it misses it (the tree "threaded", after multiple-threaded BVHs).
// Order k = 2 * axis + (direction < 0 along it) visits the children
// nearer the ray's start first for rays whose largest direction component
// is along that axis with that sign.  Per node and order:
//   hit  >= 0   an inner node: its first child in this order
//   hit  <= -2  a leaf: its triangles are listed in `triangles` from -hit-2, the last negated
//   miss        the node after this one's subtree in this order; -1 after the last
// A leaf's walk goes on at `miss` whether the ray met it or not.
//
// The stack walk (BvhWalk::Stack) reads another layout instead: the inner
// nodes, depth-first, each holding its two children's boxes and references
// (>= 0 an inner node, <= -2 a leaf listed from -ref-2), so that one visit
// tests both children; a ray goes on to the nearer child it meets and
// keeps the other on a stack of its own (a local array as deep as the
// tree).  Neighbouring lanes go their own ways, each reading its own nodes.
//
// The wide walk (BvhWalk::Wide) reads nodes of kBvhWidth children, the
// binary tree's levels collapsed (the largest inner child opened first):
// per node its children's boxes as six rows of kBvhWidth (lo x, lo y,
// lo z, hi x, hi y, hi z: one vector load each), their references (-1 in
// an empty slot, which a walk skips by it: its box is a point at the
// origin, which a ray may meet) and, per axis, the slots in the order
// of their boxes' centres along it.  Neighbouring lanes walk together: a
// child is entered when any lane meets it, nearer ones first along the
// lanes' main direction, the others kept on one stack for all of them.
//
// A leaf's list holds its triangles' numbers, the last one stored as
// -t - 1: no entry ends a list, so that a list and its corners take only
// what its triangles need (leaves hold about two triangles on large
// models, where an end entry and its corners took a third of the lists).
//
// Every walk tests a leaf's triangles with their corners from `corners`,
// beside each list entry, not from the scene's tables by triangle number:
// a leaf's corners lie together, in as few cache lines as they fill, where
// the scene's order of triangles would scatter them over a large model.
// The list keeps the numbers, which name the hit and decide ties.
#include <cstdint>
#include <string>
#include <vector>

#include "sh/raytracer/accelerator.hpp"

namespace sh::rt {

// Threaded: without a stack, neighbouring lanes together; Stack: each lane
// on its own path, with a stack; Wide: nodes of kBvhWidth children,
// neighbouring lanes together, with a stack.
enum class BvhWalk { Threaded, Stack, Wide };
BvhWalk parse_bvh_walk(const std::string& name);  // threaded, stack or wide; throws sh::Error
const char* bvh_walk_name(BvhWalk w);

// A tree larger than this misses the cache at every level of a walk, so
// the wide walk asks for the nodes it will visit ahead of reading them;
// below it the asks only cost instructions.  Measured on camera rays
// (BENCHMARKS.md, issue 24), one thread, against rtcIntersect1, on the
// Zen 2 host (16 MiB of L3), with the asks unclamped (legal IR leaves a
// prefetch's coordinates as asked): 5.9 MiB (procedural's 90 k triangles)
// 1.57x without against 1.44x with, its render 196 against 217 ms, and the
// engine model's (7.2 MiB) 30 against 32 ms; 16 MiB (300 k) the same
// within noise; 46 MiB (1 M) 0.80x without against 0.90-0.94x with.  An
// earlier host, with the clamps, gained 10 % at 11 MB.
inline constexpr std::size_t kBvhPrefetchBytes = std::size_t{16} << 20;

// The SAH weighs a node visit against a triangle test.  A tree over more
// triangles than kBvhLargeTree (about 16 MiB of nodes, lists and corners,
// a last-level cache's worth on the hosts measured) weighs it three times
// as much: its walks wait on memory at every level they go down, even with
// the children asked ahead, while a leaf's corners lie together.  Its
// leaves hold more triangles and a walk visits fewer nodes.  Measured on
// one thread against rtcIntersect1 (BENCHMARKS.md, issue 24): camera rays
// at 1 M triangles 0.93x -> 1.01x, at 300 k 1.24x -> 1.29x, shadow and
// reflection rays 4-13 % faster; on the smaller trees it cost (the engine
// model's 110 k triangles: camera rays 1.24x -> 1.06-1.26x; cornell's
// shadow rays 3.5x -> 2.0x), so they keep 1.
inline constexpr std::size_t kBvhLargeTree = 250'000;
inline constexpr double kBvhLargeTreeNodeCost = 3;
inline constexpr double kBvhMaxNodeCost = 64;

struct BvhSettings {
  int max_leaf = 8;  // 1 .. kBvhMaxLeaf triangles in a leaf
  BvhWalk walk = BvhWalk::Wide;  // the fastest on the cpu backend's lanes (BENCHMARKS.md)
  std::size_t prefetch_above = kBvhPrefetchBytes;  // Bvh::prefetch where bytes() is larger
  double node_cost = 0;  // the SAH's node visit against a triangle test, 0 .. kBvhMaxNodeCost (0: by the tree's size)
};
// The node cost a build over `triangles` takes: the settings', or by the
// tree's size where they leave it 0.  Throws sh::Error outside the range.
double sah_node_cost(const BvhSettings& s, std::size_t triangles);
inline constexpr int kBvhMaxLeaf = 64;
inline constexpr int kBvhBins = 16;
inline constexpr int kBvhSahDepth = 48;
inline constexpr int kBvhOrders = 6;
inline constexpr int kBvhWidth = 4;

// Each layout is filled only for its walk.
struct Bvh {
  BvhWalk walk = BvhWalk::Threaded;
  std::vector<float> lo, hi;               // threaded: 3 per node
  std::vector<std::int32_t> links;         // threaded: per order, per node: (hit, miss); see above
  std::vector<float> pair_lo, pair_hi;     // stack: 6 per inner node, child 0's box then child 1's
  std::vector<std::int32_t> children;      // stack: 2 per inner node; see above
  std::vector<float> wide_box;             // wide: 6 rows of kBvhWidth per node; see above
  std::vector<std::int32_t> wide_children; // wide: kBvhWidth per node
  std::vector<std::int32_t> wide_order;    // wide: per node, axis a's slots in bits 8a.., 2 bits each, lowest first
  std::int32_t root = 0;                   // stack, wide: the root's reference (a leaf where the tree is one)
  bool prefetch = false;                   // wide: a visit asks for its children's nodes, lists and corners ahead
  std::vector<std::int32_t> triangles;     // the leaves' lists, each one's last entry negated (see above)
  std::vector<float> corners;              // 9 per list entry: its triangle's corners
  int depth = 0;                           // of the deepest leaf; the root is at 0
  std::size_t node_count = 0;              // inner nodes and leaves
  double node_cost = 1;                   // the SAH's, as built
  double build_ms = 0;

  std::size_t nodes() const { return node_count; }
  std::size_t bytes() const {
    return (lo.size() + hi.size() + pair_lo.size() + pair_hi.size() + wide_box.size() + corners.size()) *
               sizeof(float) +
           (links.size() + children.size() + wide_children.size() + wide_order.size() + triangles.size()) *
               sizeof(std::int32_t);
  }
  // The triangle a list entry names, and whether it ends its list.
  static std::int32_t listed(std::int32_t entry) { return entry < 0 ? -entry - 1 : entry; }
  static bool ends_list(std::int32_t entry) { return entry < 0; }
  // hit and miss of `node` in `order` (threaded).
  std::int32_t hit(int order, std::size_t node) const { return links[2 * (order * nodes() + node)]; }
  std::int32_t miss(int order, std::size_t node) const { return links[2 * (order * nodes() + node) + 1]; }
};

// Throws sh::Error on a scene without triangles or settings out of range.
Bvh build_bvh(const Scene& scene, BvhSettings settings = {});

}  // namespace sh::rt
