#pragma once
// Embree 3 on the same rays as the tracer's kernels, as the speed anchor of
// `shtrace bench` and `shtrace rays`.
#include <vector>

#include "embree_scene.hpp"

namespace shtrace {

struct RayBatch {
  std::vector<float> origins, directions;  // x, y, z each
  std::vector<float> t_near, t_far;        // per ray; empty: from 0, without end
  std::size_t size() const { return origins.size() / 3; }
};

// The nearest hit (rtcIntersect) or whether anything is hit (rtcOccluded).
enum class Query { Nearest, Any };

// Mrays/s of Embree's scene over the rays (all threads, oneTBB), and the number
// that hit something: one ray at a time (packet 1) or packets of 4, 8 or
// 16 consecutive rays.  Zero rate where the CPU lacks the packet.
struct AnchorResult {
  double mrays_per_s = 0;
  std::size_t hits = 0;
};
AnchorResult embree_rays(const sh::rt::EmbreeScene& embree, const RayBatch& rays, int repeats, int packet = 1,
                         Query query = Query::Nearest);

}  // namespace shtrace
