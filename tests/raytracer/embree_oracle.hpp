#pragma once
// Embree 3 as an independent oracle for the intersector: the same
// triangles, the same rays, rtcIntersect1.
#include <embree3/rtcore.h>

#include <vector>

#include <sh/raytracer.hpp>

namespace oracle {

struct Hit {
  float t = -1;         // -1: miss
  int triangle = -1;
  float u = 0, v = 0;   // Embree's barycentrics of the hit
};

class Embree {
 public:
  explicit Embree(const sh::rt::Scene& scene);
  ~Embree();
  Embree(const Embree&) = delete;
  Embree& operator=(const Embree&) = delete;
  Hit intersect(sh::rt::Vec3 o, sh::rt::Vec3 d) const;

 private:
  RTCDevice device_;
  RTCScene scene_;
};

}  // namespace oracle
