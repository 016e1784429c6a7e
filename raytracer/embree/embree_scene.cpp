#include "embree_scene.hpp"

#include <limits>

namespace sh::rt {

EmbreeScene::EmbreeScene(const Scene& scene, const char* device_config, bool robust) {
  device_ = rtcNewDevice(device_config);
  scene_ = rtcNewScene(device_);
  if (robust) rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
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

bool EmbreeScene::supports_packet(int packet) const {
  RTCDeviceProperty p = packet == 4   ? RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED
                        : packet == 8 ? RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED
                                      : RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED;
  return (packet == 4 || packet == 8 || packet == 16) && rtcGetDeviceProperty(device_, p) != 0;
}

namespace {

// Embree's packets are structures of arrays; one template fills any size.
template <int N, class RayHitN, class Intersect>
void trace_packet(RTCScene scene, int count, const float* o, const float* d, int* hit, Intersect intersect) {
  alignas(64) RayHitN rh{};
  alignas(64) int valid[N];
  for (int i = 0; i < N; ++i) {
    bool live = i < count;
    valid[i] = live ? -1 : 0;
    int k = live ? i : 0;
    rh.ray.org_x[i] = o[3 * k];
    rh.ray.org_y[i] = o[3 * k + 1];
    rh.ray.org_z[i] = o[3 * k + 2];
    rh.ray.dir_x[i] = d[3 * k];
    rh.ray.dir_y[i] = d[3 * k + 1];
    rh.ray.dir_z[i] = d[3 * k + 2];
    rh.ray.tnear[i] = 0;
    rh.ray.tfar[i] = std::numeric_limits<float>::infinity();
    rh.ray.mask[i] = ~0u;
    rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  intersect(valid, scene, &context, &rh);
  for (int i = 0; i < count; ++i) hit[i] = rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int>(rh.hit.primID[i]);
}

}  // namespace

void EmbreeScene::intersect_packet(int packet, int count, const float* origins, const float* directions, int* hit) const {
  switch (packet) {
    case 4: return trace_packet<4, RTCRayHit4>(scene_, count, origins, directions, hit, rtcIntersect4);
    case 8: return trace_packet<8, RTCRayHit8>(scene_, count, origins, directions, hit, rtcIntersect8);
    default: return trace_packet<16, RTCRayHit16>(scene_, count, origins, directions, hit, rtcIntersect16);
  }
}

}  // namespace sh::rt
