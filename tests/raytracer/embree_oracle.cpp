#include "embree_oracle.hpp"

#include <limits>

#include "sh/error.hpp"

namespace oracle {

Embree::Embree(const sh::rt::Scene& scene) {
  device_ = rtcNewDevice("threads=1");
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  std::size_t n = scene.mesh.triangles();
  auto* vertices = static_cast<float*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
  auto* indices = static_cast<unsigned*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
  for (std::size_t i = 0; i < 3 * n; ++i) {
    vertices[3 * i] = scene.mesh.positions[i].x;
    vertices[3 * i + 1] = scene.mesh.positions[i].y;
    vertices[3 * i + 2] = scene.mesh.positions[i].z;
    indices[i] = static_cast<unsigned>(i);
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene_);
}

Embree::~Embree() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

Hit Embree::intersect(sh::rt::Vec3 o, sh::rt::Vec3 d) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = o.x;
  rh.ray.org_y = o.y;
  rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = std::numeric_limits<float>::min();  // hits at t > 0, as the intersector counts them
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {};
  return {rh.ray.tfar, static_cast<int>(rh.hit.primID), rh.hit.u, rh.hit.v};
}

}  // namespace oracle
