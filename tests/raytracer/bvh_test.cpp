// The BVH: every triangle in exactly one leaf, inside the leaf's box and
// every box above it; every threaded order a pre-order of the whole tree
// with the nearer child first; the stack and wide walks' layouts whole
// too; bounded on degenerate input (coincident,
// zero-area, huge and tiny coordinates); the same tree on one thread and
// on two; limits checked.  Its hits against Embree's are in
// intersector_test, extremes_test and bounded_build_test, its images
// against the grid's on every backend in octree_test.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <tbb/global_control.h>

#include "helpers.hpp"

namespace {

using sh::rt::Bvh;
using sh::rt::Vec3;

Vec3 corner(const std::vector<float>& v, std::size_t node) { return {v[3 * node], v[3 * node + 1], v[3 * node + 2]}; }

bool inside(Vec3 p, Vec3 lo, Vec3 hi) {
  return lo.x <= p.x && p.x <= hi.x && lo.y <= p.y && p.y <= hi.y && lo.z <= p.z && p.z <= hi.z;
}

// Walks order k meeting every box: visits each node once, in the order
// the links give, and checks what each node holds.
void expect_well_formed(const sh::rt::Scene& s, const Bvh& bvh, int max_leaf) {
  std::size_t n = s.mesh.triangles();
  ASSERT_GE(bvh.nodes(), 1u);
  ASSERT_EQ(bvh.links.size(), 2 * sh::rt::kBvhOrders * bvh.nodes());
  for (int k = 0; k < sh::rt::kBvhOrders; ++k) {
    std::vector<int> seen_node(bvh.nodes(), 0), seen_triangle(n, 0);
    std::vector<std::int32_t> path;  // the inner nodes above the current one
    std::size_t visits = 0;
    for (std::int32_t node = 0; node >= 0 && visits <= bvh.nodes(); ++visits) {
      auto at = static_cast<std::size_t>(node);
      ASSERT_LT(at, bvh.nodes());
      ++seen_node[at];
      std::int32_t hit = bvh.hit(k, at);
      if (hit <= -2) {
        int count = 0;
        for (std::size_t i = static_cast<std::size_t>(-hit - 2), more = 1; more; ++i, ++count) {
          more = !Bvh::ends_list(bvh.triangles.at(i));
          auto t = static_cast<std::size_t>(Bvh::listed(bvh.triangles[i]));
          ASSERT_LT(t, n);
          ++seen_triangle[t];
          for (int v = 0; v < 3; ++v)
            EXPECT_TRUE(inside(s.mesh.positions[3 * t + v], corner(bvh.lo, at), corner(bvh.hi, at)))
                << "triangle " << t << " outside leaf " << at;
        }
        EXPECT_GE(count, 1) << "empty leaf " << at;
        EXPECT_LE(count, max_leaf) << "leaf " << at;
        node = bvh.miss(k, at);
      } else {
        ASSERT_GE(hit, 0) << "node " << at << " order " << k;
        for (int c = 0; c < 3; ++c) {
          EXPECT_LE(bvh.lo[3 * at + c], bvh.lo[3 * static_cast<std::size_t>(hit) + c]);
          EXPECT_GE(bvh.hi[3 * at + c], bvh.hi[3 * static_cast<std::size_t>(hit) + c]);
        }
        node = hit;
      }
    }
    for (std::size_t i = 0; i < bvh.nodes(); ++i) ASSERT_EQ(seen_node[i], 1) << "node " << i << " in order " << k;
    for (std::size_t t = 0; t < n; ++t) ASSERT_EQ(seen_triangle[t], 1) << "triangle " << t << " in order " << k;
    EXPECT_EQ(bvh.miss(k, 0), -1) << "a ray that misses the root is done";
  }
}

// Order k visits, of an inner node's two children, first the one whose
// box's centre lies further back along its axis and direction.
void expect_nearer_child_first(const Bvh& bvh) {
  for (int k = 0; k < sh::rt::kBvhOrders; ++k)
    for (std::size_t node = 0; node < bvh.nodes(); ++node) {
      std::int32_t first = bvh.hit(k, node);
      if (first < 0) continue;
      auto a = static_cast<std::size_t>(first), b = static_cast<std::size_t>(bvh.miss(k, a));
      int axis = k / 2;
      float ca = bvh.lo[3 * a + axis] + bvh.hi[3 * a + axis], cb = bvh.lo[3 * b + axis] + bvh.hi[3 * b + axis];
      float slack = 1e-5f * (std::fabs(ca) + std::fabs(cb));  // the hair the boxes were widened by
      if (k % 2)
        EXPECT_GE(ca + slack, cb) << "node " << node << " order " << k;
      else
        EXPECT_LE(ca - slack, cb) << "node " << node << " order " << k;
    }
}

sh::rt::Scene triangles(const std::vector<Vec3>& positions) {
  sh::rt::Scene s;
  s.name = "triangles";
  s.materials.push_back({});
  s.mesh.positions = positions;
  s.mesh.material.assign(s.mesh.triangles(), 0);
  s.mesh.normals.assign(positions.size(), Vec3{0, 0, 1});
  return s;
}

const sh::rt::BvhSettings kThreaded{.walk = sh::rt::BvhWalk::Threaded};

std::size_t ceil_log2(std::size_t n) {
  std::size_t k = 0;
  while ((std::size_t{1} << k) < n) ++k;
  return k;
}

TEST(Bvh, EveryTriangleIsInOneLeafInsideEveryBoxAboveIt) {
  for (std::string name : {"cornell", "spheres", "procedural"}) {
    sh::rt::Scene s = name == "procedural" ? sh::rt::builtin_scene(name, 20000) : sh::rt::builtin_scene(name);
    Bvh bvh = sh::rt::build_bvh(s, kThreaded);
    SCOPED_TRACE(name);
    expect_well_formed(s, bvh, sh::rt::BvhSettings{}.max_leaf);
    expect_nearer_child_first(bvh);
  }
}

// A layout of references (>= 0 a node, <= -2 a leaf's list), walked from
// the root's: every node is reached once, no deeper than the binary tree
// (a walk's stack is sized by it), and every triangle lies in one leaf of
// at most max_leaf, inside the box its parent gives it.  `node(at, lo,
// hi, push)` checks node `at`, whose box is [lo, hi], and pushes each child
// with its box: push(reference, lo, hi).
struct Child {
  std::int32_t ref;
  Vec3 lo, hi;
};
template <class CheckNode>
void expect_references_well_formed(const sh::rt::Scene& s, const Bvh& bvh, int max_leaf, std::size_t nodes,
                                   CheckNode node) {
  std::size_t n = s.mesh.triangles();
  ASSERT_EQ(bvh.corners.size(), 9 * bvh.triangles.size()) << "three corners beside each list entry";
  std::vector<int> seen_node(nodes, 0), seen_triangle(n, 0);
  constexpr float inf = std::numeric_limits<float>::infinity();
  std::vector<std::pair<Child, int>> todo{{{bvh.root, {-inf, -inf, -inf}, {inf, inf, inf}}, 0}};
  while (!todo.empty()) {
    auto [v, depth] = todo.back();
    todo.pop_back();
    EXPECT_LE(depth, bvh.depth);
    if (v.ref <= -2) {
      int count = 0;
      for (std::size_t i = static_cast<std::size_t>(-v.ref - 2), more = 1; more; ++i, ++count) {
        more = !Bvh::ends_list(bvh.triangles.at(i));
        auto t = static_cast<std::size_t>(Bvh::listed(bvh.triangles[i]));
        ASSERT_LT(t, n);
        ++seen_triangle[t];
        for (int k = 0; k < 3; ++k) {
          Vec3 p = s.mesh.positions[3 * t + k], beside = corner(bvh.corners, 3 * i + static_cast<std::size_t>(k));
          EXPECT_TRUE(inside(p, v.lo, v.hi)) << "triangle " << t;
          EXPECT_TRUE(p.x == beside.x && p.y == beside.y && p.z == beside.z) << "corner " << k << " of list entry " << i;
        }
      }
      EXPECT_GE(count, 1);
      EXPECT_LE(count, max_leaf);
      continue;
    }
    ASSERT_GE(v.ref, 0);
    auto at = static_cast<std::size_t>(v.ref);
    ASSERT_LT(at, nodes);
    ++seen_node[at];
    node(at, v.lo, v.hi, [&, d = depth](std::int32_t ref, Vec3 lo, Vec3 hi) { todo.push_back({{ref, lo, hi}, d + 1}); });
  }
  for (std::size_t i = 0; i < nodes; ++i) ASSERT_EQ(seen_node[i], 1) << "node " << i;
  for (std::size_t t = 0; t < n; ++t) ASSERT_EQ(seen_triangle[t], 1) << "triangle " << t;
}

// The stack walk's layout: inner nodes that hold their two children's
// boxes, each inside its parent's.  A single leaf's tree is its root.
void expect_pairs_well_formed(const sh::rt::Scene& s, const Bvh& bvh, int max_leaf) {
  std::size_t inner = bvh.children.size() / 2;
  ASSERT_EQ(bvh.pair_lo.size(), 6 * inner);
  ASSERT_EQ(bvh.pair_hi.size(), 6 * inner);
  EXPECT_TRUE(bvh.links.empty() && bvh.lo.empty()) << "the threaded layout is not kept beside";
  expect_references_well_formed(s, bvh, max_leaf, inner, [&](std::size_t at, Vec3 box_lo, Vec3 box_hi, auto push) {
    for (std::size_t c = 0; c < 2; ++c) {
      Vec3 lo = corner(bvh.pair_lo, 2 * at + c), hi = corner(bvh.pair_hi, 2 * at + c);
      EXPECT_TRUE(inside(lo, box_lo, box_hi) && inside(hi, box_lo, box_hi)) << "child " << c << " of " << at;
      push(bvh.children[2 * at + c], lo, hi);
    }
  });
}

TEST(Bvh, TheStackWalksLayoutHoldsEveryTriangleOnceUnderItsChildBoxes) {
  sh::rt::BvhSettings stack{.max_leaf = 8, .walk = sh::rt::BvhWalk::Stack};
  for (std::string name : {"cornell", "spheres", "procedural"}) {
    sh::rt::Scene s = name == "procedural" ? sh::rt::builtin_scene(name, 20000) : sh::rt::builtin_scene(name);
    SCOPED_TRACE(name);
    Bvh bvh = sh::rt::build_bvh(s, stack), threaded = sh::rt::build_bvh(s, kThreaded);
    expect_pairs_well_formed(s, bvh, stack.max_leaf);
    EXPECT_EQ(bvh.nodes(), threaded.nodes());
    EXPECT_EQ(bvh.children.size(), threaded.nodes() - 1) << "two children for each inner node, the root a child of none";
    EXPECT_EQ(bvh.depth, threaded.depth);
    EXPECT_LT(bvh.bytes(), threaded.bytes());
  }
  sh::rt::Scene one = triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  Bvh leaf = sh::rt::build_bvh(one, stack);
  EXPECT_EQ(leaf.root, -2) << "the tree is one leaf, listed from 0";
  expect_pairs_well_formed(one, leaf, stack.max_leaf);
  EXPECT_THROW(sh::rt::parse_bvh_walk("stackless"), sh::Error);
}

// The wide walk's layout: a node's filled slots come first, each child's
// box inside its parent's; each axis's order a permutation of the slots,
// by centre along the axis.
void expect_wide_well_formed(const sh::rt::Scene& s, const Bvh& bvh, int max_leaf) {
  constexpr int w = sh::rt::kBvhWidth;
  std::size_t nodes = bvh.wide_children.size() / w;
  ASSERT_EQ(bvh.wide_box.size(), 6 * w * nodes);
  ASSERT_EQ(bvh.wide_order.size(), nodes);
  expect_references_well_formed(s, bvh, max_leaf, nodes, [&](std::size_t at, Vec3 box_lo, Vec3 box_hi, auto push) {
    const float* rows = &bvh.wide_box[6 * w * at];
    int filled = 0;
    std::array<float, w> centre[3];
    for (int slot = 0; slot < w; ++slot) {
      std::int32_t child = bvh.wide_children[w * at + static_cast<std::size_t>(slot)];
      if (child == -1) continue;
      EXPECT_EQ(slot, filled++) << "filled slots first in node " << at;
      Vec3 lo{rows[0 * w + slot], rows[1 * w + slot], rows[2 * w + slot]};
      Vec3 hi{rows[3 * w + slot], rows[4 * w + slot], rows[5 * w + slot]};
      EXPECT_TRUE(inside(lo, box_lo, box_hi) && inside(hi, box_lo, box_hi)) << "slot " << slot << " of " << at;
      for (int a = 0; a < 3; ++a) centre[a][static_cast<std::size_t>(slot)] = lo[a] + hi[a];
      push(child, lo, hi);
    }
    EXPECT_GE(filled, 2) << "node " << at;
    for (int a = 0; a < 3; ++a) {
      std::set<int> slots;
      float last = -std::numeric_limits<float>::infinity();
      for (int j = 0; j < w; ++j) {
        int slot = (bvh.wide_order[at] >> (8 * a + 2 * j)) & 3;
        slots.insert(slot);
        if (slot >= filled) continue;
        EXPECT_LE(last, centre[a][static_cast<std::size_t>(slot)]) << "axis " << a << " of node " << at;
        last = centre[a][static_cast<std::size_t>(slot)];
      }
      EXPECT_EQ(slots.size(), static_cast<std::size_t>(w)) << "axis " << a << " of node " << at;
    }
  });
}

TEST(Bvh, TheWideWalksNodesHoldEveryTriangleOnceUnderTheirChildren) {
  sh::rt::BvhSettings wide{.max_leaf = 8, .walk = sh::rt::BvhWalk::Wide};
  for (std::string name : {"cornell", "spheres", "procedural"}) {
    sh::rt::Scene s = name == "procedural" ? sh::rt::builtin_scene(name, 20000) : sh::rt::builtin_scene(name);
    SCOPED_TRACE(name);
    Bvh bvh = sh::rt::build_bvh(s, wide), binary = sh::rt::build_bvh(s, kThreaded);
    expect_wide_well_formed(s, bvh, wide.max_leaf);
    std::size_t inner = (binary.nodes() - 1) / 2, nodes = bvh.wide_children.size() / sh::rt::kBvhWidth;
    EXPECT_LT(nodes, inner * 2 / 3) << "four children a node, mostly";
    EXPECT_LT(bvh.bytes(), binary.bytes());
  }
  sh::rt::Scene one = triangles({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  Bvh leaf = sh::rt::build_bvh(one, wide);
  EXPECT_EQ(leaf.root, -2);
  expect_wide_well_formed(one, leaf, wide.max_leaf);
}

// A node weighed at more triangle tests makes fewer nodes and fuller
// leaves, still within the limit, in every layout.
TEST(Bvh, ACostlierNodeMakesFewerFullerLeaves) {
  sh::rt::Scene s = sh::rt::builtin_scene("procedural", 20000);
  sh::rt::BvhSettings cheap{.walk = sh::rt::BvhWalk::Wide, .node_cost = 1},
      costly{.walk = sh::rt::BvhWalk::Wide, .node_cost = sh::rt::kBvhLargeTreeNodeCost};
  Bvh light = sh::rt::build_bvh(s, cheap), heavy = sh::rt::build_bvh(s, costly);
  expect_wide_well_formed(s, heavy, costly.max_leaf);
  EXPECT_EQ(light.node_cost, 1);
  EXPECT_EQ(heavy.node_cost, sh::rt::kBvhLargeTreeNodeCost);
  EXPECT_LT(heavy.wide_children.size(), light.wide_children.size() * 9 / 10);
  EXPECT_LT(heavy.bytes(), light.bytes());
  costly.walk = sh::rt::BvhWalk::Threaded;
  expect_well_formed(s, sh::rt::build_bvh(s, costly), costly.max_leaf);
  costly.walk = sh::rt::BvhWalk::Stack;
  expect_pairs_well_formed(s, sh::rt::build_bvh(s, costly), costly.max_leaf);
}

// Left 0, the node cost follows the tree's size; a cost outside the range
// (NaN too) is an error that names it.
TEST(Bvh, TheNodeCostByTheTreesSizeOrAsSet) {
  EXPECT_EQ(sh::rt::sah_node_cost({}, 1), 1);
  EXPECT_EQ(sh::rt::sah_node_cost({}, sh::rt::kBvhLargeTree), 1);
  EXPECT_EQ(sh::rt::sah_node_cost({}, sh::rt::kBvhLargeTree + 1), sh::rt::kBvhLargeTreeNodeCost);
  EXPECT_EQ(sh::rt::sah_node_cost({.node_cost = 2}, sh::rt::kBvhLargeTree + 1), 2);
  EXPECT_EQ(sh::rt::sah_node_cost({.node_cost = 0.5}, 1), 0.5);
  sh::rt::Scene s = sh::rt::builtin_scene("cornell");
  for (double bad : {-1.0, sh::rt::kBvhMaxNodeCost + 1, std::nan("")}) {
    try {
      sh::rt::build_bvh(s, {.node_cost = bad});
      ADD_FAILURE() << "node cost " << bad << " accepted";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find("node cost"), std::string::npos) << e.what();
    }
  }
}

// The tree in every walk's layout, each checked; gives the threaded one.
Bvh expect_layouts_well_formed(const sh::rt::Scene& s, int max_leaf = sh::rt::BvhSettings{}.max_leaf) {
  Bvh threaded = sh::rt::build_bvh(s, {max_leaf, sh::rt::BvhWalk::Threaded});
  expect_well_formed(s, threaded, max_leaf);
  expect_pairs_well_formed(s, sh::rt::build_bvh(s, {max_leaf, sh::rt::BvhWalk::Stack}), max_leaf);
  expect_wide_well_formed(s, sh::rt::build_bvh(s, {max_leaf, sh::rt::BvhWalk::Wide}), max_leaf);
  return threaded;
}

TEST(Bvh, LeafSizeLimitsFromOneToTheLargest) {
  sh::rt::Scene s = sh::rt::builtin_scene("spheres");
  for (int leaf : {1, 2, 8, sh::rt::kBvhMaxLeaf}) {
    SCOPED_TRACE(leaf);
    expect_layouts_well_formed(s, leaf);
  }
  for (int bad : {0, sh::rt::kBvhMaxLeaf + 1}) {
    try {
      sh::rt::build_bvh(s, {bad});
      ADD_FAILURE() << "leaves of " << bad << " accepted";
    } catch (const sh::Error& e) {
      EXPECT_NE(std::string(e.what()).find("leaves of " + std::to_string(bad)), std::string::npos) << e.what();
    }
  }
}

// No plane separates coincident triangles: they are halved by count, so
// the depth is that of a balanced tree and every leaf is within its limit.
TEST(Bvh, CoincidentTrianglesMakeABalancedTree) {
  std::vector<Vec3> p;
  for (int i = 0; i < 5000; ++i) p.insert(p.end(), {{0, 0, 0}, {1, 0.2f, 0.1f}, {0.3f, 1, 0.7f}});
  sh::rt::Scene s = triangles(p);
  Bvh bvh = expect_layouts_well_formed(s);
  EXPECT_LE(static_cast<std::size_t>(bvh.depth), ceil_log2(s.mesh.triangles()));
}

// Triangles of no area (points and segments), some at one point: built,
// bounded, every one listed.
TEST(Bvh, ZeroAreaTrianglesAreListed) {
  std::vector<Vec3> p;
  for (int i = 0; i < 3000; ++i) {
    float x = static_cast<float>(i % 7);
    p.insert(p.end(), {{x, 0, 0}, {x, 0, 0}, {x, 0, 0}});
    p.insert(p.end(), {{0, x, 0}, {0, 2 * x, 0}, {0, 3 * x, 0}});
  }
  sh::rt::Scene s = triangles(p);
  Bvh bvh = expect_layouts_well_formed(s);
  EXPECT_LE(static_cast<std::size_t>(bvh.depth), sh::rt::kBvhSahDepth + ceil_log2(s.mesh.triangles()));
}

// Coordinates near the tracer's limit and near float's smallest normal
// numbers: areas are taken in double, so the SAH still separates the
// triangles, and the tree is the unscaled one's.
TEST(Bvh, HugeAndTinyCoordinatesBuildTheUnscaledTree) {
  sh::rt::Scene base = sh::rt::builtin_scene("spheres");
  Bvh unscaled = sh::rt::build_bvh(base, kThreaded);
  for (float scale : {1e17f, 1e-25f}) {
    sh::rt::Scene s = base;
    for (Vec3& v : s.mesh.positions) v = v * scale;
    SCOPED_TRACE(scale);
    Bvh bvh = expect_layouts_well_formed(s);
    EXPECT_NEAR(static_cast<double>(bvh.nodes()), static_cast<double>(unscaled.nodes()), 0.02 * unscaled.nodes());
  }
}

// Random triangles of every size up to the scene's, many overlapping.
TEST(Bvh, ASoupOfLargeAndSmallTriangles) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Vec3> p;
  for (int i = 0; i < 20000; ++i) {
    float size = std::pow(10.0f, 3 * u(rng) - 1);
    Vec3 at{u(rng), u(rng), u(rng)};
    for (int v = 0; v < 3; ++v) p.push_back(at + Vec3{u(rng), u(rng), u(rng)} * size);
  }
  sh::rt::Scene s = triangles(p);
  Bvh bvh = expect_layouts_well_formed(s);
  EXPECT_LE(static_cast<std::size_t>(bvh.depth), sh::rt::kBvhSahDepth + ceil_log2(s.mesh.triangles()));
}

// A unit sphere at the origin and a quad 1e7 away: the boxes of the
// sphere's nodes are widened for their own coordinates, not the scene's
// (which widened each by about 5, so that every ray met every leaf).
TEST(Bvh, BoxesAreWidenedForTheirOwnCoordinates) {
  sh::rt::Scene s;
  s.materials.push_back({});
  sh::rt::add_sphere(s, {0, 0, 0}, 1, 0, 64);
  sh::rt::add_quad(s, {1e7f, 0, 0}, {0, 0, 16}, {0, 16, 0}, 0);
  Bvh bvh = sh::rt::build_bvh(s, kThreaded);
  std::size_t near_origin = 0;
  for (std::size_t n = 0; n < bvh.nodes(); ++n) {
    float hi_x = bvh.hi[3 * n];
    if (hi_x > 100) continue;  // holds the quad
    ++near_origin;
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(bvh.lo[3 * n + a], -1.01f) << "node " << n;
      EXPECT_LE(bvh.hi[3 * n + a], 1.01f) << "node " << n;
    }
  }
  EXPECT_GT(near_origin, 100u);
}

