#include "embree_anchor.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include "embree_scene.hpp"

namespace shtrace {

AnchorResult embree_primary_rays(const sh::rt::Scene& scene, const std::vector<float>& origins,
                                 const std::vector<float>& directions, int repeats, int packet) {
  sh::rt::EmbreeScene embree(scene);
  if (packet > 1 && !embree.supports_packet(packet)) return {};
  std::size_t rays = origins.size() / 3;
  std::atomic<std::size_t> hits{0};
  auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) {
    hits = 0;
    // Ranges of whole packets, 256 rays at least.
    std::size_t packets = (rays + packet - 1) / packet;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets, 256 / packet),
                      [&](const tbb::blocked_range<std::size_t>& range) {
      std::size_t local = 0;
      for (std::size_t k = range.begin(); k < range.end(); ++k) {
        std::size_t i = k * packet;
        if (packet == 1) {
          RTCRayHit rh = embree.intersect({origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]},
                                          {directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]});
          local += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
          continue;
        }
        int count = static_cast<int>(std::min<std::size_t>(packet, rays - i)), hit[16];
        embree.intersect_packet(packet, count, &origins[3 * i], &directions[3 * i], hit);
        for (int j = 0; j < count; ++j) local += hit[j] >= 0;
      }
      hits += local;
    });
  }
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {static_cast<double>(rays) * repeats / seconds / 1e6, hits};
}

}  // namespace shtrace
