#include "embree_scene.hpp"

#include <limits>

namespace sh::rt {

EmbreeScene::EmbreeScene(const Scene& scene, const char* device_config) {
  device_ = rtcNewDevice(device_config);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  std::size_t n = scene.mesh.triangles();
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, 3 * n));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, n));
  for (std::size_t i = 0; i < 3 * n; ++i) {
    v[3 * i] = scene.mesh.positions[i].x;
    v[3 * i + 1] = scene.mesh.positions[i].y;
    v[3 * i + 2] = scene.mesh.positions[i].z;
    idx[i] = static_cast<unsigned>(i);  // triangles keep the scene's numbering
  }
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene_, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene_);
}

EmbreeScene::~EmbreeScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

RTCRayHit EmbreeScene::intersect(Vec3 o, Vec3 d, float t_near) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray.org_x = o.x;
  rh.ray.org_y = o.y;
  rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = t_near;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  return rh;
}

}  // namespace sh::rt
