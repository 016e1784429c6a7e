// The binned SAH build (see bvh.hpp) into a tree of nodes, then laid out
// by bvh_layout.cpp.
#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include "bvh_tree.hpp"
#include "sh/error.hpp"

namespace sh::rt::bvh {
namespace {

// Subtrees over more triangles than this are built as tasks of their own.
constexpr std::size_t kParallelBuild = 4096;
// A node over more triangles than this bins them (and finds their box) in
// parallel too: the top levels would otherwise run on one thread.
constexpr std::size_t kParallelPass = 16384;

struct Bin {
  Box box = empty_box();
  std::size_t count = 0;
};

// Each axis's bins of a node's triangles, by centroid.
struct Bins {
  std::array<std::array<Bin, kBvhBins>, 3> axis;
  Bins& operator+=(const Bins& o) {
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < kBvhBins; ++k) {
        axis[a][k].box = merge(axis[a][k].box, o.axis[a][k].box);
        axis[a][k].count += o.axis[a][k].count;
      }
    return *this;
  }
};

// A node's triangles: the union of their boxes and the box of their centroids.
struct Span {
  Box box = empty_box(), centres = empty_box();
  Span& operator+=(const Span& o) {
    box = merge(box, o.box);
    centres = merge(centres, o.centres);
    return *this;
  }
};

struct Split {
  int axis = -1, bin = 0;  // left: centroids in bins < bin
  double cost = 0;
};

class Builder {
 public:
  Builder(const std::vector<Vec3>& positions, BvhSettings limits)
      : limits_(limits), boxes_(positions.size() / 3), centres_(boxes_.size()), ids_(boxes_.size()) {
    std::iota(ids_.begin(), ids_.end(), 0);
    tbb::parallel_for(std::size_t{0}, boxes_.size(), [&](std::size_t t) {
      const Vec3* p = &positions[3 * t];
      boxes_[t] = {min(min(p[0], p[1]), p[2]), max(max(p[0], p[1]), p[2])};
      centres_[t] = centre(boxes_[t]);
    });
  }

  std::unique_ptr<Node> build(std::size_t begin, std::size_t end, int depth) {
    auto node = std::make_unique<Node>();
    Span span = over_triangles<Span>(begin, end, [&](Span& s, std::int32_t t) {
      s.box = merge(s.box, boxes_[t]);
      s.centres = grow(s.centres, centres_[t]);
    });
    node->box = span.box;
    std::size_t n = end - begin;
    Split split = depth < kBvhSahDepth ? best_split(begin, end, span) : Split{};
    bool small = n <= static_cast<std::size_t>(limits_.max_leaf);
    if (small && (split.axis < 0 || split.cost >= static_cast<double>(n))) {
      node->triangles.assign(ids_.begin() + static_cast<long>(begin), ids_.begin() + static_cast<long>(end));
      std::sort(node->triangles.begin(), node->triangles.end());
      return node;
    }
    std::size_t middle = split.axis >= 0 ? partition(begin, end, split, span.centres) : halve(begin, end, span.centres);
    auto build_child = [&](int k) {
      node->child[k] = k == 0 ? build(begin, middle, depth + 1) : build(middle, end, depth + 1);
    };
    if (n > kParallelBuild)
      tbb::parallel_invoke([&] { build_child(0); }, [&] { build_child(1); });
    else
      build_child(0), build_child(1);
    return node;
  }

  std::size_t triangles() const { return ids_.size(); }

 private:
  // add(t) over the node's triangles into one T, in parallel chunks where
  // there are many.  Every T here adds by min, max and integer sums, so the
  // result does not depend on how the chunks fell.
  template <class T, class Add>
  T over_triangles(std::size_t begin, std::size_t end, Add add) const {
    auto run = [&](std::size_t from, std::size_t to, T t) {
      for (std::size_t i = from; i < to; ++i) add(t, ids_[i]);
      return t;
    };
    if (end - begin <= kParallelPass) return run(begin, end, T{});
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(begin, end, kParallelPass / 4), T{},
        [&](const tbb::blocked_range<std::size_t>& r, T t) { return run(r.begin(), r.end(), t); },
        [](T a, const T& b) { return a += b; });
  }

  // Bins per unit of an axis whose centroids span `extent` > 0: finite in
  // double for every positive float.
  static double bin_scale(float extent) { return kBvhBins / static_cast<double>(extent); }
  static int bin_of(float c, float lo, double scale) {
    return std::clamp(static_cast<int>(static_cast<double>(c - lo) * scale), 0, kBvhBins - 1);
  }

