// The wide BVH's walk (bvh.hpp): a visit to a node tests its kBvhWidth
// children's boxes, and the children any lane meets go on one stack for
// all the lanes, the nearest last, so that it is popped next.  Nearest is
// along the lanes' main direction (walk_order): the node lists its slots
// by their boxes' centres along each axis.  Rays side by side in SIMD
// lanes walk together, as in the threaded walk, so every lane reads the
// same node with one load; a wide node needs half the visits of a binary
// one, and its children's boxes arrive together instead of one link at a
// time.
#include <limits>
#include <optional>

#include "walk.hpp"

namespace sh::rt::walk {
namespace {

// A lane's entry distance to a child it missed: beyond every nearest hit,
// kFar (a ray that has hit nothing yet) widened by kBeyondBest included.
constexpr float kMissed = std::numeric_limits<float>::max();

// A leaf's corners asked for ahead: the cache lines of its first few
// triangles (36 bytes each, five corners to a 64-byte line).
constexpr int kLeafLinesAhead = 3;
constexpr int kCornersALine = 5;

// A node's children: their boxes, axis by axis, and their entries.
struct WideNode {
  WideNode(const BvhTables& b, const Attrib1i& node);
  // Child `slot`'s box corners.
  Attrib3f lo(int slot) const { return join(join(lo_x(slot), lo_y(slot)), lo_z(slot)); }
  Attrib3f hi(int slot) const { return join(join(hi_x(slot), hi_y(slot)), hi_z(slot)); }
  // Asks for what a visit to each child will read: an inner child's
  // boxes (its six rows span two cache lines: rows 0 and 4 lie in one
  // each), children and, where the walk is ordered, its slots' order; a
  // leaf's list and its first triangles' corners.  A large tree misses
  // the cache at every level, and a walk that waits for each node before
  // it knows the next one pays a memory latency a step; asked here, the
  // children come in while this node's boxes are tested, and the siblings
  // pushed are there when popped.
  void prefetch_children(const BvhTables& b, bool ordered) const;
  Attrib4f lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
  Attrib4i kids;
  Attrib1i node;
};

WideNode::WideNode(const BvhTables& b, const Attrib1i& at) : node(at) {
  Attrib1i row = node * 6;
  lo_x = b.wide_box[row];
  lo_y = b.wide_box[row + 1];
  lo_z = b.wide_box[row + 2];
  hi_x = b.wide_box[row + 3];
  hi_y = b.wide_box[row + 4];
  hi_z = b.wide_box[row + 5];
  kids = b.wide_children[node];
}

void WideNode::prefetch_children(const BvhTables& b, bool ordered) const {
  for (int k = 0; k < kBvhWidth; ++k) {
    // A leaf or an empty slot asks for the root's rows, a node for the
    // list's first entry: both already near, and no test.
    Attrib1i inner = max(kids(k), 0), listed = max(-kids(k) - 2, 0);
    b.wide_box.prefetch(inner * 6);
    b.wide_box.prefetch(inner * 6 + 4);
    b.wide_children.prefetch(inner);
    if (ordered) b.wide_order.prefetch(inner);
    b.triangles.prefetch(listed);
    for (int line = 0; line < kLeafLinesAhead; ++line) b.corners.prefetch(listed * 3 + line * kCornersALine);
  }
}

}  // namespace

void bvh_wide(const SceneTables& s, const Ray& r, const Attrib1f& t_limit, Attrib1f& best, Attrib1i& triangle,
              Attrib2f& uv, bool any_hit, Attrib4i* lanes) {
  static_assert(kBvhWidth == 4, "a node's rows are four-wide vectors");
  const BvhTables& b = *s.bvh;
  // A visit pops one entry and pushes at most kBvhWidth, one level down.
  // Beside each node pushed, where each lane enters its box: a node no
  // lane enters before its nearest hit so far is passed over when popped,
  // its box not read.  Where any hit will do (and lanes are not counted),
  // neither the order nor the distances pay for their code: the walk is
  // inlined at every shadow ray the tracer casts.
  bool ordered = !any_hit || lanes;
  int deepest = (kBvhWidth - 1) * b.depth + 2;
  LocalArray<Attrib1i> stack(deepest, "bvh_stack");
  std::optional<LocalArray<Attrib1f>> entered;
  if (ordered) entered.emplace(deepest, "bvh_entered");
  // An ordered visit's children by slot, read back in the order they are
  // pushed: one load at a slot the lanes share, where a choice among four
  // values takes three (the ordered walks 4-13 % faster at 1 M,
  // BENCHMARKS.md).
  struct BySlot {
    LocalArray<Attrib1i> kid{kBvhWidth, "slot_kid"}, met{kBvhWidth, "slot_met"};
    LocalArray<Attrib1f> enter{kBvhWidth, "slot_enter"};
  };
  std::optional<BySlot> by_slot;
  if (ordered) by_slot.emplace();
  Attrib1i order = walk_order(r).cast<std::int32_t>();
  Attrib1i axis_bits = (order / 2) * 8, downwards = order % 2;
  Attrib1i depth = 0;
  Attrib1i node = b.root;  // >= 0 an inner node, <= -2 a leaf, -1 done
  // Counting: whether the node popped is this lane's own (its ray enters
  // the box before its nearest hit so far); the root is every lane's.
  std::optional<Attrib1i> own_node;
  if (lanes) own_node = Attrib1i(1);
  auto pop = [&] {
    if (!ordered) {
      Attrib1i some = depth > 0;
      depth -= some;
      node = cond(some, stack[depth], ConstAttrib1i(-1));
      return;
    }
    node = -1;
    SH_WHILE(node == -1 && depth > 0) {
      depth -= 1;
      Attrib1f own = (*entered)[depth] <= best * kBeyondBest;
      node = cond(any_lane(own).cast<std::int32_t>(), stack[depth], ConstAttrib1i(-1));
      if (lanes) *own_node = own.cast<std::int32_t>();
    } SH_ENDWHILE;
  };
  auto walking = [&]() -> Attrib1i {
    if (!any_hit) return node != -1;
    return node != -1 && (best >= t_limit).cast<std::int32_t>();
  };
  // Which lanes' rays meet a child's box before their nearest hit so far,
  // and where each enters it.
  auto meets = [&](const Attrib3f& lo, const Attrib3f& hi, const Attrib1f& clip_at, Attrib1f& enter) -> Attrib1f {
    Attrib1f leave;
    clip(r, lo, hi, clip_at, enter, leave);
    return enter <= leave;
  };
  // Pushes the children any lane meets, farthest first: the nearest met
  // is on top.
  auto visit_ordered = [&] {
    WideNode n(b, node);
    if (b.prefetch) n.prefetch_children(b, true);
    Attrib1f clip_at = best * kBeyondBest;
    for (int k = 0; k < kBvhWidth; ++k) {
      Attrib1f enter;
      Attrib1f own = meets(n.lo(k), n.hi(k), clip_at, enter);
      by_slot->kid.store(k, n.kids(k));
      by_slot->met.store(k, any_lane(own).cast<std::int32_t>() && n.kids(k) != -1);
      by_slot->enter.store(k, cond(own, enter, ConstAttrib1f(kMissed)));
      if (lanes) {
        Attrib1i tested = n.kids(k) != -1;
        *lanes += join(join(tested, tested && own.cast<std::int32_t>()), ConstAttrib2i(0, 0));
      }
    }
    Attrib1i by_centre = bit_and(shr(b.wide_order[node], axis_bits), 255);
    for (int j = 0; j < kBvhWidth; ++j) {
      Attrib1i position = cond(downwards, ConstAttrib1i(j), ConstAttrib1i(kBvhWidth - 1 - j));
      Attrib1i slot = bit_and(shr(by_centre, position * 2), 3);
      stack.store(depth, by_slot->kid[slot]);
      entered->store(depth, by_slot->enter[slot]);
      depth += by_slot->met[slot];
    }
  };
  // Where any hit will do, the order does not matter: the children in
  // slot order, as four copies.  A recorded loop would be a third of the
  // code, but the tracer's short pipeline does not unroll it, and with the
  // slot a program value every box coordinate becomes a choice among four:
  // renders were 3-22 % slower that way, for 2-3 % less compile.
  auto visit_any = [&] {
    WideNode n(b, node);
    if (b.prefetch) n.prefetch_children(b, false);
    Attrib1f clip_at = best * kBeyondBest;
    for (int k = 0; k < kBvhWidth; ++k) {
      Attrib1f enter;
      Attrib1f own = meets(n.lo(k), n.hi(k), clip_at, enter);
      Attrib1i kid = n.kids(k);
      stack.store(depth, kid);
      depth += any_lane(own).cast<std::int32_t>() && kid != -1;
    }
  };
  // One loop, one pop: the lanes are all at the same node, so a loop of
  // inner nodes of its own would gain nothing, and the walk's code is
  // inlined at every ray the tracer casts.
  SH_WHILE(walking()) {
    SH_IF(node >= 0) {
      if (ordered)
        visit_ordered();
      else
        visit_any();
    } SH_ELSE {
      if (lanes) *lanes += join(ConstAttrib2i(0, 0), join(ConstAttrib1i(1), *own_node));
      test_leaf(b, r, -node - 2, best, triangle, uv);
    } SH_ENDIF;
    pop();
  } SH_ENDWHILE;
}

}  // namespace sh::rt::walk
