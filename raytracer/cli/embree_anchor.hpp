#pragma once
// Embree 3's rtcIntersect1 on the same rays, as the speed anchor of
// `shtrace bench`.
#include <vector>

#include <sh/raytracer/scene.hpp>

namespace shtrace {

// Mrays/s of Embree over the rays (all threads, oneTBB), and the number
// that hit something: rtcIntersect1 (packet 1) or rtcIntersect4/8/16 on
// packets of consecutive rays.  Zero rate where the CPU lacks the packet.
struct AnchorResult {
  double mrays_per_s = 0;
  std::size_t hits = 0;
};
AnchorResult embree_primary_rays(const sh::rt::Scene& scene, const std::vector<float>& origins,
                                 const std::vector<float>& directions, int repeats, int packet = 1);

}  // namespace shtrace
