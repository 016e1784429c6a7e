#pragma once
// `shtrace rays`: the kinds of rays a render traces -- camera rays, shadow
// rays to the first light and mirror reflections at the camera rays' hits
// each traced by the scene's kernels on one backend and by Embree on the
// same rays, and shadow rays both with the any-hit walk and with the
// nearest-hit one; camera, reflection and any-hit shadow rays also by the
// hand-written C++ walk of the same BVH (hand_walk.hpp), with whether it
// found the kernels' triangles and answers; and how busy the lanes are in
// the BVH's walk.
#include <sh/raytracer.hpp>

namespace shtrace {

struct RayKindsRequest {
  sh::rt::Scene scene;
  sh::rt::RenderSettings settings;  // size (camera rays), accelerator, backend, options
  int repeats = 5;                  // warm runs of each kernel, timed together
  bool lanes = false;               // also the BVH walk's lane counts for each kind
};

int compare_ray_kinds(const RayKindsRequest& request);

}  // namespace shtrace
