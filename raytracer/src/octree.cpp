#include "sh/raytracer/octree.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>

#include "sh/error.hpp"

namespace sh::rt {
namespace {

void put_leb128(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (; v >= 0x80; v >>= 7) out.push_back(static_cast<std::uint8_t>(v | 0x80));
  out.push_back(static_cast<std::uint8_t>(v));
}

std::uint32_t get_leb128(const std::vector<std::uint8_t>& in, std::size_t& at) {
  std::uint32_t v = 0;
  for (int shift = 0;; shift += 7) {
    std::uint8_t b = in[at++];
    v |= static_cast<std::uint32_t>(b & 0x7f) << shift;
    if (b < 0x80) return v;
  }
}

// Does a split into these children separate the node's `n` triangles?  Not
// when each child would hold all of them or none, two or more all (the
// triangles cover the same ground: one child alone holding all is a
// smaller box around them, and worth going on), nor when the eight
// together would hold four times as many: a ray through the node crosses a
// child with a chance of a quarter (the child's surface over the node's),
// so it would test no fewer triangles below the split than in the node.
bool separates(const std::array<std::vector<std::int32_t>, 8>& children, std::size_t n) {
  constexpr std::size_t kNoGain = 4;
  std::size_t total = 0;
  int whole = 0, part = 0;
  for (const auto& list : children) {
    total += list.size();
    whole += list.size() == n;
    part += !list.empty() && list.size() < n;
  }
  return (whole < 2 || part > 0) && total < kNoGain * n;
}

}  // namespace

Octree::Octree(std::vector<Vec3> positions, Box bounds, OctreeLimits limits)
    : positions_(std::move(positions)), bounds_(bounds), limits_(limits) {
  auto t0 = std::chrono::steady_clock::now();
  if (limits_.max_depth < 0 || limits_.max_depth > kMaxOctreeDepth)
    throw Error("octree depth limit must be 0.." + std::to_string(kMaxOctreeDepth) + ", got " +
                std::to_string(limits_.max_depth));
  if (limits_.leaf_size < 1) throw Error("octree leaf size must be at least 1, got " + std::to_string(limits_.leaf_size));
  if (!(limits_.references_per_triangle >= 1))
    throw Error("octree references per triangle must be at least 1, got " + std::to_string(limits_.references_per_triangle));
  std::vector<std::int32_t> all(positions_.size() / 3);
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<std::int32_t>(t);
  // Saturated where the product passes what a size_t counts (1e300 per
  // triangle is no cap, not the smallest budget).
  double asked = limits_.references_per_triangle * static_cast<double>(all.size());
  reference_budget_ = asked >= 0x1p63 ? std::numeric_limits<std::size_t>::max()
                                      : std::max(kMinReferenceBudget, static_cast<std::size_t>(asked));
  references_ = all.size();
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
Octree::Children Octree::split(Place at, const std::vector<std::int32_t>& candidates) const {
  Children lists;
  Box boxes[8];
  for (int c = 0; c < 8; ++c) {
    boxes[c] = box(child(at, c));
    Vec3 hair = overlap_hair(bounds_, boxes[c].hi - boxes[c].lo);
    boxes[c] = {boxes[c].lo - hair, boxes[c].hi + hair};
  }
  for (std::int32_t t : candidates) {
    Vec3 a = positions_[3 * t], b = positions_[3 * t + 1], c = positions_[3 * t + 2];
    Vec3 lo = min(min(a, b), c), hi = max(max(a, b), c);
    for (int k = 0; k < 8; ++k) {
      // The triangle's bounds alone decide most cases: apart, or inside.
      const Box& x = boxes[k];
      bool apart = lo.x > x.hi.x || lo.y > x.hi.y || lo.z > x.hi.z || hi.x < x.lo.x || hi.y < x.lo.y || hi.z < x.lo.z;
      bool inside = lo.x >= x.lo.x && lo.y >= x.lo.y && lo.z >= x.lo.z && hi.x <= x.hi.x && hi.y <= x.hi.y && hi.z <= x.hi.z;
      if (inside || (!apart && triangle_overlaps_box(a, b, c, x.lo, x.hi))) lists[k].push_back(t);
    }
  }
  return lists;
}

// Node `index` at `place` with these triangles (ascending): an empty leaf,
// a leaf (at the depth limit or small enough), or an unbuilt node that
// keeps them as runs.
std::int32_t Octree::settle(Place place, const std::vector<std::int32_t>& list, std::int32_t index) {
  if (list.empty()) return -1;
  if (place.level == limits_.max_depth || list.size() <= static_cast<std::size_t>(limits_.leaf_size)) return leaf(list);
  keep_unbuilt(index, place, list);
  return 0;
}

std::int32_t Octree::leaf(const std::vector<std::int32_t>& list) {
  auto start = static_cast<std::int32_t>(triangles_.size());
  triangles_.insert(triangles_.end(), list.begin(), list.end());
  triangles_.push_back(-1);
  return -start - 2;
}

void Octree::keep_unbuilt(std::int32_t node, Place place, const std::vector<std::int32_t>& list) {
  if (candidate_bytes_.size() + 10 * list.size() > UINT32_MAX)  // a run takes at most 10 bytes
    throw Error("octree: more than 4 GiB of triangle lists kept for unbuilt nodes; lower the depth limit");
  unbuilt_.push_back({node, static_cast<std::uint32_t>(candidate_bytes_.size()), key(place)});
  std::int32_t end = 0;  // where the previous run ended
  for (std::size_t i = 0; i < list.size();) {
    std::size_t j = i + 1;
    while (j < list.size() && list[j] == list[j - 1] + 1) ++j;
    put_leb128(candidate_bytes_, static_cast<std::uint32_t>(list[i] - end));
    put_leb128(candidate_bytes_, static_cast<std::uint32_t>(j - i - 1));
    end = list[j - 1] + 1;
    i = j;
  }
}

std::size_t Octree::entry_of(std::int32_t node) const {
  auto it = std::lower_bound(unbuilt_.begin(), unbuilt_.end(), node,
                             [](const Unbuilt& u, std::int32_t n) { return u.node < n; });
  if (it == unbuilt_.end() || it->node != node || it->key == kDead)
    throw Error("octree: node " + std::to_string(node) + " is not an unbuilt node");
  return static_cast<std::size_t>(it - unbuilt_.begin());
}

std::vector<std::int32_t> Octree::candidates(std::size_t entry) const {
  std::size_t at = unbuilt_[entry].first_byte;
  std::size_t end = entry + 1 < unbuilt_.size() ? unbuilt_[entry + 1].first_byte : candidate_bytes_.size();
  std::vector<std::int32_t> list;
  std::int32_t run_end = 0;
  while (at < end) {
    auto first = run_end + static_cast<std::int32_t>(get_leb128(candidate_bytes_, at));
    auto count = static_cast<std::int32_t>(get_leb128(candidate_bytes_, at)) + 1;
    for (std::int32_t t = first; t < first + count; ++t) list.push_back(t);
    run_end = first + count;
  }
  return list;
}

// Drops the entries of built nodes and their lists, and gives back what the
// two vectors grew to: after a build, the store holds only what it needs.
void Octree::compact_unbuilt() {
  auto t0 = std::chrono::steady_clock::now();
  auto end_of = [&](std::size_t e) { return e + 1 < unbuilt_.size() ? unbuilt_[e + 1].first_byte : candidate_bytes_.size(); };
  std::size_t live_bytes = 0;
  for (std::size_t e = 0; e < unbuilt_.size(); ++e)
    if (unbuilt_[e].key != kDead) live_bytes += end_of(e) - unbuilt_[e].first_byte;
  std::vector<Unbuilt> live;
  std::vector<std::uint8_t> bytes;
  live.reserve(unbuilt_.size() - dead_);
  bytes.reserve(live_bytes);
  for (std::size_t e = 0; e < unbuilt_.size(); ++e) {
    if (unbuilt_[e].key == kDead) continue;
    live.push_back({unbuilt_[e].node, static_cast<std::uint32_t>(bytes.size()), unbuilt_[e].key});
    bytes.insert(bytes.end(), candidate_bytes_.begin() + unbuilt_[e].first_byte,
                 candidate_bytes_.begin() + static_cast<std::ptrdiff_t>(end_of(e)));
  }
  unbuilt_ = std::move(live);
  candidate_bytes_ = std::move(bytes);
  dead_ = 0;
  build_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::size_t Octree::build(const std::vector<std::int32_t>& requested) {
  std::size_t built = build_level(requested);
  compact_unbuilt();
  return built;
}

std::size_t Octree::build_level(const std::vector<std::int32_t>& requested) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::int32_t> todo;
  for (std::int32_t n : requested)
    if (n >= 0 && static_cast<std::size_t>(n) < nodes_.size() && nodes_[n] == 0) todo.push_back(n);
  std::sort(todo.begin(), todo.end());
  todo.erase(std::unique(todo.begin(), todo.end()), todo.end());
  std::vector<std::size_t> entries(todo.size());
  for (std::size_t i = 0; i < todo.size(); ++i) entries[i] = entry_of(todo[i]);
  // Splitting is the work and runs in parallel; placing children is a
  // sequential append.
  std::vector<Children> children(todo.size());
  std::vector<std::size_t> counts(todo.size());
  tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t i) {
    std::vector<std::int32_t> list = candidates(entries[i]);
    counts[i] = list.size();
    children[i] = split(place(unbuilt_[entries[i]].key), list);
  });
  if (nodes_.size() + 8 * todo.size() > static_cast<std::size_t>(INT32_MAX) ||
      triangles_.size() > static_cast<std::size_t>(INT32_MAX) / 2)
    throw Error("octree: more than 2^31 nodes or listed triangles; lower the depth limit or raise the leaf size");
  for (std::size_t i = 0; i < todo.size(); ++i) {
    Place at = place(unbuilt_[entries[i]].key);
    unbuilt_[entries[i]].key = kDead;
    ++dead_;
    if (!place_children(todo[i], at, children[i], counts[i])) nodes_[todo[i]] = leaf(candidates(entries[i]));
  }
  build_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return todo.size();
}

