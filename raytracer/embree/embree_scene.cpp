#include "embree_scene.hpp"

#include <atomic>
#include <chrono>
#include <limits>
#include <string>

#include <sh/error.hpp>

namespace sh::rt {

namespace {

bool count_bytes(void* total, ssize_t bytes, bool) {
  *static_cast<std::atomic<long long>*>(total) += bytes;
  return true;
}

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene, const char* device_config, bool robust) {
  device_ = rtcNewDevice(device_config);
  if (!device_)
    throw Error(std::string("Embree: no device for the configuration \"") + (device_config ? device_config : "") +
                "\" (error " + std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  std::atomic<long long> allocated{0};
  rtcSetDeviceMemoryMonitorFunction(device_, count_bytes, &allocated);
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
  auto t0 = std::chrono::steady_clock::now();
  rtcCommitScene(scene_);
  build_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  rtcSetDeviceMemoryMonitorFunction(device_, nullptr, nullptr);
  bytes_ = allocated;
}

EmbreeScene::~EmbreeScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

namespace {

RTCRay ray_of(Vec3 o, Vec3 d, float t_near, float t_far) {
  RTCRay r{};
  r.org_x = o.x;
  r.org_y = o.y;
  r.org_z = o.z;
  r.dir_x = d.x;
  r.dir_y = d.y;
  r.dir_z = d.z;
  r.tnear = t_near;
  r.tfar = t_far;
  r.mask = ~0u;
  return r;
}

}  // namespace

RTCRayHit EmbreeScene::intersect(Vec3 o, Vec3 d, float t_near, float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh{};
  rh.ray = ray_of(o, d, t_near, t_far);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  return rh;
}

// Embree marks an occluded ray by setting tfar to -inf.
bool EmbreeScene::occluded(Vec3 o, Vec3 d, float t_near, float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay r = ray_of(o, d, t_near, t_far);
  rtcOccluded1(scene_, &context, &r);
  return r.tfar < 0;
}

bool EmbreeScene::supports_packet(int packet) const {
  RTCDeviceProperty p = packet == 4   ? RTC_DEVICE_PROPERTY_NATIVE_RAY4_SUPPORTED
                        : packet == 8 ? RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED
                                      : RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED;
  return (packet == 4 || packet == 8 || packet == 16) && rtcGetDeviceProperty(device_, p) != 0;
}

namespace {

// Embree's packets are structures of arrays; one template fills any size.
template <int N, class RayN>
void fill(RayN& ray, int* valid, int count, const float* o, const float* d, const float* t_near, const float* t_far) {
  for (int i = 0; i < N; ++i) {
    bool live = i < count;
    valid[i] = live ? -1 : 0;
    int k = live ? i : 0;
    ray.org_x[i] = o[3 * k];
    ray.org_y[i] = o[3 * k + 1];
    ray.org_z[i] = o[3 * k + 2];
    ray.dir_x[i] = d[3 * k];
    ray.dir_y[i] = d[3 * k + 1];
    ray.dir_z[i] = d[3 * k + 2];
    ray.tnear[i] = t_near ? t_near[k] : 0;
    ray.tfar[i] = t_far ? t_far[k] : std::numeric_limits<float>::infinity();
    ray.mask[i] = ~0u;
  }
}

template <int N, class RayHitN, class Intersect>
void trace_packet(RTCScene scene, int count, const float* o, const float* d, const float* t_near, const float* t_far,
                  int* hit, Intersect intersect) {
  alignas(64) RayHitN rh{};
  alignas(64) int valid[N];
  fill<N>(rh.ray, valid, count, o, d, t_near, t_far);
  for (int i = 0; i < N; ++i) rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  intersect(valid, scene, &context, &rh);
  for (int i = 0; i < count; ++i) hit[i] = rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? -1 : static_cast<int>(rh.hit.primID[i]);
}

template <int N, class RayN, class Occluded>
void occlude_packet(RTCScene scene, int count, const float* o, const float* d, const float* t_near, const float* t_far,
                    int* hit, Occluded occluded) {
  alignas(64) RayN ray{};
  alignas(64) int valid[N];
  fill<N>(ray, valid, count, o, d, t_near, t_far);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  occluded(valid, scene, &context, &ray);
  for (int i = 0; i < count; ++i) hit[i] = ray.tfar[i] < 0 ? 0 : -1;
}

}  // namespace

void EmbreeScene::intersect_packet(int packet, int count, const float* o, const float* d, int* hit,
                                   const float* t_near, const float* t_far, bool occluded) const {
  if (occluded) {
    switch (packet) {
      case 4: return occlude_packet<4, RTCRay4>(scene_, count, o, d, t_near, t_far, hit, rtcOccluded4);
      case 8: return occlude_packet<8, RTCRay8>(scene_, count, o, d, t_near, t_far, hit, rtcOccluded8);
      default: return occlude_packet<16, RTCRay16>(scene_, count, o, d, t_near, t_far, hit, rtcOccluded16);
    }
  }
  switch (packet) {
    case 4: return trace_packet<4, RTCRayHit4>(scene_, count, o, d, t_near, t_far, hit, rtcIntersect4);
    case 8: return trace_packet<8, RTCRayHit8>(scene_, count, o, d, t_near, t_far, hit, rtcIntersect8);
    default: return trace_packet<16, RTCRayHit16>(scene_, count, o, d, t_near, t_far, hit, rtcIntersect16);
  }
}

}  // namespace sh::rt
