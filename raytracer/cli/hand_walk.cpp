#include "hand_walk.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <cstring>

#include <sh/raytracer/walk_bounds.hpp>

namespace shtrace {
namespace {

using sh::rt::Bvh;
using sh::rt::Vec3;

// The kernels' own bounds, so that the walk finds the kernels' hits.
using sh::rt::gamma;
using sh::rt::kBeyondBest;
using sh::rt::kTieTolerance;
using sh::rt::kTinyDirection;

// A row of a node's four children (one coordinate of each box): the
// compiler's vector extension, SSE on x86-64, another target's own
// vectors elsewhere.
using Four = float __attribute__((vector_size(16)));

Four row(const float* at) {
  Four v;
  std::memcpy(&v, at, sizeof v);
  return v;
}
Four splat(float x) { return Four{x, x, x, x}; }
// The kernels' lesser and greater: a compare and a choice.
Four lesser(Four a, Four b) { return a < b ? a : b; }
Four greater(Four a, Four b) { return a > b ? a : b; }
float greater(float a, float b) { return a > b ? a : b; }
Vec3 greater(Vec3 a, Vec3 b) { return {greater(a.x, b.x), greater(a.y, b.y), greater(a.z, b.z)}; }
float greatest(Vec3 v) { return greater(greater(v.x, v.y), v.z); }
Vec3 abs(Vec3 v) { return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}; }

// The ray as the kernels' walk::Ray sets it up: the capped reciprocal
// direction for the boxes, and the turn and shear of the watertight test.
struct OneRay {
  OneRay(Vec3 origin, Vec3 direction) : o(origin), d(direction) {
    for (int c = 0; c < 3; ++c) inv[c] = 1.0f / (std::fabs(d[c]) > kTinyDirection ? d[c] : kTinyDirection);
    Vec3 size = abs(d);
    last_is_x = size.x > size.y && size.x > size.z;
    last_is_y = !last_is_x && size.y > size.z;
    Vec3 turned = turn(d);
    float dz = turned.z != 0.0f ? turned.z : 1.0f;
    shear = {-turned.x / dz, -turned.y / dz, 1.0f / dz};
  }
  Vec3 turn(Vec3 v) const {
    if (last_is_x) return {v.y, v.z, v.x};
    if (last_is_y) return {v.z, v.x, v.y};
    return v;
  }
  Vec3 to_ray_space(Vec3 vertex) const {
    Vec3 p = turn(vertex - o);
    return {p.x + shear.x * p.z, p.y + shear.y * p.z, shear.z * p.z};
  }
  Vec3 o, d, inv, shear;
  bool last_is_x, last_is_y;
};

struct Nearest {
  float best;
  std::int32_t triangle = -1;
};

float edge_function(Vec3 p, Vec3 q) { return p.x * q.y - p.y * q.x; }
float edge_rounding(Vec3 p, Vec3 q) { return (std::fabs(p.x * q.y) + std::fabs(p.y * q.x)) * 0x1p-21f; }
float exact_edge_function(Vec3 p, Vec3 q) {
  return static_cast<float>(static_cast<double>(p.x) * q.y - static_cast<double>(p.y) * q.x);
}

float distance_error(Vec3 a, Vec3 b, Vec3 c, Vec3 barycentrics, float inv_det) {
  Vec3 largest = greater(greater(abs(a), abs(b)), abs(c));
  float x = largest.x, y = largest.y, z = largest.z;
  float dz = gamma(3) * z, dx = gamma(5) * (x + z), dy = gamma(5) * (y + z);
  float de = 2.0f * (gamma(2) * x * y + dy * x + dx * y);
  float e = greatest(abs(barycentrics));
  return 3.0f * (gamma(4) * e * z + de * std::fabs(inv_det) * z + dz * e);
}

bool in_front_of_plane(const OneRay& r, Vec3 v0, Vec3 v1, Vec3 v2) {
  Vec3 e1_far = v1 - v0, e2_far = v2 - v0, p = v0 - r.o;
  float edge_scale = 1.0f / greater(greatest(abs(e1_far)), 1e-30f);
  Vec3 e1 = e1_far * edge_scale, e2 = e2_far * edge_scale;
  Vec3 n = cross(e1, e2);
  Vec3 size = {std::fabs(e1.y * e2.z) + std::fabs(e1.z * e2.y), std::fabs(e1.z * e2.x) + std::fabs(e1.x * e2.z),
               std::fabs(e1.x * e2.y) + std::fabs(e1.y * e2.x)};
  float num = dot(n, p), den = dot(n, r.d);
  bool sure_num = std::fabs(num) > gamma(16) * dot(size, abs(p));
  bool sure_den = std::fabs(den) > gamma(16) * dot(size, abs(r.d));
  return sure_num && sure_den && (num > 0.0f) == (den > 0.0f);
}

// The kernels' watertight test (intersector.cpp), operation for operation.
void test_triangle(const OneRay& r, const float* corners, std::int32_t tri, Nearest& h) {
  Vec3 v0{corners[0], corners[1], corners[2]}, v1{corners[3], corners[4], corners[5]},
      v2{corners[6], corners[7], corners[8]};
  Vec3 a = r.to_ray_space(v0), b = r.to_ray_space(v1), c = r.to_ray_space(v2);
  float u = edge_function(b, c), v = edge_function(c, a), w = edge_function(a, b);
  if (std::fabs(u) <= edge_rounding(b, c) || std::fabs(v) <= edge_rounding(c, a) || std::fabs(w) <= edge_rounding(a, b)) {
    u = exact_edge_function(b, c);
    v = exact_edge_function(c, a);
    w = exact_edge_function(a, b);
  }
  bool outside = (u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f);
  float det = u + v + w;
  if (det == 0.0f || outside) return;
  float inv = 1.0f / det;
  Vec3 barycentrics{u * inv, v * inv, w * inv};
  float t = barycentrics.x * a.z + barycentrics.y * b.z + barycentrics.z * c.z;
  bool in_front = t > distance_error(a, b, c, barycentrics, inv);
  if (t > 0.0f && !in_front) in_front = in_front_of_plane(r, v0, v1, v2);
  bool tie = h.triangle >= 0 && std::fabs(t - h.best) <= h.best * kTieTolerance;
  bool nearer = tie ? tri < h.triangle : t < h.best;
  if (in_front && nearer) {
    h.best = t;
    h.triangle = tri;
  }
}

// A node pushed, with where the ray enters its box.
struct Pushed {
  std::int32_t ref;
  float enter;
};

// The nearest triangle before t_limit, or with `any_hit` the first one
// found (the kernels' any-hit walk stops there too).
class Walk {
 public:
  Walk(const Bvh& bvh, const OneRay& r, float t_limit, bool any_hit, Pushed* stack)
      : b_(bvh), r_(r), any_hit_(any_hit), stack_(stack) {
    h_.best = t_limit;
  }