// Appends the node's eight children; false (nothing appended) where they
// would not separate its triangles or would take the references past the
// budget: the node is to be a leaf.
bool Octree::place_children(std::int32_t node, Place at, const Children& children, std::size_t candidates) {
  std::size_t added = 0;
  for (const auto& list : children) added += list.size();
  bool apart = separates(children, candidates);
  if (!apart || references_ - candidates + added > reference_budget_) {
    ++(apart ? over_budget_ : unseparated_);
    largest_capped_leaf_ = std::max(largest_capped_leaf_, candidates);
    return false;
  }
  references_ = references_ - candidates + added;
  auto first = static_cast<std::int32_t>(nodes_.size());
  nodes_.resize(nodes_.size() + 8);
  for (int c = 0; c < 8; ++c) nodes_[first + c] = settle(child(at, c), children[c], first + c);
  nodes_[node] = first;
  return true;
}

// Level by level: each round builds the node every walk stands on (in
// parallel), then each walk steps into the child holding its cell and goes
// on while that child is unbuilt.  A node's place follows from its level
// and any cell inside it, so a walk carries no more.
std::size_t Octree::build_towards(const std::vector<std::int32_t>& requests) {
  struct Walk {
    std::int32_t node, level;
    std::array<int, 3> cell;
  };
  std::vector<Walk> walks;
  walks.reserve(requests.size() / 4);
  for (std::size_t i = 0; i + 3 < requests.size(); i += 4) {
    std::int32_t node = requests[i];
    if (node < 0 || static_cast<std::size_t>(node) >= nodes_.size() || nodes_[node] != 0) continue;
    Place at = place(unbuilt_[entry_of(node)].key);
    std::array<int, 3> cell;
    for (int a = 0; a < 3; ++a) cell[a] = std::clamp(requests[i + 1 + a], at.corner[a], at.corner[a] + (resolution() >> at.level) - 1);
    walks.push_back({node, at.level, cell});
  }
  std::size_t built = 0;
  std::vector<std::int32_t> level;
  while (!walks.empty()) {
    level.clear();
    for (const Walk& w : walks) level.push_back(w.node);
    built += build_level(level);
    std::size_t going_on = 0;
    for (Walk w : walks) {
      if (nodes_[w.node] < 0) continue;  // made a leaf: the walk ends in it
      int shift = limits_.max_depth - w.level - 1, which = 0;
      for (int a = 0; a < 3; ++a) which |= (w.cell[a] >> shift & 1) << a;
      std::int32_t next = nodes_[w.node] + which;
      if (nodes_[next] == 0) walks[going_on++] = {next, w.level + 1, w.cell};
    }
    walks.resize(going_on);
  }
  compact_unbuilt();
  return built;
}

