// The BVH's tree laid out as bvh.hpp says: nodes numbered depth-first,
// leaves' lists, and the six threaded orders or the stack walk's pairs of
// child boxes.
#include <algorithm>
#include <limits>

#include "bvh_tree.hpp"
#include "sh/error.hpp"

namespace sh::rt::bvh {
namespace {

struct Numbered {
  std::vector<const Node*> nodes;                  // depth-first, left child first
  std::vector<std::array<std::int32_t, 2>> child;  // their numbers; -1 in a leaf
  std::vector<std::int32_t> leaf_start;            // into the lists; -1 in an inner node
  int depth = 0;
};

Numbered number(const Node& root) {
  struct Visit {
    const Node* node;
    std::int32_t parent;
    int slot, depth;
  };
  Numbered out;
  std::vector<Visit> stack{{&root, -1, 0, 0}};
  while (!stack.empty()) {
    Visit v = stack.back();
    stack.pop_back();
    auto at = static_cast<std::int32_t>(out.nodes.size());
    out.nodes.push_back(v.node);
    out.child.push_back({-1, -1});
    if (v.parent >= 0) out.child[static_cast<std::size_t>(v.parent)][static_cast<std::size_t>(v.slot)] = at;
    out.depth = std::max(out.depth, v.depth);
    if (v.node->leaf()) continue;
    stack.push_back({v.node->child[1].get(), at, 1, v.depth + 1});
    stack.push_back({v.node->child[0].get(), at, 0, v.depth + 1});
  }
  return out;
}

// Threads order k: each inner node's nearer child first, for rays going
// along axis k / 2 upwards (k even) or downwards (k odd).
void thread(const Numbered& n, int k, Bvh& bvh) {
  int axis = k / 2;
  bool downwards = k % 2;
  std::int32_t* links = &bvh.links[2 * static_cast<std::size_t>(k) * n.nodes.size()];
  std::vector<std::pair<std::int32_t, std::int32_t>> stack{{0, -1}};  // node, where to go after it
  while (!stack.empty()) {
    auto [node, next] = stack.back();
    stack.pop_back();
    auto at = static_cast<std::size_t>(node);
    links[2 * at + 1] = next;
    if (n.leaf_start[at] >= 0) {
      links[2 * at] = -n.leaf_start[at] - 2;
      continue;
    }
    std::int32_t near = n.child[at][0], far = n.child[at][1];
    float c_near = centre(n.nodes[static_cast<std::size_t>(near)]->box)[axis],
          c_far = centre(n.nodes[static_cast<std::size_t>(far)]->box)[axis];
    if (downwards ? c_far > c_near : c_far < c_near) std::swap(near, far);
    links[2 * at] = near;
    stack.push_back({far, next});
    stack.push_back({near, far});
  }
}

// Inner nodes numbered in depth-first order; each holds its children's
// boxes and references.
void pair(const Numbered& n, const std::vector<float>& lo, const std::vector<float>& hi, Bvh& bvh) {
  std::vector<std::int32_t> inner(n.nodes.size(), -1);
  std::int32_t count = 0;
  for (std::size_t i = 0; i < n.nodes.size(); ++i)
    if (n.leaf_start[i] < 0) inner[i] = count++;
  auto ref = [&](std::int32_t node) {
    auto at = static_cast<std::size_t>(node);
    return inner[at] >= 0 ? inner[at] : -n.leaf_start[at] - 2;
  };
  bvh.root = ref(0);
  for (std::size_t i = 0; i < n.nodes.size(); ++i) {
    if (inner[i] < 0) continue;
    for (std::int32_t child : n.child[i]) {
      auto at = 3 * static_cast<std::size_t>(child);
      bvh.pair_lo.insert(bvh.pair_lo.end(), lo.begin() + static_cast<long>(at), lo.begin() + static_cast<long>(at) + 3);
      bvh.pair_hi.insert(bvh.pair_hi.end(), hi.begin() + static_cast<long>(at), hi.begin() + static_cast<long>(at) + 3);
      bvh.children.push_back(ref(child));
    }
  }
}

// Wide nodes: each binary inner node's children, the largest inner one
// opened into its two until there are kBvhWidth, numbered depth-first.
class Widener {
 public:
  Widener(const Numbered& n, const std::vector<float>& lo, const std::vector<float>& hi, Bvh& bvh)
      : n_(n), lo_(lo), hi_(hi), bvh_(bvh) {}