  // The SAH split of least cost over the binned centroids, relative to the
  // cost of testing one triangle: the node's cost plus each side's
  // triangles weighted by the chance (its area over the node's) a ray that
  // meets the node meets it.  None (axis -1) where the centroids coincide.
  // One pass bins every axis.
  Split best_split(std::size_t begin, std::size_t end, const Span& span) const {
    Vec3 lo = span.centres.lo, extent = span.centres.hi - span.centres.lo;
    std::array<double, 3> scale{};
    for (int axis = 0; axis < 3; ++axis) scale[axis] = extent[axis] > 0 ? bin_scale(extent[axis]) : 0;
    Bins bins = over_triangles<Bins>(begin, end, [&](Bins& b, std::int32_t t) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!(extent[axis] > 0)) continue;
        Bin& bin = b.axis[axis][bin_of(centres_[t][axis], lo[axis], scale[axis])];
        bin.box = merge(bin.box, boxes_[t]);
        ++bin.count;
      }
    });
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0)) continue;
      const std::array<Bin, kBvhBins>& bin = bins.axis[axis];
      // Right sides swept from the top, left sides from the bottom.
      double right_cost[kBvhBins] = {};
      Box right = empty_box();
      std::size_t right_count = 0;
      for (int k = kBvhBins - 1; k > 0; --k) {
        right = merge(right, bin[k].box);
        right_count += bin[k].count;
        right_cost[k] = right_count ? area(right) * static_cast<double>(right_count) : 0;
      }
      Box left = empty_box();
      std::size_t left_count = 0;
      for (int k = 1; k < kBvhBins; ++k) {
        left = merge(left, bin[k - 1].box);
        left_count += bin[k - 1].count;
        if (left_count == 0 || left_count == end - begin) continue;
        double cost = area(left) * static_cast<double>(left_count) + right_cost[k];
        if (best.axis < 0 || cost < best.cost) best = {axis, k, cost};
      }
    }
    // A flat node (every triangle in one plane) has no area: then every
    // ray that meets it meets both sides.
    double node_area = area(span.box);
    if (best.axis >= 0)
      best.cost = limits_.node_cost + (node_area > 0 ? best.cost / node_area : static_cast<double>(end - begin));
    return best;
  }

  // The children's sets, not their order, decide the tree (their boxes
  // up to the sign of a zero bound), so the partition need not be stable.
  std::size_t partition(std::size_t begin, std::size_t end, const Split& s, const Box& centres) {
    float lo = centres.lo[s.axis];
    double scale = bin_scale(centres.hi[s.axis] - lo);
    auto middle = std::partition(ids_.begin() + static_cast<long>(begin), ids_.begin() + static_cast<long>(end),
                                 [&](std::int32_t t) { return bin_of(centres_[t][s.axis], lo, scale) < s.bin; });
    return static_cast<std::size_t>(middle - ids_.begin());
  }

  // Halves by count along the widest centroid axis (ties by triangle
  // number, so the halves are the same on every run).
  std::size_t halve(std::size_t begin, std::size_t end, const Box& centres) {
    Vec3 extent = centres.hi - centres.lo;
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    std::size_t middle = begin + (end - begin) / 2;
    std::nth_element(ids_.begin() + static_cast<long>(begin), ids_.begin() + static_cast<long>(middle),
                     ids_.begin() + static_cast<long>(end), [&](std::int32_t a, std::int32_t b) {
                       float ca = centres_[a][axis], cb = centres_[b][axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    return middle;
  }

  BvhSettings limits_;
  std::vector<Box> boxes_;
  std::vector<Vec3> centres_;
  std::vector<std::int32_t> ids_;
};

}  // namespace

std::unique_ptr<Node> build_tree(const Scene& scene, BvhSettings limits) {
  if (limits.max_leaf < 1 || limits.max_leaf > kBvhMaxLeaf)
    throw Error("bvh: leaves of " + std::to_string(limits.max_leaf) + " triangles: must be 1.." +
                std::to_string(kBvhMaxLeaf));
  Builder b(scene.mesh.positions, limits);
  return b.build(0, b.triangles(), 0);
}

}  // namespace sh::rt::bvh

namespace sh::rt {

Bvh build_bvh(const Scene& scene, BvhSettings settings) {
  auto t0 = std::chrono::steady_clock::now();
  accelerator_bounds(scene);  // throws on a scene without triangles
  if (scene.mesh.triangles() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() - 2))
    throw Error("BVH: " + std::to_string(scene.mesh.triangles()) + " triangles are more than it numbers in 32 bits");
  settings.node_cost = sah_node_cost(settings, scene.mesh.triangles());
  Bvh bvh = bvh::lay_out(*bvh::build_tree(scene, settings), settings.walk);
  bvh.node_cost = settings.node_cost;
  bvh.corners.resize(9 * bvh.triangles.size());
  tbb::parallel_for(std::size_t{0}, bvh.triangles.size(), [&](std::size_t k) {
    const Vec3* corner = &scene.mesh.positions[3 * static_cast<std::size_t>(Bvh::listed(bvh.triangles[k]))];
    float* beside = &bvh.corners[9 * k];
    for (int c = 0; c < 3; ++c)
      for (int axis = 0; axis < 3; ++axis) *beside++ = corner[c][axis];
  });
  bvh.prefetch = bvh.bytes() > settings.prefetch_above;
  bvh.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

double sah_node_cost(const BvhSettings& s, std::size_t triangles) {
  if (!(s.node_cost >= 0 && s.node_cost <= kBvhMaxNodeCost))
    throw Error("bvh: node cost " + std::to_string(s.node_cost) + ": must be 0 (by the tree's size) or up to " +
                std::to_string(static_cast<int>(kBvhMaxNodeCost)) + " triangle tests");
  if (s.node_cost > 0) return s.node_cost;
  return triangles > kBvhLargeTree ? kBvhLargeTreeNodeCost : 1;
}

BvhWalk parse_bvh_walk(const std::string& name) {
  if (name == "threaded") return BvhWalk::Threaded;
  if (name == "stack") return BvhWalk::Stack;
  if (name == "wide") return BvhWalk::Wide;
  throw Error("unknown bvh walk '" + name + "' (threaded, stack or wide)");
}

const char* bvh_walk_name(BvhWalk w) {
  switch (w) {
    case BvhWalk::Threaded: return "threaded";
    case BvhWalk::Stack: return "stack";
    case BvhWalk::Wide: return "wide";
  }
  return "?";
}

}  // namespace sh::rt