void Octree::build_everything() {
  for (std::vector<std::int32_t> level = unbuilt(); !level.empty(); level = unbuilt()) build(level);
}

std::vector<std::int32_t> Octree::unbuilt() const {
  std::vector<std::int32_t> out;
  out.reserve(unbuilt_.size() - dead_);
  for (const Unbuilt& u : unbuilt_)
    if (u.key != kDead) out.push_back(u.node);
  return out;
}

// The k-th node built got children 8k+1 .. 8k+8, so one pass over the
// nodes finds each block's parent, and a pass over the blocks in the order
// they were built places every parent: its own block came before.
std::vector<std::uint64_t> Octree::built_keys() const {
  std::vector<std::int32_t> parent(built_count());
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n] >= 1) parent[static_cast<std::size_t>(nodes_[n] - 1) / 8] = static_cast<std::int32_t>(n);
  std::vector<Place> parent_place(parent.size());
  std::vector<std::uint64_t> keys(parent.size());
  for (std::size_t k = 0; k < parent.size(); ++k) {
    std::int32_t n = parent[k];
    parent_place[k] = n == 0 ? Place{} : child(parent_place[static_cast<std::size_t>(n - 1) / 8], (n - 1) % 8);
    keys[k] = key(parent_place[k]);
  }
  return keys;
}

