// The binned SAH build (see bvh.hpp) into a tree of nodes, then laid out
// by bvh_layout.cpp.
#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "bvh_tree.hpp"
#include "sh/error.hpp"

namespace sh::rt::bvh {
namespace {

// Subtrees over more triangles than this are built as tasks of their own.
constexpr std::size_t kParallelBuild = 4096;

struct Bin {
  Box box = empty_box();
  std::size_t count = 0;
};

struct Split {
  int axis = -1, bin = 0;  // left: centroids in bins < bin
  double cost = 0;
};

class Builder {
 public:
  Builder(const std::vector<Vec3>& positions, BvhLimits limits) : limits_(limits), boxes_(positions.size() / 3) {
    ids_.resize(boxes_.size());
    std::iota(ids_.begin(), ids_.end(), 0);
    tbb::parallel_for(std::size_t{0}, boxes_.size(), [&](std::size_t t) {
      const Vec3* p = &positions[3 * t];
      boxes_[t] = {min(min(p[0], p[1]), p[2]), max(max(p[0], p[1]), p[2])};
    });
  }

  std::unique_ptr<Node> build(std::size_t begin, std::size_t end, int depth) {
    auto node = std::make_unique<Node>();
    Box centres = empty_box();
    for (std::size_t i = begin; i < end; ++i) {
      node->box = merge(node->box, boxes_[ids_[i]]);
      centres = grow(centres, centre(boxes_[ids_[i]]));
    }
    std::size_t n = end - begin;
    Split split = depth < kBvhSahDepth ? best_split(begin, end, centres, area(node->box)) : Split{};
    bool small = n <= static_cast<std::size_t>(limits_.max_leaf);
    if (small && (split.axis < 0 || split.cost >= static_cast<double>(n))) {
      node->triangles.assign(ids_.begin() + static_cast<long>(begin), ids_.begin() + static_cast<long>(end));
      std::sort(node->triangles.begin(), node->triangles.end());
      return node;
    }
    std::size_t middle = split.axis >= 0 ? partition(begin, end, split, centres) : halve(begin, end, centres);
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
  static int bin_of(float c, float lo, float extent) {
    return std::clamp(static_cast<int>(static_cast<double>(c - lo) / extent * kBvhBins), 0, kBvhBins - 1);
  }

  // The SAH split of least cost over the binned centroids, relative to the
  // cost of testing one triangle: 1 for the box test plus each side's
  // triangles weighted by the chance (its area over the node's) a ray that
  // meets the node meets it.  None (axis -1) where the centroids coincide.
  Split best_split(std::size_t begin, std::size_t end, const Box& centres, double node_area) const {
    Split best;
    for (int axis = 0; axis < 3; ++axis) {
      float lo = centres.lo[axis], extent = centres.hi[axis] - centres.lo[axis];
      if (!(extent > 0)) continue;
      Bin bins[kBvhBins];
      for (std::size_t i = begin; i < end; ++i) {
        const Box& b = boxes_[ids_[i]];
        Bin& bin = bins[bin_of(centre(b)[axis], lo, extent)];
        bin.box = merge(bin.box, b);
        ++bin.count;
      }
      // Right sides swept from the top, left sides from the bottom.
      double right_cost[kBvhBins] = {};
      Box right = empty_box();
      std::size_t right_count = 0;
      for (int k = kBvhBins - 1; k > 0; --k) {
        right = merge(right, bins[k].box);
        right_count += bins[k].count;
        right_cost[k] = right_count ? area(right) * static_cast<double>(right_count) : 0;
      }
      Box left = empty_box();
      std::size_t left_count = 0;
      for (int k = 1; k < kBvhBins; ++k) {
        left = merge(left, bins[k - 1].box);
        left_count += bins[k - 1].count;
        if (left_count == 0 || left_count == end - begin) continue;
        double cost = area(left) * static_cast<double>(left_count) + right_cost[k];
        if (best.axis < 0 || cost < best.cost) best = {axis, k, cost};
      }
    }
    // A flat node (every triangle in one plane) has no area: then every
    // ray that meets it meets both sides.
    if (best.axis >= 0) best.cost = node_area > 0 ? 1 + best.cost / node_area : static_cast<double>(end - begin) + 1;
    return best;
  }

  std::size_t partition(std::size_t begin, std::size_t end, const Split& s, const Box& centres) {
    float lo = centres.lo[s.axis], extent = centres.hi[s.axis] - centres.lo[s.axis];
    auto first = ids_.begin() + static_cast<long>(begin);
    auto middle = std::stable_partition(first, ids_.begin() + static_cast<long>(end), [&](std::int32_t t) {
      return bin_of(centre(boxes_[t])[s.axis], lo, extent) < s.bin;
    });
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
                       float ca = centre(boxes_[a])[axis], cb = centre(boxes_[b])[axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    return middle;
  }

  BvhLimits limits_;
  std::vector<Box> boxes_;
  std::vector<std::int32_t> ids_;
};

}  // namespace

Box empty_box() {
  constexpr float inf = std::numeric_limits<float>::infinity();
  return {{inf, inf, inf}, {-inf, -inf, -inf}};
}

Box merge(const Box& a, const Box& b) { return {min(a.lo, b.lo), max(a.hi, b.hi)}; }

Box grow(const Box& a, Vec3 p) { return {min(a.lo, p), max(a.hi, p)}; }

Vec3 centre(const Box& b) { return (b.lo + b.hi) * 0.5f; }

// In double: coordinates up to the tracer's 1e18 square beyond float.
double area(const Box& b) {
  if (!(b.lo.x <= b.hi.x)) return 0;
  double x = static_cast<double>(b.hi.x) - b.lo.x, y = static_cast<double>(b.hi.y) - b.lo.y,
         z = static_cast<double>(b.hi.z) - b.lo.z;
  return 2 * (x * y + y * z + z * x);
}

std::unique_ptr<Node> build_tree(const Scene& scene, BvhLimits limits) {
  if (limits.max_leaf < 1 || limits.max_leaf > kBvhMaxLeaf)
    throw Error("bvh: leaves of " + std::to_string(limits.max_leaf) + " triangles: must be 1.." +
                std::to_string(kBvhMaxLeaf));
  Builder b(scene.mesh.positions, limits);
  return b.build(0, b.triangles(), 0);
}

}  // namespace sh::rt::bvh

namespace sh::rt {

Bvh build_bvh(const Scene& scene, BvhLimits limits) {
  auto t0 = std::chrono::steady_clock::now();
  Box bounds = accelerator_bounds(scene);  // throws on a scene without triangles
  Bvh bvh = bvh::lay_out(*bvh::build_tree(scene, limits), bounds);
  bvh.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

}  // namespace sh::rt
