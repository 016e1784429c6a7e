#include "embree_anchor.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>


namespace shtrace {
namespace {

bool one_ray(const sh::rt::EmbreeScene& embree, const RayBatch& rays, std::size_t i, Query query) {
  sh::rt::Vec3 o = rays.origin(i), d = rays.direction(i);
  if (query == Query::Any) return embree.occluded(o, d, rays.near(i), rays.far(i));
  return embree.intersect(o, d, rays.near(i), rays.far(i)).hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

}  // namespace

EmbreePass::EmbreePass(const sh::rt::EmbreeScene& embree, const RayBatch& rays, int packet, Query query)
    : embree_(embree), rays_(rays), packet_(packet), query_(query) {}

bool EmbreePass::supported() const { return packet_ == 1 || embree_.supports_packet(packet_); }

std::size_t EmbreePass::run() const {
  std::size_t n = rays_.size();
  std::atomic<std::size_t> hits{0};
  // Ranges of whole packets, 256 rays at least.
  std::size_t packets = (n + packet_ - 1) / packet_;
  auto chunk = [&](const tbb::blocked_range<std::size_t>& range) {
    std::size_t local = 0;
    for (std::size_t k = range.begin(); k < range.end(); ++k) {
      std::size_t i = k * packet_;
      if (packet_ == 1) {
        local += one_ray(embree_, rays_, i, query_);
        continue;
      }
      int count = static_cast<int>(std::min<std::size_t>(packet_, n - i)), hit[16];
      embree_.intersect_packet(packet_, count, &rays_.origins[3 * i], &rays_.directions[3 * i], hit,
                               rays_.t_near.empty() ? nullptr : &rays_.t_near[i],
                               rays_.t_far.empty() ? nullptr : &rays_.t_far[i], query_ == Query::Any);
      for (int j = 0; j < count; ++j) local += hit[j] >= 0;
    }
    hits += local;
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, packets, 256 / packet_), chunk);
  return hits.load();
}

// One pass untimed first, as the kernels get (their first run compiles):
// Embree's first pass over a scene pays for its caches and its threads'
// start.
AnchorResult embree_rays(const sh::rt::EmbreeScene& embree, const RayBatch& rays, int repeats, int packet, Query query) {
  EmbreePass pass(embree, rays, packet, query);
  if (!pass.supported()) return {};
  std::size_t hits = pass.run();
  auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) hits = pass.run();
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return {static_cast<double>(rays.size()) * repeats / seconds / 1e6, hits};
}

}  // namespace shtrace