// Said when the budget was spent, or when a split refused made a leaf of
// more than twice the leaf size: on clean meshes the refusals are few and
// small (a handful of triangles round a vertex on a node's face).
std::string Octree::warning() const {
  bool large = largest_capped_leaf_ > 2 * static_cast<std::size_t>(limits_.leaf_size);
  if (over_budget_ == 0 && !large) return "";
  std::string w = "octree: ";
  if (unseparated_ > 0)
    w += std::to_string(unseparated_) + " nodes not split: splitting would not separate their triangles (coincident, "
         "overlapping or degenerate triangles, or coordinates too large for the cells)";
  if (unseparated_ > 0 && over_budget_ > 0) w += "; ";
  if (over_budget_ > 0)
    w += std::to_string(over_budget_) + " nodes not split: the tree holds its budget of " + std::to_string(reference_budget_) +
         " triangle references";
  return w + "; their leaves hold up to " + std::to_string(largest_capped_leaf_) + " triangles (leaf size " +
         std::to_string(limits_.leaf_size) + ")";
}

std::size_t Octree::bytes() const { return (nodes_.size() + triangles_.size()) * sizeof(std::int32_t); }

std::size_t Octree::pending_bytes() const { return unbuilt_.capacity() * sizeof(Unbuilt) + candidate_bytes_.capacity(); }

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
