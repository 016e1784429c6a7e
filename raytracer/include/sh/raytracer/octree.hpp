#pragma once
// The octree of the lazy-octree seed, built on the host and handed to the
// kernels as two tables.  Statically it is built entirely before tracing;
// lazily it starts as an unbuilt root and grows only where rays ask (see
// sh/waves.hpp: a ray that reaches an unbuilt node stops and reports it,
// the host builds every reported node, the ray resumes).
//
// One int per node:
//   v >= 1   an inner node; its children are nodes v .. v+7, child x + 2y + 4z
//   v == 0   not built yet: its triangles are known, its children are not
//   v == -1  an empty leaf
//   v <= -2  a leaf whose triangles are listed in `triangles` from -v-2, ended by -1
// A node is built into eight children at once; a child with no triangles is
// an empty leaf, one at the depth limit or with at most `leaf_size`
// triangles a leaf, any other one is left unbuilt.  Nodes are placed in
// integer coordinates of the finest level (2^max_depth cells per axis), so
// the kernels find the leaf holding a point exactly.
//
// Bounded work: a node whose split would not separate its triangles (two
// or more children would hold all of them and the rest none, or the eight
// together four times as many: coincident or overlapping triangles,
// coordinates so large that rounding widens every cell towards its
// parent's size) becomes a leaf instead, and the references the tree holds (leaf
// lists and the lists kept for unbuilt nodes) stay within a budget
// proportional to the triangles; past it, nodes asked for become leaves.
// Both rules act on the node being built, so a lazy tree obeys them as the
// static one does; the budget alone depends on the order nodes are built
// in, and only once spent.  warning() says when either changed the tree.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sh/raytracer/accelerator.hpp"

namespace sh::rt {

struct OctreeLimits {
  int max_depth = 8;   // 0 .. kMaxOctreeDepth
  int leaf_size = 16;  // a node with at most this many triangles is a leaf
  // References (triangles listed in leaves and kept for unbuilt nodes) the
  // tree may hold, per triangle of the scene (at least kMinReferenceBudget
  // in all).
  double references_per_triangle = 64;
};
inline constexpr std::size_t kMinReferenceBudget = 1 << 16;
inline constexpr int kMaxOctreeDepth = 19;  // keys pack level and three 19-bit coordinates

class Octree {
 public:
  // An unbuilt root over the triangles (3 positions each) in `bounds`.
  Octree(std::vector<Vec3> positions, Box bounds, OctreeLimits limits);
  static Octree lazy(const Scene& scene, OctreeLimits limits);
  static Octree full(const Scene& scene, OctreeLimits limits);  // built to the leaves, level by level

  // Builds the listed nodes that are still unbuilt (in parallel); the rest
  // are ignored.  Returns how many were built (split, or made leaves where
  // a split would not separate their triangles or the budget is spent).
  std::size_t build(const std::vector<std::int32_t>& nodes);
  // Builds each requested node and, below it, the unbuilt nodes down to the
  // leaf holding the requested cell: what a ray stopped there will walk
  // into first.  Requests are (node, cell x, y, z), cells in finest-level
  // coordinates.  Returns how many nodes were built.
  std::size_t build_towards(const std::vector<std::int32_t>& requests);
  void build_everything();
  std::vector<std::int32_t> unbuilt() const;

  const std::vector<std::int32_t>& nodes() const { return nodes_; }
  const std::vector<std::int32_t>& triangles() const { return triangles_; }
  const Box& bounds() const { return bounds_; }
  const OctreeLimits& limits() const { return limits_; }
  const std::vector<Vec3>& positions() const { return positions_; }
  int resolution() const { return 1 << limits_.max_depth; }  // finest cells per axis
  Vec3 finest_cell() const;

  // Nodes built on request (not counting the root made at construction),
  // in the order they were built, each as a key of its level and place: the
  // same node has the same key in every process.  Found by walking the tree
  // (an inner node's children were appended when it was built), so the
  // tree keeps no record of them.
  std::vector<std::uint64_t> built_keys() const;
  std::size_t built_count() const { return (nodes_.size() - 1) / 8; }
  Box box_of(std::uint64_t key) const;  // the box of the node with this key
  std::size_t bytes() const;          // the two tables
  std::size_t pending_bytes() const;  // what is kept for unbuilt nodes: places and triangle lists
  double build_ms() const { return build_ms_; }
  // Triangles listed in leaves and kept for unbuilt nodes; the most allowed.
  std::size_t references() const { return references_; }
  std::size_t reference_budget() const { return reference_budget_; }
  // Nodes made leaves by the bounds above (not the depth limit or leaf
  // size), and the most triangles such a leaf holds.
  std::size_t unseparated() const { return unseparated_; }
  std::size_t over_budget() const { return over_budget_; }
  std::size_t largest_capped_leaf() const { return largest_capped_leaf_; }
  // What the bounds changed, for the user: empty unless the budget was
  // spent or a refused split left a leaf of more than twice the leaf size.
  std::string warning() const;

 private:
  struct Place {
    int level = 0;
    std::array<int, 3> corner{0, 0, 0};  // finest-level coordinates
  };
  // An unbuilt node: its index and place, and where its triangles start in
  // `candidate_bytes_` (they end where the next entry's start).  Entries are
  // appended as nodes are made, so they are sorted by node index; a built
  // one is marked dead until the entries are compacted.
  struct Unbuilt {
    std::int32_t node;
    std::uint32_t first_byte;
    std::uint64_t key;
  };
  static constexpr std::uint64_t kDead = ~std::uint64_t{0};
  using Children = std::array<std::vector<std::int32_t>, 8>;

  std::size_t build_level(const std::vector<std::int32_t>& nodes);  // build() but keeps dead entries
  bool place_children(std::int32_t node, Place at, const Children& children, std::size_t candidates);
  std::int32_t leaf(const std::vector<std::int32_t>& list);
  std::size_t entry_of(std::int32_t node) const;  // an unbuilt node's entry
  std::vector<std::int32_t> candidates(std::size_t entry) const;
  void keep_unbuilt(std::int32_t node, Place place, const std::vector<std::int32_t>& list);
  void compact_unbuilt();
  Children split(Place at, const std::vector<std::int32_t>& candidates) const;

  std::int32_t settle(Place place, const std::vector<std::int32_t>& list, std::int32_t index);
  Place child(Place parent, int which) const;
  Box box(Place p) const;  // as the kernels compute it
  static std::uint64_t key(Place p);
  static Place place(std::uint64_t key);

  std::vector<Vec3> positions_;
  Box bounds_;
  OctreeLimits limits_;
  std::vector<std::int32_t> nodes_;
  std::vector<std::int32_t> triangles_;
  std::vector<Unbuilt> unbuilt_;
  // Each unbuilt node's triangles as runs of consecutive numbers (meshes
  // number neighbouring triangles closely), each run two LEB128 numbers:
  // its distance from the previous run's end, and its length less one.
  std::vector<std::uint8_t> candidate_bytes_;
  std::size_t dead_ = 0;
  double build_ms_ = 0;
  std::size_t references_ = 0, reference_budget_ = 0;
  std::size_t unseparated_ = 0, over_budget_ = 0, largest_capped_leaf_ = 0;
};

// Nodes built by several parts (ranks) of one render and how many of them
// more than one part built: the overlap of lazy builds.
struct BuildOverlap {
  std::vector<std::size_t> per_part;
  std::size_t distinct = 0, shared = 0;  // built by any part; by two or more
};
BuildOverlap build_overlap(const std::vector<std::vector<std::uint64_t>>& keys_per_part);

}  // namespace sh::rt
