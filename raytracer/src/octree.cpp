#include "sh/raytracer/octree.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "sh/error.hpp"

namespace sh::rt {

Octree::Octree(std::vector<Vec3> positions, Box bounds, OctreeLimits limits)
    : positions_(std::move(positions)), bounds_(bounds), limits_(limits) {
  auto t0 = std::chrono::steady_clock::now();
  if (limits_.max_depth < 0 || limits_.max_depth > kMaxOctreeDepth)
    throw Error("octree depth limit must be 0.." + std::to_string(kMaxOctreeDepth) + ", got " +
                std::to_string(limits_.max_depth));
  if (limits_.leaf_size < 1) throw Error("octree leaf size must be at least 1, got " + std::to_string(limits_.leaf_size));
  std::vector<std::int32_t> all(positions_.size() / 3);
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<std::int32_t>(t);
  nodes_.push_back(0);
  triangles_.push_back(-1);  // a table is never empty
  nodes_[0] = settle(Place{}, all, 0);
  build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Over the cube that holds the scene's box: halving a flat box would cut
// its thin side into slices thinner than the triangles.
Octree Octree::lazy(const Scene& scene, OctreeLimits limits) {
  Box b = accelerator_bounds(scene);
  Vec3 extent = b.hi - b.lo;
  float side = std::max({extent.x, extent.y, extent.z});
  return Octree(scene.mesh.positions, Box{b.lo, b.lo + Vec3{side, side, side}}, limits);
}

Octree Octree::full(const Scene& scene, OctreeLimits limits) {
  Octree tree = lazy(scene, limits);
  tree.build_everything();
  return tree;
}

Vec3 Octree::finest_cell() const {
  float n = static_cast<float>(resolution());
  Vec3 extent = bounds_.hi - bounds_.lo;
  return {extent.x / n, extent.y / n, extent.z / n};
}

Octree::Place Octree::child(Place parent, int which) const {
  int half = resolution() >> (parent.level + 1);
  Place c{parent.level + 1, parent.corner};
  for (int a = 0; a < 3; ++a) c.corner[a] += (which >> a & 1) * half;
  return c;
}

// Level in the top bits, then x, y and z in kMaxOctreeDepth bits each.
constexpr std::uint64_t kField = (1u << kMaxOctreeDepth) - 1;

std::uint64_t Octree::key(Place p) {
  auto field = [](int v) { return static_cast<std::uint64_t>(v) & kField; };
  return static_cast<std::uint64_t>(p.level) << 57 | field(p.corner[0]) << 38 | field(p.corner[1]) << 19 | field(p.corner[2]);
}

Octree::Place Octree::place(std::uint64_t key) {
  auto field = [&](int shift) { return static_cast<int>(key >> shift & kField); };
  return Place{static_cast<int>(key >> 57), {field(38), field(19), field(0)}};
}

Box Octree::box(Place p) const {
  Vec3 fine = finest_cell();
  float size = static_cast<float>(resolution() >> p.level);
  return {bounds_.lo + Vec3{p.corner[0] * fine.x, p.corner[1] * fine.y, p.corner[2] * fine.z},
          bounds_.lo + Vec3{(p.corner[0] + size) * fine.x, (p.corner[1] + size) * fine.y, (p.corner[2] + size) * fine.z}};
}

Box Octree::box_of(std::uint64_t key) const { return box(place(key)); }

// The candidates of each child: the node's triangles that overlap the
// child's box (as the kernels compute it, widened by a hair).
Octree::Children Octree::split(const Pending& node) const {
  Children lists;
  Box boxes[8];
  for (int c = 0; c < 8; ++c) {
    boxes[c] = box(child(node.place, c));
    Vec3 hair = overlap_hair(bounds_, boxes[c].hi - boxes[c].lo);
    boxes[c] = {boxes[c].lo - hair, boxes[c].hi + hair};
  }
  auto sort_into_children = [&](std::int32_t t) {
    Vec3 a = positions_[3 * t], b = positions_[3 * t + 1], c = positions_[3 * t + 2];
    Vec3 lo = min(min(a, b), c), hi = max(max(a, b), c);
    for (int k = 0; k < 8; ++k) {
      // The triangle's bounds alone decide most cases: apart, or inside.
      const Box& x = boxes[k];
      bool apart = lo.x > x.hi.x || lo.y > x.hi.y || lo.z > x.hi.z || hi.x < x.lo.x || hi.y < x.lo.y || hi.z < x.lo.z;
      bool inside = lo.x >= x.lo.x && lo.y >= x.lo.y && lo.z >= x.lo.z && hi.x <= x.hi.x && hi.y <= x.hi.y && hi.z <= x.hi.z;
      if (inside || (!apart && triangle_overlaps_box(a, b, c, x.lo, x.hi))) lists[k].push_back(t);
    }
  };
  for (Run run : node.candidates)
    for (std::int32_t t = run.first; t < run.first + run.count; ++t) sort_into_children(t);
  return lists;
}

// Node `index` at `place` with these triangles (ascending): an empty leaf,
// a leaf (at the depth limit or small enough), or an unbuilt node that
// keeps them as runs.
std::int32_t Octree::settle(Place place, const std::vector<std::int32_t>& list, std::int32_t index) {
  if (list.empty()) return -1;
  if (place.level == limits_.max_depth || list.size() <= static_cast<std::size_t>(limits_.leaf_size)) {
    auto start = static_cast<std::int32_t>(triangles_.size());
    triangles_.insert(triangles_.end(), list.begin(), list.end());
    triangles_.push_back(-1);
    return -start - 2;
  }
  Pending& p = pending_[index];
  p.place = place;
  for (std::int32_t t : list)
    if (!p.candidates.empty() && p.candidates.back().first + p.candidates.back().count == t)
      ++p.candidates.back().count;
    else
      p.candidates.push_back({t, 1});
  p.candidates.shrink_to_fit();
  return 0;
}

std::size_t Octree::build(const std::vector<std::int32_t>& requested) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::int32_t> todo;
  for (std::int32_t n : requested)
    if (pending_.count(n)) todo.push_back(n);
  std::sort(todo.begin(), todo.end());
  todo.erase(std::unique(todo.begin(), todo.end()), todo.end());
  // Splitting is the work and runs in parallel; placing children is a
  // sequential append.
  std::vector<Children> children(todo.size());
  tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t i) { children[i] = split(pending_.at(todo[i])); });
  if (nodes_.size() + 8 * todo.size() > static_cast<std::size_t>(INT32_MAX) ||
      triangles_.size() > static_cast<std::size_t>(INT32_MAX) / 2)
    throw Error("octree: more than 2^31 nodes or listed triangles; lower the depth limit or raise the leaf size");
  for (std::size_t i = 0; i < todo.size(); ++i) {
    Place place = pending_.at(todo[i]).place;
    pending_.erase(todo[i]);
    auto first = static_cast<std::int32_t>(nodes_.size());
    nodes_.resize(nodes_.size() + 8);
    for (int c = 0; c < 8; ++c) nodes_[first + c] = settle(child(place, c), children[i][c], first + c);
    nodes_[todo[i]] = first;
    built_keys_.push_back(key(place));
  }
  if (pending_.bucket_count() > 4 * pending_.size() + 16) pending_.rehash(0);  // give back what the map grew to
  build_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return todo.size();
}

