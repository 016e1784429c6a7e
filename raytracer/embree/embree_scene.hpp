#pragma once
// Embree 3 as the tracer's peer: the same triangles in an Embree scene, for
// the speed anchor of `shtrace bench` and the intersection oracle of the
// tests.  Not part of the tracer library, which does not need Embree.
#include <embree3/rtcore.h>

#include <cmath>

#include <sh/raytracer/scene.hpp>

namespace sh::rt {

class EmbreeScene {
 public:
  // robust: Embree's robust mode (RTC_SCENE_FLAG_ROBUST), which avoids
  // optimisations that lose hits on edges and vertices; else its default.
  explicit EmbreeScene(const Scene& scene, const char* device_config = nullptr, bool robust = true);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // rtcIntersect1 from o along d for t in [t_near, t_far): the filled ray hit.
  RTCRayHit intersect(Vec3 o, Vec3 d, float t_near = 0, float t_far = INFINITY) const;
  // rtcOccluded1: is anything hit for t in [t_near, t_far)?
  bool occluded(Vec3 o, Vec3 d, float t_near, float t_far) const;

  // rtcIntersect4/8/16 (or rtcOccluded4/8/16) on up to `packet` rays:
  // origins and directions as x,y,z triples, t in [t_near, t_far) (null:
  // from 0, without end); the triangles hit land in hit (-1: none; with
  // `occluded`, 0 where something is in the way).  The packet size must be
  // one Embree supports on this CPU (supports_packet).
  bool supports_packet(int packet) const;

  // The scene's build: wall time of the commit, and the bytes Embree
  // holds afterwards (its vertex and index buffers included: 48 per
  // triangle).
  double build_ms() const { return build_ms_; }
  std::size_t bytes() const { return static_cast<std::size_t>(bytes_); }
  void intersect_packet(int packet, int count, const float* origins, const float* directions, int* hit,
                        const float* t_near = nullptr, const float* t_far = nullptr, bool occluded = false) const;

 private:
  RTCDevice device_;
  RTCScene scene_;
  double build_ms_ = 0;
  long long bytes_ = 0;  // changed by Embree's memory monitor
};

}  // namespace sh::rt