TEST(Bvh, TheSameTreeOnOneThreadAndOnTwo) {
  sh::rt::Scene s = sh::rt::builtin_scene("procedural", 30000);
  Bvh one;
  {
    tbb::global_control only(tbb::global_control::max_allowed_parallelism, 1);
    one = sh::rt::build_bvh(s, kThreaded);
  }
  tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
  Bvh both = sh::rt::build_bvh(s, kThreaded);
  EXPECT_EQ(one.lo, both.lo);
  EXPECT_EQ(one.hi, both.hi);
  EXPECT_EQ(one.links, both.links);
  EXPECT_EQ(one.triangles, both.triangles);
}

// auto builds the BVH where the backend's lanes walk it together; where
// each element runs alone, the grid where the triangles fill the box evenly
// (procedural's soup) and the BVH where they leave most of it empty.  The
// renderer asks the backend and says what it chose from.
TEST(AutoAccelerator, TheBvhInLanesAndAloneTheGridForAnEvenSoup) {
  EXPECT_EQ(sh::rt::parse_accel("auto"), sh::rt::Accel::Auto);
  sh::rt::Scene soup = sh::rt::builtin_scene("procedural", 20000);
  EXPECT_GE(sh::rt::filled_share(soup), 0.5);
  EXPECT_EQ(sh::rt::choose_accel(sh::rt::filled_share(soup), 1), sh::rt::Accel::Grid);
  EXPECT_EQ(sh::rt::choose_accel(sh::rt::filled_share(soup), 8), sh::rt::Accel::Bvh);
  for (std::string name : {"cornell", "spheres", "soft", "magg-glass"}) {
    sh::rt::Scene s = sh::rt::builtin_scene(name);
    EXPECT_LT(sh::rt::filled_share(s), 0.5) << name;
    for (int lanes : {1, 16}) EXPECT_EQ(sh::rt::choose_accel(sh::rt::filled_share(s), lanes), sh::rt::Accel::Bvh) << name;
  }
  auto chosen = [&](const std::string& backend, const std::string& width) {
    sh::rt::RenderSettings settings;
    settings.accel = sh::rt::Accel::Auto;
    settings.backend = backend;
    if (!width.empty()) settings.options.set("cpu.width", width);
    sh::rt::Renderer r(soup, settings);
    EXPECT_NE(r.describe_accelerator().find("auto: the backend runs"), std::string::npos) << r.describe_accelerator();
    return r.accel();
  };
  EXPECT_EQ(chosen("interp", ""), sh::rt::Accel::Grid);
  EXPECT_EQ(chosen("cpu", "scalar"), sh::rt::Accel::Grid);
  EXPECT_EQ(chosen("cpu", "8"), sh::rt::Accel::Bvh);
  EXPECT_EQ(chosen("opencl", ""), sh::lanes_of(sh::backend("opencl")) > 1 ? sh::rt::Accel::Bvh : sh::rt::Accel::Grid);
}