  std::int32_t triangle() {
    std::int32_t ref = b_.root;
    for (;;) {
      if (ref >= 0)
        ref = visit(ref);
      else
        ref = leaf(-ref - 2);
      if (any_hit_ && h_.triangle >= 0) return h_.triangle;
      if (ref == -1 && !pop(ref)) return h_.triangle;
    }
  }

 private:
  // The nearest child the ray meets (the others pushed, farthest first),
  // or -1.
  std::int32_t visit(std::int32_t node) {
    const float* box = &b_.wide_box[static_cast<std::size_t>(node) * 6 * sh::rt::kBvhWidth];
    Four ta_x = (row(box) - splat(r_.o.x)) * splat(r_.inv.x), tb_x = (row(box + 12) - splat(r_.o.x)) * splat(r_.inv.x);
    Four ta_y = (row(box + 4) - splat(r_.o.y)) * splat(r_.inv.y), tb_y = (row(box + 16) - splat(r_.o.y)) * splat(r_.inv.y);
    Four ta_z = (row(box + 8) - splat(r_.o.z)) * splat(r_.inv.z), tb_z = (row(box + 20) - splat(r_.o.z)) * splat(r_.inv.z);
    Four enter = greater(greater(lesser(ta_x, tb_x), lesser(ta_y, tb_y)), greater(lesser(ta_z, tb_z), splat(0.0f)));
    Four leave = lesser(lesser(lesser(greater(ta_x, tb_x), greater(ta_y, tb_y)), greater(ta_z, tb_z)) *
                            splat(1.0f + 2.0f * gamma(3)),
                        splat(h_.best * kBeyondBest));
    auto met = enter <= leave;
    const std::int32_t* kids = &b_.wide_children[static_cast<std::size_t>(node) * sh::rt::kBvhWidth];
    Pushed found[sh::rt::kBvhWidth];
    int count = 0;
    for (int k = 0; k < sh::rt::kBvhWidth; ++k) {
      if (!met[k] || kids[k] == -1) continue;
      int at = count++;
      for (; at > 0 && found[at - 1].enter < enter[k]; --at) found[at] = found[at - 1];
      found[at] = {kids[k], enter[k]};
    }
    if (count == 0) return -1;
    for (int k = 0; k + 1 < count; ++k) stack_[depth_++] = found[k];
    return found[count - 1].ref;
  }

  std::int32_t leaf(std::int32_t k) {
    for (bool more = true; more; ++k) {
      std::int32_t entry = b_.triangles[static_cast<std::size_t>(k)];
      more = !Bvh::ends_list(entry);
      test_triangle(r_, &b_.corners[static_cast<std::size_t>(k) * 9], Bvh::listed(entry), h_);
    }
    return -1;
  }

  // The next pushed node the ray enters before its nearest hit so far.
  bool pop(std::int32_t& ref) {
    while (depth_ > 0) {
      const Pushed& p = stack_[--depth_];
      if (p.enter <= h_.best * kBeyondBest) {
        ref = p.ref;
        return true;
      }
    }
    return false;
  }

  const Bvh& b_;
  const OneRay& r_;
  bool any_hit_;
  Pushed* stack_;
  int depth_ = 0;
  Nearest h_;
};

}  // namespace

bool HandWalk::walks(const sh::rt::Renderer& r) { return r.bvh() && r.bvh()->walk == sh::rt::BvhWalk::Wide; }

HandWalk::HandWalk(const Bvh& bvh) : bvh_(bvh) {}

std::size_t HandWalk::run(const RayBatch& rays, Query query, std::vector<std::int32_t>& triangles) const {
  triangles.assign(rays.size(), -1);
  std::atomic<std::size_t> hits{0};
  // A visit pushes at most kBvhWidth - 1 nodes and goes one level down.
  std::size_t deepest = static_cast<std::size_t>((sh::rt::kBvhWidth - 1) * bvh_.depth + 2);
  bool any_hit = query == Query::Any;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Pushed> stack(deepest);
    std::size_t local = 0;
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      OneRay r(rays.origin(i), rays.direction(i));
      float t_limit = any_hit ? rays.far(i) : sh::rt::kFar;
      triangles[i] = Walk(bvh_, r, t_limit, any_hit, stack.data()).triangle();
      local += triangles[i] >= 0;
    }
    hits += local;
  });
  return hits.load();
}

}  // namespace shtrace