std::size_t Octree::build_towards(const std::vector<std::int32_t>& requests) {
  struct Walk {
    std::int32_t node;
    std::array<int, 3> cell;
  };
  std::vector<Walk> walks;
  for (std::size_t i = 0; i + 3 < requests.size(); i += 4)
    walks.push_back({requests[i], {requests[i + 1], requests[i + 2], requests[i + 3]}});
  std::size_t built = 0;
  // Level by level: each round builds one node per walk, in parallel.
  while (!walks.empty()) {
    std::vector<std::int32_t> level;
    std::vector<Walk> going_on;
    std::vector<Place> places;
    for (const Walk& w : walks)
      if (auto it = pending_.find(w.node); it != pending_.end()) {
        level.push_back(w.node);
        going_on.push_back(w);
        places.push_back(it->second.place);
      }
    built += build(level);
    walks.clear();
    for (std::size_t i = 0; i < going_on.size(); ++i) {
      int half = resolution() >> (places[i].level + 1), which = 0;
      for (int a = 0; a < 3; ++a) which |= (going_on[i].cell[a] >= places[i].corner[a] + half) << a;
      std::int32_t next = nodes_[going_on[i].node] + which;
      if (nodes_[next] == 0) walks.push_back({next, going_on[i].cell});
    }
  }
  return built;
}

void Octree::build_everything() {
  for (std::vector<std::int32_t> level = unbuilt(); !level.empty(); level = unbuilt()) build(level);
}

std::vector<std::int32_t> Octree::unbuilt() const {
  std::vector<std::int32_t> out;
  out.reserve(pending_.size());
  for (const auto& [index, p] : pending_) out.push_back(index);
  return out;
}

std::size_t Octree::bytes() const { return (nodes_.size() + triangles_.size()) * sizeof(std::int32_t); }

// The map's own nodes and buckets included: with many small lists they are
// a good part of it.
std::size_t Octree::pending_bytes() const {
  using Entry = decltype(pending_)::value_type;
  std::size_t b = pending_.bucket_count() * sizeof(void*);
  for (const auto& [index, p] : pending_) b += sizeof(void*) + sizeof(Entry) + p.candidates.capacity() * sizeof(Run);
  return b;
}

BuildOverlap build_overlap(const std::vector<std::vector<std::uint64_t>>& keys_per_part) {
  std::map<std::uint64_t, int> parts;
  BuildOverlap o;
  for (const auto& keys : keys_per_part) {
    o.per_part.push_back(keys.size());
    for (std::uint64_t k : keys) ++parts[k];
  }
  o.distinct = parts.size();
  for (const auto& [k, n] : parts) o.shared += n > 1;
  return o;
}

}  // namespace sh::rt
