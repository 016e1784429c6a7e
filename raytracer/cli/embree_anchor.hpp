#pragma once
// Embree 3 on the same rays as the tracer's kernels, as the speed anchor of
// `shtrace bench` and `shtrace rays`.
#include <cmath>
#include <vector>

#include "embree_scene.hpp"

namespace shtrace {

struct RayBatch {
  std::vector<float> origins, directions;  // x, y, z each
  std::vector<float> t_near, t_far;        // per ray; empty: from 0, without end
  std::size_t size() const { return origins.size() / 3; }
  sh::rt::Vec3 origin(std::size_t i) const { return {origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]}; }
  sh::rt::Vec3 direction(std::size_t i) const {
    return {directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]};
  }
  float near(std::size_t i) const { return t_near.empty() ? 0 : t_near[i]; }
  float far(std::size_t i) const { return t_far.empty() ? INFINITY : t_far[i]; }
};

// The nearest hit (rtcIntersect) or whether anything is hit (rtcOccluded).
enum class Query { Nearest, Any };

// Embree's scene over the rays (all threads, oneTBB), one pass at a time:
// one ray at a time (packet 1) or packets of 4, 8 or 16 consecutive rays.
class EmbreePass {
 public:
  EmbreePass(const sh::rt::EmbreeScene& embree, const RayBatch& rays, int packet = 1, Query query = Query::Nearest);
  bool supported() const;    // whether the CPU runs the packet
  std::size_t run() const;   // one pass; the rays that hit something
 private:
  const sh::rt::EmbreeScene& embree_;
  const RayBatch& rays_;
  int packet_;
  Query query_;
};

// Mrays/s of `repeats` passes after an untimed one, and the number of rays
// that hit something.  Zero rate where the CPU lacks the packet.
struct AnchorResult {
  double mrays_per_s = 0;
  std::size_t hits = 0;
};
AnchorResult embree_rays(const sh::rt::EmbreeScene& embree, const RayBatch& rays, int repeats, int packet = 1,
                         Query query = Query::Nearest);

}  // namespace shtrace