// A tree that is one leaf has no inner node: every walk starts at the leaf
// (fuzz_models found a render refused for the wide walk's unfilled table).
TEST(Bvh, EveryWalkOfATreeThatIsOneLeaf) {
  sh::rt::Scene one = triangles({{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}});
  for (sh::rt::BvhWalk walk : {sh::rt::BvhWalk::Threaded, sh::rt::BvhWalk::Stack, sh::rt::BvhWalk::Wide}) {
    SCOPED_TRACE(sh::rt::bvh_walk_name(walk));
    rt_test::Rays rays;
    rays.add({0, 0, 5}, {0, 0, -1});
    rays.add({3, 0, 5}, {0, 0, -1});
    for (const std::string& backend : rt_test::every_backend()) {
      sh::rt::Hits hits = rt_test::trace(one, rays, backend, rt_test::Walked(sh::rt::Accel::Bvh, walk));
      EXPECT_FLOAT_EQ(hits.t[0], 5.0f) << backend;
      EXPECT_LT(hits.t[1], 0.0f) << backend;
    }
  }
}

TEST(Bvh, ASceneWithoutTrianglesIsAnError) {
  sh::rt::Scene s = triangles({});
  EXPECT_THROW(sh::rt::build_bvh(s), sh::Error);
}

// The walks' lane counts (threaded and wide): a ray alone reaches only the
// leaves its own box tests meet, and so does every ray of a backend that
// runs each alone, with the same counts; rays side by side test leaves
// their neighbours met.
TEST(BvhWalkLanes, AloneEveryLeafIsTheRaysOwnSideBySideNot) {
  sh::rt::Scene scene = sh::rt::builtin_scene("spheres");
  std::vector<float> origins, directions, limits;
  for (int i = 0; i < 400; ++i) {
    float a = 0.011f * static_cast<float>(i), b = 0.007f * static_cast<float>(i % 37);
    origins.insert(origins.end(), {0.0f, 1.0f, 8.0f});
    Vec3 d = sh::rt::normalize(Vec3{std::sin(a) * 0.4f, b * 0.3f - 0.3f, -1.0f});
    directions.insert(directions.end(), {d.x, d.y, d.z});
    limits.push_back(sh::rt::kFar);
  }
  sh::Options scalar;
  scalar.set("cpu.width", "scalar");
  sh::rt::RenderSettings settings;
  settings.accel = sh::rt::Accel::Bvh;
  for (auto [walk, any_hit] : {std::pair{sh::rt::BvhWalk::Threaded, false}, std::pair{sh::rt::BvhWalk::Threaded, true},
                               std::pair{sh::rt::BvhWalk::Wide, false}, std::pair{sh::rt::BvhWalk::Wide, true}}) {
    settings.bvh.walk = walk;
    sh::rt::Renderer r(scene, settings);
    SCOPED_TRACE(sh::rt::bvh_walk_name(walk));
    sh::rt::WalkLanes alone = r.walk_lanes(origins, directions, limits, any_hit, sh::backend("interp"));
    ASSERT_GT(alone.leaves, 0) << any_hit;
    EXPECT_EQ(alone.own_leaves, alone.leaves) << any_hit;
    EXPECT_LT(alone.met, alone.steps) << any_hit << ": boxes missed are steps too";
    sh::rt::WalkLanes cpu_alone = r.walk_lanes(origins, directions, limits, any_hit, sh::backend("cpu", scalar));
    EXPECT_EQ(cpu_alone.steps, alone.steps) << any_hit;
    EXPECT_EQ(cpu_alone.met, alone.met) << any_hit;
    EXPECT_EQ(cpu_alone.leaves, alone.leaves) << any_hit;
    EXPECT_EQ(cpu_alone.own_leaves, cpu_alone.leaves) << any_hit;
    sh::Options lanes;
    lanes.set("cpu.width", "16");
    sh::rt::WalkLanes together = r.walk_lanes(origins, directions, limits, any_hit, sh::backend("cpu", lanes));
    EXPECT_LT(together.own_leaves, together.leaves) << any_hit;
    EXPECT_GT(together.steps, alone.steps) << any_hit << ": boxes a neighbour met are steps too";
    EXPECT_GT(together.leaves, alone.leaves) << any_hit << ": neighbours' leaves are tested too";
  }
  settings.bvh.walk = sh::rt::BvhWalk::Stack;
  sh::rt::Renderer stack(scene, settings);
  EXPECT_THROW(stack.walk_lanes(origins, directions, limits, false, sh::backend("interp")), sh::Error);
  settings.accel = sh::rt::Accel::Grid;
  sh::rt::Renderer grid(scene, settings);
  EXPECT_THROW(grid.walk_lanes(origins, directions, limits, false, sh::backend("interp")), sh::Error);
}

}  // namespace