  std::int32_t ref(std::int32_t node) {
    auto at = static_cast<std::size_t>(node);
    if (n_.leaf_start[at] >= 0) return -n_.leaf_start[at] - 2;
    std::vector<std::int32_t> kids(n_.child[at].begin(), n_.child[at].end());
    while (kids.size() < static_cast<std::size_t>(kBvhWidth)) {
      auto widest = kids.end();
      for (auto k = kids.begin(); k != kids.end(); ++k)
        if (n_.leaf_start[static_cast<std::size_t>(*k)] < 0 &&
            (widest == kids.end() || area(box(*k)) > area(box(*widest))))
          widest = k;
      if (widest == kids.end()) break;
      std::array<std::int32_t, 2> grandchildren = n_.child[static_cast<std::size_t>(*widest)];
      *widest = grandchildren[0];
      kids.push_back(grandchildren[1]);
    }
    auto wide = static_cast<std::int32_t>(bvh_.wide_children.size() / kBvhWidth);
    bvh_.wide_children.resize(bvh_.wide_children.size() + kBvhWidth, -1);
    bvh_.wide_box.resize(bvh_.wide_box.size() + 6 * kBvhWidth);
    bvh_.wide_order.push_back(order(kids));
    for (std::size_t slot = 0; slot < static_cast<std::size_t>(kBvhWidth); ++slot) {
      Box b = slot < kids.size() ? box(kids[slot]) : Box{};  // an empty slot's: its reference, -1, says so
      float* at_box = &bvh_.wide_box[6 * kBvhWidth * static_cast<std::size_t>(wide)];
      for (int c = 0; c < 3; ++c) {
        at_box[c * kBvhWidth + slot] = b.lo[c];
        at_box[(3 + c) * kBvhWidth + slot] = b.hi[c];
      }
    }
    for (std::size_t slot = 0; slot < kids.size(); ++slot) {
      std::int32_t r = ref(kids[slot]);  // numbers the subtree: wide_children may grow
      bvh_.wide_children[static_cast<std::size_t>(wide) * kBvhWidth + slot] = r;
    }
    return wide;
  }

 private:
  Box box(std::int32_t node) const {
    auto at = 3 * static_cast<std::size_t>(node);
    return {{lo_[at], lo_[at + 1], lo_[at + 2]}, {hi_[at], hi_[at + 1], hi_[at + 2]}};
  }

  // Per axis, the slots by their box's centre along it, lowest first.
  std::int32_t order(const std::vector<std::int32_t>& kids) const {
    std::int32_t packed = 0;
    for (int axis = 0; axis < 3; ++axis) {
      std::array<int, kBvhWidth> slots{};
      for (int k = 0; k < kBvhWidth; ++k) slots[static_cast<std::size_t>(k)] = k;
      auto centre_of = [&](int slot) {
        return slot < static_cast<int>(kids.size()) ? centre(box(kids[static_cast<std::size_t>(slot)]))[axis]
                                                    : std::numeric_limits<float>::infinity();
      };
      std::stable_sort(slots.begin(), slots.end(), [&](int a, int b) { return centre_of(a) < centre_of(b); });
      for (int j = 0; j < kBvhWidth; ++j) packed |= slots[static_cast<std::size_t>(j)] << (8 * axis + 2 * j);
    }
    return packed;
  }

  const Numbered& n_;
  const std::vector<float>& lo_;
  const std::vector<float>& hi_;
  Bvh& bvh_;
};

// The walks number nodes, their rows of boxes and links, and the lists'
// entries' corners (three an entry) in 32 bits: a tree past that would wrap
// (about 90 M triangles in the threaded walk, whose six orders of links
// take twelve numbers a node).
void check_numbers(const Numbered& n, BvhWalk walk) {
  std::size_t per_node = walk == BvhWalk::Threaded ? 2 * kBvhOrders : walk == BvhWalk::Stack ? 6 : 6 * kBvhWidth;
  std::size_t listed = 0;
  for (const Node* node : n.nodes) listed += node->triangles.size();
  constexpr std::size_t most = std::numeric_limits<std::int32_t>::max() - 2;
  if (n.nodes.size() > most / per_node || listed > most / 3)
    throw Error("BVH: " + std::to_string(n.nodes.size()) + " nodes and " + std::to_string(listed) +
                " list entries are more than its walk numbers in 32 bits; use fewer triangles, or --accel grid or octree");
}

}  // namespace

Bvh lay_out(const Node& root, BvhWalk walk) {
  Numbered n = number(root);
  check_numbers(n, walk);
  Bvh bvh;
  bvh.walk = walk;
  bvh.depth = n.depth;
  bvh.node_count = n.nodes.size();
  n.leaf_start.assign(n.nodes.size(), -1);
  std::vector<float> lo, hi;
  for (std::size_t i = 0; i < n.nodes.size(); ++i) {
    const Box& b = n.nodes[i]->box;
    // Widened for its own coordinates: a box near the origin of a scene
    // that reaches far away stays tight (the box test's rounding at any
    // distance is clip's to cover).
    Vec3 hair = overlap_hair(b, b.hi - b.lo);
    Vec3 low = b.lo - hair, high = b.hi + hair;
    lo.insert(lo.end(), {low.x, low.y, low.z});
    hi.insert(hi.end(), {high.x, high.y, high.z});
    if (!n.nodes[i]->leaf()) continue;
    n.leaf_start[i] = static_cast<std::int32_t>(bvh.triangles.size());
    bvh.triangles.insert(bvh.triangles.end(), n.nodes[i]->triangles.begin(), n.nodes[i]->triangles.end());
    bvh.triangles.back() = -bvh.triangles.back() - 1;  // a leaf lists at least one
  }
  if (walk == BvhWalk::Stack) {
    pair(n, lo, hi, bvh);
    return bvh;
  }
  if (walk == BvhWalk::Wide) {
    bvh.root = Widener(n, lo, hi, bvh).ref(0);
    return bvh;
  }
  bvh.lo = std::move(lo);
  bvh.hi = std::move(hi);
  bvh.links.resize(2 * kBvhOrders * n.nodes.size());
  for (int k = 0; k < kBvhOrders; ++k) thread(n, k, bvh);
  return bvh;
}

}  // namespace sh::rt::bvh
