#pragma once
// Embree 3 as an independent oracle for the intersector: the same
// triangles, the same rays, rtcIntersect1, hits at t > 0 as the intersector
// counts them.
#include <embree_scene.hpp>

namespace oracle {

struct Hit {
  float t = -1;         // -1: miss
  int triangle = -1;
  float u = 0, v = 0;   // Embree's barycentrics of the hit
};

class Embree {
 public:
  explicit Embree(const sh::rt::Scene& scene) : scene_(scene, "threads=1") {}
  Hit intersect(sh::rt::Vec3 o, sh::rt::Vec3 d) const;

 private:
  sh::rt::EmbreeScene scene_;
};

}  // namespace oracle
