#pragma once
// `shtrace compare`: one of the scene's kernels run by sh::compare on every
// backend, variant and math mode, against the interpreter in f64.
#include <string>
#include <utility>
#include <vector>

#include <sh/raytracer.hpp>

namespace shtrace {

struct CompareRequest {
  sh::rt::Scene scene;
  sh::rt::RenderSettings settings;    // size, accelerator, depth; options: the rows' precision, threads, --set
  std::string kernel = "render";      // render: every pixel through the whole kernel; intersect: the intersector on primary rays
  std::vector<std::string> backends;  // empty: every one linked
  int runs = 3;
};

int compare_backends(const CompareRequest& request);

// Primary rays of the scene's camera, made by the raygen kernel on the
// default backend, in the renderer's 4x4-tile order (the same rays for
// every backend and for Embree): origins and directions, 3 floats each.
std::pair<std::vector<float>, std::vector<float>> primary_rays(sh::rt::Renderer& r, int width, int height);

}  // namespace shtrace
