#pragma once
// `shtrace accel`: the grid, the static octree and the lazy octree on one
// scene and view -- memory, build, trace and time to the first image, and
// over mpi what each rank built lazily and how much of it overlaps.
#include <string>

#include <sh/raytracer.hpp>

namespace shtrace {

// Waves, nodes built and, with several ranks, builds per rank and overlap.
void print_lazy_builds(const sh::rt::RenderReport& report);

struct AccelOptions {
  sh::rt::Scene scene;
  sh::rt::RenderSettings settings;
  std::string view = "full";  // full, or half: the same camera turned to one half of the scene, narrower
};

int compare_accelerators(AccelOptions o);

}  // namespace shtrace
