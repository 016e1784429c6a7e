#include "embree_anchor.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <limits>

namespace shtrace {

AnchorResult embree_primary_rays(const sh::rt::Scene& scene, const std::vector<float>& origins,
                                 const std::vector<float>& directions, int repeats) {
  RTCDevice device = rtcNewDevice(nullptr);
  RTCScene rtc = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  std::size_t n = scene.mesh.triangles();
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * n));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n));
  for (std::size_t i = 0; i < 3 * n; ++i) {
    v[3 * i] = scene.mesh.positions[i].x;
    v[3 * i + 1] = scene.mesh.positions[i].y;
    v[3 * i + 2] = scene.mesh.positions[i].z;
    idx[i] = static_cast<unsigned>(i);
  }
  rtcCommitGeometry(g);
  rtcAttachGeometry(rtc, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(rtc);

  std::size_t rays = origins.size() / 3;
  std::atomic<std::size_t> hits{0};
  auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < repeats; ++r) {
    hits = 0;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays, 256), [&](const tbb::blocked_range<std::size_t>& range) {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      std::size_t local = 0;
      for (std::size_t i = range.begin(); i < range.end(); ++i) {
        RTCRayHit rh{};
        rh.ray.org_x = origins[3 * i];
        rh.ray.org_y = origins[3 * i + 1];
        rh.ray.org_z = origins[3 * i + 2];
        rh.ray.dir_x = directions[3 * i];
        rh.ray.dir_y = directions[3 * i + 1];
        rh.ray.dir_z = directions[3 * i + 2];
        rh.ray.tfar = std::numeric_limits<float>::infinity();
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(rtc, &context, &rh);
        local += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      }
      hits += local;
    });
  }
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  rtcReleaseScene(rtc);
  rtcReleaseDevice(device);
  return {static_cast<double>(rays) * repeats / seconds / 1e6, hits};
}

}  // namespace shtrace
